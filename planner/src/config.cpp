// SPDX-License-Identifier: MIT
// Validation of the navigation configuration and its YAML loader.
#include "llsf/planner/config.h"

#include <cmath>
#include <set>

#include "llsf/core/error.h"

namespace llsf::planner {

using core::ConfigError;
using core::ConfigNode;

namespace {

std::string num(double v) { return core::number_text(v); }
[[noreturn]] void fail(const std::string& path, const std::string& reason) {
  throw ConfigError(path + ": " + reason);
}

// Upper bounds of every figure (docs/planner.md, "Bounds"): far above any robot on a 5.6 m
// field, low enough that distances, times and their products stay finite and a wait stays a
// wait. Each is checked at its key by the loader and again by validate() for configs built in
// code.
constexpr double kMaxDistanceM = 100.0;  ///< the field is 5.6 m across
constexpr double kMaxSpeedMps = 10.0;    ///< as the world's robot.max_speed_mps
constexpr double kMaxOmegaRps = 20.0;
constexpr double kMaxAccelMps2 = 100.0;
constexpr double kMaxAlphaRps2 = 200.0;
constexpr double kMaxWaitS = 60.0;       ///< a wait over a minute is a stuck robot
constexpr double kMaxTimeoutS = 3600.0;  ///< a game's longest duration
constexpr double kMaxAcceptRatio = 100.0;
constexpr double kMaxCoordinateM = 1000.0;  ///< as a scenario's robot start
constexpr int kMaxShortcutSteps = 10000;

constexpr core::Bound positive_at_most(double hi) {
  return {core::Bound::Kind::kOpenClosed, 0.0, hi};
}

struct DoubleKey {
  const char* key;
  double ControllerConfig::*field;
  core::Bound bound;
};

// The controller's figures; accel_fraction + turn_accel_fraction <= 1 and backoff_max_s >=
// backoff_min_s are checked after them.
constexpr DoubleKey kControllerKeys[] = {
    {"max_speed_mps", &ControllerConfig::max_speed_mps, positive_at_most(kMaxSpeedMps)},
    {"max_omega_rps", &ControllerConfig::max_omega_rps, positive_at_most(kMaxOmegaRps)},
    {"max_accel_mps2", &ControllerConfig::max_accel_mps2, positive_at_most(kMaxAccelMps2)},
    {"max_alpha_rps2", &ControllerConfig::max_alpha_rps2, positive_at_most(kMaxAlphaRps2)},
    {"accel_fraction", &ControllerConfig::accel_fraction, core::fraction()},
    {"turn_accel_fraction", &ControllerConfig::turn_accel_fraction, core::fraction()},
    {"position_tolerance_m", &ControllerConfig::position_tolerance_m,
     positive_at_most(kMaxDistanceM)},
    {"angle_tolerance_rad", &ControllerConfig::angle_tolerance_rad, positive_at_most(core::kPi)},
    {"corner_deviation_m", &ControllerConfig::corner_deviation_m, positive_at_most(kMaxDistanceM)},
    {"robot_margin_m", &ControllerConfig::robot_margin_m, core::in_range(0.0, kMaxDistanceM)},
    {"obstacle_lookahead_m", &ControllerConfig::obstacle_lookahead_m,
     positive_at_most(kMaxDistanceM)},
    {"stop_buffer_m", &ControllerConfig::stop_buffer_m, core::in_range(0.0, kMaxDistanceM)},
    {"wait_before_replan_s", &ControllerConfig::wait_before_replan_s,
     core::in_range(0.0, kMaxWaitS)},
    {"replan_jitter_s", &ControllerConfig::replan_jitter_s, core::in_range(0.0, kMaxWaitS)},
    {"replan_margin_m", &ControllerConfig::replan_margin_m, core::in_range(0.0, kMaxDistanceM)},
    {"prediction_horizon_s", &ControllerConfig::prediction_horizon_s,
     core::in_range(0.0, kMaxWaitS)},
    {"backoff_distance_m", &ControllerConfig::backoff_distance_m,
     core::in_range(0.0, kMaxDistanceM)},
    {"backoff_min_s", &ControllerConfig::backoff_min_s, core::in_range(0.0, kMaxWaitS)},
    {"backoff_max_s", &ControllerConfig::backoff_max_s, core::in_range(0.0, kMaxWaitS)},
    {"blocked_timeout_s", &ControllerConfig::blocked_timeout_s, positive_at_most(kMaxTimeoutS)},
    {"stuck_timeout_s", &ControllerConfig::stuck_timeout_s, positive_at_most(kMaxTimeoutS)},
    {"progress_m", &ControllerConfig::progress_m, positive_at_most(kMaxDistanceM)},
};

struct PlannerKey {
  const char* key;
  double PlannerConfig::*field;
  core::Bound bound;
};

constexpr PlannerKey kPlannerKeys[] = {
    {"robot_radius_m", &PlannerConfig::robot_radius_m, positive_at_most(kMaxDistanceM)},
    {"safety_margin_m", &PlannerConfig::safety_margin_m, core::in_range(0.0, kMaxDistanceM)},
    {"rrt_range_m", &PlannerConfig::rrt_range_m, positive_at_most(kMaxDistanceM)},
    {"accept_ratio", &PlannerConfig::accept_ratio, core::in_range(1.0, kMaxAcceptRatio)},
    {"accept_extra_m", &PlannerConfig::accept_extra_m, core::in_range(0.0, kMaxDistanceM)},
    {"start_escape_m", &PlannerConfig::start_escape_m, core::in_range(0.0, kMaxDistanceM)},
};
constexpr core::Bound kMaxIterations = core::in_range(10, 1000000);
constexpr core::Bound kMaxAttempts = core::in_range(1, 100);
constexpr core::Bound kShortcutSteps = core::in_range(0, kMaxShortcutSteps);

struct PlacesKey {
  const char* key;
  double PlacesConfig::*field;
  core::Bound bound;
};

constexpr PlacesKey kPlacesKeys[] = {
    {"held_puck_offset_m", &PlacesConfig::held_puck_offset_m, positive_at_most(kMaxDistanceM)},
    {"side_offset_m", &PlacesConfig::side_offset_m, positive_at_most(kMaxDistanceM)},
    {"look_distance_m", &PlacesConfig::look_distance_m, positive_at_most(kMaxDistanceM)},
    {"storage_pickup_depth_m", &PlacesConfig::storage_pickup_depth_m,
     core::in_range(0.0, kMaxDistanceM)},
    {"wait_distance_m", &PlacesConfig::wait_distance_m, core::in_range(0.0, kMaxDistanceM)},
    {"wait_lateral_m", &PlacesConfig::wait_lateral_m,
     core::in_range(-kMaxDistanceM, kMaxDistanceM)},
};
constexpr core::Bound kStoragePickups = core::in_range(1, 100);
constexpr core::Bound kCoordinate = core::in_range(-kMaxCoordinateM, kMaxCoordinateM);
constexpr core::Bound kThetaDeg = core::in_range(-360.0, 360.0);

}  // namespace

void PlacesConfig::validate() const {
  const std::string p = "planner.places.";
  for (const PlacesKey& k : kPlacesKeys) core::require(p + k.key, this->*k.field, k.bound);
  core::require(p + "storage_pickups", storage_pickups, kStoragePickups);
  std::set<std::string> names;
  for (std::size_t i = 0; i < extra.size(); ++i) {
    const std::string e = p + "extra[" + std::to_string(i) + "]";
    if (extra[i].name.empty()) fail(e + ".name", "must not be empty");
    if (!names.insert(extra[i].name).second) fail(e + ".name", "duplicate name " + extra[i].name);
    core::require(e + ".x", extra[i].pose.x, kCoordinate);
    core::require(e + ".y", extra[i].pose.y, kCoordinate);
    core::require(e + ".theta", extra[i].pose.theta, core::finite());
  }
}

void PlannerConfig::validate() const {
  for (const PlannerKey& k : kPlannerKeys)
    core::require("planner." + std::string(k.key), this->*k.field, k.bound);
  core::require("planner.max_iterations", max_iterations, kMaxIterations);
  core::require("planner.max_attempts", max_attempts, kMaxAttempts);
  core::require("planner.shortcut_steps", shortcut_steps, kShortcutSteps);
  places.validate();
}

void ControllerConfig::validate() const {
  const std::string p = "controller.";
  for (const DoubleKey& k : kControllerKeys) core::require(p + k.key, this->*k.field, k.bound);
  if (accel_fraction + turn_accel_fraction > 1.0 + 1e-12)
    fail(p + "turn_accel_fraction", "accel_fraction + turn_accel_fraction must be <= 1 (got " +
                                        num(accel_fraction + turn_accel_fraction) + ")");
  if (!(backoff_max_s >= backoff_min_s))
    fail(p + "backoff_max_s", "must be >= backoff_min_s (got " + num(backoff_max_s) + ")");
}

void NavigationConfig::validate() const {
  planner.validate();
  controller.validate();
}

// ---------------------------------------------------------------------------------------------
// YAML
// ---------------------------------------------------------------------------------------------

namespace {

void read_places(const ConfigNode& pl, PlacesConfig& c) {
  for (const PlacesKey& k : kPlacesKeys) pl.read(k.key, c.*k.field, k.bound);
  pl.read("storage_pickups", c.storage_pickups, kStoragePickups);
  if (const ConfigNode ex = pl["extra"]; ex.defined()) {
    if (!ex.is_sequence()) ex.fail("expected a list of {name, x, y, theta_deg}");
    c.extra.clear();
    for (const ConfigNode& e : ex.elements()) {
      e.require_map();
      UserPlace u;
      u.name = e.at("name").as_string();
      u.pose.x = e.at("x").as_double(kCoordinate);
      u.pose.y = e.at("y").as_double(kCoordinate);
      double deg = 0.0;
      e.read("theta_deg", deg, kThetaDeg);
      u.pose.theta = core::normalize_angle(core::deg_to_rad(deg));
      e.no_other_keys();
      c.extra.push_back(std::move(u));
    }
  }
  pl.no_other_keys();
}

void read_planner(const ConfigNode& p, PlannerConfig& c) {
  for (const PlannerKey& k : kPlannerKeys) p.read(k.key, c.*k.field, k.bound);
  p.read("max_iterations", c.max_iterations, kMaxIterations);
  p.read("max_attempts", c.max_attempts, kMaxAttempts);
  p.read("shortcut_steps", c.shortcut_steps, kShortcutSteps);
  if (const ConfigNode pl = p["places"]; pl.defined()) {
    pl.require_map();
    read_places(pl, c.places);
  }
  p.no_other_keys();
}

void read_controller(const ConfigNode& k, ControllerConfig& cc) {
  // Each figure checked at its own key, as validate() checks it.
  for (const DoubleKey& d : kControllerKeys) k.read(d.key, cc.*d.field, d.bound);
  k.no_other_keys();
}

}  // namespace

NavigationConfig load_navigation_config(const ConfigNode& node, NavigationConfig base) {
  NavigationConfig c = std::move(base);
  if (node.defined() && !node.is_null()) {
    node.require_map();
    if (const ConfigNode p = node["planner"]; p.defined()) {
      p.require_map();
      read_planner(p, c.planner);
    }
    if (const ConfigNode k = node["controller"]; k.defined()) {
      k.require_map();
      read_controller(k, c.controller);
    }
    node.no_other_keys();
  }
  node.locate_errors([&] { c.validate(); });
  return c;
}

}  // namespace llsf::planner
