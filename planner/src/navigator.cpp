// SPDX-License-Identifier: MIT
// The navigator's state machine (docs/planner.md, "Driving"):
//   driving  -- follow the path; slow down to stop before the first point where the path
//               meets another robot's disc; held there: waiting;
//   waiting  -- stopped; path clear again: driving; after wait_before_replan_s plus a seeded
//               jitter: plan around the other robots (driving) or, if that fails, back off;
//   backing off -- give way: move to a spot off the line through the blocker, wait a seeded
//               random delay (exponential back-off), then plan around again.
// Time held back by robots adds up; past blocked_timeout_s the outcome is `blocked`. Free to
// drive but no progress for stuck_timeout_s: `stuck`.
#include "llsf/planner/navigator.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <optional>

namespace llsf::planner {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
// m to the stop point and m/s: held back by a robot.
constexpr double kHeld = 0.05;
// Predicted discs per moving robot in the blocking check.
constexpr int kPredictionSteps = 5;
// m beyond the stop buffer: the way is open again.
constexpr double kClearAgain = 0.3;
// m/s: stopped enough to take a new direction.
constexpr double kSettled = 0.02;
// m/s: another robot faster than this is predicted along its velocity.
constexpr double kMovingSpeed = 0.1;
// s: time constant of the other robots' velocity estimates.
constexpr double kVelocityFilter_s = 0.2;
// m: a refuge lies this much further across than the blocker needs to pass.
constexpr double kRefugeExtra = 0.1;
// rad of heading error reduced counts as progress.
constexpr double kHeadingProgress = 0.1;
// m: forward mode comes in straight along the goal heading for this last stretch.
constexpr double kApproach = 0.4;
// Brake for another robot as if only half the distance were there: it may be coming the other
// way just as fast.
constexpr double kStopShare = 0.5;

// True if no point of [a, b] comes closer to `c` than `r` (less a hair, for a start on it).
bool segment_keeps_off(const Vec2& a, const Vec2& b, const Vec2& c, double r) {
  const Vec2 d = b - a;
  const double len2 = d.squaredNorm();
  const double t = len2 > 0.0 ? std::clamp((c - a).dot(d) / len2, 0.0, 1.0) : 0.0;
  return (a + t * d - c).norm() >= r - 1e-6;
}

}  // namespace

const char* to_string(NavOutcome outcome) {
  switch (outcome) {
    case NavOutcome::kIdle:
      return "idle";
    case NavOutcome::kRunning:
      return "running";
    case NavOutcome::kArrived:
      return "arrived";
    case NavOutcome::kNoPath:
      return "no path";
    case NavOutcome::kInvalidGoal:
      return "invalid goal";
    case NavOutcome::kBlocked:
      return "blocked";
    case NavOutcome::kStuck:
      return "stuck";
    case NavOutcome::kAborted:
      return "aborted";
  }
  return "?";
}

Navigator::Navigator(Planner& planner, ControllerConfig config, core::RandomStream rng)
    : planner_(&planner), config_(config), rng_(rng), follower_(config_) {
  config_.validate();
}

void Navigator::go_to(const Pose2D& goal, bool forward) {
  goal_ = goal;
  forward_ = forward;
  status_ = NavStatus{NavOutcome::kRunning, -1, {}};
  phase_ = NavPhase::kDriving;
  stats_ = NavStats{};
  need_plan_ = true;
  braking_ = false;
  blocker_ = -1;
  no_progress_s_ = 0.0;
}

void Navigator::go_to_place(std::string_view name, bool forward) {
  if (const Place* p = planner_->place(name)) {
    go_to(p->pose, forward);
    return;
  }
  go_to(Pose2D{});
  finish(NavOutcome::kInvalidGoal, "unknown place '" + std::string(name) + "'");
}

void Navigator::abort() {
  if (status_.outcome == NavOutcome::kRunning) finish(NavOutcome::kAborted, "aborted");
}

void Navigator::finish(NavOutcome outcome, std::string message, int blocked_by) {
  status_ = NavStatus{outcome, blocked_by, std::move(message)};
  need_plan_ = false;
  braking_ = true;
}

