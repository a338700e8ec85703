// SPDX-License-Identifier: MIT
// RefboxConfig::validate() and the YAML loader (docs/refbox.md).
#include "llsf/refbox/config.h"

#include <cctype>
#include <cmath>
#include <cstdio>
#include <functional>
#include <set>

#include "llsf/core/error.h"

namespace llsf::refbox {

using core::ConfigError;
using core::ConfigNode;

namespace {

// The longest phases (docs/refbox.md, "Configuration"): the refbox's own schedule.
constexpr int kMaxSetupS = 300;
constexpr int kMaxExplorationS = 180;

/// Reports a bad field: `field` is relative to the refbox map ("production_s", "pucks[3]").
using FailFn = std::function<void(const std::string& field, const std::string& reason)>;

std::string seconds_text(SimTime t) {
  const std::int64_t ms = t.ns() / 1000000;
  char buf[48];
  if (ms % 1000 == 0) {
    std::snprintf(buf, sizeof buf, "%lld s", static_cast<long long>(ms / 1000));
  } else {
    std::snprintf(buf, sizeof buf, "%.3f s", static_cast<double>(ms) / 1000.0);
  }
  return buf;
}

void check_config(const RefboxConfig& c, const FailFn& fail) {
  if (!is_known_rules_variant(c.rules)) {
    fail("rules", "unknown rules variant '" + c.rules + "' (known: " +
                      std::string(kRulesRefbox061) + ", " + std::string(kRulesRulebook2013) + ")");
  }
  auto check_duration = [&](const char* field, SimTime d, SimTime max) {
    if (d <= SimTime() || d > max) {
      fail(field, "must be > 0 and <= " + seconds_text(max) + " (got " + seconds_text(d) + ")");
    }
  };
  check_duration("setup_s", c.setup_duration, SimTime::from_sec(kMaxSetupS));
  check_duration("exploration_s", c.exploration_duration, SimTime::from_sec(kMaxExplorationS));
  check_duration("production_s", c.production_duration, SimTime::from_sec(kPlanProductionS));
  check_duration("overtime_s", c.overtime_duration, SimTime::from_sec(kOvertimeS));
  std::set<int> seen;
  for (std::size_t i = 0; i < c.pucks.size(); ++i) {
    const std::string f = "pucks[" + std::to_string(i) + "]";
    if (c.pucks[i] <= 0) fail(f, "puck ids must be > 0 (got " + std::to_string(c.pucks[i]) + ")");
    if (!seen.insert(c.pucks[i]).second) {
      fail(f, "duplicate puck id " + std::to_string(c.pucks[i]));
    }
  }
  for (int i = 0; i < kDeviceCount; ++i) {
    const core::Pose2D& p = c.device_poses[i];
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.theta)) {
      fail("device_poses." + std::string(kDeviceNames[i]), "must be finite");
    }
  }
  if (c.params) {
    try {
      validate_game_params(*c.params, "params",
                           c.synchronised() ? kPlanSynchronisedS : kPlanProductionS);
    } catch (const ConfigError& e) {
      const std::string what = e.what();
      const auto colon = what.find(": ");
      fail(what.substr(0, colon), what.substr(colon + 2));
    }
  }
}

// --- YAML -------------------------------------------------------------------------------------

/// A phase's length in seconds, checked at its key against (0, max_s] before the conversion to
/// the game clock (1e300 s used to overflow it into a garbled figure in the message).
SimTime read_seconds(const ConfigNode& n, const char* key, SimTime def, int max_s) {
  const ConfigNode v = n[key];
  if (!v.defined()) return def;
  const double s =
      v.as_double(core::Bound{core::Bound::Kind::kOpenClosed, 0.0, static_cast<double>(max_s)});
  return SimTime::from_seconds(s);
}

int read_int(const ConfigNode& v) { return static_cast<int>(v.as_int(core::in_range(-1e9, 1e9))); }

DeviceId read_device(const ConfigNode& v) {
  const std::string name = v.as_string();
  const auto d = device_by_name(name);
  if (!d) v.fail("unknown device '" + name + "'");
  return *d;
}

Lights read_light_code(const ConfigNode& v) {
  const std::string s = v.as_string();
  Lights l;
  for (char ch : s) {
    LightState* lamp = ch == 'R' ? &l.red : ch == 'Y' ? &l.yellow : ch == 'G' ? &l.green : nullptr;
    if (lamp == nullptr) v.fail("light code letters are R, Y, G (got '" + s + "')");
    if (*lamp == LightState::kOn) v.fail("lamp repeated in '" + s + "'");
    *lamp = LightState::kOn;
  }
  return l;
}

