// SPDX-License-Identifier: MIT
#include "llsf/core/input_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <vector>

#include "llsf/core/error.h"
#include "llsf/core/text.h"

namespace llsf::core {

namespace {

/// What a file that is not a regular one is, for the message.
const char* kind_of(mode_t mode) {
  if (S_ISDIR(mode)) return "a directory";
  if (S_ISFIFO(mode)) return "a named pipe";
  if (S_ISCHR(mode)) return "a character device";
  if (S_ISBLK(mode)) return "a block device";
  if (S_ISSOCK(mode)) return "a socket";
  return "not a file";
}

/// Closes a file descriptor on every way out.
struct Fd {
  int fd = -1;
  ~Fd() {
    if (fd >= 0) ::close(fd);
  }
};

std::string read_or_throw(const std::string& path, std::uint64_t max_bytes, std::string_view what) {
  const std::string kind(what);
  const auto cannot_open = [&](int err) {
    return ConfigError(path + ": cannot open file: cannot read the " + kind + " (" +
                       std::strerror(err) + ")" + (err == ENOENT ? near_path_hint(path) : ""));
  };
  const auto not_regular = [&](mode_t mode) {
    return ConfigError(path + ": not a regular file (" + kind_of(mode) + "); the " + kind +
                       " must be one");
  };
  const auto too_big = [&](std::uint64_t size, bool at_least) {
    return ConfigError(path + ": " + (at_least ? "more than " : "") + byte_size_text(size) +
                       " is over the limit of " + byte_size_text(max_bytes) + " for the " + kind);
  };
  // stat() follows symbolic links: a link to /dev/zero or to a named pipe is refused here,
  // before open() (which would block on a named pipe until a writer comes).
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) throw cannot_open(errno);
  if (!S_ISREG(st.st_mode)) throw not_regular(st.st_mode);
  if (static_cast<std::uint64_t>(st.st_size) > max_bytes) {
    throw too_big(static_cast<std::uint64_t>(st.st_size), false);
  }
  // O_NONBLOCK: should the path have become a named pipe since stat(), open() does not wait.
  Fd f{::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NOCTTY | O_NONBLOCK)};
  if (f.fd < 0) throw cannot_open(errno);
  if (::fstat(f.fd, &st) != 0) throw cannot_open(errno);
  if (!S_ISREG(st.st_mode)) throw not_regular(st.st_mode);
  std::string text;
  text.reserve(static_cast<std::size_t>(st.st_size));
  char buf[65536];
  while (true) {
    const ssize_t n = ::read(f.fd, buf, sizeof buf);
    if (n < 0) {
      if (errno == EINTR) continue;
      throw ConfigError(path + ": cannot read the " + kind + " (" + std::strerror(errno) + ")");
    }
    if (n == 0) break;
    // A file that grows while it is read stops at the limit all the same.
    if (text.size() + static_cast<std::size_t>(n) > max_bytes) throw too_big(max_bytes, true);
    text.append(buf, static_cast<std::size_t>(n));
  }
  if (const std::optional<std::size_t> nul = find_nul(text)) {
    const TextPosition p = text_position(text, *nul);
    throw ConfigError(path + ":" + std::to_string(p.line) + ":" + std::to_string(p.column) +
                      ": a NUL byte: the " + kind + " must be text");
  }
  return text;
}

}  // namespace

std::optional<std::string> near_path(const std::string& path) {
  namespace fs = std::filesystem;
  const fs::path p(path);
  const std::string name = p.filename().string();
  if (name.empty()) return std::nullopt;
  const fs::path dir = p.parent_path();
  std::error_code ec;
  std::vector<std::string> names;
  for (fs::directory_iterator it(dir.empty() ? fs::path(".") : dir, ec), end; !ec && it != end;
       it.increment(ec)) {
    if (names.size() == 10000) break;
    names.push_back(it->path().filename().string());
  }
  if (ec) return std::nullopt;
  std::sort(names.begin(), names.end());  // ties go to the first in name order
  const std::optional<std::string> m = closest_match(name, names);
  if (!m) return std::nullopt;
  return (dir / *m).string();
}

