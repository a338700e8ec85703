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

}  // namespace

void PlacesConfig::validate() const {
  const std::string p = "planner.places.";
  core::require(p + "held_puck_offset_m", held_puck_offset_m, core::positive());
  core::require(p + "side_offset_m", side_offset_m, core::positive());
  core::require(p + "look_distance_m", look_distance_m, core::positive());
  core::require(p + "storage_pickups", storage_pickups, core::in_range(1, 100));
  core::require(p + "storage_pickup_depth_m", storage_pickup_depth_m, core::non_negative());
  core::require(p + "wait_distance_m", wait_distance_m, core::non_negative());
  core::require(p + "wait_lateral_m", wait_lateral_m, core::finite());
  std::set<std::string> names;
  for (std::size_t i = 0; i < extra.size(); ++i) {
    const std::string e = p + "extra[" + std::to_string(i) + "]";
    if (extra[i].name.empty()) fail(e + ".name", "must not be empty");
    if (!names.insert(extra[i].name).second) fail(e + ".name", "duplicate name " + extra[i].name);
    core::require(e + ".x", extra[i].pose.x, core::finite());
    core::require(e + ".y", extra[i].pose.y, core::finite());
    core::require(e + ".theta", extra[i].pose.theta, core::finite());
  }
}

void PlannerConfig::validate() const {
  core::require("planner.robot_radius_m", robot_radius_m, core::positive());
  core::require("planner.safety_margin_m", safety_margin_m, core::non_negative());
  core::require("planner.rrt_range_m", rrt_range_m, core::positive());
  core::require("planner.max_iterations", max_iterations, core::in_range(10, 1000000));
  core::require("planner.accept_ratio", accept_ratio, core::at_least(1.0));
  core::require("planner.accept_extra_m", accept_extra_m, core::non_negative());
  core::require("planner.max_attempts", max_attempts, core::in_range(1, 100));
  core::require("planner.shortcut_steps", shortcut_steps, core::non_negative());
  core::require("planner.start_escape_m", start_escape_m, core::non_negative());
  places.validate();
}

void ControllerConfig::validate() const {
  const std::string p = "controller.";
  core::require(p + "max_speed_mps", max_speed_mps, core::positive());
  core::require(p + "max_omega_rps", max_omega_rps, core::positive());
  core::require(p + "max_accel_mps2", max_accel_mps2, core::positive());
  core::require(p + "max_alpha_rps2", max_alpha_rps2, core::positive());
  core::require(p + "accel_fraction", accel_fraction, core::fraction());
  core::require(p + "turn_accel_fraction", turn_accel_fraction, core::fraction());
  if (accel_fraction + turn_accel_fraction > 1.0 + 1e-12)
    fail(p + "turn_accel_fraction", "accel_fraction + turn_accel_fraction must be <= 1 (got " +
                                        num(accel_fraction + turn_accel_fraction) + ")");
  core::require(p + "position_tolerance_m", position_tolerance_m, core::positive());
  core::require(p + "angle_tolerance_rad", angle_tolerance_rad, core::positive());
  core::require(p + "corner_deviation_m", corner_deviation_m, core::positive());
  core::require(p + "robot_margin_m", robot_margin_m, core::non_negative());
  core::require(p + "obstacle_lookahead_m", obstacle_lookahead_m, core::positive());
  core::require(p + "stop_buffer_m", stop_buffer_m, core::non_negative());
  core::require(p + "wait_before_replan_s", wait_before_replan_s, core::non_negative());
  core::require(p + "replan_jitter_s", replan_jitter_s, core::non_negative());
  core::require(p + "replan_margin_m", replan_margin_m, core::non_negative());
  core::require(p + "prediction_horizon_s", prediction_horizon_s, core::non_negative());
  core::require(p + "backoff_distance_m", backoff_distance_m, core::non_negative());
  core::require(p + "backoff_min_s", backoff_min_s, core::non_negative());
  if (!(backoff_max_s >= backoff_min_s) || !std::isfinite(backoff_max_s))
    fail(p + "backoff_max_s", "must be >= backoff_min_s (got " + num(backoff_max_s) + ")");
  core::require(p + "blocked_timeout_s", blocked_timeout_s, core::positive());
  core::require(p + "stuck_timeout_s", stuck_timeout_s, core::positive());
  core::require(p + "progress_m", progress_m, core::positive());
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
  pl.read("held_puck_offset_m", c.held_puck_offset_m);
  pl.read("side_offset_m", c.side_offset_m);
  pl.read("look_distance_m", c.look_distance_m);
  pl.read("storage_pickups", c.storage_pickups);
  pl.read("storage_pickup_depth_m", c.storage_pickup_depth_m);
  pl.read("wait_distance_m", c.wait_distance_m);
  pl.read("wait_lateral_m", c.wait_lateral_m);
  if (const ConfigNode ex = pl["extra"]; ex.defined()) {
    if (!ex.is_sequence()) ex.fail("expected a list of {name, x, y, theta_deg}");
    c.extra.clear();
    for (const ConfigNode& e : ex.elements()) {
      e.require_map();
      UserPlace u;
      u.name = e.at("name").as_string();
      u.pose.x = e.at("x").as_double();
      u.pose.y = e.at("y").as_double();
      double deg = 0.0;
      e.read("theta_deg", deg);
      u.pose.theta = core::normalize_angle(core::deg_to_rad(deg));
      e.no_other_keys();
      c.extra.push_back(std::move(u));
    }
  }
  pl.no_other_keys();
}

