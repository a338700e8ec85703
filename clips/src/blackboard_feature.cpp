// SPDX-License-Identifier: MIT
// Blackboard feature (Fawkes-style agents, docs/fawkes.md, "The blackboard"): Fawkes' clips
// blackboard feature, re-implemented from its documented behaviour (Fawkes, commit 5f97ae515,
// src/plugins/clips/feature_blackboard.cpp, the clips-agent's host of 2013/14; the writing and
// message functions from the same file as Fawkes extended it in 2015, commits 2699cbc58,
// 47f7468e1 and 3f9455d42).
//
// (blackboard-open "Type" "Id") defines a deftemplate per interface type (slot id, multislot
// time, one slot per field of Fawkes' interface definition, in its order) whose facts go at the
// end of every run (Fawkes: a clean-up rule at salience -10000); (blackboard-enable-time-read)
// makes every cycle start with (blackboard-read) (Fawkes: a rule at salience 1000 on the (time)
// fact); (blackboard-read) asserts one fact per opened interface written since it was last read.
// Both happen without a rule firing, as the time fact's retraction: at every cycle, they were
// most of the 2013 agent's firings. The data come from the host's own blackboard
// (AgentHost::write_interface, the pose as Position3DInterface "Pose") or else from the robot's
// (AgentIo::blackboard: the skills' interface objects, which llsfsim's sensors write).
//
// Writing: (blackboard-open-writing "Type" "Id"), (blackboard-set "Type::Id" "field" value),
// (blackboard-set-multifield "Type::Id" "field" values), (blackboard-write "Type::Id");
// messages: (blackboard-create-msg "Type::Id" "XMessage") (a message of an interface opened for
// reading), (blackboard-set-msg-field ?m "field" value), (blackboard-set-msg-multifield ...),
// (blackboard-list-msg-fields ?m), (blackboard-send-msg ?m) (its id; handled at once).
#include <algorithm>
#include <cmath>
#include <deque>
#include <map>
#include <set>
#include <stdexcept>

#include "feature.h"
#include "llsf/clips/blackboard.h"

