// SPDX-License-Identifier: MIT
// Robot profiles: a named set of the robot capabilities that set the pace and the failures of a
// game -- drive limits, fine motion, alignment at a goal, light and laser rates, localization,
// navigation around other robots, jams at devices and whether skills detect being stuck.
// `ideal` is the game loop's defaults; `robotino-2013` is the 2013 Carologistics Robotino from the
// team's own files (move_base-2013 navigation, its skills' motions, the Gazebo models of the
// thesis' runs); `robotino-2013-omniscient` the earlier model of it (an omniscient navigator, jam
// dice). docs/profiles.md gives every figure with its source.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "llsf/core/config.h"
#include "llsf/sim/game_config.h"

namespace llsf::lua {
struct SkillEngineConfig;
}

namespace llsf::study {

/// A robot profile. Every field has the `ideal` value by default; named() gives the others.
struct RobotProfile {
  std::string name = "ideal";

  // Driving (world.robot and navigation.controller).
  double max_speed_mps = 1.0;
  double max_omega_rps = 2.0;
  double max_accel_mps2 = 1.0;
  double max_alpha_rps2 = 4.0;
  /// Cap of direct motor commands (fine motion at devices: motor_move, take_puck, ...); 0 = none.
  double motor_max_speed_mps = 0.0;
  double motor_max_omega_rps = 0.0;
  /// Fine alignment after every navigation goal (HandlingConfig::align_s).
  double align_s = 0.0;

  // Perception.
  sim::DetectionLevel light = sim::DetectionLevel::kGroundTruth;
  double light_frame_rate_hz = 10.0;
  double light_delay_s = 1.0;
  double light_error_rate = 0.05;
  bool light_reads_states = false;  ///< LightDetectionConfig::reads_states
  double laser_rate_hz = 5.0;
  sim::LocalizationLevel localization = sim::LocalizationLevel::kGroundTruth;
  double position_noise_m = 0.01;
  double heading_noise_rad = 0.01;

  // Navigation: the level (levels.navigation) and, at the ideal level, how the navigator deals
  // with other robots (navigation.controller).
  sim::NavigationLevel navigation = sim::NavigationLevel::kIdeal;
  /// Whether the laser runs (world.sensors.laser.enabled); the move_base-2013 level needs it.
  bool laser = true;
  double wait_before_replan_s = 1.0;
  double backoff_min_s = 0.5;
  double backoff_max_s = 3.0;
  double blocked_timeout_s = 30.0;

  // The machines' bodies (M1..M10, R1, R2, TST) in the world: depth along the facing and width
  // across it; 0 keeps the world's. The body's front stays where the world's is (0.04 m behind
  // the read zone), so pucks rest where they did.
  double machine_depth_m = 0.0;
  double machine_width_m = 0.0;
  /// The laser's mount ahead of the robot centre (world.sensors.laser.mount_x_m) and the robot
  /// as other robots' lasers see it (world.robot.laser_radius_m, laser_offset_m; 0: the body).
  double laser_mount_x_m = 0.0;
  double robot_laser_radius_m = 0.0;
  double robot_laser_offset_m = 0.0;
  /// The optical sensors' trigger range (world.sensors.optical.range_m); 0: the world's.
  double optical_range_m = 0.0;

  // Failures.
  double jam_probability = 0.0;  ///< HandlingConfig::jam_probability
  bool stuck_detection = true;   ///< HandlingConfig::stuck_detection
  /// How the skills move at machines (lua::SkillEngineConfig::motions): "llsfsim" or
  /// "carologistics-2013".
  std::string motions = "llsfsim";

  /// The names named() knows: "ideal", "robotino-2013", "robotino-2013-omniscient".
  static std::vector<std::string> names();
  /// A named profile; throws std::invalid_argument for an unknown name.
  static RobotProfile named(std::string_view name);

  /// Throws core::ConfigError "profile.<field>: reason" for the first bad field.
  void validate() const;
  /// Sets the game's and the skills' fields that the profile covers.
  void apply(sim::GameConfig& game, lua::SkillEngineConfig& skills) const;
};

/// Reads a scenario's `profile:` -- a name (`robotino-2013`) or a map with `name` and any field
/// to override (`{name: robotino-2013, max_speed_mps: 0.4}`). Errors name the file:line and key.
RobotProfile load_profile(const core::ConfigNode& node);

}  // namespace llsf::study
