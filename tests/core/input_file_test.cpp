// SPDX-License-Identifier: MIT
// Tests of read_input_file: only regular files, a size limit, no NUL bytes
// (docs/security.md, "Strict input files").
#include <doctest/doctest.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <unistd.h>

#include <cstring>
#include <filesystem>
#include <string>

#include "llsf/core/error.h"
#include "llsf/core/input_file.h"
#include "support/temp_dir.h"

using llsf::core::ConfigError;
using llsf::core::kMaxSourceBytes;
using llsf::core::read_input_file;

namespace {

/// The message read_input_file() throws for `path`, or "" if it reads the file.
std::string read_error(const std::string& path, std::uint64_t max = kMaxSourceBytes) {
  try {
    (void)read_input_file(path, max, "scenario file");
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST_CASE("read_input_file reads a regular file, also through a symbolic link") {
  const llsf::test::TempDir dir;
  dir.write("a.yaml", "name: a\n");
  std::filesystem::create_symlink(dir.file("a.yaml"), dir.file("link.yaml"));
  CHECK(read_input_file(dir.file("a.yaml"), kMaxSourceBytes, "scenario file") == "name: a\n");
  CHECK(read_input_file(dir.file("link.yaml"), kMaxSourceBytes, "scenario file") == "name: a\n");
  dir.write("empty.yaml", "");
  CHECK(read_input_file(dir.file("empty.yaml"), kMaxSourceBytes, "scenario file").empty());
}

TEST_CASE("read_input_file refuses what is not a regular file, without opening it") {
  const llsf::test::TempDir dir;
  const std::string d = dir.path.string();
  CHECK(read_error(d) == d + ": not a regular file (a directory); the scenario file must be one");
  // A named pipe: opening it would wait for a writer forever.
  REQUIRE(::mkfifo(dir.file("p.yaml").c_str(), 0600) == 0);
  CHECK(read_error(dir.file("p.yaml")) ==
        dir.file("p.yaml") + ": not a regular file (a named pipe); the scenario file must be one");
  // /dev/zero never ends; through a link, as a hostile scenario would give it.
  std::filesystem::create_symlink("/dev/zero", dir.file("z.yaml"));
  CHECK(read_error(dir.file("z.yaml")) ==
        dir.file("z.yaml") +
            ": not a regular file (a character device); the scenario file must be one");
  // A socket.
  const int s = ::socket(AF_UNIX, SOCK_STREAM, 0);
  REQUIRE(s >= 0);
  sockaddr_un addr{};
  addr.sun_family = AF_UNIX;
  const std::string sock = dir.file("s.yaml");
  REQUIRE(sock.size() < sizeof addr.sun_path);
  std::strncpy(addr.sun_path, sock.c_str(), sizeof addr.sun_path - 1);
  REQUIRE(::bind(s, reinterpret_cast<const sockaddr*>(&addr), sizeof addr) == 0);
  CHECK(read_error(sock) ==
        sock + ": not a regular file (a socket); the scenario file must be one");
  ::close(s);
}

TEST_CASE("read_input_file refuses a file over the limit before reading it") {
  const llsf::test::TempDir dir;
  // A sparse file of 100 MiB: refused by its size, not after reading it.
  { std::ofstream(dir.file("big.yaml")); }
  std::filesystem::resize_file(dir.file("big.yaml"), std::uint64_t{100} << 20);
  CHECK(read_error(dir.file("big.yaml")) ==
        dir.file("big.yaml") + ": 100 MiB is over the limit of 16 MiB for the scenario file");
  std::filesystem::resize_file(dir.file("big.yaml"), (std::uint64_t{5} << 30) / 2);
  CHECK(read_error(dir.file("big.yaml")) ==
        dir.file("big.yaml") + ": 2.5 GiB is over the limit of 16 MiB for the scenario file");
  dir.write("small.yaml", "0123456789");
  CHECK(read_error(dir.file("small.yaml"), 10).empty());
  CHECK(read_error(dir.file("small.yaml"), 9) ==
        dir.file("small.yaml") + ": 10 bytes is over the limit of 9 bytes for the scenario file");
}

TEST_CASE("read_input_file refuses NUL bytes at their line and column") {
  const llsf::test::TempDir dir;
  std::ofstream(dir.file("n.clp"), std::ios::binary) << std::string("(a)\n(b \xc3\xa4\0)\n", 11);
  CHECK(read_error(dir.file("n.clp")) ==
        dir.file("n.clp") + ":2:5: a NUL byte: the scenario file must be text");
}

TEST_CASE("read_input_file names a file it cannot open; try_read_input_file returns the message") {
  CHECK(read_error("/no/such/file.yaml") ==
        "/no/such/file.yaml: cannot open file: cannot read the scenario file (No such file or "
        "directory)");
  std::string error;
  CHECK_FALSE(llsf::core::try_read_input_file("/no/such/a.clp", kMaxSourceBytes, "CLIPS agent file",
                                              error));
  CHECK(error ==
        "/no/such/a.clp: cannot open file: cannot read the CLIPS agent file (No such file or "
        "directory)");
  const llsf::test::TempDir dir;
  dir.write("a.clp", "(defrule r =>)\n");
  CHECK(llsf::core::try_read_input_file(dir.file("a.clp"), kMaxSourceBytes, "CLIPS agent file",
                                        error) == "(defrule r =>)\n");
  CHECK(error.empty());
}

TEST_CASE("a misspelt file name gets the near name of its folder") {
  const llsf::test::TempDir dir;
  dir.write("default.yaml", "name: a\n");
  dir.write("other.yaml", "name: b\n");
  CHECK(read_error(dir.file("defualt.yaml")) ==
        dir.file("defualt.yaml") +
            ": cannot open file: cannot read the scenario file (No such file or directory) (did "
            "you mean '" +
            dir.file("default.yaml") + "'?)");
  CHECK(llsf::core::near_path(dir.file("defualt.yaml")) == dir.file("default.yaml"));
  // Nothing near, or no such folder: no hint.
  CHECK(llsf::core::near_path(dir.file("zzzzzzzz.yaml")) == std::nullopt);
  CHECK(llsf::core::near_path(dir.file("no-dir/default.yaml")) == std::nullopt);
  CHECK(llsf::core::near_path_hint(dir.file("zzzzzzzz.yaml")).empty());
}

TEST_CASE("byte_size_text, text_position and find_invalid_utf8") {
  using llsf::core::byte_size_text;
  CHECK(byte_size_text(1) == "1 byte");
  CHECK(byte_size_text(1023) == "1023 bytes");
  CHECK(byte_size_text(1536) == "1.5 KiB");
  CHECK(byte_size_text(kMaxSourceBytes) == "16 MiB");
  CHECK(byte_size_text(std::uint64_t{2147483648}) == "2 GiB");
  const auto p = llsf::core::text_position(
      "ab\nc\xc3\xa4"
      "d",
      6);
  CHECK(p.line == 2);
  CHECK(p.column == 3);
  using llsf::core::find_invalid_utf8;
  CHECK_FALSE(find_invalid_utf8("plain, \xc3\xa4, \xe2\x82\xac, \xf0\x9f\x98\x80"));
  CHECK(find_invalid_utf8("a\x80") == 1u);             // a continuation byte alone
  CHECK(find_invalid_utf8("ab\xc3") == 2u);            // cut short
  CHECK(find_invalid_utf8("\xc0\xaf") == 0u);          // overlong '/'
  CHECK(find_invalid_utf8("\xe0\x80\xaf") == 0u);      // overlong, 3 bytes
  CHECK(find_invalid_utf8("x\xed\xa0\x80") == 1u);     // a surrogate
  CHECK(find_invalid_utf8("\xf4\x90\x80\x80") == 0u);  // past U+10FFFF
  CHECK(find_invalid_utf8("\xc3(") == 0u);             // a start byte without continuation
}
