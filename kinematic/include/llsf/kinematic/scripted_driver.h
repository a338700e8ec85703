// SPDX-License-Identifier: MIT
// A scripted waypoint driver for demos, tests and benchmarks: a holonomic P-controller on the
// true pose. It is not navigation (no planning, no avoidance); that is the planner module's job.
#pragma once

#include <vector>

#include "llsf/kinematic/world.h"

namespace llsf::kinematic {

/// One target of a scripted drive.
struct Waypoint {
  Pose2D pose;
  double max_speed_mps = 1.0;
  double tolerance_m = 0.01;
  double angle_tolerance_rad = 0.02;
};

/// Drives through waypoints in order: translation and rotation at once, slowing down so as to
/// stop at each waypoint within the acceleration limit.
class ScriptedDriver {
 public:
  ScriptedDriver(std::vector<Waypoint> waypoints, const RobotModelConfig& model);

  /// The command for the robot at `pose`; advances to the next waypoint when the current one is
  /// reached. Returns a zero command once done.
  MotorCommand update(const Pose2D& pose);
  bool done() const { return index_ >= static_cast<int>(waypoints_.size()); }
  /// Index of the waypoint being driven to (== size when done).
  int index() const { return index_; }

 private:
  std::vector<Waypoint> waypoints_;
  RobotModelConfig model_;
  int index_ = 0;
};

}  // namespace llsf::kinematic