bool Navigator::plan_from(const Pose2D& pose, std::span<const DiscObstacle> others,
                          bool around_others) {
  PlanRequest req;
  req.start = pose;
  req.goal = goal_;
  // Forward (carrying a puck): come in straight along the goal heading for the last
  // kApproach metres, as the holder needs, if that stretch is free.
  bool approach = false;
  if (forward_) {
    const Vec2 g = goal_.position();
    const Vec2 pre = g - kApproach * core::unit(goal_.theta);
    if (planner_->is_segment_free(pre, g) &&
        (pose.position() - g).norm() > kApproach + config_.position_tolerance_m) {
      req.goal = Pose2D{pre.x(), pre.y(), goal_.theta};
      approach = true;
    }
  }
  if (around_others) {
    // Plan around where the others are and, for those that move, where they are going within
    // prediction_horizon_s (discs along their estimated velocity).
    predicted_.assign(others.begin(), others.end());
    for (const DiscObstacle& o : others) {
      const Vec2 v = velocity_of(o.id);
      const double speed = v.norm();
      if (speed < kMovingSpeed) continue;
      const int n = static_cast<int>(std::ceil(speed * config_.prediction_horizon_s / 0.2));
      for (int k = 1; k <= n; ++k) {
        const double t = config_.prediction_horizon_s * k / n;
        predicted_.push_back({o.id, o.position + v * t, o.radius_m});
      }
    }
    req.obstacles = predicted_;
    req.obstacle_clearance_m = config_.robot_margin_m + config_.replan_margin_m;
  }
  req.seed = rng_.next_u64();
  PlanResult r = planner_->plan(req);
  switch (r.status) {
    case PlanStatus::kFound:
      if (approach) r.path.points.push_back(goal_.position());
      follower_.set_path(std::move(r.path), forward_);
      ++stats_.plans;
      best_remaining_ = follower_.remaining_m();
      best_heading_error_ = kInf;
      no_progress_s_ = 0.0;
      return true;
    case PlanStatus::kInvalidGoal:
      finish(NavOutcome::kInvalidGoal, r.message);
      return false;
    case PlanStatus::kNoPath:
    case PlanStatus::kInvalidStart:
      if (!around_others) finish(NavOutcome::kNoPath, r.message);
      return false;
    case PlanStatus::kGoalOccupied:
      if (r.blocked_by >= 0) blocker_ = r.blocked_by;
      return false;
  }
  return false;
}

double Navigator::blocking_arc(const Pose2D& pose, std::span<const DiscObstacle> others,
                               int& who) const {
  // The first arc length (from the robot's projection, within the lookahead) where the path
  // comes closer to another robot than the two discs allow -- or than the robot is now, if
  // it is already too close (moving away is always allowed). A moving robot also blocks where
  // it will be within prediction_horizon_s (a robot crossing the path is seen before it is on
  // it); those predicted discs count only if the path enters them ahead, not if the robot is
  // in one already (someone coming up from behind is not a reason to stop).
  who = -1;
  if (!follower_.has_path()) return kInf;
  const double own = planner_->config().inflated_radius_m();
  const double s0 = follower_.progress_m();
  double best = kInf;
  for (const DiscObstacle& o : others) {
    const double sep = own + o.radius_m + config_.robot_margin_m;
    const double now = (pose.position() - o.position).norm();
    const double thr = std::min(sep, now - 0.005);
    if (thr > 0.0) {
      const double hit = path_entry(o.position, thr, s0, true);
      if (hit < best) {
        best = hit;
        who = o.id;
      }
    }
    const Vec2 v = velocity_of(o.id);
    if (v.norm() < kMovingSpeed) continue;
    for (int k = 1; k <= kPredictionSteps; ++k) {
      const Vec2 c = o.position + v * (config_.prediction_horizon_s * k / kPredictionSteps);
      const double hit = path_entry(c, sep, s0, false);
      if (hit < best) {
        best = hit;
        who = o.id;
      }
    }
  }
  return best;
}

double Navigator::path_entry(const Vec2& c, double r, double s0, bool inside_blocks) const {
  // The first arc length >= s0 within the lookahead where the path enters the disc (c, r);
  // starting inside counts as s0 if `inside_blocks`, else that disc is ignored.
  const auto& pts = follower_.path().points;
  const auto& cum = follower_.vertex_arc();
  const double s_end = s0 + config_.obstacle_lookahead_m;
  bool first = true;
  for (std::size_t i = 1; i < pts.size(); ++i) {
    if (cum[i] <= s0) continue;
    if (cum[i - 1] >= s_end) break;
    const double from = std::max(s0, cum[i - 1]);
    const Vec2 a = follower_.point_at(from);
    const double len = cum[i] - from;
    if (len <= 1e-12) continue;
    if ((a - c).norm() < r) {
      if (first && !inside_blocks) return kInf;
      return from <= s_end ? from : kInf;
    }
    first = false;
    const Vec2 dir = (pts[i] - a) / len;
    if (const auto t = core::ray_circle(a, dir, c, r); t && *t <= len) {
      return from + *t <= s_end ? from + *t : kInf;
    }
  }
  return kInf;
}

