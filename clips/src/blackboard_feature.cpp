// SPDX-License-Identifier: MIT
// Blackboard feature (Fawkes-style agents, docs/fawkes.md): Fawkes' clips blackboard feature
// for the interfaces a 2013 agent reads. (blackboard-open "Type" "Id") defines a deftemplate per
// interface type (slot id, multislot time, one slot per field, as Fawkes built it from the
// interface's fields) whose facts go at the end of every run (Fawkes: a clean-up rule at salience
// -10000); (blackboard-enable-time-read) makes every cycle start with (blackboard-read) (Fawkes:
// a rule at salience 1000 on the (time) fact); (blackboard-read) asserts one fact per opened
// interface whose data changed since it was last read. Both happen without a rule firing, as the
// time fact's retraction: at every cycle, they were most of the 2013 agent's firings. The data are
// written by the host (AgentHost::write_interface; the pose as Position3DInterface "Pose").
#include <algorithm>
#include <array>
#include <map>
#include <stdexcept>

#include "feature.h"

namespace llsf::clips::detail {

namespace {

struct FieldDef {
  const char* name;
  const char* slot;  // the deftemplate's slot definition after the name
  int length;        // > 1: a multislot
};
struct InterfaceDef {
  const char* type;
  std::vector<FieldDef> fields;
};

// The interface types (fields as Fawkes' interface definitions of 2013/14 declare them).
const std::vector<InterfaceDef>& interface_defs() {
  static const std::vector<InterfaceDef> kDefs = {
      {"Position3DInterface",
       {{"frame", "(type STRING)", 1},
        {"visibility_history", "(type INTEGER)", 1},
        {"rotation", "(type FLOAT)", 4},
        {"translation", "(type FLOAT)", 3}}},
      {"RobotinoLightInterface",
       {{"red", "(type SYMBOL)", 1},
        {"yellow", "(type SYMBOL)", 1},
        {"green", "(type SYMBOL)", 1},
        {"visibility_history", "(type INTEGER)", 1},
        {"ready", "(type SYMBOL) (allowed-values TRUE FALSE)", 1}}},
  };
  return kDefs;
}

const InterfaceDef* find_def(std::string_view type) {
  for (const InterfaceDef& d : interface_defs())
    if (type == d.type) return &d;
  return nullptr;
}

class BlackboardFeature final : public Feature {
 public:
  explicit BlackboardFeature(HostState& s) : s_(s) {}

  void define(Environment& env) override {
    env.define_function("blackboard-enable-time-read", "00", [this](Args&) {
      time_read_ = true;
      return Value{};
    });
    env.define_function("blackboard-open", "22k", [this, &env](Args& a) {
      std::string_view type, id;
      a.text(0, type);
      a.text(1, id);
      open(env, std::string(type), std::string(id));
      return Value{};
    });
    env.define_function("blackboard-read", "00", [this, &env](Args&) {
      read(env);
      return Value{};
    });
  }

  void after_reset(Environment&) override {
    for (auto& [key, o] : opened_) o.read_serial = 0;  // the reset took the facts
  }

  // The cycle's time fact is there (TimeFeature, before this feature): the facts of the
  // interfaces that changed come first, as the salience-1000 rule brought them.
  void before_run(Environment& env) override {
    cleanup(env);  // (a run cut short left them)
    if (time_read_) read(env);
  }

  // As the clean-up rules at salience -10000: every fact of an opened type goes.
  void after_run(Environment& env) override { cleanup(env); }

 private:
  struct Opened {
    std::string type, id;
    std::uint64_t read_serial = 0;  // the data's serial when last asserted
  };

