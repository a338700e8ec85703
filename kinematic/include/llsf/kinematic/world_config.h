// SPDX-License-Identifier: MIT
// The read-only description of a kinematic LLSF world: field, devices, pucks, robots, sensors.
//
// WorldConfig::default_2013() is the 2013 rule-book field (../shared/specs/llsf2013-rules.md §1).
// Where the sources give no figure (device footprints, holder geometry, sensor noise), the
// default is an assumption, stated next to the field; docs/world-config.md documents every field
// and the YAML format that load_world_config() reads.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "llsf/core/config.h"
#include "llsf/core/geometry.h"
#include "llsf/core/ids.h"
#include "llsf/core/sim_time.h"

namespace llsf::kinematic {

using core::DeviceId;
using core::Pose2D;
using core::PuckId;
using core::RobotId;
using core::SimTime;
using core::Vec2;

/// Number of signal/RFID devices on the 2013 field.
inline constexpr int kDeviceCount = 16;
/// Device names in DeviceId order (DeviceId(i) is kDeviceNames[i]).
inline constexpr std::array<std::string_view, kDeviceCount> kDeviceNames = {
    "M1", "M2",  "M3", "M4", "M5",  "M6", "M7", "M8",
    "M9", "M10", "R1", "R2", "TST", "D1", "D2", "D3"};

enum class DeviceKind { kProduction, kRecycling, kTest, kDelivery };

/// The device called `name` (exact, case-sensitive), if there is one.
std::optional<DeviceId> device_by_name(std::string_view name);
/// M1..M10 are production machines, R1/R2 recycling, TST the test station, D1..D3 gates.
DeviceKind device_kind(DeviceId id);
std::string_view device_name(DeviceId id);

/// An axis-aligned rectangle [lo, hi] on the field, in metres.
struct Rect {
  Vec2 lo{0.0, 0.0};
  Vec2 hi{0.0, 0.0};
  bool contains(const Vec2& p) const {
    return p.x() >= lo.x() && p.y() >= lo.y() && p.x() <= hi.x() && p.y() <= hi.y();
  }
  Vec2 center() const { return 0.5 * (lo + hi); }
};

/// The arena: size, walls and the marked areas of the left and right strips.
struct FieldConfig {
  double width_m = 5.6;                          ///< x extent; origin is the bottom-left corner
  double height_m = 5.6;                         ///< y extent
  double wall_thickness_m = 0.05;                ///< boards stand outside [0, width] x [0, height]
  Rect insertion_area{{0.0, 0.0}, {0.4, 2.3}};   ///< robots start here (RB drawing)
  Rect input_storage{{0.0, 2.3}, {0.4, 3.3}};    ///< the 20 S0 pucks at game start
  Rect late_order_area{{0.0, 3.3}, {0.4, 3.9}};  ///< above the storage
  Vec2 late_order_slot{0.20, 3.60};              ///< 0.1 x 0.1 m insertion slot centre
  Rect delivery_zone{{5.2, 2.3}, {5.6, 3.3}};    ///< green zone with D1..D3
};

/// One device: a static body with an RFID read zone in front of its reader and a signal light.
/// The pose is the rule-book pose (machine-space centre; for gates the delivery slot) and its
/// heading is the facing: the direction in which the reader looks out onto the field.
struct DeviceConfig {
  Pose2D pose;
  double body_depth_m = 0.0;   ///< footprint extent along the facing
  double body_width_m = 0.0;   ///< footprint extent across the facing
  double body_offset_m = 0.0;  ///< body centre along the facing from the pose (negative: behind)
  double rfid_offset_m = 0.0;  ///< read-zone centre along the facing from the pose
  double rfid_radius_m = 0.0;  ///< horizontal read radius around the zone centre (<= 0.115 m)

  /// The body footprint as an oriented box in field coordinates.
  core::OrientedBox footprint() const;
  /// Centre of the RFID read zone in field coordinates.
  Vec2 rfid_center() const;
};

/// The puck model (an ice-hockey puck with an RFID tag on top).
struct PuckModelConfig {
  double radius_m = 0.0375;       ///< RB: diameter 7.5 cm
  double mass_kg = 0.16;          ///< a standard ice-hockey puck (assumption)
  double floor_friction = 0.25;   ///< Coulomb coefficient puck/floor: sliding decel = mu * g
  double contact_friction = 0.2;  ///< puck against robots, devices, walls and other pucks
  double restitution = 0.1;
};

/// A static box on the field that is not a device (the hackathon's boxes, a board put down for
/// a test). Robots and pucks collide with it like with a wall; the laser sees it.
struct ObstacleConfig {
  std::string name;       ///< unique, non-empty ("box1")
  Pose2D pose;            ///< centre; the heading is the direction of size_x_m
  double size_x_m = 0.0;  ///< extent along the heading
  double size_y_m = 0.0;  ///< extent across the heading