namespace llsf::clips::detail {

namespace {

enum class Kind : std::uint8_t { kBool, kInteger, kFloat, kString, kEnum };

struct FieldDef {
  FieldDef(const char* n, Kind k, int len = 1, std::vector<const char*> values = {})
      : name(n), kind(k), length(len), items(std::move(values)) {}
  const char* name;
  Kind kind;
  int length;                      // > 1: an array (a multislot)
  std::vector<const char*> items;  // kEnum: the values, the first the default
};
struct MessageDef {
  const char* name;
  std::vector<FieldDef> fields;
};
struct InterfaceDef {
  const char* type;
  std::vector<FieldDef> fields;
  std::vector<MessageDef> messages;  // those llsfsim's writers handle (docs/fawkes.md)
};

// The interface types: fields as Fawkes' interface definitions declare them (Fawkes 5f97ae515,
// src/libs/interfaces/*.xml and src/plugins/robotino/interfaces/RobotinoSensorInterface.xml;
// carologistics/fawkes-robotino 6cffc15f2: RobotinoLightInterface, RobotinoAmpelInterface,
// LaserClusterInterface), in their order.
const std::vector<InterfaceDef>& interface_defs() {
  static const std::vector<const char*> kLight = {"ON", "OFF", "BLINKING", "UNKNOWN"};
  static const std::vector<InterfaceDef> kDefs = {
      {"Position3DInterface",
       {{"frame", Kind::kString},
        {"visibility_history", Kind::kInteger},
        {"rotation", Kind::kFloat, 4},
        {"translation", Kind::kFloat, 3}},
       {}},
      {"RobotinoLightInterface",
       {{"red", Kind::kEnum, 1, kLight},
        {"yellow", Kind::kEnum, 1, kLight},
        {"green", Kind::kEnum, 1, kLight},
        {"visibility_history", Kind::kInteger},
        {"ready", Kind::kBool}},
       {}},
      {"NavigatorInterface",
       {{"flags", Kind::kInteger},
        {"x", Kind::kFloat},
        {"y", Kind::kFloat},
        {"dest_x", Kind::kFloat},
        {"dest_y", Kind::kFloat},
        {"dest_ori", Kind::kFloat},
        {"dest_dist", Kind::kFloat},
        {"msgid", Kind::kInteger},
        {"final", Kind::kBool},
        {"error_code", Kind::kInteger},
        {"max_velocity", Kind::kFloat},
        {"security_distance", Kind::kFloat},
        {"escaping_enabled", Kind::kBool},
        {"drive_mode",
         Kind::kEnum,
         1,
         {"MovingNotAllowed", "CarefulForward", "SlowForward", "ModerateForward", "FastForward",
          "CarefulAllowBackward", "SlowAllowBackward", "ModerateAllowBackward", "FastAllowBackward",
          "CarefulBackward", "SlowBackward", "ModerateBackward", "FastBackward", "ESCAPE",
          "SlowDribbleBall", "ModerateDribbleBall", "FastDribbleBall", "OVERRIDE"}}},
       {{"StopMessage", {}},
        {"TurnMessage", {{"angle", Kind::kFloat}, {"velocity", Kind::kFloat}}},
        {"CartesianGotoMessage",
         {{"x", Kind::kFloat}, {"y", Kind::kFloat}, {"orientation", Kind::kFloat}}},
        {"PolarGotoMessage",
         {{"phi", Kind::kFloat}, {"dist", Kind::kFloat}, {"orientation", Kind::kFloat}}},
        {"PlaceGotoMessage", {{"place", Kind::kString}}}}},
      {"MotorInterface",
       {{"motor_state", Kind::kInteger},
        {"drive_mode", Kind::kInteger},
        {"right_rpm", Kind::kInteger},
        {"rear_rpm", Kind::kInteger},
        {"left_rpm", Kind::kInteger},
        {"odometry_path_length", Kind::kFloat},
        {"odometry_position_x", Kind::kFloat},
        {"odometry_position_y", Kind::kFloat},
        {"odometry_orientation", Kind::kFloat},
        {"vx", Kind::kFloat},
        {"vy", Kind::kFloat},
        {"omega", Kind::kFloat},
        {"des_vx", Kind::kFloat},
        {"des_vy", Kind::kFloat},
        {"des_omega", Kind::kFloat},
        {"controller", Kind::kInteger},
        {"controller_thread_name", Kind::kString}},
       {{"SetMotorStateMessage", {{"motor_state", Kind::kInteger}}},
        {"AcquireControlMessage",
         {{"controller", Kind::kInteger}, {"controller_thread_name", Kind::kString}}},
        {"ResetOdometryMessage", {}},
        {"TransMessage", {{"vx", Kind::kFloat}, {"vy", Kind::kFloat}}},
        {"RotMessage", {{"omega", Kind::kFloat}}},
        {"TransRotMessage",
         {{"vx", Kind::kFloat}, {"vy", Kind::kFloat}, {"omega", Kind::kFloat}}}}},
      {"SwitchInterface",
       {{"enabled", Kind::kBool},
        {"value", Kind::kFloat},
        {"history", Kind::kFloat},
        {"short_activations", Kind::kInteger},
        {"long_activations", Kind::kInteger},
        {"activation_count", Kind::kInteger}},
       {{"SetMessage", {{"enabled", Kind::kBool}, {"value", Kind::kFloat}}},
        {"EnableSwitchMessage", {}},
        {"DisableSwitchMessage", {}},
        {"EnableDurationMessage", {{"duration", Kind::kFloat}}}}},
      {"RobotinoAmpelInterface",
       {{"state", Kind::kEnum, 1, {"YELLOW", "GREEN", "RED", "YELLOW_FLASHING", "NO_CHANGE"}}},
       {}},
      {"LaserClusterInterface",
       {{"max_x", Kind::kFloat}},
       {{"SetMaxXMessage", {{"max_x", Kind::kFloat}}}}},
      {"SkillerInterface",
       {{"skill_string", Kind::kString},
        {"error", Kind::kString},
        {"exclusive_controller", Kind::kInteger},
        {"status", Kind::kEnum, 1, {"S_INACTIVE", "S_FINAL", "S_RUNNING", "S_FAILED"}},
        {"continuous", Kind::kBool}},
       {}},
      {"RobotinoSensorInterface",
       {{"mot_velocity", Kind::kFloat, 3},
        {"mot_position", Kind::kInteger, 3},
        {"mot_current", Kind::kFloat, 3},
        {"bumper", Kind::kBool},
        {"distance", Kind::kFloat, 9},
        {"digital_in", Kind::kBool, 8},
        {"analog_in", Kind::kFloat, 8},
        {"gyro_available", Kind::kBool},
        {"gyro_angle", Kind::kFloat},
        {"gyro_rate", Kind::kFloat}},
       {}},
  };
  return kDefs;
}

const InterfaceDef* find_def(std::string_view type) {
  for (const InterfaceDef& d : interface_defs())
    if (type == d.type) return &d;
  return nullptr;
}

const FieldDef* find_field(const std::vector<FieldDef>& fields, std::string_view name) {
  for (const FieldDef& f : fields)
    if (name == f.name) return &f;
  return nullptr;
}

const char* kind_text(const FieldDef& f) {
  switch (f.kind) {
    case Kind::kBool:
      return "TRUE or FALSE";
    case Kind::kInteger:
      return "an INTEGER";
    case Kind::kFloat:
      return "a number";
    case Kind::kString:
      return "a STRING";
    case Kind::kEnum:
      return "a SYMBOL of its enum";
  }
  return "?";
}

Value default_element(const FieldDef& f) {
  switch (f.kind) {
    case Kind::kBool:
      return Value::boolean(false);
    case Kind::kInteger:
      return Value::integer_value(0);
    case Kind::kFloat:
      return Value::float_value(0.0);
    case Kind::kString:
      return Value::string("");
    case Kind::kEnum:
      return Value::symbol(f.items.empty() ? "" : f.items.front());
  }
  return Value{};
}

Value default_value(const FieldDef& f) {
  if (f.length <= 1) return default_element(f);
  return Value::multifield(
      std::vector<Value>(static_cast<std::size_t>(f.length), default_element(f)));
}

// One element as the field's type holds it; nullopt if it cannot be (a type error).
std::optional<Value> coerce_element(const FieldDef& f, const Value& v) {
  switch (f.kind) {
    case Kind::kBool:
      if (v.is_symbol("TRUE") || v.is_symbol("FALSE")) return v;
      if (v.is_symbol("true") || v.is_symbol("false")) return Value::boolean(v.text == "true");
      return std::nullopt;
    case Kind::kInteger:
      if (v.type == Value::Type::kInteger) return v;
      if (v.type == Value::Type::kFloat && std::isfinite(v.real))
        return Value::integer_value(static_cast<std::int64_t>(std::llround(v.real)));
      return std::nullopt;
    case Kind::kFloat:
      if (v.type == Value::Type::kFloat) return v;
      if (v.type == Value::Type::kInteger)
        return Value::float_value(static_cast<double>(v.integer));
      return std::nullopt;
    case Kind::kString:
      if (v.type == Value::Type::kString) return v;
      if (v.type == Value::Type::kSymbol) return Value::string(v.text);
      return std::nullopt;
    case Kind::kEnum:
      if ((v.type == Value::Type::kSymbol || v.type == Value::Type::kString) &&
          std::any_of(f.items.begin(), f.items.end(), [&](const char* i) { return v.text == i; }))
        return Value::symbol(v.text);
      if (v.type == Value::Type::kInteger && v.integer >= 0 &&
          v.integer < static_cast<std::int64_t>(f.items.size()))
        return Value::symbol(f.items[static_cast<std::size_t>(v.integer)]);
      return std::nullopt;
  }
  return std::nullopt;
}

// True if the element is of the field's type as it is.
bool fits_element(const FieldDef& f, const Value& v) {
  switch (f.kind) {
    case Kind::kBool:
      return v.is_symbol("TRUE") || v.is_symbol("FALSE");
    case Kind::kInteger:
      return v.type == Value::Type::kInteger;
    case Kind::kFloat:
      return v.type == Value::Type::kFloat;
    case Kind::kString:
      return v.type == Value::Type::kString;
    case Kind::kEnum:
      return v.type == Value::Type::kSymbol &&
             std::any_of(f.items.begin(), f.items.end(),
                         [&](const char* i) { return v.text == i; });
  }
  return false;
}

// True if the value is what the field holds as it is (its type; an array: its length).
bool fits(const FieldDef& f, const Value& v) {
  if (f.length <= 1) return fits_element(f, v);
  return v.type == Value::Type::kMultifield &&
         v.items.size() == static_cast<std::size_t>(f.length) &&
         std::all_of(v.items.begin(), v.items.end(),
                     [&](const Value& e) { return fits_element(f, e); });
}

// A value (or, for an array, a multifield or a list of values) as the field holds it: arrays
// get their length (missing elements keep `base`'s). nullopt on a type error.
std::optional<Value> coerce(const FieldDef& f, const Value& v, const Value& base) {
  if (f.length <= 1) {
    if (v.type == Value::Type::kMultifield) {
      if (v.items.size() != 1) return std::nullopt;
      return coerce_element(f, v.items[0]);
    }
    return coerce_element(f, v);
  }
  std::vector<Value> items =
      base.type == Value::Type::kMultifield ? base.items : default_value(f).items;
  items.resize(static_cast<std::size_t>(f.length), default_element(f));
  const std::vector<Value> given =
      v.type == Value::Type::kMultifield ? v.items : std::vector<Value>{v};
  if (given.size() > items.size()) return std::nullopt;
  for (std::size_t i = 0; i < given.size(); ++i) {
    std::optional<Value> e = coerce_element(f, given[i]);
    if (!e) return std::nullopt;
    items[i] = std::move(*e);
  }
  return Value::multifield(std::move(items));
}

const Value kNoBase;  // coerce(): an array's elements not given are the defaults

// Splits "Type::Id" (Fawkes' interface uid).
bool parse_uid(std::string_view uid, std::string& type, std::string& id) {
  const std::size_t at = uid.find("::");
  if (at == std::string_view::npos || at == 0) return false;
  type = std::string(uid.substr(0, at));
  id = std::string(uid.substr(at + 2));
  return true;
}

// A message of blackboard-create-msg (an EXTERNAL-ADDRESS until it is sent).
struct InterfaceMessage {
  std::string type, id;
  const MessageDef* def = nullptr;
  InterfaceFields values;  // by the message's fields, in their order
};

class BlackboardFeature final : public Feature {
 public:
  explicit BlackboardFeature(HostState& s) : s_(s) {}

