// SPDX-License-Identifier: MIT
// A holonomic path-following controller: tracks the path polyline (tangent plus cross-track
// correction) with a speed profile that respects the acceleration limit, corners, an optional
// stop point and the goal, and turns the robot to the goal heading on the way.
#pragma once

#include <limits>
#include <vector>

#include "llsf/planner/config.h"
#include "llsf/planner/planner.h"

namespace llsf::planner {

/// A velocity command in the robot frame (x forward, y left), m/s and rad/s.
struct VelocityCommand {
  double vx_mps = 0.0;
  double vy_mps = 0.0;
  double omega_rps = 0.0;
  friend bool operator==(const VelocityCommand&, const VelocityCommand&) = default;
};

/// Follows one path. Copyable value; keeps the last command so that it ramps within limits.
class PathFollower {
 public:
  explicit PathFollower(const ControllerConfig& config);

  /// Starts following `path` from its beginning; the current velocity is kept (ramped from).
  /// `forward`: face along the path and never drive backwards (a robot carrying a puck; the
  /// assisted holder lets go when driven backwards), turning to the goal heading at the end.
  void set_path(Path path, bool forward = false);
  /// set_path with the straight path [from, to] and `goal_theta`, in the memory of the current
  /// path (a back-off step allocates nothing).
  void set_segment(const Vec2& from, const Vec2& to, double goal_theta, bool forward = false);
  bool forward() const { return forward_; }
  const Path& path() const { return path_; }
  bool has_path() const { return !path_.points.empty(); }

  /// One control step of `dt_s` seconds for a robot at `pose`: never drives past arc length
  /// `stop_at_m` (another robot ahead), braking for it as if only `stop_share` of the distance
  /// were there (0.5: the other robot may be coming the other way just as fast); returns the
  /// command.
  VelocityCommand update(const Pose2D& pose, double dt_s,
                         double stop_at_m = std::numeric_limits<double>::infinity(),
                         double stop_share = 1.0);
  /// Ramps the current velocity down within the limits (waiting); returns the command.
  VelocityCommand brake(const Pose2D& pose, double dt_s);

  /// True once the robot is within the position and angle tolerances of the path's end.
  bool arrived() const { return arrived_; }
  /// Arc length of the robot's projection onto the path (monotonic while following).
  double progress_m() const { return s_; }
  /// Path length left from the projection to the goal.
  double remaining_m() const;
  /// The goal heading minus the robot's heading at the last update.
  double heading_error_rad() const { return heading_error_; }
  /// Speed of the last command, m/s.
  double speed_mps() const { return v_world_.norm(); }
  /// The point at arc length `s` (clamped to the path).
  Vec2 point_at(double s) const;
  /// Arc length of each path vertex.
  const std::vector<double>& vertex_arc() const { return cum_; }

 private:
  /// Starts following path_ from its beginning (arc lengths and corner speeds).
  void start(bool forward);
  VelocityCommand output(const Pose2D& pose, const Vec2& v_world_target, double omega_target,
                         double dt_s);
  void project(const Vec2& p);

  ControllerConfig config_;
  Path path_;
  std::vector<double> cum_;           // arc length at each vertex
  std::vector<double> corner_speed_;  // speed allowed at each vertex
  double s_ = 0.0;
  Vec2 v_world_{0.0, 0.0};
  double omega_ = 0.0;
  double heading_error_ = 0.0;
  bool arrived_ = false;
  /// Forward mode near the goal: the goal lies behind, so keep facing along the path (instead of
  /// turning to the goal heading, which would leave only a backward move) until close to it.
  bool face_path_to_goal_ = false;
  bool forward_ = false;
};

}  // namespace llsf::planner
