// SPDX-License-Identifier: MIT
// The one config reader: a read-only view of a YAML document that remembers where every value
// came from and which keys a loader asked for, so that loaders name each key once and report
// "world.yaml:12:7: devices.M1.x: must be > 0 (got -1)" (docs/world-config.md, "Errors").
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "llsf/core/error.h"

namespace llsf::core {

/// A bound on a number, with the one wording every loader and validate() uses for it. Make one
/// with the functions below (positive(), in_range(0, 1), ...).
struct Bound {
  enum class Kind { kFinite, kGreater, kAtLeast, kAtMost, kClosed, kOpenClosed, kPort };
  Kind kind = Kind::kFinite;
  double lo = 0.0;
  double hi = 0.0;

  /// Empty if `v` satisfies the bound, else the reason, e.g. "must be > 0 (got -1)".
  std::string violation(double v) const;
};

/// A finite number: "must be a finite number (got inf)".
constexpr Bound finite() { return {Bound::Kind::kFinite}; }
/// Finite and > 0: "must be > 0 (got -1)".
constexpr Bound positive() { return {Bound::Kind::kGreater, 0.0}; }
/// Finite and >= 0: "must be >= 0 (got -1)".
constexpr Bound non_negative() { return {Bound::Kind::kAtLeast, 0.0}; }
/// Finite and >= lo: "must be >= 1 (got 0.5)".
constexpr Bound at_least(double lo) { return {Bound::Kind::kAtLeast, lo}; }
/// <= hi (any smaller number): "must be at most 60 (got 61)".
constexpr Bound at_most(double hi) { return {Bound::Kind::kAtMost, 0.0, hi}; }
/// In [lo, hi]: "must be in [1, 100] (got 0)".
constexpr Bound in_range(double lo, double hi) { return {Bound::Kind::kClosed, lo, hi}; }
/// In [0, 1]: "must be in [0, 1] (got 2)".
constexpr Bound probability() { return in_range(0.0, 1.0); }
/// In (0, 1]: "must be in (0, 1] (got 0)".
constexpr Bound fraction() { return {Bound::Kind::kOpenClosed, 0.0, 1.0}; }
/// A UDP/TCP port, 0 for "any": "must be a port in [0, 65535] (got 70000)".
constexpr Bound port() { return {Bound::Kind::kPort, 0.0, 65535.0}; }

/// Throws ConfigError "<path>: <reason>" if `v` violates `bound`; for validate() of a config
/// struct built in code (a loader reports the same failure with file:line, see
/// ConfigNode::locate_errors).
void require(std::string_view path, double v, const Bound& bound);

/// Shortest text that reads back as `v` ("0.1", "1e-05", "3"; whole numbers in full, "100000"),
/// as messages print numbers.
std::string number_text(double v);

/// The limits of strict YAML (docs/security.md, "Strict input files"): nodes of a document once
/// its aliases are expanded, and maps and lists inside each other.
inline constexpr std::uint64_t kMaxYamlNodes = 1'000'000;
inline constexpr int kMaxYamlDepth = 64;

/// Throws ConfigError "<source>:<line>:<column>: <path>: <what>" unless `text` is strict YAML:
/// UTF-8 text without NUL bytes, at most 16 MiB, no key twice in a map, at most kMaxYamlNodes
/// nodes with aliases expanded, no alias inside its own anchor, at most kMaxYamlDepth levels.
/// ConfigNode::parse() and load_file() check this first.
void check_strict_yaml(std::string_view text, const std::string& source_name);

/// A path of a config struct's validate() messages (`from`, e.g. "game.skill_rate_hz") and the
/// key of the document it comes from (`to`, e.g. "rates.skill_hz"; "" for the document's root):
/// for ConfigNode::locate_errors().
struct PathRename {
  std::string_view from;
  std::string_view to;
};

/// A node of a parsed YAML document with its source name, line/column and dotted path.
/// Cheap to copy (shares the document). Every failing accessor throws ConfigError with
/// "<source>:<line>:<column>: <path>: <what>".
class ConfigNode {
 public:
  /// Parses a file; throws ConfigError naming the file (and line) if it cannot be read (see
  /// read_input_file(): a regular file of at most 16 MiB) or parsed (see check_strict_yaml()).
  static ConfigNode load_file(const std::string& path);
  /// Parses strict YAML (check_strict_yaml()); `source_name` appears in error messages in place of
  /// a file name.
  static ConfigNode parse(std::string_view text, const std::string& source_name);

  ConfigNode();
  ~ConfigNode();
  ConfigNode(const ConfigNode&);
  ConfigNode& operator=(const ConfigNode&);

  /// False for a key that is not present.
  bool defined() const;
  bool is_null() const;
  bool is_map() const;
  bool is_sequence() const;
  bool is_scalar() const;
  /// Number of entries of a map or sequence (0 for scalars).
  int size() const;