  void define(Environment& env) override {
    env.define_function("blackboard-enable-time-read", "00", [this](Args&) {
      time_read_ = true;
      return Value{};
    });
    const auto open_reading = [this, &env](Args& a) {
      std::string_view type, id;
      a.text(0, type);
      a.text(1, id);
      open(env, std::string(type), std::string(id), false);
      return Value{};
    };
    env.define_function("blackboard-open", "22k", open_reading);
    env.define_function("blackboard-open-reading", "22k", open_reading);
    env.define_function("blackboard-open-writing", "22k", [this, &env](Args& a) {
      std::string_view type, id;
      a.text(0, type);
      a.text(1, id);
      open(env, std::string(type), std::string(id), true);
      return Value{};
    });
    env.define_function("blackboard-close", "22k", [this](Args& a) {
      std::string_view type, id;
      a.text(0, type);
      a.text(1, id);
      const std::pair<std::string, std::string> key{type, id};
      opened_.erase(key);  // (the template stays, as in Fawkes)
      writing_.erase(key);
      return Value{};
    });
    env.define_function("blackboard-preload", "11k", [this, &env](Args& a) {
      std::string_view type;
      a.text(0, type);
      if (const InterfaceDef* def = known(std::string(type), "blackboard-preload"))
        define_template(env, *def);
      return Value{};
    });
    env.define_function("blackboard-read", "00", [this, &env](Args&) {
      read(env);
      return Value{};
    });
    env.define_function("blackboard-set", "33*kk", [this, &env](Args& a) {
      set(env, a);
      return Value{};
    });
    env.define_function("blackboard-set-multifield", "3**kk", [this, &env](Args& a) {
      set(env, a);
      return Value{};
    });
    env.define_function("blackboard-write", "11k", [this, &env](Args& a) {
      std::string_view uid;
      a.text(0, uid);
      write(env, a.function(), uid);
      return Value{};
    });
    env.define_function("blackboard-create-msg", "22k",
                        [this](Args& a) { return create_message(a); });
    env.define_function("blackboard-list-msg-fields", "11a", [this, &env](Args& a) {
      InterfaceMessage* m = message_arg(env, a);
      if (m == nullptr) return Value{};
      std::vector<Value> names;
      for (const FieldDef& f : m->def->fields) names.push_back(Value::symbol(f.name));
      return Value::multifield(std::move(names));
    });
    const auto set_msg_field = [this, &env](Args& a) {
      InterfaceMessage* m = message_arg(env, a);
      if (m == nullptr) return Value{};
      std::string_view name;
      if (!a.text(1, name)) {
        env.error(a.function(), "the field name must be a string");
        return Value{};
      }
      const FieldDef* f = find_field(m->def->fields, name);
      if (f == nullptr) {
        env.error(a.function(), m->type + "::" + m->id + " " + m->def->name + " has no field " +
                                    std::string(name) + " (it has: " + names(m->def->fields) + ")");
        return Value{};
      }
      Value given = a.value(2);
      if (a.count() > 3) {  // (blackboard-set-msg-multifield ?m field v1 v2 ...)
        std::vector<Value> items;
        for (int i = 2; i < a.count(); ++i) items.push_back(a.value(i));
        given = Value::multifield(std::move(items));
      }
      auto slot = std::find_if(m->values.begin(), m->values.end(),
                               [&](const auto& v) { return v.first == f->name; });
      std::optional<Value> v = coerce(*f, given, slot->second);
      if (!v) {
        env.error(a.function(), std::string(m->def->name) + " field " + f->name + " takes " +
                                    kind_text(*f) + ", not " + given.to_string());
        return Value{};
      }
      slot->second = std::move(*v);
      return Value{};
    };
    env.define_function("blackboard-set-msg-field", "33*ak", set_msg_field);
    env.define_function("blackboard-set-msg-multifield", "3**ak", set_msg_field);
    env.define_function("blackboard-send-msg", "11a", [this, &env](Args& a) {
      InterfaceMessage* m = message_arg(env, a);
      if (m == nullptr) return Value{};
      std::unique_ptr<InterfaceMessage> owned = std::move(messages_[m]);
      messages_.erase(m);
      if (s_.io.blackboard == nullptr) {
        s_.log(LogLevel::kWarn, "blackboard-send-msg: no writer of " + owned->type +
                                    "::" + owned->id + " handles messages here");
        return Value::integer_value(0);
      }
      std::string error;
      const std::int64_t id =
          s_.io.blackboard->send(owned->type, owned->id, owned->def->name, owned->values, error);
      if (!error.empty()) {
        env.error(a.function(), error);
        return Value{};
      }
      return Value::integer_value(id);
    });
  }

