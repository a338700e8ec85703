// SPDX-License-Identifier: MIT
// Skills feature: (skill-call NAME key val ...) builds the Lua skill string as Fawkes' clips-agent
// does and hands it to the SkillRunner; the (skill ...) fact follows the runner's status.
#include <charconv>

#include "feature.h"

namespace llsf::clips::detail {
namespace {

// A Lua string literal.
void append_quoted(std::string& out, std::string_view s) {
  out += '"';
  for (char c : s) {
    switch (c) {
      case '"':
        out += "\\\"";
        break;
      case '\\':
        out += "\\\\";
        break;
      case '\n':
        out += "\\n";
        break;
      default:
        out += c;
    }
  }
  out += '"';
}

// One argument value as Fawkes writes it: numbers and the symbols true/false bare, a string
// starting with '{' (a Lua table) passed through, other strings and symbols quoted.
bool append_lua_value(std::string& out, const Value& v) {
  switch (v.type) {
    case Value::Type::kInteger:
      out += std::to_string(v.integer);
      return true;
    case Value::Type::kFloat: {
      char buf[32];
      auto r = std::to_chars(buf, buf + sizeof buf, v.real);
      out.append(buf, r.ptr);
      return true;
    }
    case Value::Type::kSymbol:
      if (v.text == "true" || v.text == "false") {
        out += v.text;
        return true;
      }
      append_quoted(out, v.text);
      return true;
    case Value::Type::kString:
      if (!v.text.empty() && v.text.front() == '{') {
        out += v.text;
        return true;
      }
      append_quoted(out, v.text);
      return true;
    default:
      return false;
  }
}

class SkillsFeature final : public Feature {
 public:
  explicit SkillsFeature(HostState& s) : s_(s) {}

  void define(Environment& env) override {
    env.define_function("skill-call", "1**", [this, &env](Args& a) {
      std::string_view name;
      if (!a.text(0, name)) {
        env.error(a.function(), "the skill name must be a symbol or string");
        return Value{};
      }
      if (a.count() % 2 != 1) {
        env.error(a.function(), "arguments must come in key value pairs");
        return Value{};
      }
      std::string sks(name);
      sks += '{';
      for (int i = 1; i < a.count(); i += 2) {
        std::string_view key;
        if (!a.text(i, key)) {
          env.error(a.function(), "argument keys must be symbols");
          return Value{};
        }
        if (i > 1) sks += ", ";
        sks.append(key);
        sks += '=';
        if (!append_lua_value(sks, a.value(i + 1))) {
          env.error(a.function(),
                    "argument " + std::string(key) + " must be a number, symbol or string");
          return Value{};
        }
      }
      sks += '}';
      if (s_.io.skills == nullptr) {
        env.error(a.function(), "this agent has no skill runner");
        return Value{};
      }
      // Only one skill string runs at a time: the previous one is aborted.
      if (active_) set_status(env, SkillStatus::kFailed, "aborted by skill-call " + sks);
      s_.log(LogLevel::kDebug, "skill-call " + sks);
      s_.io.skills->exec(sks);
      active_ = true;
      name_ = std::string(name);
      skill_string_ = sks;
      status_ = SkillStatus::kIdle;
      error_.clear();
      result_.clear();
      write_fact(env);
      return Value{};
    });
    // (skill-stop): aborts the running skill string; its fact becomes FAILED.
    env.define_function("skill-stop", "00", [this, &env](Args&) {
      if (s_.io.skills != nullptr) s_.io.skills->stop();
      if (active_) set_status(env, SkillStatus::kFailed, "stopped by skill-stop");
      return Value{};
    });
  }

  void bind(Environment& env) override { skill_ = env.find_template("skill"); }

  void after_reset(Environment& env) override {
    env.release(fact_);
    active_ = false;
  }

  void before_run(Environment& env) override {
    if (!active_ || s_.io.skills == nullptr) return;
    const SkillRunner& r = *s_.io.skills;
    if (r.skill_string() != skill_string_) {
      set_status(env, SkillStatus::kFailed, "the skill runner dropped the skill string");
      return;
    }
    const SkillStatus st = r.status();
    if (st == SkillStatus::kIdle || st == status_) return;
    result_ =
        (st == SkillStatus::kFinal || st == SkillStatus::kFailed) ? r.result() : std::string();
    set_status(env, st, st == SkillStatus::kFailed ? r.error() : std::string());
  }

 private:
  // Modifies the skill fact (retract + assert); a finished skill is no longer tracked.
  void set_status(Environment& env, SkillStatus st, std::string error) {
    status_ = st;
    error_ = std::move(error);
    write_fact(env);
    if (st == SkillStatus::kFinal || st == SkillStatus::kFailed) {
      env.release(fact_);
      active_ = false;
    }
  }

  void write_fact(Environment& env) {
    if (!fact_.empty() && !env.exists(fact_)) {
      // The agent modified the fact (a rule's modify, Fawkes' skill-update rule): the skill's
      // fact is the one with its name and skill string now.
      for (const FactCopy& f : env.facts("skill")) {
        const auto slot = [&f](std::string_view n) -> const Value* {
          for (const auto& [name, v] : f.slots)
            if (name == n) return &v;
          return nullptr;
        };
        const Value* name = slot("name");
        const Value* sks = slot("skill-string");
        if (name != nullptr && sks != nullptr && name->text == name_ && sks->text == skill_string_)
          env.eval("(retract " + std::to_string(f.index) + ")");
      }
    }
    env.retract(fact_);
    const Value v[] = {Value::string(name_), Value::symbol(to_string(status_)),
                       Value::string(skill_string_), Value::string(error_), Value::string(result_)};
    fact_ = env.assert_fact(skill_, v);
  }

  HostState& s_;
  Template skill_;
  FactHandle fact_;
  bool active_ = false;
  std::string name_, skill_string_, error_, result_;
  SkillStatus status_ = SkillStatus::kIdle;
};

}  // namespace

std::unique_ptr<Feature> make_skills_feature(HostState& s) {
  return std::make_unique<SkillsFeature>(s);
}

}  // namespace llsf::clips::detail
