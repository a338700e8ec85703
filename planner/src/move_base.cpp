// SPDX-License-Identifier: MIT
// The move_base-2013 navigation level (docs/planner.md, "move_base-2013"): the state machine of
// ROS move_base, a navfn-style global planner and a TrajectoryPlannerROS-style rollout
// controller, each written from the behaviour ROS navigation (groovy, 2013) documents.
#include "llsf/planner/move_base.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <queue>
#include <utility>

#include "llsf/core/config.h"
#include "llsf/core/error.h"
#include "llsf/core/geometry.h"

namespace llsf::planner {

using core::SimTime;

namespace {

double sign(double v) { return v < 0.0 ? -1.0 : 1.0; }

// One velocity component ramped towards `target` within `acc` over `dt`.
double ramp(double target, double current, double acc, double dt) {
  if (target >= current) return std::min(target, current + acc * dt);
  return std::max(target, current - acc * dt);
}

}  // namespace

void MoveBaseConfig::validate() const {
  const std::string p = "move_base.";
  core::require(p + "robot_radius_m", robot_radius_m, core::positive());
  core::require(p + "inflation_radius_m", inflation_radius_m, core::at_least(robot_radius_m));
  core::require(p + "inflation_radius_m", inflation_radius_m, core::at_most(2.0));
  core::require(p + "cost_scaling_factor", cost_scaling_factor, core::non_negative());
  core::require(p + "obstacle_range_m", obstacle_range_m, core::positive());
  core::require(p + "raytrace_range_m", raytrace_range_m, core::positive());
  core::require(p + "local_size_m", local_size_m, core::in_range(0.5, 20.0));
  core::require(p + "local_resolution_m", local_resolution_m, core::in_range(0.01, 0.5));
  core::require(p + "global_resolution_m", global_resolution_m, core::in_range(0.01, 0.5));
  core::require(p + "local_update_hz", local_update_hz, core::in_range(0.1, 100.0));
  core::require(p + "global_update_hz", global_update_hz, core::in_range(0.1, 100.0));
  core::require(p + "max_vel_x", max_vel_x, core::positive());
  core::require(p + "min_vel_x", min_vel_x, core::in_range(0.0, max_vel_x));
  core::require(p + "max_rotational_vel", max_rotational_vel, core::positive());
  core::require(p + "min_in_place_rotational_vel", min_in_place_rotational_vel,
                core::in_range(0.0, max_rotational_vel));
  core::require(p + "acc_lim_x", acc_lim_x, core::positive());
  core::require(p + "acc_lim_y", acc_lim_y, core::positive());
  core::require(p + "acc_lim_th", acc_lim_th, core::positive());
  core::require(p + "xy_goal_tolerance_m", xy_goal_tolerance_m, core::positive());
  core::require(p + "yaw_goal_tolerance_rad", yaw_goal_tolerance_rad, core::positive());
  core::require(p + "sim_time_s", sim_time_s, core::in_range(0.1, 10.0));
  core::require(p + "sim_granularity_m", sim_granularity_m, core::in_range(0.001, 0.5));
  core::require(p + "vx_samples", vx_samples, core::in_range(2, 50));
  core::require(p + "vtheta_samples", vtheta_samples, core::in_range(2, 100));
  core::require(p + "controller_frequency_hz", controller_frequency_hz, core::in_range(1.0, 100.0));
  core::require(p + "planner_patience_s", planner_patience_s, core::non_negative());
  core::require(p + "controller_patience_s", controller_patience_s, core::non_negative());
  core::require(p + "navgraph_direct_m", navgraph_direct_m, core::non_negative());
  core::require(p + "approach_speed_mps", approach_speed_mps, core::positive());
  core::require(p + "depart_speed_mps", depart_speed_mps, core::positive());
  core::require(p + "motor_omega_rps", motor_omega_rps, core::positive());
  core::require(p + "motor_gain_xy", motor_gain_xy, core::positive());
  core::require(p + "motor_gain_th", motor_gain_th, core::positive());
  core::require(p + "motor_min_speed_mps", motor_min_speed_mps, core::non_negative());
  core::require(p + "motor_min_omega_rps", motor_min_omega_rps, core::non_negative());
  core::require(p + "depart_tolerance_m", depart_tolerance_m, core::positive());
  core::require(p + "depart_angle_tolerance_rad", depart_angle_tolerance_rad, core::positive());
  core::require(p + "approach_tolerance_m", approach_tolerance_m, core::positive());
  core::require(p + "approach_angle_tolerance_rad", approach_angle_tolerance_rad, core::positive());
}

double MoveBaseConfig::standoff_m() const {
  const double cell = std::max(local_resolution_m, global_resolution_m);
  return std::ceil(robot_radius_m / cell - 1e-9) * cell + 2.0 * cell;
}

const char* to_string(MoveBaseState state) {
  switch (state) {
    case MoveBaseState::kIdle:
      return "idle";
    case MoveBaseState::kPlanning:
      return "planning";
    case MoveBaseState::kControlling:
      return "controlling";
    case MoveBaseState::kClearing:
      return "clearing";
    case MoveBaseState::kApproach:
      return "approach";
    case MoveBaseState::kDepart:
      return "depart";
    case MoveBaseState::kAborted:
      return "aborted";
  }
  return "?";
}

MoveBaseNavigator::MoveBaseNavigator(const Planner& planner, MoveBaseConfig config)
    : planner_(&planner), config_(config) {
  config_.validate();
  const FieldMap& f = planner.field();
  const double r = config_.global_resolution_m;
  global_ = Costmap(Vec2(0.0, 0.0), static_cast<int>(std::ceil(f.width_m / r - 1e-9)),
                    static_cast<int>(std::ceil(f.height_m / r - 1e-9)), r, config_);
  global_.set_static(planner);
  const int n =
      std::max(1, static_cast<int>(std::lround(config_.local_size_m / config_.local_resolution_m)));
  local_ = Costmap(Vec2(0.0, 0.0), n, n, config_.local_resolution_m, config_);
  grid_w_ = n + 2;
  const std::size_t cells = static_cast<std::size_t>(n + 2) * static_cast<std::size_t>(n + 2);
  path_dist_.assign(cells, 0);
  goal_dist_.assign(cells, 0);
  grid_init_.assign(cells, 0);
  queue_.assign(cells, 0);
  unreachable_ = n * n;
}

void MoveBaseNavigator::go_to(const Pose2D& goal, bool forward) {
  // move_base knew nothing of a held puck; `forward` only makes the departure turn and drive
  // forwards, as leave_IS did (docs/planner.md).
  forward_ = forward;
  goal_ = goal;
  status_ = {NavOutcome::kRunning, -1, {}};
  stats_ = {};
  plan_ = {};
  prune_from_ = 0;
  // A goal move_base cannot reach (inside the inscribed radius of a static obstacle, e.g. a
  // pose at a machine's reader): drive to the nearest pose back along the goal heading that
  // the static costmap allows, then approach in a straight line.
  base_goal_ = goal;
  needs_approach_ = false;
  const Vec2 back(-std::cos(goal.theta), -std::sin(goal.theta));
  auto clear = [&](const Vec2& p) {
    return planner_->clearance(p).distance_m >= config_.standoff_m();
  };
  if (!clear(goal.position())) {
    // The first pose back along the heading at the standoff. Where two obstacles leave less
    // room on that line (M4's input faces M3 across 0.92 m, M10's faces M7's side across
    // 0.87 m), the pose of most clearance on it, on either side of the goal, as long as the
    // line stays out of the obstacles.
    const double step = 0.01;
    Vec2 best = goal.position();
    double best_clearance = planner_->clearance(best).distance_m;
    bool found = false;
    for (double d = step; d <= 1.5; d += step) {
      const Vec2 p = goal.position() + back * d;
      const double c = planner_->clearance(p).distance_m;
      if (c >= config_.standoff_m()) {
        best = p;
        found = true;
        break;
      }
      if (c <= 0.0 || c < best_clearance - 0.1) break;  // past the room between the obstacles
      if (c > best_clearance) {
        best_clearance = c;
        best = p;
      }
    }
    for (double d = step; !found && d <= 1.5; d += step) {
      const Vec2 p = goal.position() - back * d;
      const double c = planner_->clearance(p).distance_m;
      if (c <= 0.0 || c < best_clearance - 0.1) break;  // towards the machine ahead
      if (c >= config_.standoff_m()) {
        best = p;
        break;
      }
      if (c > best_clearance) {
        best_clearance = c;
        best = p;
      }
    }
    base_goal_ = Pose2D{best.x(), best.y(), goal.theta};
    needs_approach_ = true;
  }
  final_goal_ = base_goal_;
  final_needs_approach_ = needs_approach_;
  route_.clear();
  route_next_ = 0;
  route_built_ = false;
  target_reached_ = false;
  state_ = MoveBaseState::kPlanning;
  depart_checked_ = false;
  rotating_ = false;
  escaping_ = false;
  stuck_left_ = stuck_right_ = stuck_left_strafe_ = stuck_right_strafe_ = false;
  rotating_left_ = rotating_right_ = strafe_left_ = strafe_right_ = false;
  new_goal(has_last_update_ ? last_update_ : SimTime());
}

void MoveBaseNavigator::new_goal(SimTime now) {
  // move_base's executeCb on a new goal: the recovery sequence and the patience timers start
  // over, the controller plans afresh.
  trigger_ = Trigger::kPlanning;
  recovery_index_ = 0;
  last_valid_plan_ = now;
  last_valid_control_ = now;
  rotating_to_goal_ = false;
  next_control_ = now;
}

void MoveBaseNavigator::go_to_place(std::string_view name, bool forward) {
  const Place* p = planner_->place(name);
  if (p == nullptr) {
    goal_ = {};
    state_ = MoveBaseState::kIdle;
    status_ = {NavOutcome::kInvalidGoal, -1, "unknown place '" + std::string(name) + "'"};
    return;
  }
  go_to(p->pose, forward);
}

void MoveBaseNavigator::abort() {
  if (status_.outcome == NavOutcome::kRunning) finish(NavOutcome::kAborted, "aborted");
}

void MoveBaseNavigator::finish(NavOutcome outcome, std::string message) {
  status_ = {outcome, -1, std::move(message)};
  state_ = MoveBaseState::kIdle;
  command_ = {};
  rotating_ = false;
  totals_.plans += stats_.plans;
  totals_.plan_failures += stats_.plan_failures;
  totals_.control_failures += stats_.control_failures;
  totals_.escapes += stats_.escapes;
  totals_.waypoints += stats_.waypoints;
  totals_.resends += stats_.resends;
  totals_.aborts += stats_.aborts;
  totals_.recoveries += stats_.recoveries;
  totals_.rotate_recoveries += stats_.rotate_recoveries;
  totals_.recovery_s += stats_.recovery_s;
  totals_.stopped_s += stats_.stopped_s;
}

// --- the update ----------------------------------------------------------------------------

VelocityCommand MoveBaseNavigator::update(SimTime now, const Pose2D& pose,
                                          const VelocityCommand& velocity, const Scan* scan) {
  const double dt = has_last_update_ ? (now - last_update_).seconds() : 0.0;
  last_update_ = now;
  has_last_update_ = true;
  if (scan != nullptr) {
    scan_hits_.assign(scan->hits.begin(), scan->hits.end());
    scan_beam_of_hit_.assign(scan->beams.of_hit.begin(), scan->beams.of_hit.end());
    scan_beams_ = scan->beams;
    scan_beams_.of_hit = {};
    scan_origin_ = scan->origin;
    scan_for_local_ = scan_for_global_ = true;
  }
  const bool active = state_ != MoveBaseState::kIdle;
  // shutdown_costmaps: the costmaps are updated only while move_base has a goal.
  if ((active && state_ != MoveBaseState::kAborted) || !config_.shutdown_costmaps) {
    if (now >= next_local_) {
      next_local_ = now + SimTime::period_of_hz(config_.local_update_hz);
      local_.recenter(pose.position());
      if (scan_for_local_) {
        local_.update(scan_origin_, scan_hits_, scan_beams(), pose.position(),
                      config_.robot_radius_m);
      } else {
        local_.clear_footprint(pose.position(), config_.robot_radius_m);
      }
      scan_for_local_ = false;
    }
    if (now >= next_global_) {
      next_global_ = now + SimTime::period_of_hz(config_.global_update_hz);
      if (scan_for_global_) {
        global_.update(scan_origin_, scan_hits_, scan_beams(), pose.position(),
                       config_.robot_radius_m);
      } else {
        global_.clear_footprint(pose.position(), config_.robot_radius_m);
      }
      scan_for_global_ = false;
    }
  }
  if (!active) return {};
  add_stats(dt);
  if (state_ == MoveBaseState::kPlanning && !depart_checked_) {
    // Inside a static obstacle's inscribed radius: first straight out to the nearest free point
    // (16 directions, the one behind the robot first, as leave_area backs off).
    depart_checked_ = true;
    auto clear = [&](const Vec2& p) {
      return planner_->clearance(p).distance_m >= config_.standoff_m();
    };
    if (!clear(pose.position())) {
      const double step = 0.01;
      bool found = false;
      // Where no point within reach has the standoff (between M10 and M7's side, 0.87 m
      // apart), the point of most clearance, if it gains at least a cell of the local map.
      double best_clearance =
          planner_->clearance(pose.position()).distance_m + config_.local_resolution_m;
      Pose2D best;
      bool better = false;
      for (double d = step; d <= config_.depart_max_m && !found; d += step) {
        for (int k = 0; k < 16 && !found; ++k) {
          // Straight back, then alternately 22.5 degrees more to either side.
          const double ang =
              pose.theta + core::kPi + ((k + 1) / 2) * (core::kPi / 8.0) * (k % 2 ? 1 : -1);
          const Vec2 p = pose.position() + Vec2(std::cos(ang), std::sin(ang)) * d;
          const double c = planner_->clearance(p).distance_m;
          const Pose2D to{p.x(), p.y(), forward_ ? core::normalize_angle(ang) : pose.theta};
          if (c >= config_.standoff_m()) {
            depart_to_ = to;
            found = true;
          } else if (c > best_clearance) {
            best_clearance = c;
            best = to;
            better = true;
          }
        }
      }
      if (!found && better) {
        depart_to_ = best;
        found = true;
      }
      if (found) state_ = MoveBaseState::kDepart;
    }
  }
  if (state_ == MoveBaseState::kPlanning && !route_built_) build_route(now, pose);
  if (!route_.empty() && route_step(now, pose)) return command_;
  if (state_ == MoveBaseState::kAborted) {
    command_ = {};
    return command_;
  }
  if (state_ == MoveBaseState::kDepart) {
    bool arrived = false;
    const double turn = core::angle_diff(depart_to_.theta, pose.theta);
    if (forward_ && std::abs(turn) > config_.depart_angle_tolerance_rad) {
      // Carrying a puck: turn towards the way out first (leave_IS: TURN, then MOTOR_MOVE).
      command_ =
          straight_to(pose, Pose2D{pose.x, pose.y, depart_to_.theta}, config_.depart_speed_mps,
                      config_.depart_tolerance_m, config_.depart_angle_tolerance_rad, arrived);
      return command_;
    }
    command_ = straight_to(pose, depart_to_, config_.depart_speed_mps, config_.depart_tolerance_m,
                           config_.depart_angle_tolerance_rad, arrived);
    if (arrived) {
      state_ = MoveBaseState::kPlanning;
      last_valid_plan_ = now;
      last_valid_control_ = now;
      next_control_ = now;
    }
    return command_;
  }
  if (state_ == MoveBaseState::kApproach) {
    command_ = approach(pose);
    return command_;
  }
  if (state_ == MoveBaseState::kClearing && rotating_) {
    command_ = run_recovery(now, pose);
    return command_;
  }
  if (now < next_control_) return command_;
  next_control_ = now + SimTime::period_of_hz(config_.controller_frequency_hz);

  switch (state_) {
    case MoveBaseState::kPlanning: {
      command_ = {};
      if (make_plan(pose)) {
        state_ = MoveBaseState::kControlling;
        last_valid_plan_ = now;
        if (trigger_ == Trigger::kPlanning) recovery_index_ = 0;
      } else if (now > last_valid_plan_ + SimTime::from_seconds(config_.planner_patience_s)) {
        state_ = MoveBaseState::kClearing;
        trigger_ = Trigger::kPlanning;
        start_recovery(now, pose);
      }
      break;
    }
    case MoveBaseState::kControlling: {
      // Goal reached: within both tolerances and stopped.
      const Vec2 to_goal = base_goal_.position() - pose.position();
      const bool stopped = std::hypot(velocity.vx_mps, velocity.vy_mps) <= config_.stopped_vel &&
                           std::abs(velocity.omega_rps) <= config_.stopped_vel;
      if (to_goal.norm() <= config_.xy_goal_tolerance_m &&
          std::abs(core::angle_diff(base_goal_.theta, pose.theta)) <=
              config_.yaw_goal_tolerance_rad &&
          stopped) {
        if (!route_.empty()) {
          route_done(pose);  // move_base arrived: final for the navgraph
        } else if (needs_approach_) {
          state_ = MoveBaseState::kApproach;
          command_ = approach(pose);
        } else {
          finish(NavOutcome::kArrived, {});
        }
        break;
      }
      VelocityCommand cmd;
      if (compute_velocity(pose, velocity, cmd)) {
        last_valid_control_ = now;
        command_ = cmd;
        if (trigger_ == Trigger::kControlling) recovery_index_ = 0;
      } else {
        ++stats_.control_failures;
        command_ = {};
        if (now > last_valid_control_ + SimTime::from_seconds(config_.controller_patience_s)) {
          state_ = MoveBaseState::kClearing;
          trigger_ = Trigger::kControlling;
          start_recovery(now, pose);
        } else {
          last_valid_plan_ = now;
          state_ = MoveBaseState::kPlanning;
        }
      }
      break;
    }
    case MoveBaseState::kClearing:
      start_recovery(now, pose);
      break;
    case MoveBaseState::kIdle:
    case MoveBaseState::kApproach:
    case MoveBaseState::kDepart:
    case MoveBaseState::kAborted:
      break;
  }
  return command_;
}

void MoveBaseNavigator::add_stats(double dt) {
  if (state_ == MoveBaseState::kClearing) stats_.recovery_s += dt;
  if (command_ == VelocityCommand{}) stats_.stopped_s += dt;
}

// --- recovery behaviours -------------------------------------------------------------------

void MoveBaseNavigator::start_recovery(SimTime now, const Pose2D& pose) {
  command_ = {};
  // The default sequence: conservative reset, rotation, aggressive reset, rotation.
  const int count = config_.clearing_rotation_allowed ? 4 : 2;
  if (!config_.recovery_behavior_enabled || recovery_index_ >= count) {
    give_up(trigger_ == Trigger::kPlanning ? NavOutcome::kNoPath : NavOutcome::kStuck,
            trigger_ == Trigger::kPlanning
                ? "move_base: failed to find a valid plan, even after executing recovery behaviors"
                : "move_base: failed to find a valid control, even after executing recovery "
                  "behaviors");
    return;
  }
  ++stats_.recoveries;
  const int behaviour = config_.clearing_rotation_allowed ? recovery_index_ : recovery_index_ * 2;
  ++recovery_index_;
  switch (behaviour) {
    case 0:  // conservative reset
    case 2:  // aggressive reset
    {
      const double size =
          behaviour == 0 ? config_.conservative_reset_dist_m : 4.0 * config_.circumscribed_radius_m;
      global_.reset_outside(pose.position(), size);
      local_.reset_outside(pose.position(), size);
      state_ = MoveBaseState::kPlanning;
      next_control_ = now;
      break;
    }
    default: {  // rotate in place, a full turn
      ++stats_.rotate_recoveries;
      rotating_ = true;
      rotate_start_offset_ = -core::normalize_angle(pose.theta);
      rotate_got_180_ = false;
      break;
    }
  }
}

bool MoveBaseNavigator::rotation_free(const Pose2D& pose) const {
  // A circular footprint: every heading at this position costs the same.
  return local_.cost_at(pose.position(), false) < Costmap::kInscribed;
}

VelocityCommand MoveBaseNavigator::run_recovery(SimTime now, const Pose2D& pose) {
  const double current =
      core::normalize_angle(core::normalize_angle(pose.theta) + rotate_start_offset_);
  const double left = core::kPi - current;
  auto done = [&] {
    rotating_ = false;
    state_ = MoveBaseState::kPlanning;
    next_control_ = now;
    return VelocityCommand{};
  };
  if (!rotation_free(pose)) return done();
  if (current < 0.0) rotate_got_180_ = true;
  if (rotate_got_180_ && current >= -config_.yaw_goal_tolerance_rad) return done();
  double vel = std::sqrt(2.0 * config_.acc_lim_th * left);
  vel = std::clamp(vel, config_.min_in_place_rotational_vel, config_.max_rotational_vel);
  return {0.0, 0.0, vel};
}

// --- the final approach --------------------------------------------------------------------

VelocityCommand MoveBaseNavigator::approach(const Pose2D& pose) {
  bool arrived = false;
  Pose2D target = goal_;
  if (forward_) {
    // Carrying a puck, the straight move never backs off (the holder would lose the puck):
    // a goal behind the approach pose -- where the pose of most clearance lies beyond it, as
    // a pre-pose of M10's input facing M7 -- is reached by turning to its heading where the
    // robot stands.
    const Vec2 heading(std::cos(goal_.theta), std::sin(goal_.theta));
    if ((goal_.position() - pose.position()).dot(heading) < 0.0) {
      target = Pose2D{pose.x, pose.y, goal_.theta};
    }
  }
  const VelocityCommand c =
      straight_to(pose, target, config_.approach_speed_mps, config_.approach_tolerance_m,
                  config_.approach_angle_tolerance_rad, arrived);
  if (arrived) finish(NavOutcome::kArrived, {});
  return c;
}

VelocityCommand MoveBaseNavigator::straight_to(const Pose2D& pose, const Pose2D& target,
                                               double speed, double tolerance_m,
                                               double tolerance_rad, bool& arrived) const {
  // motor_move: each axis of the robot frame on its own, no obstacle check, no timeout.
  const Vec2 d = core::rotate(target.position() - pose.position(), -pose.theta);
  const double dth = core::angle_diff(target.theta, pose.theta);
  const MoveBaseConfig& c = config_;
  auto axis = [](double left, double tolerance, double gain, double lo, double hi) {
    if (std::abs(left) <= tolerance) return 0.0;
    return sign(left) * std::min(hi, std::max(lo, gain * std::abs(left)));
  };
  // Each axis stops within tolerance / sqrt(2) (motor_move's per-axis box, sized so that the
  // move ends within `tolerance_m` of where its caller asked).
  const double box = tolerance_m / std::sqrt(2.0);
  const VelocityCommand v{
      axis(d.x(), box, c.motor_gain_xy, c.motor_min_speed_mps, speed),
      axis(d.y(), box, c.motor_gain_xy, c.motor_min_speed_mps, speed),
      axis(dth, tolerance_rad, c.motor_gain_th, c.motor_min_omega_rps, c.motor_omega_rps)};
  const bool at = v.vx_mps == 0.0 && v.vy_mps == 0.0;
  arrived = at && std::abs(dth) <= tolerance_rad;
  return v;
}

// --- ppgoto along the team's navigation graph ----------------------------------------------

namespace {

// The corridor nodes of the Carologistics' 2013 navigation graph and their connections
// (carologistics/fawkes-robotino 6cffc15f2, cfg/navgraph-llsf.yaml: positions, travel_tolerance
// and the `connections` among these nodes). Left out: the nodes at devices (M1..M10, ExpM*,
// R1, R2, T, Ins, deliver: goals, reached here by the approach) and the agent's waiting spots
// (WAIT_FOR_INS, WAIT_FOR_DELIVER, reached by directed detours only).
struct GraphNode {
  const char* name;
  double x, y, tolerance;
};
constexpr GraphNode kGraphNodes[] = {
    {"P11", 1.0, 1.1, 0.5},  {"P12", 1.0, 2.15, 0.4}, {"P13", 1.0, 3.4, 0.4},
    {"P14", 1.0, 4.4, 0.5},  {"P21", 2.2, 1.1, 0.5},  {"P22", 2.2, 2.15, 0.4},
    {"P23", 2.2, 3.4, 0.4},  {"P24", 2.2, 4.4, 0.5},  {"P31", 3.4, 1.1, 0.5},
    {"P32", 3.4, 2.15, 0.5}, {"P33", 3.4, 3.4, 0.5},  {"P34", 3.4, 4.4, 0.5},
    {"P41", 4.7, 1.1, 0.5},  {"P42", 4.7, 2.15, 0.5}, {"P43", 4.7, 3.4, 0.5},
    {"P44", 4.7, 4.4, 0.5},  {"IA", 1.0, 2.8, 0.8},   {"M9W", 1.0, 3.9, 0.5},
    {"M9N", 1.68, 4.4, 0.5}, {"M8E", 2.2, 1.65, 0.5}, {"M4S", 2.75, 1.1, 0.5},
    {"M6W", 2.2, 3.85, 0.5}, {"M6S", 2.75, 3.4, 0.5}, {"M6N", 2.75, 4.4, 0.5},
    {"M1S", 3.9, 1.1, 0.5},  {"M5E", 3.4, 2.8, 0.5},  {"M2W", 3.4, 3.92, 0.5},
    {"M1E", 4.7, 1.7, 0.5},  {"M2O", 4.7, 3.92, 0.5}, {"DW", 4.7, 3.1, 0.5},
    {"M3E", 3.4, 0.55, 0.5}, {"M7E", 3.4, 5.05, 0.5}, {"SR1", 0.4, 0.5, 0.5},
    {"SR2", 0.4, 1.75, 0.5},
};
constexpr std::pair<const char*, const char*> kGraphEdges[] = {
    {"P11", "P21"}, {"P11", "P12"}, {"P11", "SR1"}, {"P12", "SR2"}, {"P12", "IA"},  {"IA", "P13"},
    {"P12", "P22"}, {"IA", "P23"},  {"P13", "M9W"}, {"M9W", "P14"}, {"P13", "P23"}, {"IA", "P22"},
    {"P14", "M9N"}, {"M9N", "P24"}, {"P21", "M8E"}, {"M8E", "P22"}, {"P21", "M4S"}, {"M4S", "P31"},
    {"P31", "M3E"}, {"P22", "P32"}, {"P22", "P23"}, {"P23", "M6W"}, {"M6W", "P24"}, {"P23", "M6S"},
    {"M6S", "P33"}, {"P24", "M6N"}, {"M6N", "P34"}, {"P34", "M7E"}, {"P31", "P32"}, {"P31", "M1S"},
    {"M1S", "P41"}, {"P32", "P42"}, {"P32", "M5E"}, {"M5E", "P33"}, {"P33", "M2W"}, {"M2W", "P34"},
    {"P33", "P43"}, {"P43", "M2O"}, {"M2O", "P44"}, {"P34", "P44"}, {"P41", "M1E"}, {"M1E", "P42"},
    {"P42", "DW"},  {"DW", "P43"},  {"P32", "DW"},  {"P33", "DW"},
};
constexpr std::size_t kGraphSize = std::size(kGraphNodes);

std::size_t graph_index(const char* name) {
  for (std::size_t i = 0; i < kGraphSize; ++i) {
    if (std::string_view(kGraphNodes[i].name) == name) return i;
  }
  return kGraphSize;
}

// The connections by node index, resolved from the names once.
using GraphEdge = std::pair<std::size_t, std::size_t>;
const std::array<GraphEdge, std::size(kGraphEdges)>& graph_edges() {
  static const auto edges = [] {
    std::array<GraphEdge, std::size(kGraphEdges)> e{};
    for (std::size_t k = 0; k < e.size(); ++k) {
      e[k] = {graph_index(kGraphEdges[k].first), graph_index(kGraphEdges[k].second)};
    }
    return e;
  }();
  return edges;
}

std::size_t closest_node(const Vec2& p) {
  std::size_t best = 0;
  double best_d = std::numeric_limits<double>::max();
  for (std::size_t i = 0; i < kGraphSize; ++i) {
    const double d = std::hypot(kGraphNodes[i].x - p.x(), kGraphNodes[i].y - p.y());
    if (d < best_d) {
      best_d = d;
      best = i;
    }
  }
  return best;
}

}  // namespace

void MoveBaseNavigator::build_route(SimTime now, const Pose2D& pose) {
  // Fawkes' navgraph, a cartesian goto: A* from the node closest to the robot to the node
  // closest to the target, then the target itself ("free-target", the target's heading);
  // optimize_plan drops the first node when it does not lie on the way (the angle robot --
  // node -- next node at most 90 degrees).
  route_built_ = true;
  route_.clear();
  route_next_ = 0;
  if (!config_.navgraph) return;
  if ((final_goal_.position() - pose.position()).norm() < config_.navgraph_direct_m) return;
  const std::size_t from = closest_node(pose.position());
  const std::size_t to = closest_node(final_goal_.position());
  std::array<double, kGraphSize> dist{};
  std::array<std::size_t, kGraphSize> prev{};
  std::array<bool, kGraphSize> done{};
  dist.fill(std::numeric_limits<double>::infinity());
  prev.fill(kGraphSize);
  dist[to] = 0.0;  // from the goal, so that prev leads towards it
  for (std::size_t round = 0; round < kGraphSize; ++round) {
    std::size_t u = kGraphSize;
    for (std::size_t i = 0; i < kGraphSize; ++i) {
      if (!done[i] && std::isfinite(dist[i]) && (u == kGraphSize || dist[i] < dist[u])) u = i;
    }
    if (u == kGraphSize || u == from) break;
    done[u] = true;
    for (const auto& [ia, ib] : graph_edges()) {
      const std::size_t v = ia == u ? ib : ib == u ? ia : kGraphSize;
      if (v == kGraphSize || done[v]) continue;
      const double d = dist[u] + std::hypot(kGraphNodes[u].x - kGraphNodes[v].x,
                                            kGraphNodes[u].y - kGraphNodes[v].y);
      if (d < dist[v]) {
        dist[v] = d;
        prev[v] = u;
      }
    }
  }
  if (!std::isfinite(dist[from])) return;
  for (std::size_t i = from; i != kGraphSize; i = prev[i]) {
    route_.push_back({Pose2D{kGraphNodes[i].x, kGraphNodes[i].y, 0.0}, kGraphNodes[i].tolerance});
  }
  route_.push_back({final_goal_, config_.navgraph_target_tolerance_m});
  const auto sq = [](const Vec2& a, const Vec2& b) { return (a - b).squaredNorm(); };
  if (route_.size() > 1 && sq(pose.position(), route_[0].pose.position()) +
                                   sq(route_[0].pose.position(), route_[1].pose.position()) >=
                               sq(pose.position(), route_[1].pose.position())) {
    route_.erase(route_.begin());
  }
  send_goal(now, pose);
}

void MoveBaseNavigator::send_goal(SimTime now, const Pose2D& pose) {
  // send_next_goal: a node faces the way from where the robot stands; the target keeps its
  // heading. move_base takes it as a new goal: it plans at once, its timers and its recovery
  // sequence start over (a rotation under way ends first: move_base runs it to its end).
  const Waypoint& w = route_[route_next_];
  const bool last = route_next_ + 1 == route_.size();
  if (last) {
    base_goal_ = final_goal_;
    needs_approach_ = final_needs_approach_;
  } else {
    const Vec2 d = w.pose.position() - pose.position();
    base_goal_ = Pose2D{w.pose.x, w.pose.y, std::atan2(d.y(), d.x())};
    needs_approach_ = false;
  }
  sent_at_ = now;
  new_goal(now);
  // Under way, the new plan is made at once and the robot keeps its speed until the next
  // controller cycle (move_base publishes nothing while it plans).
  const bool under_way = state_ == MoveBaseState::kControlling;
  state_ = under_way && make_plan(pose) ? MoveBaseState::kControlling : MoveBaseState::kPlanning;
}

bool MoveBaseNavigator::route_step(SimTime now, const Pose2D& pose) {
  // The navgraph's loop (every step). Returns true if it ended the navigation.
  if (state_ == MoveBaseState::kDepart || state_ == MoveBaseState::kApproach ||
      state_ == MoveBaseState::kIdle) {
    return false;
  }
  if (target_reached_) {
    // Reached the target: move_base goes on until it is final or target_time passed.
    if (now - target_reached_at_ >= SimTime::from_seconds(config_.navgraph_target_time_s) ||
        state_ == MoveBaseState::kAborted) {
      route_done(pose);
      return true;
    }
    return false;
  }
  const Waypoint& w = route_[route_next_];
  const bool last = route_next_ + 1 == route_.size();
  const double dist = (w.pose.position() - pose.position()).norm();
  const bool reached =
      last ? dist <= w.tolerance && std::abs(core::angle_diff(w.pose.theta, pose.theta)) <=
                                        config_.navgraph_orientation_tolerance_rad
           : dist <= w.tolerance;
  if (reached) {
    if (last) {
      target_reached_ = true;
      target_reached_at_ = now;
      if (state_ == MoveBaseState::kAborted) {
        route_done(pose);
        return true;
      }
      return false;
    }
    ++route_next_;
    ++stats_.waypoints;
    send_goal(now, pose);
    return false;
  }
  if (now - sent_at_ > SimTime::from_seconds(config_.navgraph_resend_interval_s) &&
      !(state_ == MoveBaseState::kClearing && rotating_)) {
    ++stats_.resends;
    send_goal(now, pose);
  }
  return false;
}

void MoveBaseNavigator::route_done(const Pose2D& pose) {
  // The navgraph is final: it stops the motion; the skill's straight move follows if needed.
  route_.clear();
  target_reached_ = false;
  base_goal_ = final_goal_;
  needs_approach_ = final_needs_approach_;
  if (needs_approach_) {
    state_ = MoveBaseState::kApproach;
    command_ = approach(pose);
  } else {
    finish(NavOutcome::kArrived, {});
  }
}

void MoveBaseNavigator::give_up(NavOutcome outcome, std::string message) {
  // move_base aborts. Following the navgraph, that is no failure: the robot stands until the
  // navgraph sends the goal again (or, past the target, the navgraph is final).
  if (!route_.empty()) {
    ++stats_.aborts;
    state_ = MoveBaseState::kAborted;
    command_ = {};
    rotating_ = false;
    return;
  }
  finish(outcome, std::move(message));
}

// --- the global planner (navfn) ------------------------------------------------------------

bool MoveBaseNavigator::make_plan(const Pose2D& pose) {
  // Dijkstra over the inflated global costmap from the goal, each cell costing navfn's
  // neutral cost 50 plus 0.8 x its cost; inscribed and lethal cells are impassable, the
  // robot's own cell is cleared. The path descends the potential from the start cell.
  const Costmap& m = global_;
  const int nx = m.nx(), ny = m.ny();
  int si = 0, sj = 0, gi = 0, gj = 0;
  plan_ = {};
  if (!m.to_cell(pose.position(), si, sj) || !m.to_cell(base_goal_.position(), gi, gj)) {
    ++stats_.plan_failures;
    return false;
  }
  const std::size_t n = static_cast<std::size_t>(nx) * static_cast<std::size_t>(ny);
  const float kInf = std::numeric_limits<float>::infinity();
  potential_.assign(n, kInf);
  done_.assign(n, 0);
  auto index = [nx](int i, int j) {
    return static_cast<std::size_t>(j) * static_cast<std::size_t>(nx) + static_cast<std::size_t>(i);
  };
  auto passable = [&](int i, int j) {
    return (i == si && j == sj) || m.cost(i, j) < Costmap::kInscribed;
  };
  if (!passable(gi, gj)) {
    ++stats_.plan_failures;
    return false;
  }
  // The potential reaches the start only through a passable 4-neighbour: a robot inside the
  // inscribed cells has none, and there is no plan (the search below would find none after
  // exploring every cell it can reach).
  constexpr int kDi4[4] = {1, -1, 0, 0};
  constexpr int kDj4[4] = {0, 0, 1, -1};
  bool start_open = si == gi && sj == gj;
  for (int e = 0; e < 4 && !start_open; ++e) {
    const int a = si + kDi4[e], b = sj + kDj4[e];
    start_open = a >= 0 && b >= 0 && a < nx && b < ny && passable(a, b);
  }
  if (!start_open) {
    ++stats_.plan_failures;
    return false;
  }
  // The open list, smallest potential first and among equal ones the smallest cell index: one
  // 64-bit key, the potential's bits above the index (a non-negative float's bits order as the
  // float does).
  auto key = [](float p, std::size_t k) {
    return (static_cast<std::uint64_t>(std::bit_cast<std::uint32_t>(p)) << 32) |
           static_cast<std::uint64_t>(k);
  };
  std::priority_queue<std::uint64_t, std::vector<std::uint64_t>, std::greater<>> open;
  potential_[index(gi, gj)] = 0.0f;
  open.push(key(0.0f, index(gi, gj)));
  const std::size_t start = index(si, sj);
  while (!open.empty()) {
    const std::uint64_t top = open.top();
    open.pop();
    const float p = std::bit_cast<float>(static_cast<std::uint32_t>(top >> 32));
    const std::size_t k = static_cast<std::size_t>(top & 0xffffffffu);
    if (done_[k] != 0) continue;
    done_[k] = 1;
    if (k == start) break;
    const int i = static_cast<int>(k % static_cast<std::size_t>(nx));
    const int j = static_cast<int>(k / static_cast<std::size_t>(nx));
    for (int e = 0; e < 4; ++e) {
      const int a = i + kDi4[e], b = j + kDj4[e];
      if (a < 0 || b < 0 || a >= nx || b >= ny || !passable(a, b)) continue;
      const std::size_t kk = index(a, b);
      const float c = p + 50.0f + 0.8f * static_cast<float>(m.cost(a, b));
      if (c < potential_[kk]) {
        potential_[kk] = c;
        open.push(key(c, kk));
      }
    }
  }
  if (!std::isfinite(potential_[start])) {
    ++stats_.plan_failures;
    return false;
  }
  // Descend: from the start, always to the 8-neighbour of least potential.
  plan_.points.push_back(pose.position());
  int i = si, j = sj;
  for (std::size_t guard = 0; guard < n && !(i == gi && j == gj); ++guard) {
    int bi = i, bj = j;
    float best = potential_[index(i, j)];
    for (int dj = -1; dj <= 1; ++dj) {
      for (int di = -1; di <= 1; ++di) {
        const int a = i + di, b = j + dj;
        if ((di == 0 && dj == 0) || a < 0 || b < 0 || a >= nx || b >= ny) continue;
        const float q = potential_[index(a, b)];
        if (q < best) {
          best = q;
          bi = a;
          bj = b;
        }
      }
    }
    if (bi == i && bj == j) break;
    i = bi;
    j = bj;
    plan_.points.push_back(m.cell_center(i, j));
  }
  plan_.points.push_back(base_goal_.position());
  plan_.goal_theta = base_goal_.theta;
  prune_from_ = 0;
  ++stats_.plans;
  return true;
}

// --- the local planner (TrajectoryPlannerROS) ----------------------------------------------

void MoveBaseNavigator::update_grids(const Pose2D& pose) {
  // Path and goal distances on the local costmap (cells, 4-connected), as base_local_planner's
  // MapGrid: from every plan cell inside the window, and from the last one (the local goal).
  // A cell the search reaches is its distance, or `obstacle` when it is inscribed or lethal; a
  // cell it never reaches is `unknown`.
  const Costmap& m = local_;
  const int nx = m.nx(), ny = m.ny();
  const int obstacle = unreachable_;
  const int unknown = unreachable_ + 1;
  // Before a search: free cells unknown, blocked cells `blocked` (an obstacle once reached, else
  // unknown), the frame `obstacle` (never entered, never read).
  const int blocked = unreachable_ + 2;
  const int w = grid_w_;
  std::fill(grid_init_.begin(), grid_init_.end(), obstacle);
  for (int j = 0; j < ny; ++j) {
    int* row = grid_init_.data() + grid_index(0, j);
    for (int i = 0; i < nx; ++i) row[i] = m.cost(i, j) >= Costmap::kInscribed ? blocked : unknown;
  }
  path_dist_ = grid_init_;
  goal_dist_ = grid_init_;
  // Prune: plan points more than 1 m from the robot at the plan's start are passed.
  const std::vector<Vec2>& pts = plan_.points;
  while (prune_from_ + 1 < pts.size() && (pts[prune_from_] - pose.position()).squaredNorm() > 1.0) {
    ++prune_from_;
  }
  // Breadth-first from the queue's first `tail` cells; the frame needs no bounds checks.
  int* queue = queue_.data();
  auto bfs = [&](std::vector<int>& dist, std::size_t tail) {
    int* g = dist.data();
    for (std::size_t head = 0; head < tail; ++head) {
      const std::ptrdiff_t k = queue[head];
      const int d = g[k] + 1;
      auto visit = [&](std::ptrdiff_t kk) {
        int& n = g[kk];
        if (n == unknown) {
          n = d;
          queue[tail++] = static_cast<int>(kk);
        } else if (n == blocked) {
          n = obstacle;
        }
      };
      visit(k + 1);
      visit(k - 1);
      visit(k + w);
      visit(k - w);
    }
    for (int j = 0; j < ny; ++j) {
      int* row = g + grid_index(0, j);
      for (int i = 0; i < nx; ++i) {
        if (row[i] == blocked) row[i] = unknown;
      }
    }
  };
  // The plan at the local map's resolution: points at most one cell apart.
  std::size_t tail = 0;
  bool started = false;
  int last_i = -1, last_j = -1;
  for (std::size_t s = prune_from_; s < pts.size(); ++s) {
    const Vec2 a = pts[s];
    const Vec2 b = s + 1 < pts.size() ? pts[s + 1] : pts[s];
    const int steps = std::max(1, static_cast<int>(std::ceil((b - a).norm() / m.resolution())));
    bool left = false;
    for (int t = 0; t < steps; ++t) {
      const Vec2 p = a + (b - a) * (static_cast<double>(t) / steps);
      int i = 0, j = 0;
      if (!m.to_cell(p, i, j)) {
        if (started) left = true;
        if (left) break;
        continue;
      }
      started = true;
      const std::size_t k = grid_index(i, j);
      if (path_dist_[k] != 0) {
        path_dist_[k] = 0;
        queue[tail++] = static_cast<int>(k);
      }
      last_i = i;
      last_j = j;
    }
    if (left) break;
  }
  bfs(path_dist_, tail);
  tail = 0;
  if (last_i >= 0) {
    goal_dist_[grid_index(last_i, last_j)] = 0;
    queue[tail++] = static_cast<int>(grid_index(last_i, last_j));
  }
  bfs(goal_dist_, tail);
}

MoveBaseNavigator::TrigRun& MoveBaseNavigator::trig_run(const Pose2D& pose,
                                                        const VelocityCommand& vel, double vth_s,
                                                        int steps) const {
  const auto theta_bits = std::bit_cast<std::uint64_t>(pose.theta);
  const auto omega_bits = std::bit_cast<std::uint64_t>(vel.omega_rps);
  if (trig_used_ == 0 || trig_used_ >= 256 || theta_bits != trig_theta_bits_ ||
      omega_bits != trig_omega_bits_) {
    trig_used_ = 0;
    trig_theta_bits_ = theta_bits;
    trig_omega_bits_ = omega_bits;
    trig_cos0_ = std::cos(pose.theta);
    trig_sin0_ = std::sin(pose.theta);
  }
  const auto vth_bits = std::bit_cast<std::uint64_t>(vth_s);
  for (std::size_t n = 0; n < trig_used_; ++n) {
    TrigRun& r = trig_runs_[n];
    if (r.vth_s_bits == vth_bits && r.steps == steps) return r;
  }
  if (trig_used_ == trig_runs_.size()) trig_runs_.emplace_back();
  TrigRun& r = trig_runs_[trig_used_++];
  r.vth_s_bits = vth_bits;
  r.steps = steps;
  r.cos_th.clear();
  r.sin_th.clear();
  return r;
}

void MoveBaseNavigator::generate(const Pose2D& pose, const VelocityCommand& vel, double vx_s,
                                 double vy_s, double vth_s, Traj& t) const {
  const MoveBaseConfig& c = config_;
  const Costmap& m = local_;
  const double vmag = std::hypot(vx_s, vy_s);
  int steps = static_cast<int>(
      std::max(vmag * c.sim_time_s / c.sim_granularity_m, std::abs(vth_s) / c.sim_granularity_m) +
      0.5);
  if (steps == 0) steps = 1;
  const double dt = c.sim_time_s / steps;
  double x = pose.x, y = pose.y, th = pose.theta;
  double vx = vel.vx_mps, vy = vel.vy_mps, vth = vel.omega_rps;
  t.vx = vx_s;
  t.vy = vy_s;
  t.vth = vth_s;
  t.cost = -1.0;
  double occ = 0.0;
  int path_d = 0, goal_d = 0;
  TrigRun& run = trig_run(pose, vel, vth_s, steps);
  double trig_th = th, cos_th = trig_cos0_, sin_th = trig_sin0_;
  // (Figures in locals: the stores below could alias members.)
  const double acc_x = c.acc_lim_x, acc_y = c.acc_lim_y, acc_th = c.acc_lim_th;
  const double ox = m.origin().x(), oy = m.origin().y(), res = m.resolution();
  const int nx = m.nx(), ny = m.ny(), w = grid_w_, unreachable = unreachable_;
  const std::uint8_t* costs = m.cost_data();
  const int* path_dist = path_dist_.data();
  const int* goal_dist = goal_dist_.data();
  double end_x = t.end_x, end_y = t.end_y, end_th = t.end_th;
  for (int s = 0; s < steps; ++s) {
    // m.to_cell(Vec2(x, y), i, j), m.cost(i, j), grid_index(i, j)
    const double fx = (x - ox) / res;
    const double fy = (y - oy) / res;
    if (!(fx >= 0.0 && fy >= 0.0)) break;  // off the known map
    const int i = static_cast<int>(fx), j = static_cast<int>(fy);
    if (i >= nx || j >= ny) break;
    const std::uint8_t cost = costs[static_cast<std::size_t>(j) * static_cast<std::size_t>(nx) +
                                    static_cast<std::size_t>(i)];
    if (cost >= Costmap::kInscribed) break;  // the footprint hits an obstacle
    occ = std::max(occ, static_cast<double>(cost));
    const std::size_t k = static_cast<std::size_t>(j + 1) * static_cast<std::size_t>(w) +
                          static_cast<std::size_t>(i + 1);
    path_d = path_dist[k];
    goal_d = goal_dist[k];
    if (path_d >= unreachable || goal_d >= unreachable) {
      t.cost = -2.0;  // no clear way to the goal from here
      break;
    }
    end_x = x;
    end_y = y;
    end_th = th;
    vx = ramp(vx_s, vx, acc_x, dt);
    vy = ramp(vy_s, vy, acc_y, dt);
    vth = ramp(vth_s, vth, acc_th, dt);
    const auto step = static_cast<std::size_t>(s);
    if (step < run.cos_th.size() && !std::isnan(run.cos_th[step])) {
      cos_th = run.cos_th[step];  // this heading's values, from an earlier sample
      sin_th = run.sin_th[step];
      trig_th = th;
    } else if (vx == 0.0 && vy == 0.0) {
      // Standing (an in-place rotation once the ramp reached 0): x and y do not move, whatever
      // the heading's values; none are computed (NaN: unknown, for a later sample).
      if (step == run.cos_th.size()) {
        run.cos_th.push_back(std::numeric_limits<double>::quiet_NaN());
        run.sin_th.push_back(std::numeric_limits<double>::quiet_NaN());
      }
    } else {
      if (th != trig_th) {  // the same values, computed once per heading
        cos_th = std::cos(th);
        sin_th = std::sin(th);
        trig_th = th;
      }
      if (step < run.cos_th.size()) {
        run.cos_th[step] = cos_th;
        run.sin_th[step] = sin_th;
      } else {
        run.cos_th.push_back(cos_th);
        run.sin_th.push_back(sin_th);
      }
    }
    x += (vx * cos_th - vy * sin_th) * dt;
    y += (vx * sin_th + vy * cos_th) * dt;
    th += vth * dt;
    if (s + 1 == steps) {
      t.end_x = end_x;
      t.end_y = end_y;
      t.end_th = end_th;
      t.cost =
          c.path_distance_bias * path_d + c.goal_distance_bias * goal_d + c.occdist_scale * occ;
      return;
    }
  }
  t.end_x = end_x;  // stopped early: where the rollout got to
  t.end_y = end_y;
  t.end_th = end_th;
}

MoveBaseNavigator::Traj MoveBaseNavigator::create_trajectories(const Pose2D& pose,
                                                               const VelocityCommand& vel) {
  const MoveBaseConfig& c = config_;
  const double period = 1.0 / c.controller_frequency_hz;
  double max_vx = c.max_vel_x;
  const double final_dist = (base_goal_.position() - pose.position()).norm();
  max_vx = std::min(max_vx, final_dist / c.sim_time_s);
  // The dynamic window: what the accelerations allow within one controller period.
  max_vx = std::max(std::min(max_vx, vel.vx_mps + c.acc_lim_x * period), c.min_vel_x);
  const double min_vx = std::max(c.min_vel_x, vel.vx_mps - c.acc_lim_x * period);
  const double max_vth = std::min(c.max_rotational_vel, vel.omega_rps + c.acc_lim_th * period);
  const double min_vth = std::max(-c.max_rotational_vel, vel.omega_rps - c.acc_lim_th * period);
  const double dvx = (max_vx - min_vx) / (c.vx_samples - 1);
  const double dvth = (max_vth - min_vth) / (c.vtheta_samples - 1);

  Traj best;
  Traj comp;
  auto take_if_better = [&](bool or_equal) {
    if (comp.cost >= 0 &&
        (best.cost < 0 || comp.cost < best.cost || (or_equal && comp.cost <= best.cost))) {
      std::swap(best, comp);
    }
  };
  if (!escaping_) {
    double vx = min_vx;
    for (int a = 0; a < c.vx_samples; ++a) {
      generate(pose, vel, vx, 0.0, 0.0, comp);
      take_if_better(false);
      double vth = min_vth;
      for (int b = 0; b < c.vtheta_samples - 1; ++b) {
        generate(pose, vel, vx, 0.0, vth, comp);
        take_if_better(false);
        vth += dvth;
      }
      vx += dvx;
    }
    // Holonomic: forward with a slight strafe either way.
    generate(pose, vel, 0.1, 0.1, 0.0, comp);
    take_if_better(false);
    generate(pose, vel, 0.1, -0.1, 0.0, comp);
    take_if_better(false);
  }
  // Rotations in place, towards open space (the heading that looks nearest the goal).
  auto ahead_goal_dist = [&](const Traj& t) {
    const Vec2 p(t.end_x + c.heading_lookahead_m * std::cos(t.end_th),
                 t.end_y + c.heading_lookahead_m * std::sin(t.end_th));
    int i = 0, j = 0;
    if (!local_.to_cell(p, i, j)) return -1;
    return goal_dist_[grid_index(i, j)];
  };
  double heading_dist = std::numeric_limits<double>::max();
  double vth = min_vth;
  for (int b = 0; b < c.vtheta_samples; ++b) {
    const double limited = vth > 0 ? std::max(vth, c.min_in_place_rotational_vel)
                                   : std::min(vth, -c.min_in_place_rotational_vel);
    generate(pose, vel, 0.0, 0.0, limited, comp);
    if (comp.cost >= 0 && (comp.cost <= best.cost || best.cost < 0 || best.vy != 0.0) &&
        (vth > dvth || vth < -dvth)) {
      const int g = ahead_goal_dist(comp);
      if (g >= 0 && g < heading_dist) {
        if ((vth < 0 && !stuck_left_) || (vth > 0 && !stuck_right_)) {
          std::swap(best, comp);
          heading_dist = g;
        }
      }
    }
    vth += dvth;
  }
  auto note_oscillation = [&] {
    if (!(best.vx > 0)) {
      if (best.vth < 0) {
        if (rotating_right_) stuck_right_ = true;
        rotating_left_ = true;
      } else if (best.vth > 0) {
        if (rotating_left_) stuck_left_ = true;
        rotating_right_ = true;
      } else if (best.vy > 0) {
        if (strafe_right_) stuck_right_strafe_ = true;
        strafe_left_ = true;
      } else if (best.vy < 0) {
        if (strafe_left_) stuck_left_strafe_ = true;
        strafe_right_ = true;
      }
      prev_x_ = pose.x;
      prev_y_ = pose.y;
    }
  };
  auto reset_oscillation = [&] {
    if (std::hypot(pose.x - prev_x_, pose.y - prev_y_) > c.oscillation_reset_dist_m) {
      rotating_left_ = rotating_right_ = strafe_left_ = strafe_right_ = false;
      stuck_left_ = stuck_right_ = stuck_left_strafe_ = stuck_right_strafe_ = false;
    }
  };
  auto reset_escape = [&] {
    if (std::hypot(pose.x - escape_x_, pose.y - escape_y_) > c.escape_reset_dist_m ||
        std::abs(core::angle_diff(escape_th_, pose.theta)) > c.escape_reset_theta_rad) {
      escaping_ = false;
    }
  };
  if (best.cost >= 0) {
    note_oscillation();
    reset_oscillation();
    reset_escape();
    return best;
  }
  // Holonomic: sideways.
  for (const double vy : {-0.3, -0.1, 0.1, 0.3}) {
    generate(pose, vel, 0.0, vy, 0.0, comp);
    if (comp.cost >= 0 && (comp.cost <= best.cost || best.cost < 0)) {
      const int g = ahead_goal_dist(comp);
      if (g >= 0 && g < heading_dist) {
        if ((vy > 0 && !stuck_left_strafe_) || (vy < 0 && !stuck_right_strafe_)) {
          std::swap(best, comp);
          heading_dist = g;
        }
      }
    }
  }
  if (best.cost >= 0) {
    note_oscillation();
    reset_oscillation();
    reset_escape();
    return best;
  }
  // Nothing else: back up slowly, even where the map shows it blocked.
  generate(pose, vel, c.escape_vel_mps, 0.0, 0.0, comp);
  std::swap(best, comp);
  reset_oscillation();
  if (!escaping_ && best.cost > -2.0) {
    escape_x_ = pose.x;
    escape_y_ = pose.y;
    escape_th_ = pose.theta;
    escaping_ = true;
  }
  reset_escape();
  if (best.cost == -1.0) best.cost = 1.0;
  if (best.cost >= 0) ++stats_.escapes;
  return best;
}

bool MoveBaseNavigator::compute_velocity(const Pose2D& pose, const VelocityCommand& vel,
                                         VelocityCommand& cmd) {
  if (plan_.points.empty()) return false;
  const MoveBaseConfig& c = config_;
  const double period = 1.0 / c.controller_frequency_hz;
  // TrajectoryPlannerROS clears the robot's footprint in its costmap before every cycle.
  local_.clear_footprint(pose.position(), c.robot_radius_m);
  update_grids(pose);
  const double dist = (base_goal_.position() - pose.position()).norm();
  if (dist <= c.xy_goal_tolerance_m) {
    // At the goal position: stop within the acceleration limits, then rotate to the heading.
    const double dth = core::angle_diff(base_goal_.theta, pose.theta);
    if (std::abs(dth) <= c.yaw_goal_tolerance_rad) {
      cmd = {};
      rotating_to_goal_ = false;
      return true;
    }
    const bool stopped = std::hypot(vel.vx_mps, vel.vy_mps) <= c.stopped_vel &&
                         std::abs(vel.omega_rps) <= c.stopped_vel;
    if (!rotating_to_goal_ && !stopped) {
      const double vx =
          sign(vel.vx_mps) * std::max(0.0, std::abs(vel.vx_mps) - c.acc_lim_x * period);
      const double vy =
          sign(vel.vy_mps) * std::max(0.0, std::abs(vel.vy_mps) - c.acc_lim_y * period);
      const double vt =
          sign(vel.omega_rps) * std::max(0.0, std::abs(vel.omega_rps) - c.acc_lim_th * period);
      Traj t;
      generate(pose, vel, vx, vy, vt, t);
      if (t.cost < 0) return false;
      cmd = {vx, vy, vt};
      return true;
    }
    rotating_to_goal_ = true;
    double v = dth > 0.0
                   ? std::min(c.max_rotational_vel, std::max(c.min_in_place_rotational_vel, dth))
                   : std::max(-c.max_rotational_vel, std::min(-c.min_in_place_rotational_vel, dth));
    const double max_acc = std::abs(vel.omega_rps) + c.acc_lim_th * period;
    const double min_acc = std::abs(vel.omega_rps) - c.acc_lim_th * period;
    v = sign(v) * std::min(std::max(std::abs(v), min_acc), max_acc);
    v = sign(v) * std::min(std::sqrt(2.0 * c.acc_lim_th * std::abs(dth)), std::abs(v));
    v = v > 0.0 ? std::min(c.max_rotational_vel, std::max(c.min_in_place_rotational_vel, v))
                : std::max(-c.max_rotational_vel, std::min(-c.min_in_place_rotational_vel, v));
    Traj t;
    generate(pose, vel, 0.0, 0.0, v, t);
    if (t.cost < 0) return false;
    cmd = {0.0, 0.0, v};
    return true;
  }
  const Traj best = create_trajectories(pose, vel);
  if (best.cost < 0) return false;
  cmd = {best.vx, best.vy, best.vth};
  return true;
}

}  // namespace llsf::planner