VelocityCommand Navigator::update(core::SimTime now, const Pose2D& pose,
                                  std::span<const DiscObstacle> others) {
  const double dt = has_last_update_ ? std::max(0.0, (now - last_update_).seconds()) : 0.0;
  last_update_ = now;
  has_last_update_ = true;
  track(others, dt);
  if (status_.outcome != NavOutcome::kRunning) {
    return braking_ ? follower_.brake(pose, dt) : VelocityCommand{};
  }
  if (need_plan_) {
    need_plan_ = false;
    if (!plan_from(pose, others, false)) return follower_.brake(pose, dt);
  }

  // Held back by robots for too long in total: give up.
  auto held = [&](double step) -> bool {
    stats_.blocked_s += step;
    if (stats_.blocked_s > config_.blocked_timeout_s) {
      const std::string who = blocker_ >= 0 && blocker_ < static_cast<int>(names_.size())
                                  ? names_[static_cast<std::size_t>(blocker_)]
                                  : "robot " + std::to_string(blocker_);
      char buf[48];
      std::snprintf(buf, sizeof buf, " for %.1f s", stats_.blocked_s);
      finish(NavOutcome::kBlocked, "held back by " + who + buf, blocker_);
      return true;
    }
    return false;
  };

  switch (phase_) {
    case NavPhase::kDriving:
      return drive(now, pose, others, dt);

    case NavPhase::kWaiting: {
      int who = -1;
      const double s_block = blocking_arc(pose, others, who);
      if (s_block - follower_.progress_m() > config_.stop_buffer_m + kClearAgain) {
        phase_ = NavPhase::kDriving;
        no_progress_s_ = 0.0;
        return drive(now, pose, others, dt);
      }
      if (who >= 0) blocker_ = who;
      if (held(dt)) return follower_.brake(pose, dt);
      if (now >= wait_until_ && follower_.speed_mps() < kSettled) {
        if (plan_from(pose, others, true)) {
          ++stats_.replans;
          phase_ = NavPhase::kDriving;
          return drive(now, pose, others, dt);
        }
        if (status_.outcome != NavOutcome::kRunning) return follower_.brake(pose, dt);
        return start_backoff(now, pose, others, dt);
      }
      return follower_.brake(pose, dt);
    }

    case NavPhase::kBackingOff: {
      if (held(dt)) return follower_.brake(pose, dt);
      // Move along the short back-off path, still minding the robots around; once there (or
      // stopped) and the delay is over, plan around again.
      int who = -1;
      const double s_block = blocking_arc(pose, others, who);
      const VelocityCommand cmd =
          follower_.update(pose, dt, s_block - config_.stop_buffer_m, kStopShare);
      const bool settled = follower_.arrived() || follower_.speed_mps() < kSettled;
      if (now < wait_until_ || !settled) return cmd;
      if (plan_from(pose, others, true)) {
        ++stats_.replans;
        phase_ = NavPhase::kDriving;
        return drive(now, pose, others, dt);
      }
      if (status_.outcome != NavOutcome::kRunning) return follower_.brake(pose, dt);
      return start_backoff(now, pose, others, dt);
    }
  }
  return follower_.brake(pose, dt);
}

void Navigator::track(std::span<const DiscObstacle> others, double dt) {
  // Velocity of each other robot from its last two positions, low-pass filtered.
  for (const DiscObstacle& o : others) {
    auto it =
        std::find_if(tracks_.begin(), tracks_.end(), [&](const Track& t) { return t.id == o.id; });
    if (it == tracks_.end()) {
      tracks_.push_back({o.id, o.position, Vec2(0.0, 0.0)});
      continue;
    }
    if (dt > 0.0) {
      const Vec2 v = (o.position - it->position) / dt;
      const double k = std::min(1.0, dt / kVelocityFilter_s);
      it->velocity += k * (v - it->velocity);
    }
    it->position = o.position;
  }
}

Vec2 Navigator::velocity_of(int id) const {
  for (const Track& t : tracks_) {
    if (t.id == id) return t.velocity;
  }
  return {0.0, 0.0};
}

VelocityCommand Navigator::drive(core::SimTime now, const Pose2D& pose,
                                 std::span<const DiscObstacle> others, double dt) {
  int who = -1;
  const double s_block = blocking_arc(pose, others, who);
  const double stop_at = s_block - config_.stop_buffer_m;
  const VelocityCommand cmd = follower_.update(pose, dt, stop_at, kStopShare);
  if (follower_.arrived()) {
    finish(NavOutcome::kArrived, {});
    return cmd;
  }
  const double to_stop = stop_at - follower_.progress_m();
  if (who >= 0 && to_stop < kHeld && follower_.speed_mps() < kHeld) {
    // Held back by another robot: wait, then plan around it.
    phase_ = NavPhase::kWaiting;
    blocker_ = who;
    wait_until_ = now + core::SimTime::from_seconds(config_.wait_before_replan_s +
                                                    rng_.uniform(0.0, config_.replan_jitter_s));
    return cmd;
  }
  // Progress watchdog, only while no robot limits the speed.
  if (who >= 0 && to_stop < kClearAgain) {
    no_progress_s_ = 0.0;
  } else {
    const double rem = follower_.remaining_m();
    const double he = std::abs(follower_.heading_error_rad());
    if (rem < best_remaining_ - config_.progress_m || he < best_heading_error_ - kHeadingProgress) {
      best_remaining_ = std::min(best_remaining_, rem);
      best_heading_error_ = std::min(best_heading_error_, he);
      no_progress_s_ = 0.0;
    } else {
      no_progress_s_ += dt;
      if (no_progress_s_ > config_.stuck_timeout_s) {
        char buf[96];
        const Vec2 p = pose.position();
        std::snprintf(buf, sizeof buf, "no progress for %.1f s at (%.3f, %.3f)", no_progress_s_,
                      p.x(), p.y());
        finish(NavOutcome::kStuck, buf);
      }
    }
  }
  return cmd;
}

