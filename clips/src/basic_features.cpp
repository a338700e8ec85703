// SPDX-License-Identifier: MIT
// Small features: logging functions, seeded random, robot identity and pose, confval facts.
#include <algorithm>
#include <array>
#include <cmath>

#include "feature.h"
#include "llsf/core/rng.h"

namespace llsf::clips::detail {

std::string print_form(const Value& v) {
  switch (v.type) {
    case Value::Type::kSymbol:
    case Value::Type::kString:
      return v.text;
    case Value::Type::kMultifield: {
      std::string out;
      for (std::size_t i = 0; i < v.items.size(); ++i) {
        if (i > 0) out += ' ';
        out += print_form(v.items[i]);
      }
      return out;
    }
    default:
      return v.to_string();
  }
}

namespace {

// ---- log: (log-debug ...), (log-info ...), (log-warn ...), (log-error ...) ------------------
// Arguments are concatenated as str-cat does. (printout t ...) is routed by the host.
class LogFeature final : public Feature {
 public:
  explicit LogFeature(HostState& s) : s_(s) {}
  void define(Environment& env) override {
    static constexpr std::array<std::pair<const char*, LogLevel>, 4> kLevels = {{
        {"log-debug", LogLevel::kDebug},
        {"log-info", LogLevel::kInfo},
        {"log-warn", LogLevel::kWarn},
        {"log-error", LogLevel::kError},
    }};
    for (const auto& [name, level] : kLevels) {
      env.define_function(name, "1**", [this, level = level](Args& a) {
        std::string text;
        for (int i = 0; i < a.count(); ++i) text += print_form(a.value(i));
        s_.log(level, text);
        return Value{};
      });
      // Within the string budget (the arguments of (log-info (expand$ ?m)) may repeat one long
      // string a million times).
      env.guard_concatenation(name);
    }
    // (agent-event KIND ARG...): an outcome the agent declares as data (AgentIo::events,
    // docs/clips.md, "Agent events"), checked here: a kind the host does not know or arguments
    // that do not fit it are a runtime error, never a silent miss.
    env.define_function("agent-event", "1**", [this](Args& a) {
      std::string_view kind;
      if (a.type(0) != Value::Type::kSymbol || !a.text(0, kind)) {
        a.env().error(a.function(), "the first argument is the event's kind, a symbol (kinds: " +
                                        kinds_text() + ")");
        return Value::boolean(false);
      }
      AgentEvent e;
      bool known = false;
      for (const AgentEventKind k : kKinds) {
        if (kind == to_string(k)) {
          e.kind = k;
          known = true;
        }
      }
      if (!known) {
        a.env().error(a.function(),
                      "unknown kind '" + std::string(kind) + "' (kinds: " + kinds_text() + ")");
        return Value::boolean(false);
      }
      for (int i = 1; i < a.count(); ++i) e.args.push_back(a.value(i));
      switch (e.kind) {
        case AgentEventKind::kRoleChange:
          if (e.args.size() < 2 || e.args.size() > 3 || e.args[0].type != Value::Type::kSymbol ||
              e.args[1].type != Value::Type::kSymbol) {
            a.env().error(a.function(),
                          "role-change takes FROM TO [WHY]: the roles as symbols, e.g. "
                          "(agent-event role-change P1P2 P3 \"time is short\")");
            return Value::boolean(false);
          }
          break;
      }
      if (s_.io.events) {
        const std::string rule = a.env().executing_rule();
        e.time = s_.now;
        e.agent = s_.config.robot_name;
        e.rule = rule;
        s_.io.events(e);
      }
      return Value::boolean(true);
    });
  }

