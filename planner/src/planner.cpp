// SPDX-License-Identifier: MIT
// The Planner: static map, places, and OMPL queries (RRTConnect with an iteration-bounded
// termination condition, then vertex reduction, shortcutting and a greedy string pull).
//
// Determinism (docs/planner.md): every random draw of a query comes from a core::RandomStream
// seeded by PlanRequest::seed -- the state sampler is ours, and the two OMPL objects that keep
// an ompl::RNG (RRTConnect and PathSimplifier) get their local seeds from that stream before
// each query. Nearest neighbours are linear (OMPL's default GNAT picks pivots with an RNG of its
// own that cannot be seeded). The termination condition counts iterations, not seconds, and
// starts no thread. Nothing global of OMPL's is touched but the log level (once).
#include "llsf/planner/planner.h"

#include <ompl/base/MotionValidator.h>
#include <ompl/base/PlannerTerminationCondition.h>
#include <ompl/base/ProblemDefinition.h>
#include <ompl/base/ScopedState.h>
#include <ompl/base/SpaceInformation.h>
#include <ompl/base/StateSampler.h>
#include <ompl/base/StateValidityChecker.h>
#include <ompl/base/spaces/RealVectorStateSpace.h>
#include <ompl/datastructures/NearestNeighborsLinear.h>
#include <ompl/geometric/PathGeometric.h>
#include <ompl/geometric/PathSimplifier.h>
#include <ompl/geometric/planners/rrt/RRTConnect.h>
#include <ompl/util/Console.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <mutex>

#include "llsf/core/assert.h"
#include "llsf/core/rng.h"
#include "places.h"
#include "static_map.h"

namespace llsf::planner {

namespace ob = ompl::base;
namespace og = ompl::geometric;
using detail::StaticMap;

double Path::length_m() const {
  double len = 0.0;
  for (std::size_t i = 1; i < points.size(); ++i) len += (points[i] - points[i - 1]).norm();
  return len;
}

const char* to_string(PlanStatus status) {
  switch (status) {
    case PlanStatus::kFound:
      return "found";
    case PlanStatus::kNoPath:
      return "no path";
    case PlanStatus::kInvalidGoal:
      return "invalid goal";
    case PlanStatus::kGoalOccupied:
      return "goal occupied";
    case PlanStatus::kInvalidStart:
      return "invalid start";
  }
  return "?";
}

namespace {

std::string xy(const Vec2& p) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "(%.3f, %.3f)", p.x(), p.y());
  return buf;
}

Vec2 to_vec(const ob::State* s) {
  const auto* r = s->as<ob::RealVectorStateSpace::StateType>();
  return {r->values[0], r->values[1]};
}
void set_vec(ob::State* s, const Vec2& p) {
  auto* r = s->as<ob::RealVectorStateSpace::StateType>();
  r->values[0] = p.x();
  r->values[1] = p.y();
}

/// What the OMPL callbacks need to know about the query in progress.
struct QueryContext {
  const StaticMap* map = nullptr;
  core::RandomStream stream{0};
  std::span<const DiscObstacle> discs;
  double disc_radius = 0.0;  // own inflated radius + obstacle clearance

  bool free(const Vec2& p) const {
    return map->point_free(p) && detail::discs_free(discs, disc_radius, p);
  }
  bool segment_free(const Vec2& a, const Vec2& b) const {
    return map->segment_free(a, b) && detail::discs_segment_free(discs, disc_radius, a, b);
  }
};

/// Uniform samples inside the walls' inflated rectangle, drawn from the query's stream.
class StreamSampler : public ob::StateSampler {
 public:
  StreamSampler(const ob::StateSpace* space, QueryContext* q) : ob::StateSampler(space), q_(q) {
    const double r = q->map->radius();
    lo_ = Vec2(r, r);
    hi_ = Vec2(q->map->width() - r, q->map->height() - r);
  }
  void sampleUniform(ob::State* s) override {
    set_vec(s, {q_->stream.uniform(lo_.x(), hi_.x()), q_->stream.uniform(lo_.y(), hi_.y())});
  }
  void sampleUniformNear(ob::State* s, const ob::State* near, double d) override {
    const Vec2 c = to_vec(near);
    set_vec(s, clamp({q_->stream.uniform(c.x() - d, c.x() + d),
                      q_->stream.uniform(c.y() - d, c.y() + d)}));
  }
  void sampleGaussian(ob::State* s, const ob::State* mean, double sd) override {
    const Vec2 c = to_vec(mean);
    set_vec(s, clamp({q_->stream.normal(c.x(), sd), q_->stream.normal(c.y(), sd)}));
  }

 private:
  Vec2 clamp(const Vec2& p) const { return p.cwiseMax(lo_).cwiseMin(hi_); }
  QueryContext* q_;
  Vec2 lo_, hi_;
};

