// SPDX-License-Identifier: MIT
// Validation of the navigation configuration and its YAML loader.
#include "llsf/planner/config.h"

#include <charconv>
#include <cmath>
#include <map>
#include <set>

#include "llsf/core/error.h"

namespace llsf::planner {

using core::ConfigError;
using core::ConfigNode;

namespace {

std::string num(double v) {
  char buf[64];
  const auto r = std::to_chars(buf, buf + sizeof buf, v);
  return std::string(buf, r.ptr);
}
[[noreturn]] void fail(const std::string& path, const std::string& reason) {
  throw ConfigError(path + ": " + reason);
}
void positive(const std::string& path, double v) {
  if (!(v > 0.0) || !std::isfinite(v)) fail(path, "must be > 0 (got " + num(v) + ")");
}
void non_negative(const std::string& path, double v) {
  if (!(v >= 0.0) || !std::isfinite(v)) fail(path, "must be >= 0 (got " + num(v) + ")");
}
void finite(const std::string& path, double v) {
  if (!std::isfinite(v)) fail(path, "must be a finite number (got " + num(v) + ")");
}
void fraction(const std::string& path, double v) {
  if (!(v > 0.0 && v <= 1.0)) fail(path, "must be in (0, 1] (got " + num(v) + ")");
}

}  // namespace

void PlacesConfig::validate() const {
  const std::string p = "planner.places.";
  positive(p + "held_puck_offset_m", held_puck_offset_m);
  positive(p + "side_offset_m", side_offset_m);
  positive(p + "look_distance_m", look_distance_m);
  if (storage_pickups < 1 || storage_pickups > 100)
    fail(p + "storage_pickups",
         "must be in [1, 100] (got " + std::to_string(storage_pickups) + ")");
  non_negative(p + "storage_pickup_depth_m", storage_pickup_depth_m);
  non_negative(p + "wait_distance_m", wait_distance_m);
  finite(p + "wait_lateral_m", wait_lateral_m);
  std::set<std::string> names;
  for (std::size_t i = 0; i < extra.size(); ++i) {
    const std::string e = p + "extra[" + std::to_string(i) + "]";
    if (extra[i].name.empty()) fail(e + ".name", "must not be empty");
    if (!names.insert(extra[i].name).second) fail(e + ".name", "duplicate name " + extra[i].name);
    finite(e + ".x", extra[i].pose.x);
    finite(e + ".y", extra[i].pose.y);
    finite(e + ".theta", extra[i].pose.theta);
  }
}

void PlannerConfig::validate() const {
  positive("planner.robot_radius_m", robot_radius_m);
  non_negative("planner.safety_margin_m", safety_margin_m);
  positive("planner.rrt_range_m", rrt_range_m);
  if (max_iterations < 10 || max_iterations > 1000000)
    fail("planner.max_iterations",
         "must be in [10, 1000000] (got " + std::to_string(max_iterations) + ")");
  if (!(accept_ratio >= 1.0) || !std::isfinite(accept_ratio))
    fail("planner.accept_ratio", "must be >= 1 (got " + num(accept_ratio) + ")");
  non_negative("planner.accept_extra_m", accept_extra_m);
  if (max_attempts < 1 || max_attempts > 100)
    fail("planner.max_attempts", "must be in [1, 100] (got " + std::to_string(max_attempts) + ")");
  if (shortcut_steps < 0)
    fail("planner.shortcut_steps", "must be >= 0 (got " + std::to_string(shortcut_steps) + ")");
  non_negative("planner.start_escape_m", start_escape_m);
  places.validate();
}

void ControllerConfig::validate() const {
  const std::string p = "controller.";
  positive(p + "max_speed_mps", max_speed_mps);
  positive(p + "max_omega_rps", max_omega_rps);
  positive(p + "max_accel_mps2", max_accel_mps2);
  positive(p + "max_alpha_rps2", max_alpha_rps2);
  fraction(p + "accel_fraction", accel_fraction);
  fraction(p + "turn_accel_fraction", turn_accel_fraction);
  if (accel_fraction + turn_accel_fraction > 1.0 + 1e-12)
    fail(p + "turn_accel_fraction", "accel_fraction + turn_accel_fraction must be <= 1 (got " +
                                        num(accel_fraction + turn_accel_fraction) + ")");
  positive(p + "position_tolerance_m", position_tolerance_m);
  positive(p + "angle_tolerance_rad", angle_tolerance_rad);
  positive(p + "corner_deviation_m", corner_deviation_m);
  non_negative(p + "robot_margin_m", robot_margin_m);
  positive(p + "obstacle_lookahead_m", obstacle_lookahead_m);
  non_negative(p + "stop_buffer_m", stop_buffer_m);
  non_negative(p + "wait_before_replan_s", wait_before_replan_s);
  non_negative(p + "replan_jitter_s", replan_jitter_s);
  non_negative(p + "replan_margin_m", replan_margin_m);
  non_negative(p + "prediction_horizon_s", prediction_horizon_s);
  non_negative(p + "backoff_distance_m", backoff_distance_m);
  non_negative(p + "backoff_min_s", backoff_min_s);
  if (!(backoff_max_s >= backoff_min_s) || !std::isfinite(backoff_max_s))
    fail(p + "backoff_max_s", "must be >= backoff_min_s (got " + num(backoff_max_s) + ")");
  positive(p + "blocked_timeout_s", blocked_timeout_s);
  positive(p + "stuck_timeout_s", stuck_timeout_s);
  positive(p + "progress_m", progress_m);
}

void NavigationConfig::validate() const {
  planner.validate();
  controller.validate();
}

// ---------------------------------------------------------------------------------------------
// YAML
// ---------------------------------------------------------------------------------------------

namespace {

class Loader {
 public:
  NavigationConfig load(const ConfigNode& root, NavigationConfig c) {
    root.require_map();
    root.check_keys({"planner", "controller"});
    if (const ConfigNode p = section(root, "planner"); p.defined()) {
      p.check_keys({"robot_radius_m", "safety_margin_m", "rrt_range_m", "max_iterations",
                    "accept_ratio", "accept_extra_m", "max_attempts", "shortcut_steps",
                    "start_escape_m", "places"});
      num(p, "robot_radius_m", c.planner.robot_radius_m);
      num(p, "safety_margin_m", c.planner.safety_margin_m);
      num(p, "rrt_range_m", c.planner.rrt_range_m);
      integer(p, "max_iterations", c.planner.max_iterations);
      num(p, "accept_ratio", c.planner.accept_ratio);
      num(p, "accept_extra_m", c.planner.accept_extra_m);
      integer(p, "max_attempts", c.planner.max_attempts);
      integer(p, "shortcut_steps", c.planner.shortcut_steps);
      num(p, "start_escape_m", c.planner.start_escape_m);
      if (const ConfigNode pl = section(p, "places"); pl.defined())
        read_places(pl, c.planner.places);
    }
    if (const ConfigNode k = section(root, "controller"); k.defined()) {
      ControllerConfig& cc = c.controller;
      k.check_keys({"max_speed_mps",        "max_omega_rps",
                    "max_accel_mps2",       "max_alpha_rps2",
                    "accel_fraction",       "turn_accel_fraction",
                    "position_tolerance_m", "angle_tolerance_rad",
                    "corner_deviation_m",   "robot_margin_m",
                    "obstacle_lookahead_m", "stop_buffer_m",
                    "wait_before_replan_s", "replan_jitter_s",
                    "replan_margin_m",      "prediction_horizon_s",
                    "backoff_distance_m",   "backoff_min_s",
                    "backoff_max_s",        "blocked_timeout_s",
                    "stuck_timeout_s",      "progress_m"});
      num(k, "max_speed_mps", cc.max_speed_mps);
      num(k, "max_omega_rps", cc.max_omega_rps);
      num(k, "max_accel_mps2", cc.max_accel_mps2);
      num(k, "max_alpha_rps2", cc.max_alpha_rps2);
      num(k, "accel_fraction", cc.accel_fraction);
      num(k, "turn_accel_fraction", cc.turn_accel_fraction);
      num(k, "position_tolerance_m", cc.position_tolerance_m);
      num(k, "angle_tolerance_rad", cc.angle_tolerance_rad);
      num(k, "corner_deviation_m", cc.corner_deviation_m);
      num(k, "robot_margin_m", cc.robot_margin_m);
      num(k, "obstacle_lookahead_m", cc.obstacle_lookahead_m);
      num(k, "stop_buffer_m", cc.stop_buffer_m);
      num(k, "wait_before_replan_s", cc.wait_before_replan_s);
      num(k, "replan_jitter_s", cc.replan_jitter_s);
      num(k, "replan_margin_m", cc.replan_margin_m);
      num(k, "prediction_horizon_s", cc.prediction_horizon_s);
      num(k, "backoff_distance_m", cc.backoff_distance_m);
      num(k, "backoff_min_s", cc.backoff_min_s);
      num(k, "backoff_max_s", cc.backoff_max_s);
      num(k, "blocked_timeout_s", cc.blocked_timeout_s);
      num(k, "stuck_timeout_s", cc.stuck_timeout_s);
      num(k, "progress_m", cc.progress_m);
    }
    try {
      c.validate();
    } catch (const ConfigError& e) {
      throw ConfigError(locate(root, e.what()).location() + ": " + e.what());
    }
    return c;
  }

