// SPDX-License-Identifier: MIT
// Navigation of one robot to a goal: plans with the game's Planner, follows the path, and deals
// with other robots (slow down, wait, plan around, back off after a seeded random delay, give up
// as `blocked`). The outcome is a value.
#pragma once

#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "llsf/core/rng.h"
#include "llsf/core/sim_time.h"
#include "llsf/planner/path_follower.h"
#include "llsf/planner/planner.h"

namespace llsf::planner {

enum class NavOutcome {
  kIdle,         ///< no goal given yet
  kRunning,      ///< on the way
  kArrived,      ///< within the position and angle tolerances of the goal
  kNoPath,       ///< the static map does not connect the robot and the goal
  kInvalidGoal,  ///< the goal is not a pose the robot can take (inside an obstacle, unknown place)
  kBlocked,      ///< other robots held the robot back for ControllerConfig::blocked_timeout_s
  kStuck,        ///< free to drive but no progress for ControllerConfig::stuck_timeout_s
  kAborted,      ///< abort() was called
};
const char* to_string(NavOutcome outcome);

/// What the navigation came to; `blocked_by` is the DiscObstacle::id last in the way.
struct NavStatus {
  NavOutcome outcome = NavOutcome::kIdle;
  int blocked_by = -1;
  std::string message;
};

/// What the navigator is doing while kRunning.
enum class NavPhase { kDriving, kWaiting, kBackingOff };

/// Counters of one navigation (reset by go_to).
struct NavStats {
  int plans = 0;    ///< successful plans, the first one included
  int replans = 0;  ///< plans around other robots
  int backoffs = 0;
  double blocked_s = 0.0;  ///< time held back by other robots
};

/// Drives one robot. Borrows the game's planner (which must outlive it). Not thread-safe; the
/// steady state (following a path) does not allocate, planning does.
class Navigator {
 public:
  /// `rng` (e.g. rng.stream("planner/robot1")) seeds the robot's plans and back-off delays.
  Navigator(Planner& planner, ControllerConfig config, core::RandomStream rng);

  /// Starts navigating to `goal` (robot pose, heading = final orientation); plans on the next
  /// update. Replaces any previous goal. `forward`: drive facing along the path, never
  /// backwards (carrying a puck).
  void go_to(const Pose2D& goal, bool forward = false);
  /// go_to the named place; an unknown name ends the navigation as kInvalidGoal.
  void go_to_place(std::string_view name, bool forward = false);
  /// Stops: the next updates brake, the outcome is kAborted.
  void abort();
  /// Names of the DiscObstacle ids (robots) for messages ("held back by robot2"); without a
  /// name an id is shown as "robot <id>".
  void set_obstacle_names(std::vector<std::string> names) { names_ = std::move(names); }

  /// One control step at simulated time `now` for the robot at `pose`, with the other robots
  /// (not this one) as discs; call it every physics step or at any steady rate. Returns the
  /// velocity command; once the navigation has ended it brakes to a stop, then returns zero.
  VelocityCommand update(core::SimTime now, const Pose2D& pose,
                         std::span<const DiscObstacle> others);

  const NavStatus& status() const { return status_; }
  NavPhase phase() const { return phase_; }
  const NavStats& stats() const { return stats_; }
  /// The path being followed (empty before the first plan).
  const Path& path() const { return follower_.path(); }
  const Pose2D& goal() const { return goal_; }

 private:
  std::vector<std::string> names_;
  void finish(NavOutcome outcome, std::string message, int blocked_by = -1);
  bool plan_from(const Pose2D& pose, std::span<const DiscObstacle> others, bool around_others);
  double blocking_arc(const Pose2D& pose, std::span<const DiscObstacle> others, int& who) const;
  double path_entry(const Vec2& c, double r, double s0, bool inside_blocks) const;
  VelocityCommand drive(core::SimTime now, const Pose2D& pose, std::span<const DiscObstacle> others,
                        double dt);
  VelocityCommand start_backoff(core::SimTime now, const Pose2D& pose,
                                std::span<const DiscObstacle> others, double dt);
  void track(std::span<const DiscObstacle> others, double dt);
  Vec2 velocity_of(int id) const;

  struct Track {
    int id;
    Vec2 position;
    Vec2 velocity;
  };

  Planner* planner_;
  ControllerConfig config_;
  core::RandomStream rng_;
  PathFollower follower_;
  Pose2D goal_;
  bool forward_ = false;
  NavStatus status_;
  NavPhase phase_ = NavPhase::kDriving;
  NavStats stats_;
  bool need_plan_ = false;
  bool braking_ = false;  // ended: brake to a stop
  core::SimTime last_update_;
  bool has_last_update_ = false;
  // Waiting / backing off.
  core::SimTime wait_until_;
  int blocker_ = -1;
  // Other robots: estimated velocities, and the discs planned around (kept to reuse memory).
  std::vector<Track> tracks_;
  std::vector<DiscObstacle> predicted_;
  // Progress watchdog.
  double best_remaining_ = 0.0;
  double best_heading_error_ = 0.0;
  double no_progress_s_ = 0.0;
};

}  // namespace llsf::planner
