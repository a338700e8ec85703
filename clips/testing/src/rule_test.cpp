// SPDX-License-Identifier: MIT
// Rule tests without C++ (llsf/clips/rule_test.h): the YAML reader, fact patterns, messages from
// YAML, and the runner on AgentFixture. Format: docs/agent-tests.md.
#include "llsf/clips/rule_test.h"

#include <google/protobuf/descriptor.h>
#include <google/protobuf/message.h>
#include <google/protobuf/text_format.h>
#include <google/protobuf/util/message_differencer.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <numbers>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <utility>

#include "llsf/clips/agent_files.h"
#include "llsf/comm/registry.h"
#include "llsf/core/config.h"
#include "llsf/core/input_file.h"
#include "llsf/core/text.h"

namespace llsf::clips {

namespace {

namespace fs = std::filesystem;
namespace pb = google::protobuf;
using core::ConfigNode;

/// "file:line" of a node (its location without the column).
std::string line_of(const ConfigNode& n) {
  std::string loc = n.location();
  const auto colon = loc.rfind(':');
  if (colon != std::string::npos && colon > 0 && loc.find(':') != colon) loc.resize(colon);
  return loc;
}

// ---- fact patterns ------------------------------------------------------------------------------

/// A fact pattern: "(machine (name M1) (loaded-with S0 S1))" or the ordered "(state IDLE)".
/// Slots not named match anything; "(signal)" matches every signal fact.
struct Pattern {
  std::string text;
  std::string template_name;
  bool ordered = false;
  std::vector<Value> fields;
  std::vector<std::pair<std::string, std::vector<Value>>> slots;
};

/// A pattern names a slot its template lacks, or is ordered for a deftemplate (bad input).
struct PatternMismatch : std::runtime_error {
  using std::runtime_error::runtime_error;
};

struct Token {
  enum class Kind { kOpen, kClose, kAtom };
  Kind kind = Kind::kAtom;
  Value value;
};

Value atom_value(const std::string& s) {
  const bool numeric_start = !s.empty() && (std::isdigit(static_cast<unsigned char>(s[0])) != 0 ||
                                            s[0] == '-' || s[0] == '+' || s[0] == '.');
  if (numeric_start && s.find_first_of("0123456789") != std::string::npos) {
    std::int64_t i = 0;
    const char* b = s.data() + (s[0] == '+' ? 1 : 0);
    const auto [p, ec] = std::from_chars(b, s.data() + s.size(), i);
    if (ec == std::errc() && p == s.data() + s.size()) return Value::integer_value(i);
    char* end = nullptr;
    const double d = std::strtod(s.c_str(), &end);
    if (end == s.c_str() + s.size()) return Value::float_value(d);
  }
  return Value::symbol(s);
}

std::vector<Token> tokenize(std::string_view s) {
  std::vector<Token> out;
  std::size_t i = 0;
  while (i < s.size()) {
    const char c = s[i];
    if (std::isspace(static_cast<unsigned char>(c)) != 0) {
      ++i;
    } else if (c == '(' || c == ')') {
      out.push_back({c == '(' ? Token::Kind::kOpen : Token::Kind::kClose, {}});
      ++i;
    } else if (c == '"') {
      std::string text;
      ++i;
      bool closed = false;
      while (i < s.size()) {
        if (s[i] == '\\' && i + 1 < s.size()) {
          text += s[i + 1];
          i += 2;
        } else if (s[i] == '"') {
          closed = true;
          ++i;
          break;
        } else {
          text += s[i++];
        }
      }
      if (!closed) throw std::invalid_argument("a string without its closing quote");
      out.push_back({Token::Kind::kAtom, Value::string(std::move(text))});
    } else {
      std::size_t j = i;
      while (j < s.size() && std::isspace(static_cast<unsigned char>(s[j])) == 0 && s[j] != '(' &&
             s[j] != ')' && s[j] != '"')
        ++j;
      out.push_back({Token::Kind::kAtom, atom_value(std::string(s.substr(i, j - i)))});
      i = j;
    }
  }
  return out;
}

Pattern parse_pattern_text(const std::string& text) {
  const std::vector<Token> t = tokenize(text);
  Pattern p;
  p.text = text;
  std::size_t i = 0;
  auto need = [&](bool ok, const char* what) {
    if (!ok) throw std::invalid_argument(what);
  };
  need(t.size() >= 3 && t[0].kind == Token::Kind::kOpen, "a fact starts with '(' and a name");
  need(t[1].kind == Token::Kind::kAtom && t[1].value.type == Value::Type::kSymbol,
       "a fact starts with '(' and a name");
  p.template_name = t[1].value.text;
  i = 2;
  if (t[i].kind == Token::Kind::kOpen) {
    while (i < t.size() && t[i].kind == Token::Kind::kOpen) {
      ++i;
      need(i < t.size() && t[i].kind == Token::Kind::kAtom &&
               t[i].value.type == Value::Type::kSymbol,
           "a slot is '(' name values... ')'");
      std::pair<std::string, std::vector<Value>> slot{t[i].value.text, {}};
      ++i;
      while (i < t.size() && t[i].kind == Token::Kind::kAtom) slot.second.push_back(t[i++].value);
      need(i < t.size() && t[i].kind == Token::Kind::kClose,
           "a slot is '(' name values... ')' (no nested parentheses)");
      ++i;
      p.slots.push_back(std::move(slot));
    }
  } else {
    p.ordered = true;
    while (i < t.size() && t[i].kind == Token::Kind::kAtom) p.fields.push_back(t[i++].value);
    if (p.fields.empty()) p.ordered = false;  // "(name)": every fact of the template
  }
  need(i < t.size() && t[i].kind == Token::Kind::kClose, "unbalanced parentheses");
  need(i + 1 == t.size(), "text after the fact's closing parenthesis");
  return p;
}

Pattern parse_pattern(const ConfigNode& n) {
  const std::string text = n.as_string();
  try {
    return parse_pattern_text(text);
  } catch (const std::invalid_argument& e) {
    n.fail("not a fact pattern (" + std::string(e.what()) + "): " + text +
           "; write (template (slot value...)...) or an ordered fact (name field...)");
  }
}

bool same_value(const Value& a, const Value& e) {
  if (a.is_number() && e.is_number()) return a.number() == e.number();
  return a == e;
}

bool slot_matches(const Value& actual, const std::vector<Value>& expected) {
  if (actual.type == Value::Type::kMultifield) {
    if (actual.items.size() != expected.size()) return false;
    for (std::size_t i = 0; i < expected.size(); ++i)
      if (!same_value(actual.items[i], expected[i])) return false;
    return true;
  }
  return expected.size() == 1 && same_value(actual, expected[0]);
}

bool is_ordered(const Fact& f) { return f.slots.size() == 1 && f.slots[0].first.empty(); }

/// The facts of `p`'s template that match it. Throws PatternMismatch for a slot the template
/// lacks or an ordered pattern of a deftemplate.
std::vector<Fact> matching(const AgentHost& agent, const Pattern& p) {
  std::vector<Fact> out;
  for (Fact& f : agent.facts(p.template_name)) {
    if (p.ordered) {
      if (!is_ordered(f)) {
        throw PatternMismatch(p.template_name + " is a deftemplate: name its slots, e.g. (" +
                              p.template_name + " (" + f.slots.at(0).first + " ...))");
      }
      if (slot_matches(f.slots[0].second, p.fields)) out.push_back(std::move(f));
      continue;
    }
    bool ok = true;
    for (const auto& slot : p.slots) {
      const std::string& name = slot.first;
      const std::vector<Value>& values = slot.second;
      const auto it = std::find_if(f.slots.begin(), f.slots.end(),
                                   [&](const auto& s) { return s.first == name; });
      if (it == f.slots.end()) {
        std::vector<std::string> names;
        for (const auto& s : f.slots) names.push_back(s.first);
        std::string msg = "template " + p.template_name + " has no slot '" + name + "'";
        if (const auto m = core::closest_match(name, names)) msg += " (did you mean '" + *m + "'?)";
        throw PatternMismatch(msg);
      }
      if (!slot_matches(it->second, values)) {
        ok = false;
        break;
      }
    }
    if (ok) out.push_back(std::move(f));
  }
  return out;
}

std::string values_text(const std::vector<Value>& vs) {
  std::string s;
  for (const Value& v : vs) s += " " + v.to_string();
  return s;
}

std::string fact_text(const Fact& f) {
  std::string s = "(" + f.template_name;
  for (const auto& [name, v] : f.slots) {
    const std::string vals =
        v.type == Value::Type::kMultifield ? values_text(v.items) : " " + v.to_string();
    s += name.empty() ? vals : " (" + name + vals + ")";
  }
  return s + ")";
}

// ---- messages from YAML -------------------------------------------------------------------------

const pb::Message* find_type(const ConfigNode& n, const comm::MessageRegistry& registry) {
  const std::string name = n.as_string();
  std::vector<std::string> names;
  std::vector<int> hits;
  for (int i = 0; i < registry.size(); ++i) {
    const std::string& full = registry.name_at(i);
    names.push_back(full);
    if (full == name) return registry.prototype(registry.key_at(i));
    if (full.size() > name.size() && full.ends_with("." + name)) hits.push_back(i);
  }
  if (hits.size() == 1) return registry.prototype(registry.key_at(hits[0]));
  if (hits.size() > 1) {
    std::string list;
    for (int i : hits) list += (list.empty() ? "" : ", ") + registry.name_at(i);
    n.fail("message type '" + name + "' is ambiguous: " + list);
  }
  std::string msg = "unknown message type '" + name + "'";
  if (const auto m = core::closest_match(name, names)) msg += " (did you mean '" + *m + "'?)";
  std::string list;
  for (const std::string& s : names) list += (list.empty() ? "" : ", ") + s;
  n.fail(msg + "; the types: " + list);
}

void fill_message(const ConfigNode& node, pb::Message& m);

void set_field(const ConfigNode& n, pb::Message& m, const pb::FieldDescriptor* f) {
  const pb::Reflection* r = m.GetReflection();
  const bool rep = f->is_repeated();
  switch (f->cpp_type()) {
    case pb::FieldDescriptor::CPPTYPE_MESSAGE: {
      if (!n.is_map()) n.fail("a message field takes a map of its fields");
      pb::Message* sub = rep ? r->AddMessage(&m, f) : r->MutableMessage(&m, f);
      fill_message(n, *sub);
      return;
    }
    case pb::FieldDescriptor::CPPTYPE_ENUM: {
      const std::string s = n.as_string();
      const pb::EnumDescriptor* e = f->enum_type();
      const pb::EnumValueDescriptor* v = e->FindValueByName(s);
      if (v == nullptr) {
        std::string list;
        for (int i = 0; i < e->value_count(); ++i)
          list += (list.empty() ? "" : ", ") + e->value(i)->name();
        n.fail("unknown value '" + s + "' of " + e->full_name() + " (expected one of: " + list +
               ")");
      }
      rep ? r->AddEnum(&m, f, v) : r->SetEnum(&m, f, v);
      return;
    }
    case pb::FieldDescriptor::CPPTYPE_INT32: {
      const auto v = n.as_int(core::in_range(std::numeric_limits<std::int32_t>::min(),
                                             std::numeric_limits<std::int32_t>::max()));
      rep ? r->AddInt32(&m, f, static_cast<std::int32_t>(v))
          : r->SetInt32(&m, f, static_cast<std::int32_t>(v));
      return;
    }
    case pb::FieldDescriptor::CPPTYPE_INT64:
      rep ? r->AddInt64(&m, f, n.as_int()) : r->SetInt64(&m, f, n.as_int());
      return;
    case pb::FieldDescriptor::CPPTYPE_UINT32: {
      const auto v = n.as_int(core::in_range(0, std::numeric_limits<std::uint32_t>::max()));
      rep ? r->AddUInt32(&m, f, static_cast<std::uint32_t>(v))
          : r->SetUInt32(&m, f, static_cast<std::uint32_t>(v));
      return;
    }
    case pb::FieldDescriptor::CPPTYPE_UINT64: {
      const auto v = static_cast<std::uint64_t>(n.as_int(core::non_negative()));
      rep ? r->AddUInt64(&m, f, v) : r->SetUInt64(&m, f, v);
      return;
    }
    case pb::FieldDescriptor::CPPTYPE_DOUBLE:
      rep ? r->AddDouble(&m, f, n.as_double()) : r->SetDouble(&m, f, n.as_double());
      return;
    case pb::FieldDescriptor::CPPTYPE_FLOAT: {
      const auto v = static_cast<float>(n.as_double());
      rep ? r->AddFloat(&m, f, v) : r->SetFloat(&m, f, v);
      return;
    }
    case pb::FieldDescriptor::CPPTYPE_BOOL:
      rep ? r->AddBool(&m, f, n.as_bool()) : r->SetBool(&m, f, n.as_bool());
      return;
    case pb::FieldDescriptor::CPPTYPE_STRING:
      rep ? r->AddString(&m, f, n.as_string()) : r->SetString(&m, f, n.as_string());
      return;
  }
}

/// Sets `m`'s fields from a YAML map: scalars, enum names, maps for nested messages, sequences
/// for repeated fields.
void fill_message(const ConfigNode& node, pb::Message& m) {
  const pb::Descriptor* d = m.GetDescriptor();
  if (node.is_null()) return;
  if (!node.is_map()) node.fail("the fields of " + d->full_name() + " are a map");
  for (const std::string& key : node.keys()) {
    const ConfigNode v = node[key];
    const pb::FieldDescriptor* f = d->FindFieldByName(key);
    if (f == nullptr) {
      std::vector<std::string> names;
      for (int i = 0; i < d->field_count(); ++i) names.push_back(d->field(i)->name());
      std::string msg = d->full_name() + " has no field '" + key + "'";
      if (const auto c = core::closest_match(key, names)) msg += " (did you mean '" + *c + "'?)";
      std::string list;
      for (const std::string& s : names) list += (list.empty() ? "" : ", ") + s;
      v.fail(msg + "; its fields: " + list);
    }
    if (f->is_repeated()) {
      if (!v.is_sequence()) v.fail("a repeated field takes a list");
      for (const ConfigNode& e : v.elements()) set_field(e, m, f);
    } else {
      set_field(v, m, f);
    }
  }
}

/// A message of `type` from the step's `fields` (YAML) or `text` (protobuf text format).
std::shared_ptr<const pb::Message> message_of(const ConfigNode& item, const pb::Message& type) {
  std::shared_ptr<pb::Message> m(type.New());
  const ConfigNode fields = item["fields"];
  const ConfigNode text = item["text"];
  if (fields.defined() && text.defined()) text.fail("give the fields either as fields or as text");
  if (fields.defined()) fill_message(fields, *m);
  if (text.defined() && !pb::TextFormat::ParseFromString(text.as_string(), m.get())) {
    text.fail("not " + type.GetDescriptor()->full_name() +
              " in protobuf's text format (e.g. phase: PRODUCTION game_time { sec: 10 })");
  }
  return m;
}

// ---- the file -----------------------------------------------------------------------------------

enum class Op {
  kStep,
  kUntil,
  kSkill,
  kReceive,
  kAssert,
  kRetract,
  kModify,
  kPose,
  kEval,
  kExpect,
  kExpectNot,
  kExpectSkill,
  kExpectNoSkill,
  kExpectSent,
  kExpectNotSent,
  kExpectLog,
  kExpectNotLog,
  kExpectTrue,
  kExpectNoErrors,
};

constexpr std::pair<std::string_view, Op> kOps[] = {
    {"step", Op::kStep},
    {"until", Op::kUntil},
    {"skill", Op::kSkill},
    {"receive", Op::kReceive},
    {"assert", Op::kAssert},
    {"retract", Op::kRetract},
    {"modify", Op::kModify},
    {"pose", Op::kPose},
    {"eval", Op::kEval},
    {"expect", Op::kExpect},
    {"expect_not", Op::kExpectNot},
    {"expect_skill", Op::kExpectSkill},
    {"expect_no_skill", Op::kExpectNoSkill},
    {"expect_sent", Op::kExpectSent},
    {"expect_not_sent", Op::kExpectNotSent},
    {"expect_log", Op::kExpectLog},
    {"expect_not_log", Op::kExpectNotLog},
    {"expect_true", Op::kExpectTrue},
    {"expect_no_errors", Op::kExpectNoErrors},
};

constexpr int kAgentPeriodMs = 100;
constexpr int kDefaultUntilCycles = 100;

struct Step {
  Op op = Op::kStep;
  std::string where;  ///< "file:line"
  std::string name;   ///< the action's key
  int cycles = 0;     ///< step; until's max
  Pattern pattern;    ///< until, retract, modify (the new slot values), expect, expect_not
  std::optional<Pattern> where_pattern;  ///< modify's `where`
  std::vector<std::string> facts;        ///< assert
  int count = -1;                        ///< expect, expect_sent: exact number
  SkillStatus status = SkillStatus::kIdle;
  std::optional<std::string> result, error;
  const pb::Message* type = nullptr;           ///< receive, expect_sent, expect_not_sent
  std::shared_ptr<const pb::Message> message;  ///< receive; expect_sent's fields (partial)
  std::string from = "refbox";                 ///< receive
  int from_id = 0;                             ///< receive
  std::string text;                            ///< skill string, log text, expression
  core::Pose2D pose;
};

struct RobotIdentity {
  std::string name = "robot1";
  int number = 1;
  std::string team = "Carologistics";
  std::int64_t seed = 1;
};

struct Case {
  std::string name;
  std::string where;
  std::vector<Step> given;
  std::vector<Step> steps;
  RobotIdentity robot;
  bool locks = false;
  int lock_team_size = 1;
  ConfigEntries config;
  bool allow_runtime_errors = false;
};

int cycles_of(const ConfigNode& n) {
  const std::string s = n.as_string();
  if (!s.empty() && s.back() == 's') {
    char* end = nullptr;
    const double secs = std::strtod(s.c_str(), &end);
    if (end != s.c_str() + s.size() - 1 || !(secs >= 0.0))
      n.fail("a time is a number of cycles (5) or of seconds (2.5s)");
    return static_cast<int>(std::llround(secs * 1000.0 / kAgentPeriodMs));
  }
  return static_cast<int>(n.as_int(core::in_range(0, 1'000'000)));
}

SkillStatus status_of(const ConfigNode& n) {
  static const std::pair<std::string_view, SkillStatus> names[] = {
      {"FINAL", SkillStatus::kFinal},
      {"FAILED", SkillStatus::kFailed},
      {"RUNNING", SkillStatus::kRunning},
      {"IDLE", SkillStatus::kIdle}};
  const std::string v = n.as_string();
  for (const auto& [name, st] : names)
    if (v == name) return st;
  n.fail("unknown skill status '" + v + "' (expected one of: FINAL, FAILED, RUNNING, IDLE)");
}

Step parse_step(const ConfigNode& item, bool given, const comm::MessageRegistry& registry) {
  Step s;
  s.where = line_of(item);
  if (item.is_scalar() && given) {
    s.op = Op::kAssert;
    s.name = "assert";
    s.facts.push_back(item.as_string());
    return s;
  }
  if (!item.is_map()) {
    item.fail(
        "a step is a map with one action, e.g. `- step: 1`, `- skill: FINAL` or `- expect: "
        "(state IDLE)`");
  }
  std::vector<std::pair<std::string_view, Op>> present;
  for (const auto& [name, op] : kOps)
    if (item[name].defined()) present.emplace_back(name, op);
  if (present.empty()) {
    item.no_other_keys();  // a misspelt action: "did you mean"
    item.fail(
        "a step needs one action (step, until, skill, receive, assert, retract, modify, "
        "pose, eval, expect, expect_not, expect_skill, expect_no_skill, expect_sent, "
        "expect_not_sent, expect_log, expect_not_log, expect_true, expect_no_errors)");
  }
  if (present.size() > 1) {
    item[present[1].first].fail("one action per step, and this one has " +
                                std::string(present[0].first) + " and " +
                                std::string(present[1].first) + ": make them two list items");
  }
  s.op = present[0].second;
  s.name = std::string(present[0].first);
  const ConfigNode v = item[s.name];
  switch (s.op) {
    case Op::kStep:
      s.cycles = cycles_of(v);
      break;
    case Op::kUntil:
      s.pattern = parse_pattern(v);
      s.cycles = kDefaultUntilCycles;
      if (item["max"].defined()) s.cycles = cycles_of(item["max"]);
      break;
    case Op::kSkill:
      s.status = status_of(v);
      if (item["result"].defined()) s.result = item["result"].as_string();
      if (item["error"].defined()) s.error = item["error"].as_string();
      break;
    case Op::kReceive:
      s.type = find_type(v, registry);
      s.message = message_of(item, *s.type);
      item.read("from", s.from);
      item.read("from_id", s.from_id);
      break;
    case Op::kAssert:
      if (v.is_sequence()) {
        for (const ConfigNode& e : v.elements()) s.facts.push_back(e.as_string());
      } else {
        s.facts.push_back(v.as_string());
      }
      break;
    case Op::kRetract:
    case Op::kExpect:
    case Op::kExpectNot:
      s.pattern = parse_pattern(v);
      if (s.op == Op::kExpect) item.read("count", s.count);
      break;
    case Op::kModify:
      s.pattern = parse_pattern(v);
      if (s.pattern.ordered || s.pattern.slots.empty())
        v.fail("modify takes the template and the slots to change, e.g. (game (phase PRODUCTION))");
      if (item["where"].defined()) {
        s.where_pattern = parse_pattern(item["where"]);
        if (s.where_pattern->template_name != s.pattern.template_name)
          item["where"].fail("the fact to modify is a " + s.pattern.template_name);
      }
      break;
    case Op::kPose: {
      double x = 0.0, y = 0.0, ori = 0.0, ori_deg = 0.0;
      v.require_map();
      v.read("x", x);
      v.read("y", y);
      v.read("ori", ori);
      v.read("ori_deg", ori_deg);
      v.no_other_keys();
      s.pose = core::Pose2D{x, y, ori + ori_deg * std::numbers::pi / 180.0};
      break;
    }
    case Op::kEval:
    case Op::kExpectTrue:
    case Op::kExpectLog:
    case Op::kExpectNotLog:
    case Op::kExpectSkill:
      s.text = v.as_string();
      break;
    case Op::kExpectNoSkill:
    case Op::kExpectNoErrors:
      if (!v.as_bool()) v.fail("write `" + s.name + ": true`");
      break;
    case Op::kExpectSent:
    case Op::kExpectNotSent:
      s.type = find_type(v, registry);
      if (item["fields"].defined() || item["text"].defined()) s.message = message_of(item, *s.type);
      if (s.op == Op::kExpectSent) item.read("count", s.count);
      break;
  }
  item.no_other_keys();
  return s;
}

std::vector<Step> parse_steps(const ConfigNode& list, bool given,
                              const comm::MessageRegistry& registry) {
  std::vector<Step> out;
  if (!list.defined() || list.is_null()) return out;
  if (!list.is_sequence()) list.fail("a list of steps");
  for (const ConfigNode& item : list.elements()) out.push_back(parse_step(item, given, registry));
  return out;
}

void read_robot(const ConfigNode& n, RobotIdentity& r) {
  if (!n.defined()) return;
  n.require_map();
  n.read("name", r.name);
  n.read("number", r.number, core::in_range(1, 99));
  n.read("team", r.team);
  n.read("seed", r.seed);
  n.no_other_keys();
}

/// The line of the test file on which the text of `setup` starts: the line after a block scalar's
/// `|` or `>`, else the value's line.
int setup_first_line(const ConfigNode& setup, const std::string& path) {
  const std::string loc = setup.location();
  const auto c2 = loc.rfind(':');
  const auto c1 = c2 == std::string::npos || c2 == 0 ? std::string::npos : loc.rfind(':', c2 - 1);
  if (c1 == std::string::npos) return 1;
  const int line = std::atoi(loc.c_str() + c1 + 1);
  const int column = std::atoi(loc.c_str() + c2 + 1);
  std::istringstream in(core::read_input_file(path, core::kMaxSourceBytes, "rule-test file"));
  std::string text;
  for (int i = 0; i < line && std::getline(in, text); ++i) {
  }
  const auto at = static_cast<std::size_t>(std::max(column - 1, 0));
  const bool block = at < text.size() && (text[at] == '|' || text[at] == '>');
  return std::max(1, block ? line + 1 : line);
}

/// `over`'s entries replace `base`'s of the same path.
ConfigEntries merge(ConfigEntries base, const ConfigEntries& over) {
  for (const ConfigEntry& e : over) {
    std::erase_if(base, [&](const ConfigEntry& b) { return b.path == e.path; });
    base.push_back(e);
  }
  return base;
}

}  // namespace

// ---- finding files ------------------------------------------------------------------------------

std::vector<std::string> find_rule_test_files(const std::vector<std::string>& paths) {
  std::vector<std::string> out;
  for (const std::string& p : paths) {
    std::error_code ec;
    if (fs::is_regular_file(p, ec)) {
      out.push_back(p);
      continue;
    }
    if (!fs::is_directory(p, ec)) throw core::UserError(p + ": no such file or directory");
    std::vector<std::string> found;
    for (const auto& f : fs::recursive_directory_iterator(p, ec)) {
      const std::string name = f.path().filename().string();
      if (f.is_regular_file() && name.ends_with("_test.yaml")) found.push_back(f.path().string());
    }
    if (found.empty())
      throw core::UserError(p + ": no test files (*_test.yaml) in this directory or below");
    std::sort(found.begin(), found.end());
    out.insert(out.end(), found.begin(), found.end());
  }
  return out;
}

// ---- RuleTestFile -------------------------------------------------------------------------------

struct RuleTestFile::Impl {
  std::string path;
  const comm::MessageRegistry* registry = nullptr;
  std::vector<std::string> agent_files;
  std::string setup;
  std::vector<Case> cases;