class Checker : public ob::StateValidityChecker {
 public:
  Checker(const ob::SpaceInformationPtr& si, const QueryContext* q)
      : ob::StateValidityChecker(si), q_(q) {}
  bool isValid(const ob::State* s) const override { return q_->free(to_vec(s)); }

 private:
  const QueryContext* q_;
};

/// Exact motion checks (segment against boxes and discs) instead of OMPL's sampled ones: a
/// path that passes is free everywhere, not only at a resolution.
class ExactMotionValidator : public ob::MotionValidator {
 public:
  ExactMotionValidator(const ob::SpaceInformationPtr& si, const QueryContext* q)
      : ob::MotionValidator(si), q_(q) {}
  bool checkMotion(const ob::State* s1, const ob::State* s2) const override {
    const bool ok = q_->segment_free(to_vec(s1), to_vec(s2));
    ok ? ++valid_ : ++invalid_;
    return ok;
  }
  bool checkMotion(const ob::State* s1, const ob::State* s2,
                   std::pair<ob::State*, double>& last_valid) const override {
    if (checkMotion(s1, s2)) return true;
    // The last free point along the motion, to 1 cm.
    const Vec2 a = to_vec(s1), b = to_vec(s2);
    const double len = (b - a).norm();
    const int n = std::max(1, static_cast<int>(std::ceil(len / 0.01)));
    double t = 0.0;
    for (int k = 1; k <= n; ++k) {
      const double tk = static_cast<double>(k) / n;
      if (!q_->segment_free(a, a + tk * (b - a))) break;
      t = tk;
    }
    if (last_valid.first) set_vec(last_valid.first, a + t * (b - a));
    last_valid.second = t;
    return false;
  }

 private:
  const QueryContext* q_;
};

class SeededRRTConnect : public og::RRTConnect {
 public:
  using og::RRTConnect::RRTConnect;
  void seed(std::uint_fast32_t s) { rng_.setLocalSeed(s); }
};

class SeededSimplifier : public og::PathSimplifier {
 public:
  using og::PathSimplifier::PathSimplifier;
  void seed(std::uint_fast32_t s) { rng_.setLocalSeed(s); }
};

double polyline_length(const std::vector<Vec2>& pts) {
  double len = 0.0;
  for (std::size_t i = 1; i < pts.size(); ++i) len += (pts[i] - pts[i - 1]).norm();
  return len;
}

std::uint_fast32_t seed32(core::RandomStream& s) {
  return static_cast<std::uint_fast32_t>(s.next_u64() >> 32);
}

/// OMPL keeps process-wide state (SelfConfig's map from SpaceInformation to its settings, whose
/// entries hold the SpaceInformation's control block) and guards it inside the library, where
/// ThreadSanitizer cannot see the ordering. Planners of games on several threads are therefore
/// made and destroyed one at a time under this mutex (once per robot and game: no cost).
std::mutex& ompl_mutex() {
  static std::mutex m;
  return m;
}

}  // namespace

struct Planner::Impl {
  FieldMap field;
  PlannerConfig config;
  StaticMap map;
  std::vector<Place> places;
  QueryContext query;
  /// Unlocks ompl_mutex() (locked by ~Impl) once the OMPL members below, declared after it and so
  /// destroyed before it, are gone.
  struct OmplUnlock {
    bool locked = false;
    OmplUnlock() = default;
    OmplUnlock(const OmplUnlock&) = delete;
    OmplUnlock& operator=(const OmplUnlock&) = delete;
    ~OmplUnlock() {
      if (locked) ompl_mutex().unlock();
    }
  } ompl_unlock;
  ob::SpaceInformationPtr si;
  std::shared_ptr<SeededRRTConnect> rrt;
  std::shared_ptr<SeededSimplifier> simplifier;

  Impl(FieldMap f, PlannerConfig c)
      : field(std::move(f)),
        config(std::move(c)),
        map(field, config.inflated_radius_m()),
        places(detail::derive_places(field, config.places, map)) {
    static std::once_flag quiet;
    std::call_once(quiet, [] { ompl::msg::setLogLevel(ompl::msg::LOG_WARN); });
    query.map = &map;

    const std::lock_guard<std::mutex> lock(ompl_mutex());
    auto space = std::make_shared<ob::RealVectorStateSpace>(2);
    ob::RealVectorBounds bounds(2);
    bounds.setLow(0, 0.0);
    bounds.setHigh(0, field.width_m);
    bounds.setLow(1, 0.0);
    bounds.setHigh(1, field.height_m);
    space->setBounds(bounds);
    QueryContext* q = &query;
    space->setStateSamplerAllocator(
        [q](const ob::StateSpace* s) { return std::make_shared<StreamSampler>(s, q); });
    si = std::make_shared<ob::SpaceInformation>(space);
    si->setStateValidityChecker(std::make_shared<Checker>(si, q));
    si->setMotionValidator(std::make_shared<ExactMotionValidator>(si, q));
    si->setup();
    rrt = std::make_shared<SeededRRTConnect>(si);
    rrt->setRange(config.rrt_range_m);
    rrt->setNearestNeighbors<ompl::NearestNeighborsLinear>();
    simplifier = std::make_shared<SeededSimplifier>(si);
  }
  ~Impl() {
    ompl_mutex().lock();  // held until ompl_unlock goes, after the OMPL members
    ompl_unlock.locked = true;
  }
  Impl(const Impl&) = delete;
  Impl& operator=(const Impl&) = delete;