GameParams read_params(const ConfigNode& n) {
  n.require_map();
  GameParams p;
  const ConfigNode types = n.at("machine_types");
  types.require_map();
  for (const std::string& k : types.keys()) {
    const auto d = device_by_name(k);
    if (!d || !is_production_machine(*d)) types[k].fail("keys must be M1..M10");
  }
  for (int i = 0; i < kProductionMachineCount; ++i) {
    const ConfigNode v = types.at(kDeviceNames[i]);
    const auto t = machine_type_from_string(v.as_string());
    if (!t || static_cast<int>(*t) > 4) v.fail("must be one of T1..T5");
    p.machine_types[i] = *t;
  }
  const ConfigNode proc = n.at("proc_time_s");
  const ConfigNode codes = n.at("light_codes");
  for (int t = 0; t < 5; ++t) {
    const std::string key{'T', static_cast<char>('1' + t)};
    p.proc_time_s[t] = read_int(proc.at(key));
    p.light_codes[t] = read_light_code(codes.at(key));
  }
  proc.no_other_keys();
  codes.no_other_keys();
  const ConfigNode q = n.at("order_quantities");
  if (!q.is_sequence() || q.size() != kRegularOrderCount) q.fail("expected a list of 9 integers");
  for (int i = 0; i < kRegularOrderCount; ++i) p.order_quantities[i] = read_int(q.at(i));
  const ConfigNode late = n.at("late_order_start_s");
  if (!late.is_sequence() || late.size() != kLateOrderCount) {
    late.fail("expected a list of 2 integers");
  }
  for (int i = 0; i < kLateOrderCount; ++i) p.late_order_start_s[i] = read_int(late.at(i));
  for (const ConfigNode& e : n.at("down_times").elements()) {
    e.require_map();
    p.down_times.push_back(
        DownTime{read_device(e.at("machine")), read_int(e.at("start_s")), read_int(e.at("end_s"))});
    e.no_other_keys();
  }
  for (const ConfigNode& e : n.at("gate_schedule").elements()) {
    e.require_map();
    p.gate_schedule.push_back(
        GatePeriod{read_device(e.at("gate")), read_int(e.at("start_s")), read_int(e.at("end_s"))});
    e.no_other_keys();
  }
  n.no_other_keys();
  return p;
}

}  // namespace

void RefboxConfig::validate() const {
  check_config(*this, [](const std::string& field, const std::string& reason) {
    throw ConfigError("refbox." + field + ": " + reason);
  });
}

std::array<core::Pose2D, kDeviceCount> RefboxConfig::default_device_poses() {
  constexpr double pi = core::kPi;
  return {core::Pose2D{3.92, 1.68, 1.5 * pi},
          {3.92, 3.92, 0.0},
          {2.80, 0.56, 0.5 * pi},
          {2.80, 1.68, 0.5 * pi},
          {2.80, 2.80, pi},
          {2.80, 3.92, 0.5 * pi},
          {2.80, 5.04, 1.5 * pi},
          {1.68, 1.68, pi},
          {1.68, 3.92, 1.5 * pi},
          {1.68, 5.04, 0.0},
          {5.40, 0.20, 0.75 * pi},
          {0.20, 5.40, 1.75 * pi},
          {5.40, 5.40, 1.25 * pi},
          {5.34, 3.15, pi},
          {5.34, 2.80, pi},
          {5.34, 2.45, pi}};
}

RefboxConfig load_refbox_config(const ConfigNode& node) {
  RefboxConfig c;
  node.require_map();
  if (!node.is_map()) {
    c.validate();
    return c;
  }
  node.read("rules", c.rules);
  if (node["recycle_points"].defined()) {
    const std::int64_t v = node["recycle_points"].as_int();
    if (v < 0 || v > 100) node["recycle_points"].fail("must be in 0..100");
    c.recycle_points = static_cast<int>(v);
  }
  node.read("team", c.team);
  node.read("skip_setup", c.skip_setup);
  c.setup_duration = read_seconds(node, "setup_s", c.setup_duration, kMaxSetupS);
  c.exploration_duration =
      read_seconds(node, "exploration_s", c.exploration_duration, kMaxExplorationS);
  c.production_duration =
      read_seconds(node, "production_s", c.production_duration, kPlanProductionS);
  if (node["pucks"].defined()) {
    c.pucks.clear();
    for (const ConfigNode& e : node["pucks"].elements()) c.pucks.push_back(read_int(e));
  }
  node.read("learn_unknown_pucks", c.learn_unknown_pucks);
  if (node["mode"].defined()) {
    const ConfigNode v = node["mode"];
    std::string name = v.as_string();
    for (char& ch : name) ch = static_cast<char>(std::toupper(static_cast<unsigned char>(ch)));
    const auto m = refbox_mode_from_string(name);
    if (!m) v.fail("must be standalone, master or slave (got '" + v.as_string() + "')");
    c.mode = *m;
  }
  c.overtime_duration = read_seconds(node, "overtime_s", c.overtime_duration, kOvertimeS);
  if (node["params"].defined() && !node["params"].is_null()) c.params = read_params(node["params"]);
  node.no_other_keys();
  check_config(
      c, [&](const std::string& field, const std::string& reason) { node.fail_at(field, reason); });
  return c;
}

RefboxConfig load_refbox_config_file(const std::string& path) {
  return load_refbox_config(ConfigNode::load_file(path));
}

}  // namespace llsf::refbox