 private:
  static constexpr AgentEventKind kKinds[] = {AgentEventKind::kRoleChange};
  static std::string kinds_text() {
    std::string out;
    for (const AgentEventKind k : kKinds)
      out += std::string(out.empty() ? "" : ", ") + to_string(k);
    return out;
  }
  HostState& s_;
};

// ---- random: (random [lo hi]) and (seed n) per environment -----------------------------------
// CLIPS 6.30's (random) calls the C library's rand(), one process-wide sequence; we replace both
// functions with a stream seeded from AgentConfig::seed, so agents do not disturb each other.
class RandomFeature final : public Feature {
 public:
  explicit RandomFeature(HostState& s) : rng_(s.config.seed), seed_(s.config.seed) {}
  void define(Environment& env) override {
    env.define_function("random", "02i", [this](Args& a) {
      std::int64_t lo = 0, hi = 2147483647;  // glibc's RAND_MAX, as (random) without arguments
      if (a.count() == 2) {
        a.integer(0, lo);
        a.integer(1, hi);
        if (hi < lo) {
          a.env().error(a.function(), "the upper bound is below the lower bound");
          return Value::boolean(false);
        }
      } else if (a.count() == 1) {
        a.env().error(a.function(), "expects no arguments or two (lower and upper bound)");
        return Value::boolean(false);
      }
      return Value::integer_value(rng_.uniform_int(lo, hi));
    });
    // (seed n): the stream restarts from n mixed with this robot's own seed (AgentConfig::seed,
    // from the scenario seed and the robot's name): the same n gives the same sequence in
    // every game of the scenario seed, but different robots draw different sequences. Agents
    // that seed from the clock, as the 2013 agent's lock election did ((seed (nth$ 2 ?now))),
    // would otherwise draw one sequence on every robot of a lock-step simulation.
    env.define_function("seed", "11i", [this](Args& a) {
      std::int64_t s = 0;
      a.integer(0, s);
      const auto n = static_cast<std::uint64_t>(s);
      rng_ = core::RandomStream(core::fnv1a(&n, sizeof n, core::fnv1a(&seed_, sizeof seed_)));
      return Value{};
    });
  }
  // A restart of the agent starts the sequence again.
  void after_reset(Environment&) override { rng_ = core::RandomStream(seed_); }

 private:
  core::RandomStream rng_;
  std::uint64_t seed_;
};

// ---- robot: ?*ROBOT-NAME* etc., (robot-info ...), (pose (x) (y) (ori)) ----------------------
class RobotFeature final : public Feature {
 public:
  explicit RobotFeature(HostState& s) : s_(s) {}
  void bind(Environment& env) override {
    info_ = env.find_template("robot-info");
    pose_ = env.find_template("pose");
  }
  void after_reset(Environment& env) override {
    // A Fawkes-style agent owns these globals (the 2013 agent defines and sets them from its
    // config): a reset gives them back their defglobal values; the host sets them only before
    // the entry file runs (AgentHost::load_file).
    if (!s_.config.fawkes) set_globals(env);
    const Value v[] = {Value::symbol(s_.config.robot_name),
                       Value::integer_value(s_.config.robot_number),
                       Value::string(s_.config.team_name)};
    FactHandle h = env.assert_fact(info_, v);
    env.release(h);
    env.release(pose_fact_);  // the reset retracted it
    s_.pose_dirty = s_.pose.has_value();
  }
  // A Fawkes-style agent reads the pose from the blackboard: Position3DInterface "Pose", written
  // at every cycle as the 2013 localization wrote it at its rate (the map frame; the yaw as the
  // quaternion (0 0 sin(a/2) cos(a/2)); visibility_history counts the updates).
  void write_pose_interface() {
    // (the map's entries are never erased: looked up once)
    if (pose_data_ == nullptr) pose_data_ = &s_.blackboard[{"Position3DInterface", "Pose"}];
    HostState::InterfaceData& d = *pose_data_;
    d.time = s_.now;
    const double h = s_.pose->theta / 2.0;
    auto& f = d.fields;
    const auto floats = [](const Value& v, std::size_t n) {
      return v.type == Value::Type::kMultifield && v.items.size() == n &&
             std::all_of(v.items.begin(), v.items.end(),
                         [](const Value& e) { return e.type == Value::Type::kFloat; });
    };
    if (f.size() == 4 && f[0].first == "frame" && f[0].second.is_string("/map") &&
        f[1].first == "visibility_history" && f[1].second.type == Value::Type::kInteger &&
        f[2].first == "rotation" && floats(f[2].second, 4) && f[3].first == "translation" &&
        floats(f[3].second, 3)) {
      // As this function wrote them last time: the numbers updated in place.
      f[1].second.integer = static_cast<std::int64_t>(d.serial) + 1;
      std::vector<Value>& r = f[2].second.items;
      std::vector<Value>& t = f[3].second.items;
      r[0].real = 0.0;
      r[1].real = 0.0;
      r[2].real = std::sin(h);
      r[3].real = std::cos(h);
      t[0].real = s_.pose->x;
      t[1].real = s_.pose->y;
      t[2].real = 0.0;
      ++d.serial;
      return;
    }
    d.fields = {
        {"frame", Value::string("/map")},
        {"visibility_history", Value::integer_value(static_cast<std::int64_t>(d.serial) + 1)},
        {"rotation",
         Value::multifield({Value::float_value(0.0), Value::float_value(0.0),
                            Value::float_value(std::sin(h)), Value::float_value(std::cos(h))})},
        {"translation",
         Value::multifield({Value::float_value(s_.pose->x), Value::float_value(s_.pose->y),
                            Value::float_value(0.0)})}};
    ++d.serial;
  }
  void set_globals(Environment& env) {
    env.set_global("ROBOT-NAME", Value::symbol(s_.config.robot_name));
    env.set_global("ROBOT-NUMBER", Value::integer_value(s_.config.robot_number));
    env.set_global("TEAM-NAME", Value::string(s_.config.team_name));
  }
  void before_run(Environment& env) override {
    if (s_.config.fawkes && s_.pose) write_pose_interface();
    if (!s_.pose_dirty) return;
    s_.pose_dirty = false;
    env.retract(pose_fact_);
    const Value v[] = {Value::float_value(s_.pose->x), Value::float_value(s_.pose->y),
                       Value::float_value(s_.pose->theta)};
    pose_fact_ = env.assert_fact(pose_, v);
  }

