// SPDX-License-Identifier: MIT
#include "llsf/core/config.h"

#include <yaml-cpp/eventhandler.h>
#include <yaml-cpp/parser.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <map>
#include <optional>
#include <set>
#include <sstream>

#include "llsf/core/input_file.h"
#include "llsf/core/text.h"

namespace llsf::core {

// --- Bounds -----------------------------------------------------------------------------------

std::string number_text(double v) {
  char buf[64];
  // Whole numbers in full ("100000", not the shorter "1e+05").
  const bool whole = std::abs(v) < 1e15 && v == std::trunc(v);
  const auto r = whole ? std::to_chars(buf, buf + sizeof buf, v, std::chars_format::fixed)
                       : std::to_chars(buf, buf + sizeof buf, v);
  return std::string(buf, r.ptr);
}

std::string Bound::violation(double v) const {
  const std::string got = " (got " + number_text(v) + ")";
  const bool fin = std::isfinite(v);
  switch (kind) {
    case Kind::kFinite:
      return fin ? "" : "must be a finite number" + got;
    case Kind::kGreater:
      return v > lo && fin ? "" : "must be > " + number_text(lo) + got;
    case Kind::kAtLeast:
      return v >= lo && fin ? "" : "must be >= " + number_text(lo) + got;
    case Kind::kAtMost:
      return v <= hi ? "" : "must be at most " + number_text(hi) + got;
    case Kind::kClosed:
      return v >= lo && v <= hi
                 ? ""
                 : "must be in [" + number_text(lo) + ", " + number_text(hi) + "]" + got;
    case Kind::kOpenClosed:
      return v > lo && v <= hi
                 ? ""
                 : "must be in (" + number_text(lo) + ", " + number_text(hi) + "]" + got;
    case Kind::kPort:
      return v >= lo && v <= hi
                 ? ""
                 : "must be a port in [" + number_text(lo) + ", " + number_text(hi) + "]" + got;
  }
  return "";
}

void require(std::string_view path, double v, const Bound& bound) {
  if (std::string why = bound.violation(v); !why.empty()) {
    throw ConfigError(std::string(path) + ": " + why);
  }
}

// --- ConfigNode -------------------------------------------------------------------------------

/// The keys asked for, per map path, for one parsed document (shared by all its nodes). Keys
/// are kept in the order first asked, for the "did you mean" hint.
struct AskedKeys {
  std::map<std::string, std::vector<std::string>, std::less<>> by_map;
  void ask(const std::string& map_path, std::string_view key) {
    auto& keys = by_map[map_path];
    if (std::find(keys.begin(), keys.end(), key) == keys.end()) keys.emplace_back(key);
  }
};

struct ConfigNode::Impl {
  YAML::Node node;
  std::string source;
  std::string path;
  YAML::Mark mark;  // of the node, or of the parent for undefined keys
  bool defined = false;
  std::shared_ptr<AskedKeys> asked = std::make_shared<AskedKeys>();
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

// --- Strict YAML ------------------------------------------------------------------------------

namespace {

/// One pass over the events of a document before yaml-cpp builds its tree: refuses a key given
/// twice in a map, aliases that expand past kMaxYamlNodes, an alias inside its own anchor (a
/// tree that contains itself) and nesting past kMaxYamlDepth, each at the offending node's
/// file:line:column with its path.
class StrictChecker : public YAML::EventHandler {
 public:
  explicit StrictChecker(const std::string& source) : source_(source) {}

  void OnDocumentStart(const YAML::Mark&) override {}
  void OnDocumentEnd() override {}
  void OnAnchor(const YAML::Mark&, const std::string& name) override { pending_name_ = name; }

  void OnNull(const YAML::Mark& mark, YAML::anchor_t anchor) override {
    const std::string path = begin_node(mark, nullptr);
    count(mark, path, 1);
    if (anchor != YAML::NullAnchor) finish_anchor(anchor, 1, std::nullopt);
    end_node();
  }
  void OnAlias(const YAML::Mark& mark, YAML::anchor_t anchor) override {
    const auto scalar = scalars_.find(anchor);
    const std::string path = begin_node(mark, scalar == scalars_.end() ? nullptr : &scalar->second);
    if (open_.count(anchor) != 0) {
      fail(mark, path,
           "the alias *" + name_of(anchor) +
               " is inside its own anchor (a structure that contains itself)");
    }
    const auto size = sizes_.find(anchor);
    aliases_ = true;
    count(mark, path, size == sizes_.end() ? 1 : size->second);
    end_node();
  }
  void OnScalar(const YAML::Mark& mark, const std::string&, YAML::anchor_t anchor,
                const std::string& value) override {
    const std::string path = begin_node(mark, &value);
    count(mark, path, 1);
    if (anchor != YAML::NullAnchor) finish_anchor(anchor, 1, value);
    end_node();
  }
  void OnSequenceStart(const YAML::Mark& mark, const std::string&, YAML::anchor_t anchor,
                       YAML::EmitterStyle::value) override {
    start_container(mark, anchor, false);
  }
  void OnSequenceEnd() override { end_container(); }
  void OnMapStart(const YAML::Mark& mark, const std::string&, YAML::anchor_t anchor,
                  YAML::EmitterStyle::value) override {
    start_container(mark, anchor, true);
  }
  void OnMapEnd() override { end_container(); }

