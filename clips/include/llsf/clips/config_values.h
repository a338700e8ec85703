// SPDX-License-Identifier: MIT
// ConfigEntry: configuration values handed to an agent as Fawkes-style `confval` facts,
// (confval (path "/x/y") (type FLOAT|UINT|INT|BOOL|STRING) (value ..) (is-list FALSE)
// (list-value)).
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "llsf/clips/value.h"

namespace llsf::core {
class ConfigNode;
}

namespace llsf::clips {

/// Type of a config value (the symbols of confval's `type` slot).
enum class ConfigType : std::uint8_t { kFloat, kUint, kInt, kBool, kString };

/// "FLOAT", "UINT", "INT", "BOOL", "STRING".
const char* to_string(ConfigType type);

/// One config value or list. Values are CLIPS values: FLOAT/INTEGER numbers, the symbols
/// TRUE/FALSE for BOOL, STRING for strings.
struct ConfigEntry {
  std::string path;  ///< "/clips-agent/llsf2013/team-name"
  ConfigType type = ConfigType::kString;
  bool is_list = false;
  std::vector<Value> values;  ///< one value, or the list's elements

  static ConfigEntry of(std::string path, double v);
  static ConfigEntry of(std::string path, std::int64_t v);  ///< UINT if >= 0, else INT
  static ConfigEntry of(std::string path, int v) { return of(std::move(path), std::int64_t{v}); }
  static ConfigEntry of(std::string path, bool v);
  static ConfigEntry of(std::string path, std::string v);
  static ConfigEntry of(std::string path, const char* v) {
    return of(std::move(path), std::string(v));
  }
  static ConfigEntry list(std::string path, std::vector<std::string> v);
  static ConfigEntry list(std::string path, std::vector<double> v);
};

using ConfigEntries = std::vector<ConfigEntry>;

/// Flattens a YAML map into entries: nested keys join with '/' under `prefix` ("/clips-agent"),
/// scalars become BOOL (true/false), INT/UINT (integers), FLOAT (numbers) or STRING, sequences of
/// scalars become lists (typed by their first element). Throws core::ConfigError (with file:line)
/// for a sequence holding maps or sequences.
ConfigEntries config_from_node(const core::ConfigNode& node, std::string_view prefix = "");

}  // namespace llsf::clips
