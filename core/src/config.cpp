// SPDX-License-Identifier: MIT
#include "llsf/core/config.h"

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <fstream>
#include <sstream>

namespace llsf::core {

struct ConfigNode::Impl {
  YAML::Node node;
  std::string source;
  std::string path;
  YAML::Mark mark;  // of the node, or of the parent for undefined keys
  bool defined = false;
};

namespace {
std::string child_path(const std::string& parent, std::string_view key) {
  if (parent.empty()) return std::string(key);
  return parent + "." + std::string(key);
}
std::string describe(const YAML::Node& n) {
  if (!n.IsDefined()) return "nothing";
  if (n.IsNull()) return "null";
  if (n.IsMap()) return "a map";
  if (n.IsSequence()) return "a list";
  return "'" + n.Scalar() + "'";
}
}  // namespace

ConfigNode::ConfigNode() : impl_(std::make_shared<Impl>()) {}
ConfigNode::~ConfigNode() = default;
ConfigNode::ConfigNode(const ConfigNode&) = default;
ConfigNode& ConfigNode::operator=(const ConfigNode&) = default;
ConfigNode::ConfigNode(std::shared_ptr<const Impl> impl) : impl_(std::move(impl)) {}

ConfigNode ConfigNode::load_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw ConfigError(path + ": cannot open file");
  std::ostringstream ss;
  ss << in.rdbuf();
  return parse(ss.str(), path);
}

ConfigNode ConfigNode::parse(std::string_view text, const std::string& source_name) {
  auto impl = std::make_shared<Impl>();
  impl->source = source_name;
  try {
    impl->node = YAML::Load(std::string(text));
  } catch (const YAML::Exception& e) {
    throw ConfigError(source_name + ":" + std::to_string(e.mark.line + 1) + ":" +
                      std::to_string(e.mark.column + 1) + ": YAML syntax error: " + e.msg);
  }
  impl->mark = impl->node.Mark();
  impl->defined = true;
  return ConfigNode(std::move(impl));
}

bool ConfigNode::defined() const { return impl_->defined && impl_->node.IsDefined(); }
bool ConfigNode::is_null() const { return defined() && impl_->node.IsNull(); }
bool ConfigNode::is_map() const { return defined() && impl_->node.IsMap(); }
bool ConfigNode::is_sequence() const { return defined() && impl_->node.IsSequence(); }
bool ConfigNode::is_scalar() const { return defined() && impl_->node.IsScalar(); }
int ConfigNode::size() const {
  return (is_map() || is_sequence()) ? static_cast<int>(impl_->node.size()) : 0;
}

ConfigNode ConfigNode::operator[](std::string_view key) const {
  auto impl = std::make_shared<Impl>();
  impl->source = impl_->source;
  impl->path = child_path(impl_->path, key);
  impl->mark = impl_->mark;
  if (is_map()) {
    const YAML::Node child = impl_->node[std::string(key)];
    if (child.IsDefined()) {
      impl->node = child;
      impl->defined = true;
      if (child.Mark().line >= 0) impl->mark = child.Mark();
    }
  }
  return ConfigNode(std::move(impl));
}

ConfigNode ConfigNode::at(std::string_view key) const {
  if (!is_map()) fail("expected a map with the key '" + std::string(key) + "'");
  ConfigNode c = (*this)[key];
  if (!c.defined()) fail("missing required key '" + std::string(key) + "'");
  return c;
}

ConfigNode ConfigNode::at(int index) const {
  if (!is_sequence()) fail("expected a list");
  if (index < 0 || index >= size()) fail("index " + std::to_string(index) + " out of range");
  auto impl = std::make_shared<Impl>();
  impl->source = impl_->source;
  impl->path = impl_->path + "[" + std::to_string(index) + "]";
  impl->node = impl_->node[static_cast<std::size_t>(index)];
  impl->mark = impl->node.Mark().line >= 0 ? impl->node.Mark() : impl_->mark;
  impl->defined = true;
  return ConfigNode(std::move(impl));
}

std::vector<std::string> ConfigNode::keys() const {
  if (!is_map()) fail("expected a map, got " + describe(impl_->node));
  std::vector<std::string> out;
  for (const auto& kv : impl_->node) {
    if (!kv.first.IsScalar()) fail("map keys must be plain names");
    out.push_back(kv.first.Scalar());
  }
  return out;
}

std::vector<ConfigNode> ConfigNode::elements() const {
  if (!is_sequence()) fail("expected a list, got " + describe(impl_->node));
  std::vector<ConfigNode> out;
  for (int i = 0; i < size(); ++i) out.push_back(at(i));
  return out;
}