  /// The box in field coordinates.
  core::OrientedBox footprint() const { return {pose, Vec2(0.5 * size_x_m, 0.5 * size_y_m)}; }
};

/// A puck present at the start, with its RFID id.
struct PuckPlacement {
  int id = 0;
  Vec2 position{0.0, 0.0};
};

/// How the passive puck holder at the robot's front keeps a puck.
enum class HolderMode {
  kPhysical,  ///< friction only: a puck can slide out while the robot turns (thesis behaviour)
  kAssisted,  ///< a puck in the holder stays there while turning, until the robot backs away
};

/// The passive holder: two arms left and right of the puck pocket at the robot's front.
struct HolderConfig {
  HolderMode mode = HolderMode::kAssisted;
  double inner_width_m = 0.09;  ///< gap between the arms (puck diameter 0.075 m)
  double arm_length_m = 0.065;  ///< arms reach this far beyond the body's front (RB: <= 0.15)
  double arm_thickness_m = 0.01;
  double arm_friction = 0.05;  ///< puck against the arms (smooth plastic, assumption)
  /// Assisted mode lets the puck go once the commanded backward speed exceeds this.
  double release_backing_speed_mps = 0.02;
};

/// The Robotino model shared by every robot.
struct RobotModelConfig {
  double radius_m = 0.185;      ///< thesis: diameter 37 cm
  double mass_kg = 20.0;        ///< heavy, so that pucks do not stop it
  double max_speed_mps = 1.0;   ///< translational speed limit (2013 robots)
  double max_omega_rps = 2.0;   ///< rotational speed limit
  double max_accel_mps2 = 1.0;  ///< translational acceleration limit
  double max_alpha_rps2 = 4.0;  ///< rotational acceleration limit (assumption)
  double contact_friction = 0.3;
  /// The robot at laser height as other robots' lasers see it: a circle of this radius (0: the
  /// body's `radius_m`) whose centre lies `laser_offset_m` ahead of the robot's (negative:
  /// behind). The thesis' Gazebo Robotino has a smaller cylinder at laser height, shifted back.
  double laser_radius_m = 0.0;
  double laser_offset_m = 0.0;
  HolderConfig holder;
};

/// A robot present at the start.
struct RobotStart {
  std::string name;
  Pose2D pose;
  /// Jersey number (the beacons' `number`, the agent's ?*ROBOT-NUMBER*); 0: its index + 1.
  int jersey = 0;
  int jersey_or(int index) const { return jersey > 0 ? jersey : index + 1; }
};

/// Wheel odometry: integrates the commanded wheel motion (so it keeps counting while the robot
/// pushes against an obstacle) with an error that grows with distance, rotation and acceleration.
struct OdometryConfig {
  double rate_hz = 50.0;
  // Each std is the one reached after 1 unit; the error grows with the square root of the
  // distance / rotation / accumulated velocity change (a random walk, independent of rate_hz).
  double trans_noise_per_m = 0.01;        ///< translation error std after 1 m driven
  double rot_noise_per_rad = 0.01;        ///< heading error std after 1 rad turned
  double accel_noise_per_mps = 0.02;      ///< translation error std after 1 m/s of velocity change
  double accel_rot_noise_per_rps = 0.01;  ///< heading error std after 1 rad/s of omega change
};

/// Gyroscope: true yaw rate with Gaussian noise and a constant bias, and its integral.
struct GyroConfig {
  double rate_hz = 100.0;
  double noise_std_rps = 0.005;
  double bias_rps = 0.0005;
};

/// Infrared distance sensor looking into the puck pocket from the robot's front.
struct IrConfig {
  double rate_hz = 30.0;
  double range_m = 0.10;  ///< readings beyond this report range_m
  double noise_std_m = 0.002;
  double threshold_m = 0.02;  ///< puck detected when the reading is below this
};

/// The two digital optical sensors at the holder arm tips, looking forward.
struct OpticalConfig {
  double rate_hz = 30.0;
  /// Trigger distance. The thesis' real sensors reached the corner walls beside R1/R2 (its
  /// recycling-corner problem); 0.30 m reproduces that, a short range hides the walls.
  double range_m = 0.30;
  double miss_probability = 0.0;  ///< chance that a triggered sensor reports false
};

/// Ground-truth pose, for the `ground_truth` localization level.
struct GroundTruthConfig {
  double rate_hz = 30.0;
};

/// A planar laser range finder at the robot's centre, beams spread over the full circle.
struct LaserConfig {
  bool enabled = true;
  int beams = 360;
  double rate_hz = 5.0;  ///< thesis: 5 Hz in simulation
  double min_range_m = 0.02;
  double max_range_m = 5.6;
  double noise_std_m = 0.01;
  double mount_x_m = 0.0;  ///< sensor position in the robot frame
  double mount_y_m = 0.0;
};

struct SensorsConfig {
  OdometryConfig odometry;
  GyroConfig gyro;
  IrConfig ir;
  OpticalConfig optical;
  GroundTruthConfig ground_truth;
  LaserConfig laser;
};

/// Box2D stepping parameters.
struct PhysicsConfig {
  SimTime step = SimTime::from_ms(10);  ///< fixed step (100 Hz)
  int velocity_iterations = 8;
  int position_iterations = 3;
};

/// Everything that describes a world before it starts. Aggregate with in-class defaults; call
/// validate() (World's constructor does) to check it.
struct WorldConfig {
  FieldConfig field;
  std::array<DeviceConfig, kDeviceCount> devices{};
  /// Extra static boxes (none on the 2013 field; sim's hackathon variant adds some).
  std::vector<ObstacleConfig> obstacles;
  PuckModelConfig puck;
  std::vector<PuckPlacement> pucks;
  RobotModelConfig robot;
  std::vector<RobotStart> robots;
  SensorsConfig sensors;
  PhysicsConfig physics;

  /// The 2013 field: 16 devices at the rule-book poses, 20 pucks (ids 1..20) in the input
  /// storage, 3 robots in the insertion area.
  static WorldConfig default_2013();

  /// Throws core::ConfigError naming the offending field (e.g. "devices.M3: footprint overlaps
  /// devices.M4") for negative sizes, overlapping devices, objects outside the field, ...
  void validate() const;
};

/// Reads a world config from YAML on top of `base` (only the keys present override). Throws
/// core::ConfigError with file:line and field path for unknown keys, bad values and failed
/// validation. The format is documented in docs/world-config.md.
WorldConfig load_world_config(const core::ConfigNode& node,
                              WorldConfig base = WorldConfig::default_2013());
/// load_world_config() of a YAML file.
WorldConfig load_world_config_file(const std::string& path);

}  // namespace llsf::kinematic