 private:
  HostState& s_;
  Template info_, pose_;
  FactHandle pose_fact_;
  HostState::InterfaceData* pose_data_ = nullptr;  // Position3DInterface "Pose"
};

// ---- config: confval facts after each (reset), or on (config-load PREFIX) -------------------
// llsfsim's agents get every value after each (reset); Fawkes-style agents (AgentConfig::fawkes)
// only those under the prefix they load, when they call (config-load "/clips-agent"), as
// Fawkes' config feature asserted them.
class ConfigFeature final : public Feature {
 public:
  explicit ConfigFeature(HostState& s) : s_(s) {}
  void define(Environment& env) override {
    env.define_function("config-load", "11k", [this, &env](Args& a) {
      std::string_view prefix;
      a.text(0, prefix);
      assert_values(env, prefix);
      return Value{};
    });
  }
  void bind(Environment& env) override { confval_ = env.find_template("confval"); }
  void after_reset(Environment& env) override {
    if (!s_.config.fawkes) assert_values(env, {});
  }

 private:
  // The values whose path starts with `prefix` (all for an empty prefix); an identical confval
  // fact that exists already is not asserted twice (CLIPS refuses duplicates).
  void assert_values(Environment& env, std::string_view prefix) {
    for (const auto& e : s_.config.config) {
      if (!std::string_view(e.path).starts_with(prefix)) continue;
      Value v[5];
      v[0] = Value::string(e.path);
      v[1] = Value::symbol(to_string(e.type));
      if (e.is_list) {
        v[3] = Value::boolean(true);
        v[4] = Value::multifield(e.values);
      } else {
        v[2] = e.values.empty() ? Value::symbol("nil") : e.values.front();
        v[3] = Value::boolean(false);
      }
      FactHandle h = env.assert_fact(confval_, v);
      env.release(h);
    }
  }

  HostState& s_;
  Template confval_;
};

}  // namespace

std::unique_ptr<Feature> make_log_feature(HostState& s) { return std::make_unique<LogFeature>(s); }
std::unique_ptr<Feature> make_random_feature(HostState& s) {
  return std::make_unique<RandomFeature>(s);
}
std::unique_ptr<Feature> make_robot_feature(HostState& s) {
  return std::make_unique<RobotFeature>(s);
}
std::unique_ptr<Feature> make_config_feature(HostState& s) {
  return std::make_unique<ConfigFeature>(s);
}

}  // namespace llsf::clips::detail