std::string near_path_hint(const std::string& path) {
  const std::optional<std::string> m = near_path(path);
  return m ? " (did you mean '" + *m + "'?)" : "";
}

std::string read_input_file(const std::string& path, std::uint64_t max_bytes,
                            std::string_view what) {
  return read_or_throw(path, max_bytes, what);
}

std::optional<std::string> try_read_input_file(const std::string& path, std::uint64_t max_bytes,
                                               std::string_view what, std::string& error) {
  try {
    std::string text = read_or_throw(path, max_bytes, what);
    error.clear();
    return text;
  } catch (const ConfigError& e) {
    error = e.what();
    return std::nullopt;
  }
}

std::string byte_size_text(std::uint64_t bytes) {
  static constexpr const char* kUnits[] = {"KiB", "MiB", "GiB", "TiB", "PiB", "EiB"};
  if (bytes < 1024) return std::to_string(bytes) + (bytes == 1 ? " byte" : " bytes");
  std::uint64_t unit = 1024;
  int u = 0;
  while (u + 1 < 6 && bytes / unit >= 1024) {
    unit *= 1024;
    ++u;
  }
  char buf[64];
  if (bytes % unit == 0) {
    std::snprintf(buf, sizeof buf, "%llu %s", static_cast<unsigned long long>(bytes / unit),
                  kUnits[u]);
  } else {
    std::snprintf(buf, sizeof buf, "%.1f %s",
                  static_cast<double>(bytes) / static_cast<double>(unit), kUnits[u]);
  }
  return buf;
}

TextPosition text_position(std::string_view text, std::size_t offset) {
  TextPosition p;
  const std::size_t end = std::min(offset, text.size());
  for (std::size_t i = 0; i < end; ++i) {
    const auto c = static_cast<unsigned char>(text[i]);
    if (c == '\n') {
      ++p.line;
      p.column = 1;
    } else if ((c & 0xC0) != 0x80) {  // not a UTF-8 continuation byte
      ++p.column;
    }
  }
  return p;
}

std::optional<std::size_t> find_nul(std::string_view text) {
  const std::size_t at = text.find('\0');
  if (at == std::string_view::npos) return std::nullopt;
  return at;
}

std::optional<std::size_t> find_invalid_utf8(std::string_view text) {
  const std::size_t n = text.size();
  std::size_t i = 0;
  while (i < n) {
    const auto c = static_cast<unsigned char>(text[i]);
    if (c < 0x80) {
      ++i;
      continue;
    }
    int len = 0;
    std::uint32_t cp = 0;
    if (c >= 0xC2 && c <= 0xDF) {
      len = 2;
      cp = c & 0x1Fu;
    } else if (c >= 0xE0 && c <= 0xEF) {
      len = 3;
      cp = c & 0x0Fu;
    } else if (c >= 0xF0 && c <= 0xF4) {
      len = 4;
      cp = c & 0x07u;
    } else {
      return i;  // a continuation byte without a start, 0xC0/0xC1 (overlong) or 0xF5..0xFF
    }
    if (i + static_cast<std::size_t>(len) > n) return i;
    for (int k = 1; k < len; ++k) {
      const auto cc = static_cast<unsigned char>(text[i + static_cast<std::size_t>(k)]);
      if ((cc & 0xC0) != 0x80) return i;
      cp = (cp << 6) | (cc & 0x3Fu);
    }
    const bool overlong = (len == 3 && cp < 0x800) || (len == 4 && cp < 0x10000);
    if (overlong || (cp >= 0xD800 && cp <= 0xDFFF) || cp > 0x10FFFF) return i;
    i += static_cast<std::size_t>(len);
  }
  return std::nullopt;
}

}  // namespace llsf::core