 private:
  ConfigNode section(const ConfigNode& parent, std::string_view key) {
    ConfigNode n = parent[key];
    if (n.defined()) {
      n.require_map();
      seen_.insert_or_assign(n.path(), n);
    }
    return n;
  }
  void num(const ConfigNode& parent, std::string_view key, double& out) {
    if (const ConfigNode n = parent[key]; n.defined()) {
      out = n.as_double();
      seen_.insert_or_assign(n.path(), n);
    }
  }
  void integer(const ConfigNode& parent, std::string_view key, int& out) {
    if (const ConfigNode n = parent[key]; n.defined()) {
      parent.read(key, out);
      seen_.insert_or_assign(n.path(), n);
    }
  }
  void read_places(const ConfigNode& pl, PlacesConfig& c) {
    pl.check_keys({"held_puck_offset_m", "side_offset_m", "look_distance_m", "storage_pickups",
                   "storage_pickup_depth_m", "wait_distance_m", "wait_lateral_m", "extra"});
    num(pl, "held_puck_offset_m", c.held_puck_offset_m);
    num(pl, "side_offset_m", c.side_offset_m);
    num(pl, "look_distance_m", c.look_distance_m);
    integer(pl, "storage_pickups", c.storage_pickups);
    num(pl, "storage_pickup_depth_m", c.storage_pickup_depth_m);
    num(pl, "wait_distance_m", c.wait_distance_m);
    num(pl, "wait_lateral_m", c.wait_lateral_m);
    if (const ConfigNode ex = pl["extra"]; ex.defined()) {
      if (!ex.is_sequence()) ex.fail("expected a list of {name, x, y, theta_deg}");
      c.extra.clear();
      for (const ConfigNode& e : ex.elements()) {
        e.require_map();
        e.check_keys({"name", "x", "y", "theta_deg"});
        UserPlace u;
        u.name = e.at("name").as_string();
        u.pose.x = e.at("x").as_double();
        u.pose.y = e.at("y").as_double();
        double deg = 0.0;
        e.read("theta_deg", deg);
        u.pose.theta = core::normalize_angle(core::deg_to_rad(deg));
        seen_.insert_or_assign(e.path(), e);
        c.extra.push_back(std::move(u));
      }
    }
  }
  /// The node read at the path the message starts with, or its nearest read ancestor.
  const ConfigNode& locate(const ConfigNode& root, const std::string& message) const {
    std::string p = message.substr(0, message.find(": "));
    while (!p.empty()) {
      if (auto it = seen_.find(p); it != seen_.end()) return it->second;
      const auto cut = p.find_last_of(".[");
      p = cut == std::string::npos ? std::string() : p.substr(0, cut);
    }
    return root;
  }

  std::map<std::string, ConfigNode> seen_;
};

}  // namespace

NavigationConfig load_navigation_config(const ConfigNode& node, NavigationConfig base) {
  if (!node.defined() || node.is_null()) {
    try {
      base.validate();
    } catch (const ConfigError& e) {
      throw ConfigError(node.location() + ": " + e.what());
    }
    return base;
  }
  return Loader().load(node, std::move(base));
}

}  // namespace llsf::planner