  AgentConfig config_of(const Case& c) const {
    AgentConfig cfg;
    cfg.robot_name = c.robot.name;
    cfg.robot_number = c.robot.number;
    cfg.team_name = c.robot.team;
    cfg.seed = static_cast<std::uint64_t>(c.robot.seed);
    cfg.config = c.config;
    if (c.locks) {
      cfg.locks = true;
      cfg.lock_config.team_size = c.lock_team_size;
      // As sim::AgentBrain: the team agents read the switch as a confval.
      std::erase_if(cfg.config,
                    [](const ConfigEntry& e) { return e.path == "/clips-agent/use-locks"; });
      cfg.config.push_back(ConfigEntry::of("/clips-agent/use-locks", true));
    }
    return cfg;
  }

  /// Loads the agent into `f`; throws AgentLoadError.
  void load_agent(AgentFixture& f) const {
    for (const std::string& file : agent_files) f.load_file(file);
    if (!setup.empty()) f.load(setup, path);
  }
};

RuleTestFile::RuleTestFile(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
RuleTestFile::~RuleTestFile() = default;
RuleTestFile::RuleTestFile(RuleTestFile&&) noexcept = default;
RuleTestFile& RuleTestFile::operator=(RuleTestFile&&) noexcept = default;

const std::string& RuleTestFile::path() const { return impl_->path; }
int RuleTestFile::size() const { return static_cast<int>(impl_->cases.size()); }
const std::string& RuleTestFile::case_name(int index) const {
  return impl_->cases.at(static_cast<std::size_t>(index)).name;
}

RuleTestFile RuleTestFile::load(const std::string& path, const comm::MessageRegistry& registry) {
  auto impl = std::make_unique<Impl>();
  impl->path = path;
  impl->registry = &registry;
  const ConfigNode root = ConfigNode::load_file(path);
  if (!root.is_map())
    root.fail("a test file is a map with agent, tests, ... (docs/agent-tests.md)");
  const fs::path dir = fs::path(path).parent_path();

  // The agent: files or directories relative to the test file.
  const ConfigNode agent = root.at("agent");
  std::vector<std::string> entries;
  const auto add_entry = [&](const ConfigNode& n) {
    const fs::path p = fs::path(n.as_string());
    const fs::path full = p.is_absolute() ? p : dir / p;
    std::error_code ec;
    if (!fs::exists(full, ec))
      n.fail("no such file or directory: " + full.string() + " (relative to the test file)");
    entries.push_back(full.lexically_normal().string());
  };
  if (agent.is_sequence()) {
    for (const ConfigNode& e : agent.elements()) add_entry(e);
  } else {
    add_entry(agent);
  }
  impl->agent_files = expand_agent_files(entries);
  if (impl->agent_files.empty()) agent.fail("no *.clp files");
  if (const ConfigNode setup = root["setup"]; setup.defined()) {
    // Padded with empty lines, so that CLIPS' errors name the test file's lines.
    impl->setup = std::string(static_cast<std::size_t>(setup_first_line(setup, path) - 1), '\n') +
                  setup.as_string();
  }
  std::string description;
  root.read("description", description);

  // File-wide defaults of the cases.
  Case defaults;
  read_robot(root["robot"], defaults.robot);
  root.read("locks", defaults.locks);
  root.read("lock_team_size", defaults.lock_team_size, core::in_range(1, 99));
  if (root["config"].defined()) {
    root["config"].require_map();
    defaults.config = config_from_node(root["config"], "/clips-agent");
  }

  const ConfigNode tests = root.at("tests");
  if (!tests.is_sequence() || tests.size() == 0) tests.fail("a list of test cases");
  std::map<std::string, std::string> names;
  for (const ConfigNode& t : tests.elements()) {
    if (!t.is_map()) t.fail("a test case is a map with name, given, steps");
    Case c = defaults;
    c.where = line_of(t);
    c.name = t.at("name").as_string();
    if (const auto [it, fresh] = names.emplace(c.name, c.where); !fresh)
      t["name"].fail("a second test case named '" + c.name + "' (the first at " + it->second + ")");
    read_robot(t["robot"], c.robot);
    t.read("locks", c.locks);
    t.read("lock_team_size", c.lock_team_size, core::in_range(1, 99));
    if (t["config"].defined()) {
      t["config"].require_map();
      c.config = merge(c.config, config_from_node(t["config"], "/clips-agent"));
    }
    t.read("allow_runtime_errors", c.allow_runtime_errors);
    c.given = parse_steps(t["given"], true, registry);
    c.steps = parse_steps(t["steps"], false, registry);
    t.no_other_keys();
    if (c.steps.empty() && c.given.empty()) t.fail("a test case needs given facts or steps");
    impl->cases.push_back(std::move(c));
  }
  root.no_other_keys();

  // The agent must load (with each case's lock switch: the lock template exists only with it).
  for (const bool locks : {false, true}) {
    const auto it = std::find_if(impl->cases.begin(), impl->cases.end(),
                                 [&](const Case& c) { return c.locks == locks; });
    if (it == impl->cases.end()) continue;
    AgentFixture f(impl->config_of(*it), &registry);
    try {
      impl->load_agent(f);
    } catch (const AgentLoadError& e) {
      agent.fail(std::string("the agent does not load") + (locks ? " (locks: true)" : "") + ":\n" +
                 e.what());
    }
  }
  return RuleTestFile(std::move(impl));
}

namespace {

/// What has been looked at by the expectations of one kind (skill calls, broadcasts, log lines):
/// they see what happened since time last advanced after such an expectation.
struct Window {
  std::size_t start = 0;
  bool looked = false;
  std::string since = "the start of the case";
};

/// Runs one case.
class CaseRunner {
 public:
  CaseRunner(const Case& c, AgentFixture& f, RuleTestResult& r) : case_(c), f_(f), r_(r) {}

  bool run(const std::vector<Step>& steps) {
    for (const Step& s : steps) {
      try {
        if (!exec(s)) {
          runtime_errors_context();
          return false;
        }
      } catch (const PatternMismatch& e) {
        r_.bad_input = true;
        return fail(s, e.what());
      } catch (const std::invalid_argument& e) {
        r_.bad_input = true;
        return fail(s, e.what());
      }
    }
    return true;
  }

  bool final_checks() {
    if (!case_.allow_runtime_errors && f_.agent().runtime_errors() > 0) {
      r_.failure.push_back(case_.where + ": test " + case_.name +
                           ": expected no runtime errors but there were " +
                           std::to_string(f_.agent().runtime_errors()) +
                           " (allow them with allow_runtime_errors: true)");
      add_error_lines();
      return false;
    }
    return true;
  }

 private:
  bool fail(const Step& s, const std::string& what) {
    r_.failure.insert(r_.failure.begin(), s.where + ": test " + case_.name + ": " + what);
    return false;
  }
  void context(const std::string& line) { r_.failure.push_back("  " + line); }

  void add_error_lines() {
    for (const LoggedLine& l : f_.log())
      if (l.level == LogLevel::kError) context(l.text);
  }

  // A failed expectation is often the effect of a runtime error earlier in the case (the rule
  // stopped before it asserted or called what was expected): show the errors with it, not only
  // with -v.
  void runtime_errors_context() {
    const int n = f_.agent().runtime_errors();
    if (n == 0) return;
    context("the agent had " + std::to_string(n) + " runtime error" + (n == 1 ? "" : "s") +
            " (a likely cause):");
    for (const LoggedLine& l : f_.log())
      if (l.level == LogLevel::kError) context("  " + l.text);
  }

  void facts_context(const std::string& template_name) {
    const std::vector<Fact> facts = f_.facts(template_name);
    if (facts.empty()) {
      context("the agent has no " + template_name + " facts");
      return;
    }
    context("the agent's " + template_name + " facts:");
    constexpr std::size_t kMax = 20;
    for (std::size_t i = 0; i < facts.size() && i < kMax; ++i) context("  " + fact_text(facts[i]));
    if (facts.size() > kMax) context("  ... and " + std::to_string(facts.size() - kMax) + " more");
  }

  void advance(int cycles, const Step& s) {
    // A window that an expectation looked at starts anew.
    const std::string since = "line " + s.where.substr(s.where.rfind(':') + 1);
    const std::size_t sizes[] = {f_.skills().calls().size(), f_.sent().size(), f_.log().size()};
    Window* windows[] = {&skills_, &sent_, &log_};
    for (int i = 0; i < 3; ++i) {
      if (!windows[i]->looked) continue;
      *windows[i] = Window{sizes[i], false, since};
    }
    for (int i = 0; i < cycles; ++i) {
      f_.step(core::SimTime::from_ms(kAgentPeriodMs));
      ++r_.cycles;
    }
  }

  /// Opens the window of an expectation kind: what happened since it was last looked at.
  template <class Seq>
  std::pair<std::size_t, std::size_t> look(Window& w, const Seq& seq) {
    w.looked = true;
    return {std::min(w.start, seq.size()), seq.size()};
  }

  bool exec(const Step& s) {
    AgentHost& a = f_.agent();
    switch (s.op) {
      case Op::kStep:
        step_cycles(s, s.cycles);
        return true;
      case Op::kUntil: {
        for (int k = 0;; ++k) {
          if (!matching(a, s.pattern).empty()) return true;
          if (k == s.cycles) break;
          step_cycles(s, 1);
        }
        fail(s, "expected " + s.pattern.text + " within " + std::to_string(s.cycles) + " cycles (" +
                    core::number_text(s.cycles * kAgentPeriodMs / 1000.0) +
                    " s) but it did not appear");
        facts_context(s.pattern.template_name);
        return false;
      }
      case Op::kSkill:
        if (s.result) f_.skills().set_result(*s.result);
        f_.skills().set_status(s.status, s.error.value_or(""));
        return true;
      case Op::kReceive: {
        std::unique_ptr<pb::Message> m(s.message->New());
        m->CopyFrom(*s.message);
        a.receive(std::move(m), s.from, s.from_id, f_.now());
        return true;
      }
      case Op::kAssert:
        for (const std::string& fact : s.facts) a.assert_fact(fact);  // invalid_argument: bad
        return true;
      case Op::kRetract: {
        const std::vector<Fact> found = matching(a, s.pattern);
        if (found.empty()) {
          fail(s, "expected a fact " + s.pattern.text + " to retract but there is none");
          facts_context(s.pattern.template_name);
          return false;
        }
        for (const Fact& fact : found)
          eval_checked(s, "(retract " + std::to_string(fact.index) + ")");
        return true;
      }
      case Op::kModify: {
        std::vector<Fact> found;
        if (s.where_pattern) {
          found = matching(a, *s.where_pattern);
        } else {
          found = f_.facts(s.pattern.template_name);
          if (found.size() > 1) {
            r_.bad_input = true;
            fail(s, "there are " + std::to_string(found.size()) + " " + s.pattern.template_name +
                        " facts: say which with `where: (" + s.pattern.template_name +
                        " (slot value))`");
            return false;
          }
        }
        if (found.empty()) {
          fail(s,
               "expected a fact " +
                   (s.where_pattern ? s.where_pattern->text : "(" + s.pattern.template_name + ")") +
                   " to modify but there is none");
          facts_context(s.pattern.template_name);
          return false;
        }
        // Check the slot names before CLIPS sees them (a bad one is bad input, not a runtime
        // error of the agent).
        for (const auto& slot : s.pattern.slots) {
          const std::string& name = slot.first;
          const auto& have = found[0].slots;
          if (std::any_of(have.begin(), have.end(), [&](const auto& x) { return x.first == name; }))
            continue;
          std::vector<std::string> names;
          for (const auto& x : have) names.push_back(x.first);
          std::string msg = "template " + s.pattern.template_name + " has no slot '" + name + "'";
          if (const auto m = core::closest_match(name, names))
            msg += " (did you mean '" + *m + "'?)";
          throw PatternMismatch(msg);
        }
        std::string set;
        for (const auto& [name, values] : s.pattern.slots)
          set += " (" + name + values_text(values) + ")";
        for (const Fact& fact : found) {
          eval_checked(s, "(do-for-fact ((?f " + s.pattern.template_name +
                              ")) (= (fact-index ?f) " + std::to_string(fact.index) +
                              ") (modify ?f" + set + "))");
        }
        return true;
      }
      case Op::kPose:
        a.set_pose(s.pose);
        return true;
      case Op::kEval:
        a.eval(s.text);
        return true;
      case Op::kExpect:
      case Op::kExpectNot: {
        const std::size_t n = matching(a, s.pattern).size();
        const bool want_absent = s.op == Op::kExpectNot;
        bool ok =
            want_absent ? n == 0 : (s.count >= 0 ? n == static_cast<std::size_t>(s.count) : n > 0);
        if (ok) return true;
        std::string what;
        if (want_absent) {
          what = "expected no fact " + s.pattern.text + " but there " +
                 (n == 1 ? std::string("is one") : "are " + std::to_string(n));
        } else if (s.count >= 0) {
          what = "expected " + std::to_string(s.count) + " facts " + s.pattern.text +
                 " but there " + (n == 1 ? std::string("is one") : "are " + std::to_string(n));
        } else {
          what = "expected a fact " + s.pattern.text + " but there is none";
        }
        fail(s, what);
        facts_context(s.pattern.template_name);
        return false;
      }
      case Op::kExpectSkill:
      case Op::kExpectNoSkill: {
        const auto& calls = f_.skills().calls();
        const auto [b, e] = look(skills_, calls);
        const bool exact = s.text.find('{') != std::string::npos;
        bool found = false;
        for (std::size_t i = b; i < e; ++i) {
          const std::string& c = calls[i];
          if (exact ? c == s.text : c.substr(0, c.find('{')) == s.text) found = true;
        }
        if (s.op == Op::kExpectNoSkill ? b == e : found) return true;
        std::string list;
        for (std::size_t i = b; i < e; ++i) list += (list.empty() ? "" : ", ") + calls[i];
        if (s.op == Op::kExpectNoSkill) {
          fail(s,
               "expected no skill call since " + skills_.since + " but the agent called " + list);
        } else {
          fail(s, "expected a skill call " + s.text + " since " + skills_.since + " but " +
                      (b == e ? "the agent called no skill" : "the agent called " + list));
          facts_context("skill");
        }
        return false;
      }
      case Op::kExpectSent:
      case Op::kExpectNotSent: {
        auto& sent = f_.sent();
        const auto [b, e] = look(sent_, sent);
        int n = 0;
        std::vector<std::string> of_type;
        std::map<std::string, int> others;
        for (std::size_t i = b; i < e; ++i) {
          const pb::Message& m = *sent[i];
          if (m.GetDescriptor() != s.type->GetDescriptor()) {
            ++others[m.GetDescriptor()->full_name()];
            continue;
          }
          of_type.push_back(m.ShortDebugString());
          if (s.message) {
            pb::util::MessageDifferencer d;
            d.set_scope(pb::util::MessageDifferencer::PARTIAL);
            d.set_repeated_field_comparison(pb::util::MessageDifferencer::AS_SET);
            if (!d.Compare(*s.message, m)) continue;
          }
          ++n;
        }
        const std::string type = s.type->GetDescriptor()->full_name();
        const std::string want =
            type + (s.message ? " {" + s.message->ShortDebugString() + "}" : std::string());
        bool ok = s.op == Op::kExpectNotSent ? n == 0 : (s.count >= 0 ? n == s.count : n > 0);
        if (ok) return true;
        if (s.op == Op::kExpectNotSent) {
          fail(s, "expected no broadcast " + want + " since " + sent_.since +
                      " but the agent sent " + std::to_string(n));
        } else if (s.count >= 0) {
          fail(s, "expected " + std::to_string(s.count) + " broadcasts " + want + " since " +
                      sent_.since + " but the agent sent " + std::to_string(n));
        } else {
          fail(s, "expected a broadcast " + want + " since " + sent_.since + " but " +
                      (of_type.empty() ? "the agent sent none of that type"
                                       : "none of the " + std::to_string(of_type.size()) +
                                             " of that type matches"));
        }
        constexpr std::size_t kMax = 10;
        for (std::size_t i = 0; i < of_type.size() && i < kMax; ++i)
          context("sent " + type + " {" + of_type[i] + "}");
        for (const auto& [name, count] : others)
          context("sent " + std::to_string(count) + "x " + name);
        return false;
      }
      case Op::kExpectLog:
      case Op::kExpectNotLog: {
        const auto& log = f_.log();
        const auto [b, e] = look(log_, log);
        std::size_t hit = e;
        for (std::size_t i = b; i < e && hit == e; ++i)
          if (log[i].text.find(s.text) != std::string::npos) hit = i;
        if ((s.op == Op::kExpectLog) == (hit != e)) return true;
        if (s.op == Op::kExpectLog) {
          fail(s, "expected a log line containing \"" + s.text + "\" since " + log_.since +
                      " but there is none");
          constexpr std::size_t kMax = 10;
          const std::size_t from = e - b > kMax ? e - kMax : b;
          if (from < e) context("the agent's log (last lines):");
          for (std::size_t i = from; i < e; ++i) context("  " + log[i].text);
        } else {
          fail(s, "expected no log line containing \"" + s.text + "\" since " + log_.since +
                      " but: " + log[hit].text);
        }
        return false;
      }
      case Op::kExpectTrue: {
        const int errors = a.runtime_errors();
        const Value v = a.eval(s.text);
        if (a.runtime_errors() > errors || v.type == Value::Type::kVoid) {
          r_.bad_input = true;
          fail(s, "cannot evaluate " + s.text);
          add_error_lines();
          return false;
        }
        if (!v.is_symbol("FALSE")) return true;
        fail(s, "expected " + s.text + " to be true but it is FALSE");
        return false;
      }
      case Op::kExpectNoErrors:
        if (a.runtime_errors() == 0) return true;
        fail(s, "expected no runtime errors but there were " + std::to_string(a.runtime_errors()));
        add_error_lines();
        return false;
    }
    return true;
  }

  void step_cycles(const Step& s, int cycles) { advance(cycles, s); }

  void eval_checked(const Step& s, const std::string& expression) {
    const int errors = f_.agent().runtime_errors();
    f_.agent().eval(expression);
    if (f_.agent().runtime_errors() > errors)
      throw std::invalid_argument(s.name + " failed: " + expression);
  }

  const Case& case_;
  AgentFixture& f_;
  RuleTestResult& r_;
  Window skills_, sent_, log_;
};

}  // namespace

RuleTestResult RuleTestFile::run(int index) const {
  const Case& c = impl_->cases.at(static_cast<std::size_t>(index));
  RuleTestResult r;
  r.file = impl_->path;
  r.name = c.name;
  AgentFixture f(impl_->config_of(c), impl_->registry);
  try {
    impl_->load_agent(f);
  } catch (const AgentLoadError& e) {
    r.bad_input = true;
    r.failure.push_back(c.where + ": test " + c.name + ": the agent does not load: " + e.what());
    return r;
  }
  f.agent().start(f.now());
  CaseRunner runner(c, f, r);
  r.passed = runner.run(c.given) && runner.run(c.steps) && runner.final_checks();
  r.log = f.log();
  return r;
}

}  // namespace llsf::clips
