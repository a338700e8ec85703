// SPDX-License-Identifier: MIT
// ConfigEntry constructors and the YAML flattening.
#include "llsf/clips/config_values.h"

#include <charconv>

#include "llsf/core/config.h"

namespace llsf::clips {

const char* to_string(ConfigType type) {
  switch (type) {
    case ConfigType::kFloat:
      return "FLOAT";
    case ConfigType::kUint:
      return "UINT";
    case ConfigType::kInt:
      return "INT";
    case ConfigType::kBool:
      return "BOOL";
    case ConfigType::kString:
      return "STRING";
  }
  return "STRING";
}

ConfigEntry ConfigEntry::of(std::string path, double v) {
  return {std::move(path), ConfigType::kFloat, false, {Value::float_value(v)}};
}

ConfigEntry ConfigEntry::of(std::string path, std::int64_t v) {
  return {std::move(path),
          v >= 0 ? ConfigType::kUint : ConfigType::kInt,
          false,
          {Value::integer_value(v)}};
}

ConfigEntry ConfigEntry::of(std::string path, bool v) {
  return {std::move(path), ConfigType::kBool, false, {Value::boolean(v)}};
}

ConfigEntry ConfigEntry::of(std::string path, std::string v) {
  return {std::move(path), ConfigType::kString, false, {Value::string(std::move(v))}};
}

ConfigEntry ConfigEntry::list(std::string path, std::vector<std::string> v) {
  ConfigEntry e{std::move(path), ConfigType::kString, true, {}};
  for (auto& s : v) e.values.push_back(Value::string(std::move(s)));
  return e;
}

ConfigEntry ConfigEntry::list(std::string path, std::vector<double> v) {
  ConfigEntry e{std::move(path), ConfigType::kFloat, true, {}};
  for (double d : v) e.values.push_back(Value::float_value(d));
  return e;
}

namespace {

// A YAML scalar typed as Fawkes' YAML config does: bool, then integer, then float, else string.
std::pair<ConfigType, Value> scalar(const core::ConfigNode& n) {
  const std::string s = n.as_string();
  if (s == "true" || s == "false") return {ConfigType::kBool, Value::boolean(s == "true")};
  std::int64_t i = 0;
  auto [ip, iec] = std::from_chars(s.data(), s.data() + s.size(), i);
  if (iec == std::errc() && ip == s.data() + s.size() && !s.empty())
    return {i >= 0 ? ConfigType::kUint : ConfigType::kInt, Value::integer_value(i)};
  double d = 0;
  auto [dp, dec] = std::from_chars(s.data(), s.data() + s.size(), d);
  if (dec == std::errc() && dp == s.data() + s.size() && !s.empty())
    return {ConfigType::kFloat, Value::float_value(d)};
  return {ConfigType::kString, Value::string(s)};
}

void flatten(const core::ConfigNode& n, const std::string& path, ConfigEntries& out) {
  if (n.is_map()) {
    for (const auto& key : n.keys()) flatten(n.at(key), path + "/" + key, out);
    return;
  }
  if (n.is_sequence()) {
    ConfigEntry e{path.empty() ? "/" : path, ConfigType::kString, true, {}};
    bool first = true;
    for (const auto& el : n.elements()) {
      if (!el.is_scalar()) el.fail("config lists may only hold scalars");
      auto [type, v] = scalar(el);
      if (first) e.type = type;
      first = false;
      e.values.push_back(std::move(v));
    }
    out.push_back(std::move(e));
    return;
  }
  if (n.is_null()) return;
  auto [type, v] = scalar(n);
  out.push_back({path.empty() ? "/" : path, type, false, {std::move(v)}});
}

}  // namespace

ConfigEntries config_from_node(const core::ConfigNode& node, std::string_view prefix) {
  ConfigEntries out;
  std::string root(prefix);
  while (!root.empty() && root.back() == '/') root.pop_back();
  flatten(node, root, out);
  return out;
}

}  // namespace llsf::clips