  void open(Environment& env, const std::string& type, const std::string& id) {
    const InterfaceDef* def = find_def(type);
    if (def == nullptr) {
      s_.log(LogLevel::kWarn, "blackboard-open: no interface type " + type + " (llsfsim offers " +
                                  types_text() + "; docs/fawkes.md)");
      return;
    }
    if (opened_.contains({type, id})) return;
    const bool first = std::none_of(opened_.begin(), opened_.end(),
                                    [&](const auto& o) { return o.first.first == type; });
    if (first) {
      std::string t = "(deftemplate " + type + " (slot id (type STRING))" +
                      " (multislot time (type INTEGER) (cardinality 2 2))";
      for (const FieldDef& f : def->fields)
        t += std::string(f.length > 1 ? " (multislot " : " (slot ") + f.name + " " + f.slot + ")";
      t += ")";
      env.load(t);
      cleanup_.push_back(env.find_template(type));
    }
    opened_[{type, id}] = Opened{type, id, 0};
  }

  void read(Environment& env) {
    for (auto& [key, o] : opened_) {
      const auto it = s_.blackboard.find(key);
      if (it == s_.blackboard.end() || it->second.serial == o.read_serial) continue;
      o.read_serial = it->second.serial;
      const HostState::InterfaceData& d = it->second;
      if (assert_direct(env, o, d)) continue;
      std::string fact = "(" + o.type + " (id \"" + o.id + "\") (time " +
                         std::to_string(d.time.ns() / 1'000'000'000) + " " +
                         std::to_string((d.time.ns() % 1'000'000'000) / 1000) + ")";
      for (const auto& [name, v] : d.fields) {
        fact += " (" + name;
        if (v.type == Value::Type::kMultifield) {
          for (const Value& item : v.items) fact += " " + item.to_string();
        } else {
          fact += " " + v.to_string();
        }
        fact += ")";
      }
      fact += ")";
      if (!env.assert_string(fact))
        s_.log(LogLevel::kWarn, "blackboard-read: cannot assert " + fact);
    }
  }

  // The fact built from values, without printing and parsing it (the agent reads its
  // interfaces at every cycle); false if a field is not a slot of the type's template (the
  // text path then reports it).
  bool assert_direct(Environment& env, const Opened& o, const HostState::InterfaceData& d) {
    auto found = templates_.find(o.type);
    if (found == templates_.end()) {
      Template looked_up;
      try {
        looked_up = env.find_template(o.type);
      } catch (const std::logic_error&) {
        return false;
      }
      found = templates_.emplace(o.type, std::move(looked_up)).first;
    }
    const Template& t = found->second;
    values_.assign(t.slots.size(), Value{});
    const std::int64_t ns = d.time.ns();
    values_[static_cast<std::size_t>(t.slot_index("id"))] = Value::string(o.id);
    values_[static_cast<std::size_t>(t.slot_index("time"))] =
        Value::multifield({Value::integer_value(ns / 1'000'000'000),
                           Value::integer_value((ns % 1'000'000'000) / 1000)});
    for (const auto& [name, v] : d.fields) {
      const auto slot = std::find(t.slots.begin(), t.slots.end(), name);
      if (slot == t.slots.end()) return false;
      values_[static_cast<std::size_t>(slot - t.slots.begin())] = v;
    }
    FactHandle h = env.assert_fact(t, values_);
    env.release(h);
    return true;
  }

  void cleanup(Environment& env) {
    for (const Template& t : cleanup_) env.retract_all(t);
  }

  static std::string types_text() {
    std::string out;
    for (const InterfaceDef& d : interface_defs())
      out += (out.empty() ? "" : ", ") + std::string(d.type);
    return out;
  }

  HostState& s_;
  std::map<std::pair<std::string, std::string>, Opened> opened_;
  std::vector<Value> values_;                  // assert_direct's slot values
  std::map<std::string, Template> templates_;  // by type, looked up once
  std::vector<Template> cleanup_;              // the opened types
  bool time_read_ = false;                     // blackboard-enable-time-read
};

}  // namespace

std::unique_ptr<Feature> make_blackboard_feature(HostState& s) {
  return std::make_unique<BlackboardFeature>(s);
}

}  // namespace llsf::clips::detail