  void after_reset(Environment&) override {
    for (auto& [key, o] : opened_) {  // the reset took the facts
      o.read_serial = 0;
      o.read_time.reset();
      o.robot_writer = true;
    }
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
    std::uint64_t read_serial = 0;             // the host's data: their serial when last asserted
    std::optional<core::SimTime> read_time;    // the robot's data: their time when last asserted
    bool robot_writer = true;                  // as last read (else: read again on a new version)
    std::int64_t version = 0;                  // Blackboard::version() when last read
    const InterfaceDef* def = nullptr;         // its type (looked up once)
    HostState::InterfaceData* host = nullptr;  // the host's data, once there are any
  };

  const InterfaceDef* known(const std::string& type, std::string_view function) {
    const InterfaceDef* def = find_def(type);
    if (def == nullptr)
      s_.log(LogLevel::kWarn, std::string(function) + ": no interface type " + type +
                                  " (llsfsim offers " + types_text() + "; docs/fawkes.md)");
    return def;
  }

  void define_template(Environment& env, const InterfaceDef& def) {
    if (std::find(defined_.begin(), defined_.end(), def.type) != defined_.end()) return;
    std::string t = std::string("(deftemplate ") + def.type + " (slot id (type STRING))" +
                    " (multislot time (type INTEGER) (cardinality 2 2))";
    for (const FieldDef& f : def.fields) {
      t += std::string(f.length > 1 ? " (multislot " : " (slot ") + f.name;
      switch (f.kind) {
        case Kind::kBool:
          t += " (type SYMBOL) (allowed-values TRUE FALSE))";
          break;
        case Kind::kInteger:
          t += " (type INTEGER))";
          break;
        case Kind::kFloat:
          t += " (type FLOAT))";
          break;
        case Kind::kString:
          t += " (type STRING))";
          break;
        case Kind::kEnum:
          t += " (type SYMBOL))";
          break;
      }
    }
    t += ")";
    env.load(t);
    defined_.emplace_back(def.type);
    cleanup_.push_back(env.find_template(def.type));
  }