  /// The child under `key`, possibly undefined (check with defined()).
  ConfigNode operator[](std::string_view key) const;
  /// The child under `key`; throws if absent.
  ConfigNode at(std::string_view key) const;
  /// The i-th element of a sequence.
  ConfigNode at(int index) const;
  /// The keys of a map, in document order; throws if this is not a map.
  std::vector<std::string> keys() const;
  /// The elements of a sequence; throws if this is not a sequence.
  std::vector<ConfigNode> elements() const;
  /// Throws naming the first key of this map that no accessor (operator[], at, read) asked for
  /// -- a typo or a key the loader does not know -- at its file:line, with "did you mean" when
  /// an asked-for key is close. A loader reads each key once, then calls this once per map.
  /// Does nothing for an undefined, null or non-map node.
  void no_other_keys() const;
  /// Throws if this node is defined and is not a map (a null node counts as an empty map).
  void require_map() const;

  double as_double() const;
  std::int64_t as_int() const;
  bool as_bool() const;
  std::string as_string() const;
  /// As as_double() / as_int(), then fails at this node if the value violates `bound`
  /// ("must be > 0 (got -1)"): for a value that is not simply stored by read().
  double as_double(const Bound& bound) const;
  std::int64_t as_int(const Bound& bound) const;

  /// If `key` is present, parses it into `out`; otherwise leaves `out` unchanged.
  void read(std::string_view key, double& out) const;
  void read(std::string_view key, int& out) const;
  void read(std::string_view key, std::int64_t& out) const;
  void read(std::string_view key, bool& out) const;
  void read(std::string_view key, std::string& out) const;
  /// As read(), then fails at the value if it violates `bound` ("must be > 0 (got -1)").
  void read(std::string_view key, double& out, const Bound& bound) const;
  void read(std::string_view key, int& out, const Bound& bound) const;
  /// If `key` is present, it must be one of the `names`; `out` becomes the matching value.
  /// Fails with "unknown <what> 'x' (expected one of: a, b)".
  template <class E>
  void read_enum(std::string_view key, E& out,
                 std::initializer_list<std::pair<std::string_view, E>> names,
                 std::string_view what = "value") const {
    const ConfigNode c = (*this)[key];
    if (!c.defined()) return;
    const std::string s = c.as_string();
    std::string list;
    for (const auto& [name, value] : names) {
      if (name == s) {
        out = value;
        return;
      }
      list += (list.empty() ? "" : ", ") + std::string(name);
    }
    c.fail("unknown " + std::string(what) + " '" + s + "' (expected one of: " + list + ")");
  }

  /// Replaces the value at `dotted_path` (map keys joined by '.', relative to this map node;
  /// missing maps on the way are created) by `value` and returns this node. Errors about the
  /// replaced part then name `value`'s location. This changes the parsed document that every
  /// ConfigNode of the same parse shares: parse the text again for an unchanged copy (scenario
  /// matrices do).
  ConfigNode& set(std::string_view dotted_path, const ConfigNode& value);

  /// Dotted path from the document root, e.g. "devices.M1.x" or "robots[2].start".
  const std::string& path() const;
  /// "<source>:<line>:<column>" of this node (of its parent for an undefined key).
  std::string location() const;
  /// Throws ConfigError "<location>: <path>: <message>".
  [[noreturn]] void fail(const std::string& message) const;

  /// The node at `relative_path` ("a.b[2].c", relative to this node), or the deepest node on
  /// the way that exists in the document.
  ConfigNode resolve(std::string_view relative_path) const;
  /// Throws ConfigError "<location>: <path>.<relative_path>: <reason>" at the node resolve()
  /// finds -- or, if only an ancestor exists, at a deeper path that `reason` names and that the
  /// document has (so "devices.M4: footprint overlaps devices.M8" points at a moved M8).
  [[noreturn]] void fail_at(std::string_view relative_path, const std::string& reason) const;
  /// Runs `check` (typically a config struct's validate()) and re-throws a ConfigError
  /// "<relative.path>: <reason>" from it with fail_at(): the one way loaders put file:line on
  /// validate() errors.
  template <class F>
  void locate_errors(F&& check) const {
    try {
      std::forward<F>(check)();
    } catch (const ConfigError& e) {
      relocate(e);
    }
  }
  /// As locate_errors(check), for a check whose paths are not the document's keys (a config
  /// struct's validate() names "game.skill_rate_hz" for the key rates.skill_hz): each `renames`
  /// entry whose `from` starts the error's path (up to a '.' or '[', or ending in '[') turns it
  /// into `to` + the rest. Of several matches, the first whose whole path is in the document
  /// wins, else the one that reaches deepest into it; with none, the path is kept. The message
  /// then names the renamed path at its node's file:line.
  template <class F>
  void locate_errors(F&& check, std::span<const PathRename> renames) const {
    try {
      std::forward<F>(check)();
    } catch (const ConfigError& e) {
      relocate(e, renames);
    }
  }
  /// fail_at() for a message "<relative.path>: <reason>" (a message without a leading path is
  /// reported at this node), the path renamed by `renames` as for locate_errors().
  [[noreturn]] void relocate(const ConfigError& e, std::span<const PathRename> renames = {}) const;

 private:
  struct Impl;
  explicit ConfigNode(std::shared_ptr<const Impl> impl);
  std::shared_ptr<const Impl> impl_;
};

}  // namespace llsf::core
