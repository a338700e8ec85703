// SPDX-License-Identifier: MIT
#include "llsf/kinematic/scripted_driver.h"

#include <algorithm>
#include <cmath>

namespace llsf::kinematic {

ScriptedDriver::ScriptedDriver(std::vector<Waypoint> waypoints, const RobotModelConfig& model)
    : waypoints_(std::move(waypoints)), model_(model) {}

MotorCommand ScriptedDriver::update(const Pose2D& pose) {
  while (!done()) {
    const Waypoint& w = waypoints_[index_];
    const Vec2 err = w.pose.position() - pose.position();
    const double dist = err.norm();
    const double dth = core::angle_diff(w.pose.theta, pose.theta);
    if (dist <= w.tolerance_m && std::abs(dth) <= w.angle_tolerance_rad) {
      ++index_;
      continue;
    }
    // Speed that still allows stopping at the waypoint (v^2 = 2 a d), with a small P term
    // for the last centimetres.
    const double a = 0.8 * model_.max_accel_mps2;
    const double v =
        std::min({w.max_speed_mps, model_.max_speed_mps, std::sqrt(2.0 * a * dist), 3.0 * dist});
    const double al = 0.8 * model_.max_alpha_rps2;
    const double om = std::copysign(
        std::min({model_.max_omega_rps, std::sqrt(2.0 * al * std::abs(dth)), 4.0 * std::abs(dth)}),
        dth);
    // Turning while driving rotates the velocity in the robot frame at omega * v, which the
    // wheels can only follow within the acceleration limit: keep the path straight.
    const double v_turn = std::min(v, 0.8 * model_.max_accel_mps2 / std::max(std::abs(om), 1e-6));
    const Vec2 vw = dist > 1e-9 ? Vec2(err * (v_turn / dist)) : Vec2(0.0, 0.0);
    const Vec2 vr = core::rotate(vw, -pose.theta);
    return {vr.x(), vr.y(), om};
  }
  return {};
}

}  // namespace llsf::kinematic