 private:
  struct Frame {
    bool is_map = false;
    std::string path;
    int index = 0;                                       // a list: the next element's index
    bool at_key = true;                                  // a map: the next node is a key
    std::string key;                                     // a map: the key of the value that follows
    std::map<std::string, int, std::less<>> first_line;  // a map: each key's first line
    YAML::anchor_t anchor = YAML::NullAnchor;
    std::uint64_t nodes_before = 0;
  };

  [[noreturn]] void fail(const YAML::Mark& mark, const std::string& path,
                         const std::string& message) const {
    throw ConfigError(source_ + ":" + std::to_string(mark.line + 1) + ":" +
                      std::to_string(mark.column + 1) + ": " +
                      (path.empty() ? std::string("(top level)") : shorten(path)) + ": " + message);
  }

  /// `s`, or its start and end around "..." if it is longer than 120 characters (a path 64
  /// levels deep, a key of a megabyte).
  static std::string shorten(const std::string& s) {
    if (s.size() <= 120) return s;
    return s.substr(0, 56) + "..." + s.substr(s.size() - 56);
  }

  std::string name_of(YAML::anchor_t anchor) const {
    const auto it = names_.find(anchor);
    return it == names_.end() ? std::to_string(anchor) : it->second;
  }

  /// The path of the node that starts at `mark`; checks a map key (`scalar` is its text, or
  /// null for a key that is not a scalar) against the map's earlier keys.
  std::string begin_node(const YAML::Mark& mark, const std::string* scalar) {
    if (stack_.empty()) return "";
    Frame& f = stack_.back();
    if (!f.is_map) return f.path + "[" + std::to_string(f.index) + "]";
    if (!f.at_key) return child_path(f.path, f.key);
    f.key = scalar != nullptr ? *scalar : std::string("(key)");
    const std::string path = child_path(f.path, f.key);
    if (scalar != nullptr) {
      const auto [it, fresh] = f.first_line.emplace(*scalar, mark.line + 1);
      if (!fresh) {
        fail(mark, path,
             "key '" + shorten(*scalar) + "' given twice (first at line " +
                 std::to_string(it->second) + ")");
      }
    }
    return path;
  }

  /// After a node: the next node of a map is a value or a key, of a list the next element.
  void end_node() {
    if (stack_.empty()) return;
    Frame& f = stack_.back();
    if (f.is_map) {
      f.at_key = !f.at_key;
    } else {
      ++f.index;
    }
  }

  void count(const YAML::Mark& mark, const std::string& path, std::uint64_t n) {
    nodes_ += n;
    if (nodes_ <= kMaxYamlNodes) return;
    if (aliases_) {
      fail(mark, path,
           "the aliases expand the document to more than " + std::to_string(kMaxYamlNodes) +
               " nodes (aliases of aliases, a \"billion laughs\"?)");
    }
    fail(mark, path, "more than " + std::to_string(kMaxYamlNodes) + " nodes in the document");
  }

  void finish_anchor(YAML::anchor_t anchor, std::uint64_t size,
                     const std::optional<std::string>& scalar) {
    sizes_[anchor] = size;
    if (scalar) scalars_[anchor] = *scalar;
    if (!pending_name_.empty()) names_[anchor] = pending_name_;
    pending_name_.clear();
  }

  void start_container(const YAML::Mark& mark, YAML::anchor_t anchor, bool is_map) {
    const std::string path = begin_node(mark, nullptr);
    if (static_cast<int>(stack_.size()) >= kMaxYamlDepth) {
      fail(mark, path,
           "nesting deeper than " + std::to_string(kMaxYamlDepth) +
               " levels (maps and lists inside each other)");
    }
    Frame f;
    f.is_map = is_map;
    f.path = path;
    f.anchor = anchor;
    f.nodes_before = nodes_;
    if (anchor != YAML::NullAnchor) {
      open_.insert(anchor);
      if (!pending_name_.empty()) names_[anchor] = pending_name_;
      pending_name_.clear();
    }
    count(mark, path, 1);
    stack_.push_back(std::move(f));
  }

