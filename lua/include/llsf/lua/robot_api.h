// SPDX-License-Identifier: MIT
// The robot as skills see it: the simulated Fawkes blackboard. `sim/` implements it for each
// robot at the scenario's abstraction levels (ground-truth or noisy localization, ground-truth or
// vision light and puck detection); the skill engine only ever talks to this interface.
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

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

/// A puck seen by the hackathon's flashlight camera, in the robot frame (x forward, y left).
struct ColourPuckSighting {
  core::Vec2 position{0.0, 0.0};  ///< metres
  double distance_m = 0.0;        ///< from the robot centre
  double bearing_rad = 0.0;       ///< atan2(y, x): 0 straight ahead, positive to the left
  std::string colour;             ///< "red", ... (may be wrong: the camera's false-colour rate)
};

/// What a rescue skill knows about the hackathon's task (docs/hackathon.md).
struct RescueInfo {
  core::Vec2 safe_lo{0.0, 0.0};  ///< the safe area [lo, hi] in the field frame, metres
  core::Vec2 safe_hi{0.0, 0.0};
  std::string safe_place;              ///< the navigator place in front of the safe area ("SAFE")
  std::vector<std::string> counted;    ///< colours that score
  std::vector<std::string> decoys;     ///< colours that cost points in the safe area
  double held_puck_offset_m = 0.2225;  ///< robot centre to a held puck's centre
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

/// A named place of the field (docs/planner.md "Places"): where the robot stands and the point
/// it is about (e.g. the RFID zone centre a held puck lands on).
struct PlaceInfo {
  core::Pose2D pose;
  core::Vec2 target{0.0, 0.0};
};

/// Estimated duration of a drive at the symbolic skill level.
struct TravelEstimate {
  bool ok = false;
  double length_m = 0.0;  ///< planned path length
  double seconds = 0.0;   ///< path length over the cruise speed plus turning
  std::string error;      ///< why there is no estimate (no path, invalid goal)
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
  /// The hackathon's colour camera (empty outside the hackathon variant), valid until the next
  /// sensor update.
  virtual std::span<const ColourPuckSighting> colour_pucks() const { return {}; }
  /// The hackathon's task: safe area, its place, the colours; nullptr outside the variant.
  virtual const RescueInfo* rescue() const { return nullptr; }

  /// A named place ("M3", "M3_left", "INS_2", ...); nullopt for unknown names.
  virtual std::optional<PlaceInfo> place(std::string_view name) const = 0;

  // --- Symbolic skill level (docs/skills.md "The symbolic level") ------------------------------
  // Skills at the symbolic level do not drive: they wait an estimated duration and then change
  // the world directly. Requests take effect at the start of the next tick. Robots at the
  // physical level throw std::logic_error from these (the skill fails with that message).

  /// True if this robot runs at the symbolic skill level.
  virtual bool symbolic() const { return false; }
  /// Estimated time to drive from the robot's pose to `goal`.
  virtual TravelEstimate symbolic_travel(const core::Pose2D& goal) const;
  /// Puts the robot at `pose`; a puck it holds comes along.
  virtual void symbolic_move(const core::Pose2D& pose);
  /// Puts the free puck nearest to `point` (within `radius_m`, not held by another robot) into
  /// the holder; puck_in_holder() tells whether there was one.
  virtual void symbolic_pick(const core::Vec2& point, double radius_m);
  /// Lays the held puck down at `point` and lets go of it.
  virtual void symbolic_drop(const core::Vec2& point);
};

inline TravelEstimate RobotApi::symbolic_travel(const core::Pose2D&) const {
  throw std::logic_error("symbolic_travel: the robot does not run at the symbolic skill level");
}
inline void RobotApi::symbolic_move(const core::Pose2D&) {
  throw std::logic_error("symbolic_move: the robot does not run at the symbolic skill level");
}
inline void RobotApi::symbolic_pick(const core::Vec2&, double) {
  throw std::logic_error("symbolic_pick: the robot does not run at the symbolic skill level");
}
inline void RobotApi::symbolic_drop(const core::Vec2&) {
  throw std::logic_error("symbolic_drop: the robot does not run at the symbolic skill level");
}

}  // namespace llsf::lua
