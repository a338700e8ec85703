// SPDX-License-Identifier: MIT
// Read-only configuration of navigation: the map inflation and OMPL query settings
// (PlannerConfig), the named places (PlacesConfig) and the path-following controller with its
// handling of other robots (ControllerConfig). docs/planner.md lists every key.
#pragma once

#include <string>
#include <vector>

#include "llsf/core/config.h"
#include "llsf/planner/field_map.h"

namespace llsf::planner {

/// A place given in the configuration (a waiting point of the team's choice, ...).
struct UserPlace {
  std::string name;
  Pose2D pose;
};

/// How named places are derived from device poses (see docs/planner.md, "Places").
struct PlacesConfig {
  /// Robot centre to the centre of a puck held in the holder (kinematic: 0.185 + 0.0375).
  double held_puck_offset_m = 0.2225;
  /// Consumed pucks lie this far left/right of the RFID zone centre, across the facing.
  double side_offset_m = 0.22;
  /// Exploration look position: this far in front of the device pose, facing it.
  double look_distance_m = 0.6;
  /// Number of pick-up poses spread along the input storage.
  int storage_pickups = 5;
  /// Depth of the pick-up spot inside the input storage, from its open side (front column).
  double storage_pickup_depth_m = 0.12;
  /// Waiting points: this far out from the storage / delivery zone's open side ...
  double wait_distance_m = 0.9;
  /// ... and this far along it, towards the insertion area (negative y on the 2013 field).
  double wait_lateral_m = -0.7;
  /// Extra places; names must not clash with derived ones.
  std::vector<UserPlace> extra;

  void validate() const;
};

/// The static map and the OMPL queries.
struct PlannerConfig {
  double robot_radius_m = 0.185;  ///< the Robotino body
  /// Added to the radius for every static obstacle and wall. 0.075 makes the disc 0.26 m: it
  /// then also covers the holder arms (0.25 m) and a held puck (0.26 m) at any heading.
  double safety_margin_m = 0.075;
  /// OMPL RRTConnect range: the longest edge added in one step.
  double rrt_range_m = 1.0;
  /// A query gives up (no path) after this many planner iterations. Iterations, not seconds,
  /// so that the outcome does not depend on the machine's speed.
  int max_iterations = 1500;
  /// A path longer than accept_ratio * straight distance + accept_extra_m is planned again
  /// (another RRTConnect run from the same seed's stream), up to max_attempts runs; the
  /// shortest wins. RRTConnect sometimes goes round the far side of a machine row.
  double accept_ratio = 1.3;
  double accept_extra_m = 0.3;
  int max_attempts = 3;
  /// Rounds of OMPL's shortcutPath (0 = OMPL's default).
  int shortcut_steps = 0;
  /// A start inside the inflated obstacles (a robot pushed into the margin) is first moved out
  /// along the shortest free direction, at most this far.
  double start_escape_m = 0.3;
  PlacesConfig places;

  /// Planning radius: robot_radius_m + safety_margin_m.
  double inflated_radius_m() const { return robot_radius_m + safety_margin_m; }
  /// Throws core::ConfigError naming the field, e.g. "planner.safety_margin_m: must be >= 0".
  void validate() const;
};

/// The path-following controller and how it deals with other robots.
struct ControllerConfig {
  double max_speed_mps = 1.0;
  double max_omega_rps = 2.0;
  double max_accel_mps2 = 1.0;
  double max_alpha_rps2 = 4.0;
  /// The controller plans with this fraction of the acceleration limits (the rest is headroom
  /// for feedback and for the velocity rotation of turning while driving).
  double accel_fraction = 0.7;
  /// Turning at omega while driving at v rotates the velocity in the robot frame at omega * v;
  /// this fraction of max_accel_mps2 bounds it so that the wheels keep a straight path.
  double turn_accel_fraction = 0.25;
  double position_tolerance_m = 0.02;
  double angle_tolerance_rad = 0.03;
  /// How far the robot may swing out at a path corner; sets the corner speed. The 0.26 m
  /// disc covers the holder arms with only millimetres to spare: keep this small.
  double corner_deviation_m = 0.01;
  /// Other robots closer to the path than the two discs plus this margin block it.
  double robot_margin_m = 0.0;
  /// The path is checked for other robots this far ahead.
  double obstacle_lookahead_m = 1.5;
  /// Stop this far before the point where the path meets another robot's disc.
  double stop_buffer_m = 0.05;
  /// Blocked for this long (plus a seeded jitter up to replan_jitter_s): plan around.
  double wait_before_replan_s = 1.0;
  double replan_jitter_s = 1.0;
  /// Extra clearance kept from other robots when planning around them.
  double replan_margin_m = 0.06;
  /// A moving robot also blocks, and is planned around, where it will be within this time at
  /// its estimated velocity.
  double prediction_horizon_s = 1.5;
  /// No way around: give way -- move at most this far to a spot off the line through the
  /// blocker (far enough across it for the blocker to pass, else as far as possible) -- and
  /// wait a seeded random delay.
  double backoff_distance_m = 1.2;
  /// The delay is uniform in [min, min + k (max - min)], k = 1, 2, 2, ... for the 1st, 2nd,
  /// 3rd, ... back-off of one navigation (capped exponential back-off).
  double backoff_min_s = 0.5;
  double backoff_max_s = 3.0;
  /// Total time held back by other robots after which the goal is given up as `blocked`.
  double blocked_timeout_s = 30.0;
  /// No progress (progress_m less path to go, or 0.1 rad less heading error) for this long
  /// while free to drive: `stuck`.
  double stuck_timeout_s = 4.0;
  double progress_m = 0.03;

  /// Throws core::ConfigError naming the field, e.g. "controller.max_speed_mps: must be > 0".
  void validate() const;
};

/// Both parts, as one YAML document has them (`planner:` and `controller:`).
struct NavigationConfig {
  PlannerConfig planner;
  ControllerConfig controller;
  void validate() const;
};

/// Reads `planner:` / `controller:` keys on top of `base` (only present keys override) and
/// validates. Throws core::ConfigError with file:line and field path (unknown keys too).
NavigationConfig load_navigation_config(const core::ConfigNode& node,
                                        NavigationConfig base = NavigationConfig{});

}  // namespace llsf::planner