  void end_container() {
    const Frame f = std::move(stack_.back());
    stack_.pop_back();
    if (f.anchor != YAML::NullAnchor) {
      open_.erase(f.anchor);
      sizes_[f.anchor] = nodes_ - f.nodes_before;
    }
    end_node();
  }

  const std::string& source_;
  std::vector<Frame> stack_;
  std::uint64_t nodes_ = 0;
  bool aliases_ = false;
  std::map<YAML::anchor_t, std::uint64_t> sizes_;  // nodes of each anchor, expanded
  std::map<YAML::anchor_t, std::string> scalars_;  // the text of each scalar anchor
  std::map<YAML::anchor_t, std::string> names_;    // each anchor's name
  std::set<YAML::anchor_t> open_;                  // anchors of containers not yet ended
  std::string pending_name_;
};

std::string location_of(const std::string& source, std::string_view text, std::size_t offset) {
  const TextPosition p = text_position(text, offset);
  return source + ":" + std::to_string(p.line) + ":" + std::to_string(p.column);
}

}  // namespace

void check_strict_yaml(std::string_view text, const std::string& source_name) {
  if (text.size() > kMaxSourceBytes) {
    throw ConfigError(source_name + ": " + byte_size_text(text.size()) + " is over the limit of " +
                      byte_size_text(kMaxSourceBytes) + " for YAML");
  }
  if (const std::optional<std::size_t> nul = find_nul(text)) {
    throw ConfigError(location_of(source_name, text, *nul) + ": a NUL byte: YAML must be text");
  }
  if (const std::optional<std::size_t> bad = find_invalid_utf8(text)) {
    char byte[8];
    std::snprintf(byte, sizeof byte, "0x%02X", static_cast<unsigned char>(text[*bad]));
    throw ConfigError(location_of(source_name, text, *bad) + ": invalid UTF-8 (byte " + byte +
                      "): YAML must be UTF-8 text");
  }
  std::istringstream in{std::string(text)};
  StrictChecker checker(source_name);
  try {
    YAML::Parser parser(in);
    parser.HandleNextDocument(checker);
  } catch (const YAML::Exception& e) {
    throw ConfigError(source_name + ":" + std::to_string(e.mark.line + 1) + ":" +
                      std::to_string(e.mark.column + 1) + ": YAML syntax error: " + e.msg);
  }
}

ConfigNode::ConfigNode() : impl_(std::make_shared<Impl>()) {}
ConfigNode::~ConfigNode() = default;
ConfigNode::ConfigNode(const ConfigNode&) = default;
ConfigNode& ConfigNode::operator=(const ConfigNode&) = default;
ConfigNode::ConfigNode(std::shared_ptr<const Impl> impl) : impl_(std::move(impl)) {}

ConfigNode ConfigNode::load_file(const std::string& path) {
  return parse(read_input_file(path, kMaxSourceBytes, "YAML file"), path);
}

ConfigNode ConfigNode::parse(std::string_view text, const std::string& source_name) {
  check_strict_yaml(text, source_name);
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
  impl->asked = impl_->asked;
  if (is_map()) impl_->asked->ask(impl_->path, key);
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
  impl->asked = impl_->asked;
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

void ConfigNode::no_other_keys() const {
  if (!is_map()) return;
  static const std::vector<std::string> kNone;
  const auto it = impl_->asked->by_map.find(impl_->path);
  const std::vector<std::string>& asked = it == impl_->asked->by_map.end() ? kNone : it->second;
  for (const auto& kv : impl_->node) {
    const std::string k = kv.first.Scalar();
    if (std::find(asked.begin(), asked.end(), k) != asked.end()) continue;
    // The closest asked-for key within a third of the name's length is a likely typo.
    const std::optional<std::string> best = closest_match(k, asked);
    std::string hint;
    if (best) {
      hint = " (did you mean '" + *best + "'?)";
    } else if (!asked.empty()) {
      std::string list;
      for (const std::string& a : asked) list += (list.empty() ? "" : ", ") + a;
      hint = " (allowed: " + list + ")";
    }
    (*this)[k].fail("unknown key '" + k + "'" + hint);
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

double ConfigNode::as_double(const Bound& bound) const {
  const double v = as_double();
  if (std::string why = bound.violation(v); !why.empty()) fail(why);
  return v;
}

std::int64_t ConfigNode::as_int(const Bound& bound) const {
  const std::int64_t v = as_int();
  if (std::string why = bound.violation(static_cast<double>(v)); !why.empty()) fail(why);
  return v;
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
void ConfigNode::read(std::string_view key, double& out, const Bound& bound) const {
  if (auto c = (*this)[key]; c.defined()) out = c.as_double(bound);
}
void ConfigNode::read(std::string_view key, int& out, const Bound& bound) const {
  if (auto c = (*this)[key]; c.defined()) {
    int v = 0;
    read(key, v);
    if (std::string why = bound.violation(v); !why.empty()) c.fail(why);
    out = v;
  }
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

// --- Putting a location on validate() errors --------------------------------------------------

namespace {
bool is_path_char(char ch) {
  return (ch >= 'a' && ch <= 'z') || (ch >= 'A' && ch <= 'Z') || (ch >= '0' && ch <= '9') ||
         ch == '_' || ch == '.' || ch == '[' || ch == ']';
}
}  // namespace

ConfigNode ConfigNode::resolve(std::string_view rel) const {
  ConfigNode n = *this;
  std::size_t i = 0;
  while (i < rel.size()) {
    if (rel[i] == '[') {
      const std::size_t close = rel.find(']', i);
      if (close == std::string_view::npos || !n.is_sequence()) return n;
      int index = -1;
      std::from_chars(rel.data() + i + 1, rel.data() + close, index);
      if (index < 0 || index >= n.size()) return n;
      n = n.at(index);
      i = close + 1;
    } else {
      if (rel[i] == '.') ++i;
      const std::size_t end = std::min(rel.find_first_of(".[", i), rel.size());
      if (end == i || !n.is_map()) return n;
      const ConfigNode child = n[rel.substr(i, end - i)];
      if (!child.defined()) return n;
      n = child;
      i = end;
    }
  }
  return n;
}

void ConfigNode::fail_at(std::string_view rel, const std::string& reason) const {
  std::string full = impl_->path;
  if (!full.empty() && !rel.empty() && rel.front() != '[') full += ".";
  full += rel;
  const ConfigNode at = resolve(rel);
  if (at.path() == full) at.fail(reason);
  // Only an ancestor exists: a deeper path named in the reason may be closer to the cause.
  // Only path-like words (with a '.' or '[') count, so that "the field" does not match `field`.
  const ConfigNode* best = &at;
  ConfigNode named;
  for (std::size_t i = 0; i < reason.size();) {
    if (!is_path_char(reason[i]) || (i > 0 && is_path_char(reason[i - 1]))) {
      ++i;
      continue;
    }
    std::size_t end = i;
    while (end < reason.size() && is_path_char(reason[end])) ++end;
    std::string_view word(reason.data() + i, end - i);
    while (!word.empty() && (word.back() == '.' || word.back() == ']')) {
      if (word.back() == ']' && word.find('[') != std::string_view::npos) break;
      word.remove_suffix(1);
    }
    if (word.find_first_of(".[") != std::string_view::npos) {
      ConfigNode c = resolve(word);
      std::string want = impl_->path;
      if (!want.empty() && word.front() != '[') want += ".";
      want += word;
      if (c.path() == want && c.path().size() > best->path().size()) {
        named = c;
        best = &named;
      }
    }
    i = end;
  }
  throw ConfigError(best->location() + ": " + (full.empty() ? "(top level)" : full) + ": " +
                    reason);
}

void ConfigNode::relocate(const ConfigError& e, std::span<const PathRename> renames) const {
  const std::string what = e.what();
  const std::size_t colon = what.find(": ");
  const std::string_view head = std::string_view(what).substr(0, colon);
  const bool is_path =
      colon != std::string::npos && !head.empty() &&
      std::all_of(head.begin(), head.end(), [](char ch) { return is_path_char(ch); });
  if (!is_path) throw ConfigError(location() + ": " + what);
  // The renamed path that the document has, else the one that reaches deepest into it.
  std::string path(head);
  std::optional<std::size_t> best;  // how deep the best candidate reaches into the document
  for (const PathRename& r : renames) {
    if (r.from.empty() || !head.starts_with(r.from)) continue;
    const std::string_view rest = head.substr(r.from.size());
    if (!rest.empty() && r.from.back() != '[' && rest.front() != '.' && rest.front() != '[') {
      continue;  // "game.skill" does not start "game.skill_rate_hz"
    }
    std::string renamed(r.to);
    renamed += renamed.empty() && !rest.empty() && rest.front() == '.' ? rest.substr(1) : rest;
    std::string want = impl_->path;
    if (!want.empty() && !renamed.empty() && renamed.front() != '[') want += ".";
    want += renamed;
    const std::string found = resolve(renamed).path();
    if (found == want) {
      path = renamed;
      break;
    }
    // Depth in keys and indices: on a tie the earlier rename wins.
    const auto depth = static_cast<std::size_t>(
        std::count_if(found.begin(), found.end(), [](char ch) { return ch == '.' || ch == '['; }));
    if (!best || depth > *best) {
      best = depth;
      path = renamed;
    }
  }
  fail_at(path, what.substr(colon + 2));
}

}  // namespace llsf::core