  void open(Environment& env, const std::string& type, const std::string& id, bool writing) {
    const InterfaceDef* def = known(type, writing ? "blackboard-open-writing" : "blackboard-open");
    if (def == nullptr) return;
    define_template(env, *def);
    if (!writing) {
      opened_.try_emplace({type, id});
      return;
    }
    if (writing_.contains({type, id})) return;
    // One writer per interface, as Fawkes' blackboard: what llsfsim's sensors write is theirs.
    if (s_.io.blackboard != nullptr) {
      InterfaceReading r;
      std::string error;
      if (s_.io.blackboard->read(type, id, r, error) && r.robot_writer) {
        s_.log(LogLevel::kWarn, "blackboard-open-writing: " + type + "::" + id +
                                    " has a writer (llsfsim's sensors or actuators)");
        return;
      }
    }
    InterfaceFields fields;
    for (const FieldDef& f : def->fields) fields.emplace_back(f.name, default_value(f));
    writing_[{type, id}] = std::move(fields);
  }

  void set(Environment& env, Args& a) {
    std::string_view uid, name;
    a.text(0, uid);
    a.text(1, name);
    std::string type, id;
    parse_uid(uid, type, id);
    auto it = writing_.find({type, id});
    if (it == writing_.end()) {
      env.error(a.function(), std::string(uid) + " is not opened for writing " +
                                  "(blackboard-open-writing \"Type\" \"Id\")");
      return;
    }
    const FieldDef* f = find_field(find_def(type)->fields, name);
    if (f == nullptr) {
      env.error(a.function(), std::string(uid) + " has no field " + std::string(name) +
                                  " (it has: " + names(find_def(type)->fields) + ")");
      return;
    }
    Value given = a.value(2);
    if (a.count() > 3) {  // (blackboard-set-multifield uid field v1 v2 ...)
      std::vector<Value> items;
      for (int i = 2; i < a.count(); ++i) items.push_back(a.value(i));
      given = Value::multifield(std::move(items));
    }
    auto slot = std::find_if(it->second.begin(), it->second.end(),
                             [&](const auto& v) { return v.first == f->name; });
    std::optional<Value> v = coerce(*f, given, slot->second);
    if (!v) {
      env.error(a.function(), std::string(uid) + " field " + f->name + " takes " + kind_text(*f) +
                                  ", not " + given.to_string());
      return;
    }
    slot->second = std::move(*v);
  }

