// SPDX-License-Identifier: MIT
// The kinematic LLSF world: field, walls, devices, pucks and Robotinos in Box2D, stepped with a
// fixed time step; returns the events of each step and keeps every robot's sensor readings.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <vector>

#include "llsf/core/rng.h"
#include "llsf/kinematic/sensors.h"
#include "llsf/kinematic/world_config.h"

namespace llsf::kinematic {

/// A holonomic velocity command in the robot frame (x forward, y left). The world clamps it to
/// the robot's speed limits and ramps to it within the acceleration limits.
struct MotorCommand {
  double vx_mps = 0.0;
  double vy_mps = 0.0;
  double omega_rps = 0.0;
};

/// The three lamps of a signal tower. The world only displays them; the refbox decides.
enum class LampState : std::uint8_t { kOff, kOn, kBlink };
struct SignalLights {
  LampState red = LampState::kOff;
  LampState yellow = LampState::kOff;
  LampState green = LampState::kOff;
  friend bool operator==(const SignalLights&, const SignalLights&) = default;
};

enum class RfidEventKind : std::uint8_t { kEntered, kLeft };
/// A puck's centre entered or left a device's RFID read zone during a step.
struct RfidEvent {
  core::SimTime time;
  RfidEventKind kind = RfidEventKind::kEntered;
  PuckId puck;
  DeviceId device;
};

enum class CollisionKind : std::uint8_t { kRobotRobot, kRobotWall, kRobotDevice };
/// A robot's body started touching a wall, a device or another robot.
struct CollisionEvent {
  core::SimTime time;
  CollisionKind kind = CollisionKind::kRobotWall;
  RobotId robot;
  RobotId other_robot;  ///< for kRobotRobot
  DeviceId device;      ///< for kRobotDevice
};

/// What happened during one step, in order of occurrence; valid until the next step.
struct WorldEvents {
  std::vector<RfidEvent> rfid;
  std::vector<CollisionEvent> collisions;
};

/// The world. Not copyable (it owns a Box2D world); not thread-safe; one per game.
/// Steady-state step() does not allocate.
class World {
 public:
  /// Validates `config` (throws core::ConfigError) and builds the world. Sensor noise draws from
  /// streams of `rng` named "kinematic/<robot>/<sensor>".
  World(const WorldConfig& config, const core::Rng& rng);
  ~World();
  World(const World&) = delete;
  World& operator=(const World&) = delete;

  const WorldConfig& config() const;
  /// Simulated time: number of steps taken times the physics step.
  core::SimTime time() const;

  /// Advances the world by one physics step (config().physics.step): applies motor commands,
  /// steps Box2D, updates holders, RFID zones and sensors. Returns this step's events.
  const WorldEvents& step();

  // --- robots -------------------------------------------------------------------------------
  int robot_count() const;
  RobotId robot_by_name(std::string_view name) const;  ///< invalid id if unknown
  /// Sets the command that holds until the next call (robot frame, m/s and rad/s).
  void set_command(RobotId robot, const MotorCommand& command);
  /// The true pose of the robot.
  Pose2D robot_pose(RobotId robot) const;
  /// The true velocity (world frame, m/s) and angular velocity (rad/s).
  Vec2 robot_velocity(RobotId robot) const;
  double robot_omega(RobotId robot) const;
  /// The velocity the wheels currently drive (after limits and ramping), robot frame.
  MotorCommand robot_wheel_velocity(RobotId robot) const;
  /// The puck an assisted holder currently keeps, if any.
  std::optional<PuckId> held_puck(RobotId robot) const;
  /// Moves a robot (e.g. back into the insertion area after maintenance); stops it.
  void teleport_robot(RobotId robot, const Pose2D& pose);
  /// The latest sensor readings of a robot.
  const RobotSensors& sensors(RobotId robot) const;

  // --- pucks --------------------------------------------------------------------------------
  /// Ids of the pucks in the world (removed ones are gone), in insertion order.
  std::span<const PuckId> pucks() const;
  bool has_puck(PuckId puck) const;
  Vec2 puck_position(PuckId puck) const;
  /// Appends the positions of the pucks in the world to `out`, in pucks() order (one pass, no
  /// look-ups).
  void puck_positions(std::vector<Vec2>& out) const;
  /// True if the centre of a puck in the world is closer than `distance_m` to `point`
  /// (|position - point| < distance_m; one pass, no look-ups).
  bool any_puck_within(const Vec2& point, double distance_m) const;
  Vec2 puck_velocity(PuckId puck) const;
  /// The device whose RFID zone the puck's centre is in, if any.
  std::optional<DeviceId> puck_zone(PuckId puck) const;
  /// Pucks whose centres are in the device's RFID zone (rarely more than one).
  std::vector<PuckId> pucks_in_zone(DeviceId device) const;
  /// Adds a puck (the referee inserting a late-order S0); the id must be new and > 0. Emits an
  /// entered event on the next step if it lies in a zone.
  void add_puck(PuckId puck, const Vec2& position);
  /// Removes a puck from the field (a delivered product taken away); emits a left event on the
  /// next step if it was in a zone.
  void remove_puck(PuckId puck);
  /// Moves a puck and stops it (referee action).
  void teleport_puck(PuckId puck, const Vec2& position);

  // --- devices ------------------------------------------------------------------------------
  void set_lights(DeviceId device, const SignalLights& lights);
  SignalLights lights(DeviceId device) const;
  /// Every device's lamps, in DeviceId order.
  std::span<const SignalLights, kDeviceCount> all_lights() const;

  /// FNV-1a hash over time, every body's pose and velocity and every robot's odometry state:
  /// equal hashes after equal steps mean equal games.
  std::uint64_t state_hash() const;

  /// Number of Box2D bodies currently awake (for diagnostics and benchmarks).
  int awake_body_count() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace llsf::kinematic