void read_planner(const ConfigNode& p, PlannerConfig& c) {
  p.read("robot_radius_m", c.robot_radius_m);
  p.read("safety_margin_m", c.safety_margin_m);
  p.read("rrt_range_m", c.rrt_range_m);
  p.read("max_iterations", c.max_iterations);
  p.read("accept_ratio", c.accept_ratio);
  p.read("accept_extra_m", c.accept_extra_m);
  p.read("max_attempts", c.max_attempts);
  p.read("shortcut_steps", c.shortcut_steps);
  p.read("start_escape_m", c.start_escape_m);
  if (const ConfigNode pl = p["places"]; pl.defined()) {
    pl.require_map();
    read_places(pl, c.places);
  }
  p.no_other_keys();
}

void read_controller(const ConfigNode& k, ControllerConfig& cc) {
  k.read("max_speed_mps", cc.max_speed_mps);
  k.read("max_omega_rps", cc.max_omega_rps);
  k.read("max_accel_mps2", cc.max_accel_mps2);
  k.read("max_alpha_rps2", cc.max_alpha_rps2);
  k.read("accel_fraction", cc.accel_fraction);
  k.read("turn_accel_fraction", cc.turn_accel_fraction);
  k.read("position_tolerance_m", cc.position_tolerance_m);
  k.read("angle_tolerance_rad", cc.angle_tolerance_rad);
  k.read("corner_deviation_m", cc.corner_deviation_m);
  k.read("robot_margin_m", cc.robot_margin_m);
  k.read("obstacle_lookahead_m", cc.obstacle_lookahead_m);
  k.read("stop_buffer_m", cc.stop_buffer_m);
  k.read("wait_before_replan_s", cc.wait_before_replan_s);
  k.read("replan_jitter_s", cc.replan_jitter_s);
  k.read("replan_margin_m", cc.replan_margin_m);
  k.read("prediction_horizon_s", cc.prediction_horizon_s);
  k.read("backoff_distance_m", cc.backoff_distance_m);
  k.read("backoff_min_s", cc.backoff_min_s);
  k.read("backoff_max_s", cc.backoff_max_s);
  k.read("blocked_timeout_s", cc.blocked_timeout_s);
  k.read("stuck_timeout_s", cc.stuck_timeout_s);
  k.read("progress_m", cc.progress_m);
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
