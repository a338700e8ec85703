// SPDX-License-Identifier: MIT
// Path following: tangent tracking with cross-track correction along the polyline, a speed
// profile (acceleration limit, corner speeds, stop point, goal), heading control within the
// budget that turning while driving leaves, and ramped output.
#include "llsf/planner/path_follower.h"

#include <algorithm>
#include <cmath>

#include "llsf/core/assert.h"

namespace llsf::planner {

namespace {
constexpr double kCrossTrackGain = 2.0;  // 1/s: pulls the robot back onto the path
constexpr double kGoalGain = 2.0;        // 1/s: final P approach (v = k d near the goal)
constexpr double kTurnGain = 3.0;        // 1/s: heading P term near the goal heading
constexpr double kProjectWindow = 0.6;   // m of path searched ahead of the last projection
constexpr double kCornerHold = 0.1;      // m past a corner still driven at its speed
constexpr double kFinalTurn = 0.3;    // m before the goal: forward mode turns to the goal heading
constexpr double kForwardCone = 1.2;  // rad: forward mode turns on the spot beyond this
}  // namespace

PathFollower::PathFollower(const ControllerConfig& config) : config_(config) {}

void PathFollower::set_path(Path path, bool forward) {
  LLSF_DEMAND(path.points.size() >= 2);
  path_ = std::move(path);
  start(forward);
}

void PathFollower::set_segment(const Vec2& from, const Vec2& to, double goal_theta, bool forward) {
  path_.points.clear();
  path_.points.push_back(from);
  path_.points.push_back(to);
  path_.goal_theta = goal_theta;
  start(forward);
}

void PathFollower::start(bool forward) {
  forward_ = forward;
  const auto& pts = path_.points;
  const int n = static_cast<int>(pts.size());
  cum_.assign(n, 0.0);
  for (int i = 1; i < n; ++i) cum_[i] = cum_[i - 1] + (pts[i] - pts[i - 1]).norm();
  // Corner speeds: driving round a corner of deflection phi with the usable acceleration
  // a deviates a velocity-ramping robot by about v^2 sin(phi) sin(phi/2) / a to the outside.
  const double a = config_.accel_fraction * config_.max_accel_mps2;
  corner_speed_.assign(n, config_.max_speed_mps);
  corner_speed_[n - 1] = 0.0;
  for (int i = 1; i + 1 < n; ++i) {
    const Vec2 u1 = pts[i] - pts[i - 1], u2 = pts[i + 1] - pts[i];
    if (u1.norm() < 1e-9 || u2.norm() < 1e-9) continue;
    const double cos_phi = std::clamp(u1.normalized().dot(u2.normalized()), -1.0, 1.0);
    const double phi = std::acos(cos_phi);
    const double k = std::sin(std::min(phi, 0.5 * core::kPi)) * std::sin(0.5 * phi);
    if (k > 1e-9) {
      corner_speed_[i] =
          std::min(config_.max_speed_mps, std::sqrt(config_.corner_deviation_m * a / k));
    }
  }
  s_ = 0.0;
  arrived_ = false;
  face_path_to_goal_ = false;
}

double PathFollower::remaining_m() const { return cum_.empty() ? 0.0 : cum_.back() - s_; }

Vec2 PathFollower::point_at(double s) const {
  const auto& pts = path_.points;
  if (s <= 0.0) return pts.front();
  for (std::size_t i = 1; i < pts.size(); ++i) {
    if (s <= cum_[i]) {
      const double seg = cum_[i] - cum_[i - 1];
      const double t = seg > 0.0 ? (s - cum_[i - 1]) / seg : 1.0;
      return pts[i - 1] + t * (pts[i] - pts[i - 1]);
    }
  }
  return pts.back();
}

void PathFollower::project(const Vec2& p) {
  // The nearest point on the path within a window ahead of the last projection; progress
  // never goes back.
  const auto& pts = path_.points;
  double best_d = std::numeric_limits<double>::infinity();
  double best_s = s_;
  for (std::size_t i = 1; i < pts.size(); ++i) {
    if (cum_[i] < s_) continue;
    if (cum_[i - 1] > s_ + kProjectWindow) break;
    const Vec2 a = pts[i - 1], d = pts[i] - pts[i - 1];
    const double len2 = d.squaredNorm();
    double t = len2 > 0.0 ? std::clamp((p - a).dot(d) / len2, 0.0, 1.0) : 0.0;
    const double s = cum_[i - 1] + t * (cum_[i] - cum_[i - 1]);
    if (s < s_) t = (s_ - cum_[i - 1]) / std::max(cum_[i] - cum_[i - 1], 1e-12);
    const double dist = (a + t * d - p).norm();
    if (dist < best_d - 1e-12) {
      best_d = dist;
      best_s = std::max(s_, cum_[i - 1] + t * (cum_[i] - cum_[i - 1]));
    }
  }
  s_ = best_s;
}

VelocityCommand PathFollower::output(const Pose2D& pose, const Vec2& v_target, double omega_target,
                                     double dt) {
  // Ramp the world-frame velocity within what is left after the turning budget.
  const double a = (1.0 - config_.turn_accel_fraction) * config_.max_accel_mps2;
  Vec2 dv = v_target - v_world_;
  const double max_dv = a * dt;
  if (dv.norm() > max_dv) dv *= max_dv / dv.norm();
  v_world_ += dv;
  const double max_dw = config_.max_alpha_rps2 * dt;
  omega_ += std::clamp(omega_target - omega_, -max_dw, max_dw);
  Vec2 vr = core::rotate(v_world_, -pose.theta);
  if (forward_ && vr.x() < 0.0) {
    // Never command backwards in forward mode; keep the velocity state consistent.
    vr.x() = 0.0;
    v_world_ = core::rotate(vr, pose.theta);
  }
  return {vr.x(), vr.y(), omega_};
}

VelocityCommand PathFollower::update(const Pose2D& pose, double dt, double stop_at_m,
                                     double stop_share) {
  if (!has_path()) return brake(pose, dt);
  const Vec2 p = pose.position();
  project(p);
  const Vec2 goal = path_.points.back();
  const double to_goal = (goal - p).norm();
  heading_error_ = core::angle_diff(path_.goal_theta, pose.theta);
  if (arrived_ || (to_goal <= config_.position_tolerance_m &&
                   std::abs(heading_error_) <= config_.angle_tolerance_rad)) {
    arrived_ = true;
    return brake(pose, dt);
  }

  // Speed: the limit, the corners ahead, the stop point and the goal, each reachable with
  // the usable deceleration.
  const double a = config_.accel_fraction * config_.max_accel_mps2;
  double v = config_.max_speed_mps;
  for (std::size_t i = 1; i < cum_.size(); ++i) {
    // A corner's speed holds until kCornerHold past it, so that the velocity has turned
    // before the robot speeds up again (else it swings out).
    if (cum_[i] + kCornerHold <= s_) continue;
    const double before = std::max(cum_[i] - s_, 0.0);
    v = std::min(v, std::sqrt(corner_speed_[i] * corner_speed_[i] + 2.0 * a * before));
  }
  const double stop_left = stop_at_m - s_;
  v = std::min(v, stop_left > 0.0 ? std::sqrt(2.0 * a * stop_share * stop_left) : 0.0);
  const double remaining = std::max(cum_.back() - s_, to_goal);
  v = std::min(v, kGoalGain * remaining);

  // Direction: the path tangent plus a pull back onto the path; near the goal straight at it.
  Vec2 dir;
  const double seg_len = 0.05;
  const Vec2 here = point_at(s_);
  const Vec2 ahead = point_at(s_ + seg_len);
  if (cum_.back() - s_ < seg_len || (ahead - here).norm() < 1e-9) {
    dir = to_goal > 1e-9 ? Vec2((goal - p) / to_goal) : Vec2(0.0, 0.0);
    v = std::min(v, kGoalGain * to_goal);
  } else {
    const Vec2 tangent = (ahead - here).normalized();
    dir = tangent * 1.0 + (here - p) * (kCrossTrackGain / std::max(v, 0.1));
    if (dir.norm() > 1e-9) dir.normalize();
  }
  if (stop_left <= 0.0) v = 0.0;

  // Heading: towards the goal heading -- or, driving forwards, along the path until the last
  // kFinalTurn metres -- within the rotation limits and the budget that turning while driving
  // leaves: omega * v <= turn_accel_fraction * a_max.
  double e = heading_error_;
  if (forward_ && dir.norm() > 1e-9 && cum_.back() - s_ <= kFinalTurn && !face_path_to_goal_ &&
      to_goal > config_.position_tolerance_m && dir.dot(core::unit(pose.theta)) < -0.2) {
    // The goal lies behind within the final-turn zone (e.g. a short move back from a machine
    // with a puck): turning to the goal heading first would leave only a backward move, which
    // forward mode forbids. Face along the path until the goal is reached.
    face_path_to_goal_ = true;
  }
  if (face_path_to_goal_ && to_goal <= config_.position_tolerance_m) face_path_to_goal_ = false;
  if (forward_ && dir.norm() > 1e-9 && (cum_.back() - s_ > kFinalTurn || face_path_to_goal_)) {
    // Face along the path; never backwards (an assisted holder lets its puck go): turn on
    // the spot first, then drive with the forward share of the direction only. In the last
    // kFinalTurn metres the robot turns to the goal heading and output() only cuts any
    // backward part of the command.
    e = core::angle_diff(std::atan2(dir.y(), dir.x()), pose.theta);
    const double off = std::abs(e);
    v = off > kForwardCone ? 0.0 : v * std::cos(off);
  }
  const double al = config_.accel_fraction * config_.max_alpha_rps2;
  double om =
      std::min({config_.max_omega_rps, std::sqrt(2.0 * al * std::abs(e)), kTurnGain * std::abs(e)});
  const double speed = std::max(v_world_.norm(), v);
  if (speed > 1e-6) {
    om = std::min(om, config_.turn_accel_fraction * config_.max_accel_mps2 / speed);
  }
  return output(pose, dir * v, std::copysign(om, e), dt);
}

VelocityCommand PathFollower::brake(const Pose2D& pose, double dt) {
  return output(pose, Vec2(0.0, 0.0), 0.0, dt);
}

}  // namespace llsf::planner