  void write(Environment& env, std::string_view function, std::string_view uid) {
    std::string type, id;
    parse_uid(uid, type, id);
    auto it = writing_.find({type, id});
    if (it == writing_.end()) {
      env.error(function, std::string(uid) + " is not opened for writing");
      return;
    }
    if (s_.io.blackboard != nullptr) {
      const std::string error = s_.io.blackboard->write(type, id, it->second);
      if (!error.empty()) env.error(function, error);
      return;
    }
    // No robot blackboard: the host's own (a reader of the same interface sees it).
    auto& d = s_.blackboard[{type, id}];
    d.time = s_.now;
    d.fields = it->second;
    ++d.serial;
  }

  Value create_message(Args& a) {
    std::string_view uid, name;
    a.text(0, uid);
    a.text(1, name);
    std::string type, id;
    if (!parse_uid(uid, type, id) || !opened_.contains({type, id})) {
      s_.log(LogLevel::kWarn, "blackboard-create-msg: no interface " + std::string(uid) +
                                  " opened for reading (blackboard-open \"Type\" \"Id\")");
      return Value::boolean(false);
    }
    const InterfaceDef* def = find_def(type);
    const auto msg = std::find_if(def->messages.begin(), def->messages.end(),
                                  [&](const MessageDef& m) { return name == m.name; });
    if (msg == def->messages.end()) {
      std::string have;
      for (const MessageDef& m : def->messages)
        have += (have.empty() ? "" : ", ") + std::string(m.name);
      s_.log(LogLevel::kWarn,
             "blackboard-create-msg: " + type + " has no message " + std::string(name) +
                 " (llsfsim's writers handle: " + (have.empty() ? "none" : have) + ")");
      return Value::boolean(false);
    }
    if (messages_.size() >= kMaxUnsentMessages) {
      // An agent that creates messages and never sends them would grow the host without
      // bound (CLIPS' memory budget does not see them).
      s_.log(LogLevel::kWarn, "blackboard-create-msg: " + std::to_string(kMaxUnsentMessages) +
                                  " messages created and not yet sent; send one "
                                  "(blackboard-send-msg) before creating more");
      return Value::boolean(false);
    }
    auto m = std::make_unique<InterfaceMessage>();
    m->type = type;
    m->id = id;
    m->def = &*msg;
    for (const FieldDef& f : msg->fields) m->values.emplace_back(f.name, default_value(f));
    InterfaceMessage* raw = m.get();
    messages_[raw] = std::move(m);
    return Value::external(raw);
  }

