// SPDX-License-Identifier: MIT
// Path planning on the static field map with OMPL (RRTConnect + shortcutting), other robots as
// disc obstacles, and the named places.
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "llsf/planner/config.h"
#include "llsf/planner/field_map.h"

namespace llsf::planner {

/// A moving obstacle (another robot) as a disc; `id` is the caller's (e.g. a RobotId value).
struct DiscObstacle {
  int id = -1;
  Vec2 position{0.0, 0.0};
  double radius_m = 0.0;
};

/// One query. `seed` makes the query a pure function of (map, request): the same request with
/// the same seed gives the same path, whatever was planned before and in whatever thread.
struct PlanRequest {
  Pose2D start;
  Pose2D goal;
  /// Discs to avoid besides the static map; the robot's own radius plus `clearance_m` is added.
  std::span<const DiscObstacle> obstacles;
  double obstacle_clearance_m = 0.0;
  std::uint64_t seed = 0;
};

enum class PlanStatus {
  kFound,
  kNoPath,        ///< start and goal are free but not connected (within max_iterations)
  kInvalidGoal,   ///< the goal lies inside a static obstacle's inflated footprint or outside
  kGoalOccupied,  ///< the goal is free of static obstacles but another robot stands on it
  kInvalidStart,  ///< the start is inside an obstacle and no free point is near enough
};

/// A polyline from the start position to the goal position, and the goal heading.
struct Path {
  std::vector<Vec2> points;  ///< at least two (start and goal) unless empty
  double goal_theta = 0.0;
  double length_m() const;
};

struct PlanResult {
  PlanStatus status = PlanStatus::kNoPath;
  Path path;                   ///< set for kFound
  std::string message;         ///< why, for everything but kFound
  int blocked_by = -1;         ///< DiscObstacle::id that occupies the goal (kGoalOccupied)
  bool escaped_start = false;  ///< the path begins with a move out of the safety margin
  int iterations = 0;          ///< planner iterations used
};

const char* to_string(PlanStatus status);

/// Nearest static obstacle of a point: the signed distance (negative inside) and its name
/// ("M3", "wall x=0", or a NamedBox name).
struct Clearance {
  double distance_m = 0.0;
  std::string obstacle;
};

/// The planner of one game: the static map, the places and the OMPL objects. Not copyable;
/// not thread-safe (one per game; games in different threads use different planners and do
/// not influence each other, see docs/planner.md "Determinism").
class Planner {
 public:
  /// Validates both, builds the map and derives the places; throws core::ConfigError.
  Planner(FieldMap field, PlannerConfig config);
  ~Planner();
  Planner(const Planner&) = delete;
  Planner& operator=(const Planner&) = delete;

  const FieldMap& field() const;
  const PlannerConfig& config() const;

  /// Every named place (derived and configured), in a fixed order.
  const std::vector<Place>& places() const;
  /// The place called `name`; a bare device name ("M1") means its input place ("M1_input").
  /// nullptr if there is none.
  const Place* place(std::string_view name) const;

  /// Plans from request.start to request.goal. Allocates; meant for a few hundred queries per
  /// game, not for every step.
  PlanResult plan(const PlanRequest& request);
  /// The number of plan() calls so far, whatever their outcome.
  std::int64_t plan_count() const { return plan_count_; }

  /// True if a robot centred at `p` keeps the inflated radius from static obstacles and walls,
  /// and radius + clearance from the discs (hand-written check, the planner's hot path).
  bool is_free(const Vec2& p, std::span<const DiscObstacle> obstacles = {},
               double obstacle_clearance_m = 0.0) const;
  /// True if the straight segment [a, b] is free in the same sense (exact, not sampled).
  bool is_segment_free(const Vec2& a, const Vec2& b, std::span<const DiscObstacle> obstacles = {},
                       double obstacle_clearance_m = 0.0) const;
  /// The nearest static obstacle or wall of `p` and its exact signed distance (hand-written
  /// geometry of the static map, as the hot-path checks).
  Clearance clearance(const Vec2& p) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  std::int64_t plan_count_ = 0;
};

}  // namespace llsf::planner