  /// The free point nearest to `p` within `max_m` (1 cm rings, 32 directions), if any.
  /// A start free of static obstacles (inside a disc only) moves out along a statically free
  /// segment.
  std::optional<Vec2> escape(const Vec2& p, double max_m) const {
    const int rings = static_cast<int>(std::floor(max_m / 0.01 + 1e-9));
    const bool static_free = map.point_free(p);
    for (int k = 1; k <= rings; ++k) {
      for (int j = 0; j < 32; ++j) {
        const Vec2 c = p + 0.01 * k * core::unit(2.0 * core::kPi * j / 32.0);
        if (query.free(c) && (!static_free || map.segment_free(p, c))) return c;
      }
    }
    return std::nullopt;
  }

  /// Replaces runs of vertices by straight segments wherever they are free: from each vertex,
  /// jump to the farthest one visible. Deterministic and cheap on short paths.
  void string_pull(std::vector<Vec2>& pts) const {
    std::vector<Vec2> out{pts.front()};
    std::size_t i = 0;
    while (i + 1 < pts.size()) {
      std::size_t j = pts.size() - 1;
      while (j > i + 1 && !query.segment_free(pts[i], pts[j])) --j;
      out.push_back(pts[j]);
      i = j;
    }
    pts = std::move(out);
  }

  Clearance clearance(const Vec2& p) const {
    int which = 0;
    const double d = map.signed_distance(p, &which);
    return {d, map.obstacle_name(which)};
  }

  /// One RRTConnect run and its simplification, drawing from query.stream.
  bool solve_once(const Vec2& start, const Vec2& goal, std::vector<Vec2>& pts, int& iterations) {
    rrt->seed(seed32(query.stream));
    simplifier->seed(seed32(query.stream));
    auto pdef = std::make_shared<ob::ProblemDefinition>(si);
    ob::ScopedState<> s(si), g(si);
    set_vec(s.get(), start);
    set_vec(g.get(), goal);
    pdef->setStartAndGoalStates(s, g);
    rrt->clear();
    rrt->setProblemDefinition(pdef);
    int n = 0;
    const int limit = config.max_iterations;
    const ob::PlannerTerminationCondition ptc([&n, limit] { return ++n > limit; });
    const ob::PlannerStatus st = rrt->solve(ptc);
    iterations += std::min(n, limit);
    if (st != ob::PlannerStatus::EXACT_SOLUTION) {
      rrt->clear();
      return false;
    }
    auto& path = *pdef->getSolutionPath()->as<og::PathGeometric>();
    simplifier->reduceVertices(path);
    simplifier->shortcutPath(path, static_cast<unsigned>(config.shortcut_steps));
    pts.clear();
    for (std::size_t i = 0; i < path.getStateCount(); ++i) pts.push_back(to_vec(path.getState(i)));
    rrt->clear();
    // OMPL keeps the exact start and goal states; make sure of it before pulling.
    pts.front() = start;
    pts.back() = goal;
    string_pull(pts);
    return true;
  }