  InterfaceMessage* message_arg(Environment& env, Args& a) {
    void* p = nullptr;
    if (!a.address(0, p) || !messages_.contains(static_cast<InterfaceMessage*>(p))) {
      env.error(a.function(), "not a message of blackboard-create-msg (or one already sent)");
      return nullptr;
    }
    return static_cast<InterfaceMessage*>(p);
  }

  void read(Environment& env) {
    for (auto& [key, o] : opened_) {
      if (o.def == nullptr) o.def = find_def(key.first);
      const InterfaceDef& def = *o.def;
      if (o.host == nullptr) {  // (the host's entries are never erased: found once)
        const auto it = s_.blackboard.find(key);
        if (it != s_.blackboard.end()) o.host = &it->second;
      }
      if (o.host != nullptr) {  // the host's own data
        if (o.host->serial == o.read_serial) continue;
        o.read_serial = o.host->serial;
        assert_fact(env, def, key.second, o.host->time, o.host->fields);
        continue;
      }
      if (s_.io.blackboard == nullptr) continue;
      // An interface no sensor writes changes only with a write or a message.
      const std::int64_t version = s_.io.blackboard->version();
      if (!o.robot_writer && version != 0 && version == o.version) continue;
      InterfaceReading r;
      std::string error;
      if (!s_.io.blackboard->read(key.first, key.second, r, error)) continue;
      o.robot_writer = r.robot_writer;
      o.version = version;
      if (!r.has_writer || !r.written || r.written == o.read_time) continue;
      o.read_time = r.written;
      assert_fact(env, def, key.second, *r.written, r.fields);
    }
  }

