// SPDX-License-Identifier: MIT
// Reading an input file (a scenario, a config YAML, an agent's CLIPS file, a Lua skill, a rule
// test) safely: only a regular file (a named pipe would block, /dev/zero never ends), only up to a
// size limit, and only text without NUL bytes. docs/security.md, "Strict input files".
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

namespace llsf::core {

/// The limit on the size of a source or config file: YAML, CLIPS, Lua, rule tests (16 MiB).
inline constexpr std::uint64_t kMaxSourceBytes = std::uint64_t{16} << 20;

/// The text of the file at `path`. Throws ConfigError, without ever opening a file that is not a
/// regular one:
///   "PATH: cannot open file: cannot read the WHAT (No such file or directory)", then
///   " (did you mean 'NEAR'?)" when the folder has a name near it (near_path)
///   "PATH: not a regular file (a named pipe); the WHAT must be one"
///   "PATH: 2.0 GiB is over the limit of 16 MiB for the WHAT"
///   "PATH:LINE:COLUMN: a NUL byte: the WHAT must be text"
/// `what` names the kind of file, e.g. "scenario file".
std::string read_input_file(const std::string& path, std::uint64_t max_bytes,
                            std::string_view what);

/// As read_input_file(), but returns nullopt and sets `error` to the message instead of throwing
/// (for loaders with their own error type).
std::optional<std::string> try_read_input_file(const std::string& path, std::uint64_t max_bytes,
                                               std::string_view what, std::string& error);

/// For a path that does not exist: the path with its last part replaced by the name of its
/// folder's entry nearest to it (a likely typo: `scenarios/defualt.yaml` ->
/// `scenarios/default.yaml`; core::closest_match), else nullopt (the folder missing, or nothing
/// near). Reads at most 10,000 entries of the folder.
std::optional<std::string> near_path(const std::string& path);

/// " (did you mean 'NEAR'?)" for near_path(path), else "".
std::string near_path_hint(const std::string& path);

/// A byte count for messages: "512 bytes", "1.5 KiB", "16 MiB", "2.0 GiB".
std::string byte_size_text(std::uint64_t bytes);

/// The 1-based line and column (in characters, counting a UTF-8 sequence as one) of byte
/// `offset` of `text`.
struct TextPosition {
  int line = 1;
  int column = 1;
};
TextPosition text_position(std::string_view text, std::size_t offset);

/// Offset of the first NUL byte of `text`, or nullopt.
std::optional<std::size_t> find_nul(std::string_view text);
/// Offset of the first byte of `text` that does not start or continue a valid UTF-8 sequence
/// (overlong forms, surrogates and code points past U+10FFFF count as invalid), or nullopt.
std::optional<std::size_t> find_invalid_utf8(std::string_view text);

}  // namespace llsf::core