void ConfigNode::require_map() const {
  if (defined() && !is_null() && !is_map()) fail("expected a map, got " + describe(impl_->node));
}

void ConfigNode::check_keys(std::initializer_list<std::string_view> allowed) const {
  if (!is_map()) return;
  for (const auto& kv : impl_->node) {
    const std::string k = kv.first.Scalar();
    bool ok = false;
    for (auto a : allowed) ok = ok || (a == k);
    if (!ok) {
      std::string list;
      for (auto a : allowed) list += (list.empty() ? "" : ", ") + std::string(a);
      (*this)[k].fail("unknown key '" + k + "' (allowed: " + list + ")");
    }
  }
}

double ConfigNode::as_double() const {
  if (!is_scalar()) fail("expected a number, got " + describe(impl_->node));
  const std::string& s = impl_->node.Scalar();
  std::size_t used = 0;
  double v = 0.0;
  try {
    v = std::stod(s, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used == 0 || used != s.size() || !std::isfinite(v)) {
    fail("expected a number, got '" + s + "'");
  }
  return v;
}

std::int64_t ConfigNode::as_int() const {
  if (!is_scalar()) fail("expected an integer, got " + describe(impl_->node));
  const std::string& s = impl_->node.Scalar();
  std::size_t used = 0;
  long long v = 0;
  try {
    v = std::stoll(s, &used, 10);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used == 0 || used != s.size()) fail("expected an integer, got '" + s + "'");
  return v;
}

bool ConfigNode::as_bool() const {
  if (is_scalar()) {
    const std::string& s = impl_->node.Scalar();
    if (s == "true" || s == "yes" || s == "on") return true;
    if (s == "false" || s == "no" || s == "off") return false;
  }
  fail("expected true or false, got " + describe(impl_->node));
}

std::string ConfigNode::as_string() const {
  if (!is_scalar()) fail("expected a string, got " + describe(impl_->node));
  return impl_->node.Scalar();
}

void ConfigNode::read(std::string_view key, double& out) const {
  if (auto c = (*this)[key]; c.defined()) out = c.as_double();
}
void ConfigNode::read(std::string_view key, int& out) const {
  if (auto c = (*this)[key]; c.defined()) {
    const std::int64_t v = c.as_int();
    if (v < INT32_MIN || v > INT32_MAX) c.fail("integer out of range");
    out = static_cast<int>(v);
  }
}
void ConfigNode::read(std::string_view key, std::int64_t& out) const {
  if (auto c = (*this)[key]; c.defined()) out = c.as_int();
}
void ConfigNode::read(std::string_view key, bool& out) const {
  if (auto c = (*this)[key]; c.defined()) out = c.as_bool();
}
void ConfigNode::read(std::string_view key, std::string& out) const {
  if (auto c = (*this)[key]; c.defined()) out = c.as_string();
}

const std::string& ConfigNode::path() const { return impl_->path; }

std::string ConfigNode::location() const {
  const auto& m = impl_->mark;
  if (m.line < 0) return impl_->source;
  return impl_->source + ":" + std::to_string(m.line + 1) + ":" + std::to_string(m.column + 1);
}

ConfigNode& ConfigNode::set(std::string_view dotted_path, const ConfigNode& value) {
  require_map();
  if (!value.defined()) value.fail("nothing to set '" + std::string(dotted_path) + "' to");
  std::vector<std::string> keys;
  std::size_t pos = 0;
  while (pos <= dotted_path.size()) {
    const std::size_t dot = dotted_path.find('.', pos);
    const std::string_view k =
        dotted_path.substr(pos, dot == std::string_view::npos ? std::string_view::npos : dot - pos);
    if (k.empty()) fail("bad key path '" + std::string(dotted_path) + "'");
    keys.emplace_back(k);
    if (dot == std::string_view::npos) break;
    pos = dot + 1;
  }
  YAML::Node cur = impl_->node;  // shares the document
  if (!cur.IsMap()) cur = YAML::Node(YAML::NodeType::Map);
  for (std::size_t i = 0; i + 1 < keys.size(); ++i) {
    YAML::Node next = cur[keys[i]];
    if (!next.IsDefined() || !next.IsMap()) {
      cur[keys[i]] = YAML::Node(YAML::NodeType::Map);
      next = cur[keys[i]];
    }
    cur.reset(next);
  }
  cur[keys.back()] = value.impl_->node;
  return *this;
}

void ConfigNode::fail(const std::string& message) const {
  const std::string p = impl_->path.empty() ? std::string("(top level)") : impl_->path;
  throw ConfigError(location() + ": " + p + ": " + message);
}

}  // namespace llsf::core