  // The fact built from values, without printing and parsing it (the agent reads its
  // interfaces at every cycle): every field of the definition, as its type holds it (a field
  // the data lack, or cannot be held, its default). The values are passed by pointer: a field
  // the data hold as its type does is not copied.
  void assert_fact(Environment& env, const InterfaceDef& def, const std::string& id,
                   core::SimTime time, const InterfaceFields& fields) {
    const Plan& plan = plan_of(env, def);
    slot_values_.assign(plan.t.slots.size(), nullptr);
    converted_.resize(def.fields.size());
    const std::int64_t ns = time.ns();
    id_value_.text = id;
    time_value_.items[0].integer = ns / 1'000'000'000;
    time_value_.items[1].integer = (ns % 1'000'000'000) / 1000;
    slot_values_[plan.id_slot] = &id_value_;
    slot_values_[plan.time_slot] = &time_value_;
    for (std::size_t i = 0; i < def.fields.size(); ++i) {
      const FieldDef& f = def.fields[i];
      const auto given = std::find_if(fields.begin(), fields.end(),
                                      [&](const auto& v) { return v.first == f.name; });
      if (given != fields.end() && fits(f, given->second)) {
        slot_values_[plan.field_slots[i]] = &given->second;  // (the usual case: no conversion)
        continue;
      }
      std::optional<Value> v;
      if (given != fields.end()) v = coerce(f, given->second, kNoBase);
      converted_[i] = v ? std::move(*v) : default_value(f);
      slot_values_[plan.field_slots[i]] = &converted_[i];
    }
    FactHandle h = env.assert_fact(plan.t, std::span<const Value* const>(slot_values_));
    env.release(h);
  }

  // A type's template and the slot of each of its fields, looked up once.
  struct Plan {
    const InterfaceDef* def = nullptr;
    Template t;
    std::size_t id_slot = 0, time_slot = 0;
    std::vector<std::size_t> field_slots;  // by the definition's fields
  };
  const Plan& plan_of(Environment& env, const InterfaceDef& def) {
    for (const Plan& p : plans_)
      if (p.def == &def) return p;
    Plan p;
    p.def = &def;
    auto found = templates_.find(std::string_view(def.type));
    if (found == templates_.end())
      found = templates_.emplace(def.type, env.find_template(def.type)).first;
    p.t = found->second;
    p.id_slot = static_cast<std::size_t>(p.t.slot_index("id"));
    p.time_slot = static_cast<std::size_t>(p.t.slot_index("time"));
    for (const FieldDef& f : def.fields) {
      p.field_slots.push_back(static_cast<std::size_t>(p.t.slot_index(f.name)));
    }
    plans_.push_back(std::move(p));
    return plans_.back();
  }

  void cleanup(Environment& env) {
    for (const Template& t : cleanup_) env.retract_all(t);
  }

  static std::string names(const std::vector<FieldDef>& fields) {
    std::string out;
    for (const FieldDef& f : fields) out += (out.empty() ? "" : ", ") + std::string(f.name);
    return out.empty() ? "none" : out;
  }

  static std::string types_text() {
    std::string out;
    for (const InterfaceDef& d : interface_defs())
      out += (out.empty() ? "" : ", ") + std::string(d.type);
    return out;
  }

  HostState& s_;
  std::map<std::pair<std::string, std::string>, Opened> opened_;  // for reading
  std::map<std::pair<std::string, std::string>, InterfaceFields> writing_;
  std::map<InterfaceMessage*, std::unique_ptr<InterfaceMessage>> messages_;  // not yet sent
  static constexpr std::size_t kMaxUnsentMessages = 1000;
  std::vector<const Value*> slot_values_;  // assert_fact's slot values
  std::vector<Value> converted_;           // assert_fact's fields converted or defaulted
  Value id_value_ = Value::string("");
  Value time_value_ = Value::multifield({Value::integer_value(0), Value::integer_value(0)});
  std::deque<Plan> plans_;                                  // by type (stable addresses)
  std::map<std::string, Template, std::less<>> templates_;  // by type, looked up once
  std::vector<std::string> defined_;                        // the types with a template
  std::vector<Template> cleanup_;                           // their templates
  bool time_read_ = false;                                  // blackboard-enable-time-read
};

}  // namespace

std::unique_ptr<Feature> make_blackboard_feature(HostState& s) {
  return std::make_unique<BlackboardFeature>(s);
}

}  // namespace llsf::clips::detail
