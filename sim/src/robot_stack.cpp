// SPDX-License-Identifier: MIT
#include "llsf/sim/robot_stack.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include "llsf/core/assert.h"
#include "llsf/core/geometry.h"
#include "llsf/refbox/types.h"

namespace llsf::sim {

namespace {

lua::NavStatus to_api(planner::NavOutcome o) {
  switch (o) {
    case planner::NavOutcome::kIdle:
      return lua::NavStatus::kIdle;
    case planner::NavOutcome::kRunning:
      return lua::NavStatus::kRunning;
    case planner::NavOutcome::kArrived:
      return lua::NavStatus::kArrived;
    case planner::NavOutcome::kNoPath:
      return lua::NavStatus::kNoPath;
    case planner::NavOutcome::kInvalidGoal:
      return lua::NavStatus::kInvalidGoal;
    case planner::NavOutcome::kBlocked:
      return lua::NavStatus::kBlocked;
    case planner::NavOutcome::kStuck:
      return lua::NavStatus::kStuck;
    case planner::NavOutcome::kAborted:
      return lua::NavStatus::kAborted;
  }
  return lua::NavStatus::kIdle;
}

}  // namespace

comm::FrameError RobotRadio::broadcast(const google::protobuf::Message& message) {
  LLSF_DEMAND_MSG(hub_ != nullptr, "the robot stack is not attached to a hub");
  return hub_->broadcast(peer_, message, now_);
}

RobotStack::RobotStack(std::string name, int index, const core::Pose2D& start,
                       const GameConfig& config, planner::Planner& planner,
                       std::vector<std::string> robot_names, std::vector<DeviceView> devices,
                       const core::Rng& rng)
    : name_(std::move(name)),
      index_(index),
      levels_(config.levels),
      robot_names_(std::move(robot_names)),
      devices_(std::move(devices)),
      planner_(&planner),
      nav_(planner, config.controller, rng.stream("planner/" + name_)),
      handling_(config.handling),
      jam_rng_(rng.stream("sim/" + name_ + "/jam")),
      localization_(config.levels.localization, start,
                    rng.stream("sim/" + name_ + "/localization")),
      light_(config.levels.light, devices_, rng.stream("sim/" + name_ + "/light")),
      puck_vision_(config.levels.puck) {
  nav_.set_obstacle_names(robot_names_);  // "held back by robot2"
  if (config.levels.navigation == NavigationLevel::kMoveBase2013) {
    move_base_.emplace(planner, config.levels.move_base);
    laser_mount_ = {config.world.sensors.laser.mount_x_m, config.world.sensors.laser.mount_y_m};
  }
}

// --- actuation -------------------------------------------------------------------------------

kinematic::MotorCommand RobotStack::actuate(SimTime now,
                                            std::span<const planner::DiscObstacle> others) {
  switch (drive_) {
    case Drive::kNavigator: {
      if (move_base_) {
        const bool was_running = move_base_->status().outcome == planner::NavOutcome::kRunning;
        planner::MoveBaseNavigator::Scan scan{scan_origin_, scan_hits_, scan_beams_};
        scan.beams.of_hit = scan_beam_of_hit_;
        const planner::VelocityCommand c = move_base_->update(
            now, localization_.estimate().pose, odom_velocity_, scan_new_ ? &scan : nullptr);
        scan_new_ = false;
        if (was_running) note_nav_end(now);
        note_arrival(now, move_base_->status().outcome);
        return handle({c.vx_mps, c.vy_mps, c.omega_rps}, false);
      }
      const bool was_running = nav_.status().outcome == planner::NavOutcome::kRunning;
      const planner::VelocityCommand c = nav_.update(now, localization_.estimate().pose, others);
      if (was_running) note_nav_end(now);
      note_arrival(now, nav_.status().outcome);
      return handle({c.vx_mps, c.vy_mps, c.omega_rps}, false);
    }
    case Drive::kMotor:
      return handle(velocity_, true);
    case Drive::kIdle:
      break;
  }
  return {};
}

void RobotStack::note_arrival(SimTime now, planner::NavOutcome outcome) {
  if (arrived_at_ || outcome != planner::NavOutcome::kArrived) return;
  // Only the end of a real drive is aligned again (robot profiles): a short push is not.
  const bool drove = (true_pose_.position() - goal_from_).norm() >= handling_.align_min_drive_m;
  arrived_at_ = drove ? now : now - SimTime::from_seconds(handling_.align_s);
}

kinematic::MotorCommand RobotStack::handle(kinematic::MotorCommand c, bool motor) {
  const HandlingConfig& h = handling_;
  if (motor && h.motor_max_speed_mps > 0.0) {
    const double v = std::hypot(c.vx_mps, c.vy_mps);
    if (v > h.motor_max_speed_mps) {
      c.vx_mps *= h.motor_max_speed_mps / v;
      c.vy_mps *= h.motor_max_speed_mps / v;
    }
  }
  if (motor && h.motor_max_omega_rps > 0.0) {
    c.omega_rps = std::clamp(c.omega_rps, -h.motor_max_omega_rps, h.motor_max_omega_rps);
  }
  // A new run of motor commands near a device may jam (one draw per approach, only near one).
  if (motor && motor_started_ && jam_device_ < 0 && h.jam_probability > 0.0) {
    motor_started_ = false;
    int nearest = -1;
    double best = h.jam_zone_m;
    for (std::size_t i = 0; i < devices_.size(); ++i) {
      const double d = (devices_[i].front - true_pose_.position()).norm();
      if (d <= best) {
        best = d;
        nearest = static_cast<int>(i);
      }
    }
    if (nearest >= 0 && jam_rng_.bernoulli(h.jam_probability)) {
      jam_device_ = nearest;
      jammed_since_ = now_;
      ++jams_;
    }
  }
  if (jam_device_ < 0) return c;
  if (h.stuck_detection && now_ >= jammed_since_ + SimTime::from_seconds(h.jam_recovery_s)) {
    jam_device_ = -1;  // the skills' recovery got it free
    return c;
  }
  // Jammed: only a motion away from the device's front gets the robot free.
  const core::Vec2 to_device =
      devices_[static_cast<std::size_t>(jam_device_)].front - true_pose_.position();
  const double cs = std::cos(true_pose_.theta), sn = std::sin(true_pose_.theta);
  const core::Vec2 v_field(cs * c.vx_mps - sn * c.vy_mps, sn * c.vx_mps + cs * c.vy_mps);
  const double n = to_device.norm();
  const double towards = n > 1e-9 ? v_field.dot(to_device) / n : 0.0;
  if (towards < -0.02) {
    jam_device_ = -1;
    return c;
  }
  return {};
}

void RobotStack::goto_place(std::string_view place, bool forward_only) {
  arrived_at_.reset();
  goal_from_ = true_pose_.position();
  goal_place_.assign(place);
  goal_known_ = planner_->place(place) != nullptr;
  if (move_base_) {
    move_base_->go_to_place(place, forward_only);
  } else {
    nav_.go_to_place(place, forward_only);
  }
  drive_ = Drive::kNavigator;
  ++goal_id_;
  note_nav_end(now_);  // an unknown place is refused at once
}

void RobotStack::goto_pose(const core::Pose2D& pose, bool forward_only) {
  arrived_at_.reset();
  goal_from_ = true_pose_.position();
  goal_place_.clear();
  goal_known_ = true;
  if (move_base_) {
    move_base_->go_to(pose, forward_only);
  } else {
    nav_.go_to(pose, forward_only);
  }
  drive_ = Drive::kNavigator;
  ++goal_id_;
}

void RobotStack::note_nav_end(SimTime now) {
  const planner::NavStatus& s = nav_status();
  switch (s.outcome) {
    case planner::NavOutcome::kNoPath:
    case planner::NavOutcome::kInvalidGoal:
    case planner::NavOutcome::kBlocked:
    case planner::NavOutcome::kStuck:
      break;
    default:
      return;
  }
  NavFailure& f =
      nav_failure_ring_[static_cast<std::size_t>(nav_failure_count_ % kNavFailureMemory)];
  f.time = now;
  f.outcome = s.outcome;
  f.message = s.message;
  f.goal = move_base_ ? move_base_->goal() : nav_.goal();
  f.place = goal_place_;
  f.goal_known = goal_known_;
  ++nav_failure_count_;
}

const NavFailure* RobotStack::nav_failure(std::int64_t n) const {
  if (n < 0 || n >= nav_failure_count_ || n < nav_failure_count_ - kNavFailureMemory)
    return nullptr;
  return &nav_failure_ring_[static_cast<std::size_t>(n % kNavFailureMemory)];
}

lua::NavState RobotStack::navigator() const {
  const planner::NavStatus& s = nav_status();
  lua::NavState out;
  out.status = to_api(s.outcome);
  // The fine alignment after an arrival (robot profiles): still running until it is done.
  if (s.outcome == planner::NavOutcome::kArrived && handling_.align_s > 0.0 &&
      (!arrived_at_ || now_ < *arrived_at_ + SimTime::from_seconds(handling_.align_s))) {
    out.status = lua::NavStatus::kRunning;
  }
  out.error = s.message;
  if (s.blocked_by >= 0 && s.blocked_by < static_cast<int>(robot_names_.size())) {
    out.blocked_by = robot_names_[static_cast<std::size_t>(s.blocked_by)];
  }
  out.goal_id = goal_id_;
  return out;
}

void RobotStack::nav_abort() {
  if (move_base_) {
    move_base_->abort();
  } else if (nav_.status().outcome == planner::NavOutcome::kRunning) {
    nav_.abort();
  }
}

void RobotStack::stop() {
  nav_abort();
  drive_ = Drive::kIdle;
  velocity_ = {};
}

void RobotStack::set_velocity(double vx_mps, double vy_mps, double omega_rps) {
  nav_abort();
  if (drive_ != Drive::kMotor) motor_started_ = true;
  drive_ = Drive::kMotor;
  velocity_ = {vx_mps, vy_mps, omega_rps};
}

std::optional<lua::PlaceInfo> RobotStack::place(std::string_view name) const {
  const planner::Place* p = planner_->place(name);
  if (p == nullptr) return std::nullopt;
  return lua::PlaceInfo{p->pose, p->target};
}

// --- symbolic skill level --------------------------------------------------------------------

namespace {
void require_symbolic(bool symbolic, const char* what) {
  if (!symbolic) {
    throw std::logic_error(std::string(what) +
                           ": the robot does not run at the symbolic skill level");
  }
}
}  // namespace

lua::TravelEstimate RobotStack::symbolic_travel(const core::Pose2D& goal) const {
  require_symbolic(symbolic(), "symbolic_travel");
  planner::PlanRequest req;
  req.start = localization_.estimate().pose;
  req.goal = goal;
  req.seed = ++travel_queries_;
  const planner::PlanResult r = planner_->plan(req);
  lua::TravelEstimate out;
  if (r.status != planner::PlanStatus::kFound) {
    out.error = std::string(planner::to_string(r.status)) + ": " + r.message;
    return out;
  }
  out.ok = true;
  out.length_m = r.path.length_m();
  // Turning: along the path's segments, and to the goal heading at the end.
  double turn = 0.0;
  double heading = localization_.estimate().pose.theta;
  const auto& pts = r.path.points;
  for (std::size_t i = 1; i < pts.size(); ++i) {
    const core::Vec2 d = pts[i] - pts[i - 1];
    if (d.norm() < 1e-6) continue;
    const double h = std::atan2(d.y(), d.x());
    turn += std::abs(core::angle_diff(h, heading));
    heading = h;
  }
  turn += std::abs(core::angle_diff(goal.theta, heading));
  out.seconds =
      out.length_m / levels_.symbolic.cruise_speed_mps + turn / levels_.symbolic.turn_rate_rps;
  return out;
}

void RobotStack::symbolic_move(const core::Pose2D& pose) {
  require_symbolic(symbolic(), "symbolic_move");
  stop();
  SymbolicRequest r;
  r.kind = SymbolicRequest::Kind::kMove;
  r.pose = pose;
  symbolic_requests_.push_back(r);
}

void RobotStack::on_teleported(const core::Pose2D& from, const core::Pose2D& to) {
  localization_.teleported(from, to);
}

void RobotStack::symbolic_pick(const core::Vec2& point, double radius_m) {
  require_symbolic(symbolic(), "symbolic_pick");
  SymbolicRequest r;
  r.kind = SymbolicRequest::Kind::kPick;
  r.point = point;
  r.radius_m = radius_m;
  symbolic_requests_.push_back(r);
}

void RobotStack::symbolic_drop(const core::Vec2& point) {
  require_symbolic(symbolic(), "symbolic_drop");
  SymbolicRequest r;
  r.kind = SymbolicRequest::Kind::kDrop;
  r.point = point;
  symbolic_requests_.push_back(r);
}

// --- sensing ---------------------------------------------------------------------------------

void RobotStack::sense(const RobotPercept& p) {
  LLSF_ASSERT(p.sensors != nullptr);
  now_ = p.now;
  radio_.set_time(p.now);
  true_pose_ = p.true_pose;
  const kinematic::RobotSensors& s = *p.sensors;
  puck_in_holder_ = s.ir.puck_detected;
  ir_distance_m_ = s.ir.distance_m;
  optical_ = {s.optical.left, s.optical.right};
  laser_ = {s.laser.angle_min_rad, s.laser.angle_increment_rad, s.laser.ranges};
  localization_.update(p.now, p.true_pose, s.odometry);
  if (move_base_) {
    odom_velocity_ = {s.odometry.vx_mps, s.odometry.vy_mps, s.odometry.omega_rps};
    if (s.laser.seq != laser_seq_) {
      // A new scan: its hits in field coordinates at the pose the robot believes it has.
      laser_seq_ = s.laser.seq;
      const core::Pose2D est = localization_.estimate().pose;
      scan_origin_ = est.to_parent(laser_mount_);
      scan_hits_.clear();
      scan_beam_of_hit_.clear();
      const std::size_t n = s.laser.ranges.size();
      if (beam_dirs_.size() != n) {
        // The beams' directions in the robot frame, once (the scan's geometry is fixed).
        beam_dirs_.resize(n);
        for (std::size_t i = 0; i < n; ++i) {
          const double a =
              s.laser.angle_min_rad + static_cast<double>(i) * s.laser.angle_increment_rad;
          beam_dirs_[i] = {std::cos(a), std::sin(a)};
        }
      }
      const double c = std::cos(est.theta), sn = std::sin(est.theta);
      for (std::size_t i = 0; i < n; ++i) {
        const float r = s.laser.ranges[i];
        if (!std::isfinite(r)) continue;
        const core::Vec2& d = beam_dirs_[i];
        scan_hits_.emplace_back(scan_origin_.x() + r * (c * d.x() - sn * d.y()),
                                scan_origin_.y() + r * (sn * d.x() + c * d.y()));
        scan_beam_of_hit_.push_back(static_cast<int>(i));
      }
      scan_beams_ = {
          est.theta + s.laser.angle_min_rad, s.laser.angle_increment_rad, static_cast<int>(n), {}};
      scan_new_ = true;
    }
  }
  light_.update(p.now, p.true_pose, p.lights);
  puck_vision_.update(p.now, p.true_pose, p.pucks);
}

}  // namespace llsf::sim