  PlanResult plan(const PlanRequest& req) {
    PlanResult result;
    const Vec2 goal = req.goal.position();
    Vec2 start = req.start.position();
    const double r = map.radius();
    query.discs = req.obstacles;
    // The request's obstacles are borrowed for this call only.
    struct Forget {
      QueryContext& q;
      ~Forget() { q.discs = {}; }
    } forget{query};
    query.disc_radius = r + req.obstacle_clearance_m;

    // The goal: inside the field, clear of static obstacles, then of the discs.
    if (!std::isfinite(goal.x()) || !std::isfinite(goal.y()) || !std::isfinite(req.goal.theta)) {
      result.status = PlanStatus::kInvalidGoal;
      result.message = "goal is not a finite pose";
      return result;
    }
    if (goal.x() < 0.0 || goal.y() < 0.0 || goal.x() > map.width() || goal.y() > map.height()) {
      char buf[96];
      std::snprintf(buf, sizeof buf, " lies outside the field [0, %.2f] x [0, %.2f]", map.width(),
                    map.height());
      result.status = PlanStatus::kInvalidGoal;
      result.message = "goal " + xy(goal) + buf;
      return result;
    }
    if (!map.point_free(goal)) {
      const Clearance c = clearance(goal);
      char buf[160];
      if (c.distance_m < 0.0)
        std::snprintf(buf, sizeof buf, "lies inside %s (%.3f m deep)", c.obstacle.c_str(),
                      -c.distance_m);
      else
        std::snprintf(buf, sizeof buf, "is %.3f m from %s; the robot needs %.3f m", c.distance_m,
                      c.obstacle.c_str(), r);
      result.status = PlanStatus::kInvalidGoal;
      result.message = "goal " + xy(goal) + " " + buf;
      return result;
    }
    for (const DiscObstacle& d : req.obstacles) {
      if ((goal - d.position).norm() < query.disc_radius + d.radius_m) {
        result.status = PlanStatus::kGoalOccupied;
        result.blocked_by = d.id;
        result.message = "goal " + xy(goal) + " is occupied by obstacle " + std::to_string(d.id);
        return result;
      }
    }

    // The start: a robot pushed into the margin first moves out along the shortest way.
    if (!std::isfinite(start.x()) || !std::isfinite(start.y())) {
      result.status = PlanStatus::kInvalidStart;
      result.message = "start is not a finite pose";
      return result;
    }
    std::vector<Vec2> prefix;
    if (!query.free(start)) {
      const auto out = escape(start, config.start_escape_m);
      if (!out) {
        result.status = PlanStatus::kInvalidStart;
        char buf[64];
        std::snprintf(buf, sizeof buf, " has no free point within %.2f m", config.start_escape_m);
        result.message = "start " + xy(start) + buf;
        return result;
      }
      prefix.push_back(start);
      start = *out;
      result.escaped_start = true;
    }

    std::vector<Vec2> pts;
    if (query.segment_free(start, goal)) {
      pts = {start, goal};
    } else {
      // OMPL: every draw from the stream of this query's seed. A path much longer than the
      // straight line probably went round the wrong side of something: try again, keep the
      // shortest.
      query.stream = core::RandomStream(req.seed);
      const double good = config.accept_ratio * (goal - start).norm() + config.accept_extra_m;
      double best_len = std::numeric_limits<double>::infinity();
      for (int attempt = 0; attempt < config.max_attempts; ++attempt) {
        std::vector<Vec2> cand;
        const bool found = solve_once(start, goal, cand, result.iterations);
        if (!found) {
          if (attempt > 0) break;
          result.status = PlanStatus::kNoPath;
          result.message = "no path from " + xy(start) + " to " + xy(goal) + " within " +
                           std::to_string(config.max_iterations) + " iterations";
          return result;
        }
        const double len = polyline_length(cand);
        if (len < best_len) {
          best_len = len;
          pts = std::move(cand);
        }
        if (best_len <= good) break;
      }
    }
    result.status = PlanStatus::kFound;
    result.path.points = std::move(prefix);
    result.path.points.insert(result.path.points.end(), pts.begin(), pts.end());
    result.path.goal_theta = core::normalize_angle(req.goal.theta);
    return result;
  }
};

Planner::Planner(FieldMap field, PlannerConfig config) {
  field.validate();
  config.validate();
  impl_ = std::make_unique<Impl>(std::move(field), std::move(config));
}

Planner::~Planner() = default;

const FieldMap& Planner::field() const { return impl_->field; }
const PlannerConfig& Planner::config() const { return impl_->config; }
const std::vector<Place>& Planner::places() const { return impl_->places; }

const Place* Planner::place(std::string_view name) const {
  for (const Place& p : impl_->places) {
    if (p.name == name) return &p;
  }
  // A bare device name is its input place.
  if (impl_->field.device(name)) return place(std::string(name) + "_input");
  return nullptr;
}

PlanResult Planner::plan(const PlanRequest& request) {
  ++plan_count_;
  return impl_->plan(request);
}

bool Planner::is_free(const Vec2& p, std::span<const DiscObstacle> obstacles,
                      double obstacle_clearance_m) const {
  return impl_->map.point_free(p) &&
         detail::discs_free(obstacles, impl_->map.radius() + obstacle_clearance_m, p);
}

bool Planner::is_segment_free(const Vec2& a, const Vec2& b, std::span<const DiscObstacle> obstacles,
                              double obstacle_clearance_m) const {
  return impl_->map.segment_free(a, b) &&
         detail::discs_segment_free(obstacles, impl_->map.radius() + obstacle_clearance_m, a, b);
}

Clearance Planner::clearance(const Vec2& p) const { return impl_->clearance(p); }

}  // namespace llsf::planner
