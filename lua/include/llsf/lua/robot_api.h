// SPDX-License-Identifier: MIT
// The robot as skills see it: the simulated Fawkes blackboard. `sim/` implements it for each
// robot at the scenario's abstraction levels (ground-truth or noisy localization, ground-truth or
// vision light and puck detection); the skill engine only ever talks to this interface.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <string_view>

#include "llsf/core/geometry.h"
#include "llsf/core/sim_time.h"

namespace llsf::lua {

/// The robot's belief of its pose (at the localization abstraction level).
struct PoseEstimate {
  core::Pose2D pose;
  core::SimTime stamp;
  bool valid = false;
};

/// What the navigator is doing.
enum class NavStatus : std::uint8_t {
  kIdle,         ///< no goal given since the last stop
  kRunning,      ///< driving to the goal
  kArrived,      ///< reached the goal within tolerances
  kNoPath,       ///< no path exists
  kInvalidGoal,  ///< unknown place, or a goal inside an obstacle
  kBlocked,      ///< held back by another robot too long
  kStuck,        ///< no progress
  kAborted,      ///< stopped by stop() or a new goal
};

/// The navigator's state; `error` explains failures, `blocked_by` names the blocking robot.
struct NavState {
  NavStatus status = NavStatus::kIdle;
  std::string error;
  std::string blocked_by;
  std::uint64_t goal_id = 0;  ///< increments with every goal
};

/// A lamp as a reader sees it.
enum class Lamp : std::uint8_t { kOff, kOn, kBlink };

/// The signal light of the device the robot faces, as its light detection reports it.
struct LightReading {
  bool visible = false;  ///< a device is in front, within range, and has been read
  std::string device;    ///< "M1", "R2", "D3", ...
  Lamp red = Lamp::kOff;
  Lamp yellow = Lamp::kOff;
  Lamp green = Lamp::kOff;
  core::SimTime stable_since;  ///< time since which the reading has not changed
};

/// A puck seen by the puck detection, in the robot frame (x forward, y left), metres.
struct PuckSighting {
  core::Vec2 position{0.0, 0.0};
};

/// The two digital optical sensors at the holder's arm tips.
struct OpticalSensors {
  bool left = false;
  bool right = false;
};

/// A laser scan in the robot frame: beam i at angle_min_rad + i * angle_increment_rad; +inf =
/// no echo. The span is valid until the robot's next sensor update.
struct LaserView {
  double angle_min_rad = 0.0;
  double angle_increment_rad = 0.0;
  std::span<const float> ranges;
};

/// One robot's interfaces. Implementations are owned by `sim/`; the skill engine borrows one per
/// robot. Calls happen on the simulation thread during the skill cycle.
class RobotApi {
 public:
  virtual ~RobotApi() = default;

  /// Simulated time now (the skill clock).
  virtual core::SimTime now() const = 0;
  /// The robot's name ("robot1", ...).
  virtual std::string_view name() const = 0;

  /// Pose at the localization abstraction level.
  virtual PoseEstimate pose() const = 0;

  /// Navigator: drive to a named place ("M3", "M3_input", "INS_1", ... see docs/planner.md) or
  /// a pose; `forward_only` keeps the holder in front (for carrying a puck). A new goal replaces
  /// the old one. Unknown places end in kInvalidGoal with an error naming the place.
  virtual void goto_place(std::string_view place, bool forward_only) = 0;
  virtual void goto_pose(const core::Pose2D& pose, bool forward_only) = 0;
  virtual NavState navigator() const = 0;
  /// Stops the navigator and the motor (status kAborted if a goal was running).
  virtual void stop() = 0;

  /// Motor: a velocity in the robot frame (m/s, rad/s), held until changed; stops the
  /// navigator. The world applies its speed and acceleration limits.
  virtual void set_velocity(double vx_mps, double vy_mps, double omega_rps) = 0;

  /// Puck holder: the IR sensor's puck detection and distance (m).
  virtual bool puck_in_holder() const = 0;
  virtual double ir_distance_m() const = 0;
  /// The optical side sensors.
  virtual OpticalSensors optical() const = 0;
  /// Light-signal detection of the device in front.
  virtual LightReading light() const = 0;
  /// Puck detection (relative positions), valid until the next sensor update.
  virtual std::span<const PuckSighting> pucks() const = 0;
  /// The latest laser scan.
  virtual LaserView laser() const = 0;
};

}  // namespace llsf::lua
