// SPDX-License-Identifier: MIT
// Config-loading helpers: a read-only view of a YAML document that remembers where every value
// came from, so that loaders can report "world.yaml:12:7: devices.M1.x: expected a number".
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "llsf/core/error.h"

namespace llsf::core {

/// A node of a parsed YAML document with its source name, line/column and dotted path.
/// Cheap to copy (shares the document). Every failing accessor throws ConfigError with
/// "<source>:<line>:<column>: <path>: <what>".
class ConfigNode {
 public:
  /// Parses a file; throws ConfigError naming the file (and line) if it cannot be read or parsed.
  static ConfigNode load_file(const std::string& path);
  /// Parses text; `source_name` appears in error messages in place of a file name.
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
  /// Throws naming the first key of this map that is not in `allowed` (catches typos).
  void check_keys(std::initializer_list<std::string_view> allowed) const;
  /// Throws if this node is defined and is not a map (a null node counts as an empty map).
  void require_map() const;

  double as_double() const;
  std::int64_t as_int() const;
  bool as_bool() const;
  std::string as_string() const;

  /// If `key` is present, parses it into `out`; otherwise leaves `out` unchanged.
  void read(std::string_view key, double& out) const;
  void read(std::string_view key, int& out) const;
  void read(std::string_view key, std::int64_t& out) const;
  void read(std::string_view key, bool& out) const;
  void read(std::string_view key, std::string& out) const;

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

 private:
  struct Impl;
  explicit ConfigNode(std::shared_ptr<const Impl> impl);
  std::shared_ptr<const Impl> impl_;
};

}  // namespace llsf::core