VelocityCommand Navigator::start_backoff(core::SimTime now, const Pose2D& pose,
                                         std::span<const DiscObstacle> others, double dt) {
  ++stats_.backoffs;
  phase_ = NavPhase::kBackingOff;
  // Exponential back-off, capped: the range of the random delay doubles after the first
  // back-off of this navigation (1x, then 2x), so that two robots that keep giving way to each
  // other at the same moments soon stop doing so. (A higher cap made them wait so long that
  // more navigations ended blocked in the swap tests.)
  const double spread = std::min(std::pow(2.0, stats_.backoffs - 1), 2.0);
  const double lo = config_.backoff_min_s;
  wait_until_ = now + core::SimTime::from_seconds(
                          rng_.uniform(lo, lo + spread * (config_.backoff_max_s - lo)));
  // Give way: move to a refuge off the line through the blocker and this robot -- the blocker
  // most likely wants to pass along it -- far enough across it for the blocker to pass
  // (refuge_lateral), by a straight free move that comes closer to no one. Candidates fan out
  // from "across" towards "back", nearest first, a seeded random side first; failing that, the
  // best partial step.
  const Vec2 p = pose.position();
  Vec2 away(0.0, 0.0);
  double blocker_radius = planner_->config().inflated_radius_m();
  for (const DiscObstacle& o : others) {
    if (o.id == blocker_) {
      away = p - o.position;
      blocker_radius = o.radius_m;
    }
  }
  if (away.norm() < 1e-6 && follower_.has_path()) {
    away = p - follower_.point_at(follower_.progress_m() + 0.1);
  }
  if (away.norm() > 1e-6 && config_.backoff_distance_m > 0.0) {
    away.normalize();
    const double side = rng_.bernoulli(0.5) ? 1.0 : -1.0;
    const Vec2 n = side * Vec2(-away.y(), away.x());
    const double own = planner_->config().inflated_radius_m();
    const double lateral =
        own + blocker_radius + config_.robot_margin_m + config_.replan_margin_m + kRefugeExtra;
    auto usable = [&](const Vec2& target) {
      bool ok = planner_->is_segment_free(p, target);
      for (const DiscObstacle& o : others) {
        const double sep = own + o.radius_m + config_.robot_margin_m;
        ok = ok && (target - o.position).norm() >= sep &&
             segment_keeps_off(p, target, o.position, std::min(sep, (p - o.position).norm()));
      }
      return ok;
    };
    // Angles from `away`: across first, then more and more backwards.
    constexpr double kDeg = core::kPi / 180.0;
    const double angles[] = {90 * kDeg, 75 * kDeg,  60 * kDeg, 105 * kDeg,
                             45 * kDeg, 120 * kDeg, 30 * kDeg};
    std::optional<Vec2> partial;
    for (double dist = 0.2; dist <= config_.backoff_distance_m + 1e-9; dist += 0.1) {
      for (const double a : angles) {
        for (const double sg : {1.0, -1.0}) {
          const Vec2 d = std::cos(a) * away + sg * std::sin(a) * n;
          const Vec2 target = p + d * dist;
          if (!usable(target)) continue;
          if (std::abs(dist * std::sin(a)) >= lateral) {
            follower_.set_segment(p, target, pose.theta, forward_);
            return follower_.update(pose, dt);
          }
          if (!partial && dist >= 0.3) partial = target;
        }
      }
    }
    // No refuge: straight back, or the first partial step found.
    for (double dist = config_.backoff_distance_m; dist >= 0.2; dist -= 0.1) {
      if (partial) break;
      if (usable(p + away * dist)) partial = p + away * dist;
    }
    if (partial) {
      follower_.set_segment(p, *partial, pose.theta, forward_);
      return follower_.update(pose, dt);
    }
  }
  follower_.set_segment(p, p, pose.theta);
  return follower_.brake(pose, dt);
}

}  // namespace llsf::planner
