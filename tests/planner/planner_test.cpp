// SPDX-License-Identifier: MIT
// Planner: map, places, queries, clearance (FCL as the oracle), determinism.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <thread>

#include "fcl_oracle.h"
#include "llsf/core/error.h"
#include "static_map.h"
#include "world_fixture.h"

using namespace llsf;
using namespace llsf::planner;
using llsf::sim::field_map_from_world;

namespace {

const kinematic::WorldConfig& world2013() {
  static const kinematic::WorldConfig w = kinematic::WorldConfig::default_2013();
  return w;
}

Planner& shared_planner() {
  static Planner p(field_map_from_world(world2013()), PlannerConfig{});
  return p;
}

// Independent oracle: the clearance of a point from the world's own device footprints and
// walls, by the geometry of core::OrientedBox (not the planner's map).
double world_clearance(const Vec2& p) {
  const auto& w = world2013();
  double d = std::min({p.x(), p.y(), w.field.width_m - p.x(), w.field.height_m - p.y()});
  for (const auto& dev : w.devices) {
    const OrientedBox b = dev.footprint();
    const Vec2 l = b.pose.to_local(p);
    const double dx = std::max(std::abs(l.x()) - b.half_extents.x(), 0.0);
    const double dy = std::max(std::abs(l.y()) - b.half_extents.y(), 0.0);
    const double inside =
        std::max(std::abs(l.x()) - b.half_extents.x(), std::abs(l.y()) - b.half_extents.y());
    d = std::min(d, (dx > 0.0 || dy > 0.0) ? std::hypot(dx, dy) : inside);
  }
  return d;
}

// Minimum oracle clearance along a path, sampled every millimetre.
double path_clearance(const Path& path) {
  double m = 1e9;
  for (std::size_t i = 1; i < path.points.size(); ++i) {
    const Vec2 a = path.points[i - 1], b = path.points[i];
    const int n = std::max(1, static_cast<int>((b - a).norm() / 0.001));
    for (int k = 0; k <= n; ++k) m = std::min(m, world_clearance(a + (b - a) * (double(k) / n)));
  }
  return m;
}

// The free points of a 2013 field on a coarse grid (starts and goals for queries).
std::vector<Vec2> free_grid(const Planner& p, double step) {
  std::vector<Vec2> out;
  for (double x = step / 2; x < 5.6; x += step)
    for (double y = step / 2; y < 5.6; y += step)
      if (p.is_free({x, y})) out.push_back({x, y});
  return out;
}

}  // namespace

TEST_CASE("the game's map carries the world's obstacles: no free point inside a box") {
  // The planner tests build their map with the game's own function (sim::field_map_from_world),
  // so a scenario's obstacles reach the planner as they do in a game.
  const core::Vec2 spot(4.9, 1.7);          // between M1 and the delivery gates, no place near
  REQUIRE(shared_planner().is_free(spot));  // free without the box
  kinematic::WorldConfig w = world2013();
  w.obstacles.push_back({"box1", {spot.x(), spot.y(), 0.0}, 0.4, 0.4});
  const FieldMap f = field_map_from_world(w);
  REQUIRE(f.obstacles.size() == 1);
  CHECK(f.obstacles.front().name == "box1");
  const Planner p(f, PlannerConfig{});
  CHECK_FALSE(p.is_free(spot));
  CHECK_FALSE(p.is_free(spot + core::Vec2(0.2 + 0.5 * p.config().inflated_radius_m(), 0.0)));
}

TEST_CASE("the static map's exact checks agree with FCL and with the world's geometry") {
  const FieldMap f = field_map_from_world(world2013());
  const detail::StaticMap map(f, 0.26);
  const test::FclOracle fcl(map);
  core::RandomStream rng(7);
  int inside = 0;
  for (int k = 0; k < 2000; ++k) {
    const Vec2 p(rng.uniform(0.0, 5.6), rng.uniform(0.0, 5.6));
    int w1 = 0, w2 = 0;
    const double mine = map.signed_distance(p, &w1);
    const double theirs = fcl.distance(p, &w2);
    const double oracle = world_clearance(p);
    CHECK(mine == doctest::Approx(oracle).epsilon(1e-9));
    if (mine > 0.0) {
      CHECK(theirs == doctest::Approx(mine).epsilon(1e-6));
      CHECK(map.obstacle_name(w1) == map.obstacle_name(w2));
    } else {
      ++inside;
      CHECK(theirs == 0.0);
    }
    CHECK(map.point_free(p) == (mine >= 0.26));
  }
  CHECK(inside > 0);
}

TEST_CASE("segment checks are exact: a segment grazing a box corner") {
  FieldMap f;
  f.obstacles.push_back({"box", OrientedBox{Pose2D{2.0, 2.0, 0.0}, Vec2(0.1, 0.1)}});
  const detail::StaticMap map(f, 0.2);
  // Passing the corner (2.1, 2.1) at 0.2 + 1 mm and at 0.2 - 1 mm, diagonally.
  const Vec2 dir = Vec2(1.0, -1.0).normalized();
  const Vec2 n = Vec2(1.0, 1.0).normalized();
  const Vec2 c(2.1, 2.1);
  CHECK(map.segment_free(c + n * 0.201 - dir, c + n * 0.201 + dir));
  CHECK_FALSE(map.segment_free(c + n * 0.199 - dir, c + n * 0.199 + dir));
  // Both ends free, the middle crosses the box.
  CHECK_FALSE(map.segment_free({1.0, 2.0}, {3.0, 2.0}));
}

TEST_CASE("the FCL oracle measures segments: a box beside, across and at its corner") {
  FieldMap f;
  f.obstacles.push_back({"box", OrientedBox{Pose2D{2.0, 2.0, 0.0}, Vec2(0.1, 0.1)}});
  const detail::StaticMap map(f, 0.2);
  const test::FclOracle fcl(map);
  int which = -9;
  CHECK(fcl.segment_distance({1.5, 2.3}, {2.5, 2.3}, &which) == doctest::Approx(0.2).epsilon(1e-6));
  CHECK(which == 0);
  CHECK(fcl.segment_distance({1.5, 2.0}, {2.5, 2.0}) == 0.0);  // through the box
  // Diagonally past the corner (2.1, 2.1) at 0.2 m.
  const Vec2 n = Vec2(1.0, 1.0).normalized(), dir = Vec2(1.0, -1.0).normalized();
  const Vec2 c = Vec2(2.1, 2.1) + 0.2 * n;
  CHECK(fcl.segment_distance(c - dir, c + dir) == doctest::Approx(0.2).epsilon(1e-6));
  CHECK(test::FclOracle::segment_disc_distance({0.0, 1.0}, {2.0, 1.0}, {1.0, 1.5}, 0.26) ==
        doctest::Approx(0.24).epsilon(1e-6));
  CHECK(test::FclOracle::segment_disc_distance({0.0, 1.0}, {2.0, 1.0}, {1.0, 1.2}, 0.26) == 0.0);
}

TEST_CASE("planned paths: the robot's footprint swept along them, checked with FCL") {
  // Every segment of every found path, as a capsule, against FCL's walls and boxes and against
  // the other robots as cylinders: the swept footprint keeps the inflated radius from the map
  // and radius + clearance from the discs (FCL's GJK distance, to 1 um). Paths graze the limit:
  // asking 1 mm more fails 7 segments.
  Planner& p = shared_planner();
  const detail::StaticMap map(field_map_from_world(world2013()), p.config().inflated_radius_m());
  const test::FclOracle fcl(map);
  const auto pts = free_grid(p, 0.3);
  core::RandomStream rng(11);
  const double r = p.config().inflated_radius_m();
  constexpr double kClearance = 0.05;
  constexpr double kTol = 1e-6;
  int found = 0, around = 0;
  for (int k = 0; k < 200; ++k) {
    const Vec2& a = pts[rng.uniform_int(0, static_cast<int>(pts.size()) - 1)];
    const Vec2& b = pts[rng.uniform_int(0, static_cast<int>(pts.size()) - 1)];
    // Up to three other robots, off the start and the goal.
    std::vector<DiscObstacle> discs;
    const int n = rng.uniform_int(0, 3);
    while (static_cast<int>(discs.size()) < n) {
      const Vec2& c = pts[rng.uniform_int(0, static_cast<int>(pts.size()) - 1)];
      if ((c - a).norm() > 2 * r + kClearance + 0.1 && (c - b).norm() > 2 * r + kClearance + 0.1) {
        discs.push_back({static_cast<int>(discs.size()), c, r});
      }
    }
    const PlanResult res =
        p.plan({{a.x(), a.y(), 0.0}, {b.x(), b.y(), 1.0}, discs, kClearance, rng.next_u64()});
    if (res.status != PlanStatus::kFound) continue;
    ++found;
    if (!discs.empty()) ++around;
    for (std::size_t i = 1; i < res.path.points.size(); ++i) {
      const Vec2& s0 = res.path.points[i - 1];
      const Vec2& s1 = res.path.points[i];
      int which = 0;
      const double d = fcl.segment_distance(s0, s1, &which);
      INFO("query ", k, " segment ", i, " nearest ", map.obstacle_name(which));
      CHECK(d >= r - kTol);
      for (const DiscObstacle& o : discs) {
        CHECK(test::FclOracle::segment_disc_distance(s0, s1, o.position, o.radius_m) >=
              r + kClearance - kTol);
      }
    }
  }
  CHECK(found > 150);
  CHECK(around > 100);
}

TEST_CASE("places: names, poses facing the devices, and the held puck in the RFID zone") {
  const Planner& p = shared_planner();
  const auto& w = world2013();
  const double held = p.config().places.held_puck_offset_m;
  for (int i = 0; i < kinematic::kDeviceCount; ++i) {
    const std::string name(kinematic::device_name(core::DeviceId(i)));
    const Place* in = p.place(name + "_input");
    REQUIRE(in != nullptr);
    CHECK(p.place(name) == in);  // the bare name is the input place
    // The puck held at the robot's front lies on the RFID zone centre.
    const Vec2 puck = in->pose.position() + held * core::unit(in->pose.theta);
    CHECK((puck - w.devices[i].rfid_center()).norm() < 1e-9);
    // The robot faces the device.
    CHECK(std::abs(core::angle_diff(in->pose.theta, w.devices[i].pose.theta + core::kPi)) < 1e-9);
    REQUIRE(p.place(name + "_look") != nullptr);
    const bool production = i < 10;
    CHECK((p.place(name + "_left") != nullptr) == production);
    CHECK((p.place(name + "_right") != nullptr) == production);
  }
  for (const char* n : {"INS_1", "INS_5", "LATE_ORDER", "WAIT_INS", "WAIT_DELIVERY"})
    CHECK(p.place(n) != nullptr);
  CHECK(p.place("INS_6") == nullptr);
  CHECK(p.place("nowhere") == nullptr);
  // M1 faces down (3pi/2): its input place lies below it, the robot facing up.
  const Place* m1 = p.place("M1");
  CHECK(m1->pose.x == doctest::Approx(3.92));
  CHECK(m1->pose.y == doctest::Approx(1.68 - 0.14 - 0.2225));
  CHECK(m1->pose.theta == doctest::Approx(core::kPi / 2));
  // Left/right as seen by the robot facing M1 (facing +y): left is -x.
  CHECK(p.place("M1_left")->target.x() < 3.92);
  CHECK(p.place("M1_right")->target.x() > 3.92);
  // The late-order place holds the puck on the slot, facing the wall.
  const Place* late = p.place("LATE_ORDER");
  CHECK((late->pose.position() + held * core::unit(late->pose.theta) - Vec2(0.2, 3.6)).norm() <
        1e-9);
  // Every place is free.
  for (const Place& pl : p.places()) {
    INFO(pl.name);
    CHECK(p.is_free(pl.pose.position()));
    CHECK(world_clearance(pl.pose.position()) >= p.config().inflated_radius_m() - 1e-9);
  }
}

TEST_CASE("every named place is reachable from the insertion area, keeping the clearance") {
  Planner& p = shared_planner();
  const double r = p.config().inflated_radius_m();
  int escaped = 0;
  std::uint64_t seed = 1;
  for (const Pose2D start :
       {Pose2D{0.20, 0.40, 0.0}, Pose2D{0.20, 1.00, 0.0}, Pose2D{0.20, 1.60, 0.0}}) {
    for (const Place& pl : p.places()) {
      INFO(pl.name);
      const PlanResult res = p.plan({start, pl.pose, {}, 0.0, seed++});
      REQUIRE(res.status == PlanStatus::kFound);
      CHECK(res.path.points.front() == start.position());
      CHECK(res.path.points.back() == pl.pose.position());
      CHECK(res.path.goal_theta == doctest::Approx(pl.pose.theta));
      // The insertion poses lie in the margin (0.2 m from the wall): the path first leaves it,
      // then keeps the full clearance.
      Path rest = res.path;
      if (res.escaped_start) {
        ++escaped;
        CHECK((rest.points[1] - rest.points[0]).norm() <= p.config().start_escape_m + 1e-9);
        rest.points.erase(rest.points.begin());
      }
      CHECK(path_clearance(rest) >= r - 1e-6);
    }
  }
  CHECK(escaped > 0);
}

TEST_CASE("random queries: every path keeps the required clearance") {
  Planner& p = shared_planner();
  const auto pts = free_grid(p, 0.3);
  core::RandomStream rng(3);
  const double r = p.config().inflated_radius_m();
  int detours = 0;
  for (int k = 0; k < 300; ++k) {
    const Vec2& a = pts[rng.uniform_int(0, static_cast<int>(pts.size()) - 1)];
    const Vec2& b = pts[rng.uniform_int(0, static_cast<int>(pts.size()) - 1)];
    const PlanResult res =
        p.plan({{a.x(), a.y(), 0.0}, {b.x(), b.y(), 1.0}, {}, 0.0, rng.next_u64()});
    REQUIRE(res.status == PlanStatus::kFound);
    CHECK_FALSE(res.escaped_start);
    if (res.path.points.size() > 2) ++detours;
    CHECK(path_clearance(res.path) >= r - 1e-6);
    // Never much longer than needed: within 2x the straight line plus a detour round a machine.
    CHECK(res.path.length_m() <= 2.0 * (b - a).norm() + 1.5);
  }
  CHECK(detours > 50);  // the field forces detours; the test is not only about straight lines
}

TEST_CASE("a goal inside an obstacle is rejected with a clear error") {
  Planner& p = shared_planner();
  const Pose2D start{0.6, 0.6, 0.0};
  PlanResult res = p.plan({start, {2.80, 0.56, 0.0}, {}, 0.0, 1});  // M3's centre
  CHECK(res.status == PlanStatus::kInvalidGoal);
  CHECK(res.message.find("inside M3") != std::string::npos);
  res = p.plan({start, {2.80, 0.80, 0.0}, {}, 0.0, 1});  // in front of M3, too close
  CHECK(res.status == PlanStatus::kInvalidGoal);
  CHECK(res.message.find("from M3") != std::string::npos);
  CHECK(res.message.find("needs 0.260 m") != std::string::npos);
  res = p.plan({start, {0.1, 4.5, 0.0}, {}, 0.0, 1});
  CHECK(res.status == PlanStatus::kInvalidGoal);
  CHECK(res.message.find("wall x=0") != std::string::npos);
  res = p.plan({start, {7.0, 1.0, 0.0}, {}, 0.0, 1});
  CHECK(res.status == PlanStatus::kInvalidGoal);
  CHECK(res.message == "goal (7.000, 1.000) lies outside the field [0, 5.60] x [0, 5.60]");
}

TEST_CASE("an unreachable goal gives no path") {
  // A pen of four boards in the field's middle: free inside, closed all round.
  FieldMap f;
  auto board = [&](const char* name, double x, double y, double hx, double hy) {
    f.obstacles.push_back({name, OrientedBox{Pose2D{x, y, 0.0}, Vec2(hx, hy)}});
  };
  board("pen south", 2.8, 2.0, 0.9, 0.05);
  board("pen north", 2.8, 3.6, 0.9, 0.05);
  board("pen west", 2.0, 2.8, 0.05, 0.85);
  board("pen east", 3.6, 2.8, 0.05, 0.85);
  Planner p(f, PlannerConfig{});
  REQUIRE(p.is_free({2.8, 2.8}));
  const PlanResult res = p.plan({{0.6, 0.6, 0.0}, {2.8, 2.8, 0.0}, {}, 0.0, 5});
  CHECK(res.status == PlanStatus::kNoPath);
  CHECK(res.message.find("no path") != std::string::npos);
  CHECK(res.iterations == p.config().max_iterations);
  // The same map still plans round the pen.
  CHECK(p.plan({{0.6, 0.6, 0.0}, {5.0, 5.0, 0.0}, {}, 0.0, 5}).status == PlanStatus::kFound);
}

TEST_CASE("other robots as discs: planned around, and a goal they occupy is reported") {
  Planner& p = shared_planner();
  const Pose2D a{1.0, 2.25, 0.0}, b{4.6, 2.25, 0.0};
  REQUIRE(p.plan({a, b, {}, 0.0, 1}).path.points.size() == 2);  // straight without robots
  const DiscObstacle robot{7, {2.2, 2.25}, 0.26};
  const std::vector<DiscObstacle> obs{robot};
  const PlanResult res = p.plan({a, b, obs, 0.05, 1});
  REQUIRE(res.status == PlanStatus::kFound);
  CHECK(res.path.points.size() > 2);
  for (std::size_t i = 1; i < res.path.points.size(); ++i) {
    CHECK(detail::segment_point_distance(res.path.points[i - 1], res.path.points[i],
                                         robot.position) >= 0.26 + 0.26 + 0.05 - 1e-9);
  }
  const PlanResult occ = p.plan({a, {2.3, 2.25, 0.0}, obs, 0.05, 1});
  CHECK(occ.status == PlanStatus::kGoalOccupied);
  CHECK(occ.blocked_by == 7);
}

TEST_CASE("same seed, same path; different seeds explore differently") {
  Planner& p = shared_planner();
  const Pose2D a{0.6, 0.6, 0.0}, b{4.5, 4.8, 0.0};
  const std::vector<DiscObstacle> obs{{1, {2.2, 2.2}, 0.26}, {2, {3.4, 3.4}, 0.26}};
  const PlanResult r1 = p.plan({a, b, obs, 0.05, 42});
  p.plan({b, a, obs, 0.0, 9});  // an unrelated query in between
  const PlanResult r2 = p.plan({a, b, obs, 0.05, 42});
  REQUIRE(r1.status == PlanStatus::kFound);
  CHECK(r1.path.points == r2.path.points);
  // A second planner (a second game) gives the same path for the same request.
  Planner q(field_map_from_world(world2013()), PlannerConfig{});
  CHECK(q.plan({a, b, obs, 0.05, 42}).path.points == r1.path.points);
  int differ = 0;
  for (std::uint64_t s = 1; s <= 10; ++s) {
    differ += p.plan({a, b, obs, 0.05, s}).path.points != r1.path.points;
  }
  CHECK(differ > 0);
}

TEST_CASE("two games planning in parallel threads do not change each other's paths") {
  // Reference: each game's query sequence alone.
  auto game = [](std::uint64_t seed) {
    Planner p(field_map_from_world(world2013()), PlannerConfig{});
    core::RandomStream rng(seed);
    const auto pts = free_grid(p, 0.4);
    std::vector<std::vector<Vec2>> paths;
    for (int k = 0; k < 150; ++k) {
      const Vec2& a = pts[rng.uniform_int(0, static_cast<int>(pts.size()) - 1)];
      const Vec2& b = pts[rng.uniform_int(0, static_cast<int>(pts.size()) - 1)];
      const std::vector<DiscObstacle> obs{{1, 0.5 * (a + b), 0.2}};
      const PlanResult res =
          p.plan({{a.x(), a.y(), 0.0}, {b.x(), b.y(), 0.0}, obs, 0.0, rng.next_u64()});
      paths.push_back(res.path.points);
    }
    return paths;
  };
  const auto ref1 = game(1), ref2 = game(2);
  std::vector<std::vector<Vec2>> got1, got2;
  std::thread t1([&] { got1 = game(1); });
  std::thread t2([&] { got2 = game(2); });
  t1.join();
  t2.join();
  CHECK(got1 == ref1);
  CHECK(got2 == ref2);
  CHECK(ref1 != ref2);
}

TEST_CASE("bad maps and configs are rejected naming the field") {
  FieldMap f;
  f.obstacles.push_back({"a", OrientedBox{Pose2D{1.0, 1.0, 0.0}, Vec2(0.1, 0.1)}});
  f.obstacles.push_back({"a", OrientedBox{Pose2D{2.0, 1.0, 0.0}, Vec2(0.1, 0.1)}});
  CHECK_THROWS_WITH_AS(Planner(f, PlannerConfig{}),
                       doctest::Contains("field.obstacles[1].name: duplicate name a"),
                       core::ConfigError);
  f.obstacles.pop_back();
  f.obstacles.push_back({"out", OrientedBox{Pose2D{5.55, 1.0, 0.0}, Vec2(0.1, 0.1)}});
  CHECK_THROWS_WITH_AS(Planner(f, PlannerConfig{}), doctest::Contains("outside the field"),
                       core::ConfigError);
  PlannerConfig c;
  c.safety_margin_m = -0.1;
  CHECK_THROWS_WITH_AS(Planner(FieldMap{}, c), doctest::Contains("planner.safety_margin_m"),
                       core::ConfigError);
  // A user place inside a machine.
  PlannerConfig u;
  u.places.extra.push_back({"bad", Pose2D{2.8, 0.56, 0.0}});
  CHECK_THROWS_WITH_AS(Planner(field_map_from_world(world2013()), u),
                       doctest::Contains("places.bad: pose (2.800, 0.560) is"), core::ConfigError);
}

TEST_CASE("the YAML loader reads both sections and reports bad values at their line") {
  const auto node = core::ConfigNode::parse(
      "planner:\n  safety_margin_m: 0.05\n  places:\n    extra:\n      - {name: P1, x: 1.0, "
      "y: 1.0, theta_deg: 90}\ncontroller:\n  max_speed_mps: 0.5\n",
      "nav.yaml");
  const NavigationConfig c = load_navigation_config(node);
  CHECK(c.planner.safety_margin_m == 0.05);
  CHECK(c.controller.max_speed_mps == 0.5);
  REQUIRE(c.planner.places.extra.size() == 1);
  CHECK(c.planner.places.extra[0].pose.theta == doctest::Approx(core::kPi / 2));
  CHECK_THROWS_WITH_AS(load_navigation_config(
                           core::ConfigNode::parse("controller:\n  max_speed_mps: -1\n", "n.yaml")),
                       "n.yaml:2:18: controller.max_speed_mps: must be in (0, 10] (got -1)",
                       core::ConfigError);
  CHECK_THROWS_WITH_AS(
      load_navigation_config(core::ConfigNode::parse("planner:\n  safety_margn_m: 1\n", "n.yaml")),
      doctest::Contains("safety_margn_m"), core::ConfigError);
  CHECK_THROWS_WITH_AS(load_navigation_config(core::ConfigNode::parse(
                           "planner:\n  places:\n    extra: 5\n", "n.yaml")),
                       doctest::Contains("n.yaml:3:12: planner.places.extra: expected a list"),
                       core::ConfigError);
  CHECK_THROWS_WITH_AS(load_navigation_config(
                           core::ConfigNode::parse("planner:\n  max_iterations: many\n", "n.yaml")),
                       doctest::Contains("n.yaml:2:19"), core::ConfigError);
  CHECK_THROWS_WITH_AS(load_navigation_config(core::ConfigNode::parse(
                           "controller:\n  backoff_min_s: 2\n  backoff_max_s: 1\n", "n.yaml")),
                       "n.yaml:3:18: controller.backoff_max_s: must be >= backoff_min_s (got 1)",
                       core::ConfigError);
}

TEST_CASE("every navigation figure has an upper bound, reported at its key") {
  const auto error_of = [](const std::string& yaml) -> std::string {
    try {
      load_navigation_config(core::ConfigNode::parse(yaml, "n.yaml"));
    } catch (const core::ConfigError& e) {
      return e.what();
    }
    return "(no error)";
  };
  // Each of these used to load.
  CHECK(error_of("controller:\n  wait_before_replan_s: 1e300\n") ==
        "n.yaml:2:25: controller.wait_before_replan_s: must be in [0, 60] (got 1e+300)");
  CHECK(error_of("controller:\n  max_speed_mps: 1e300\n") ==
        "n.yaml:2:18: controller.max_speed_mps: must be in (0, 10] (got 1e+300)");
  CHECK(error_of("controller:\n  replan_jitter_s: 61\n") ==
        "n.yaml:2:20: controller.replan_jitter_s: must be in [0, 60] (got 61)");
  CHECK(error_of("controller:\n  backoff_max_s: 1e300\n") ==
        "n.yaml:2:18: controller.backoff_max_s: must be in [0, 60] (got 1e+300)");
  CHECK(error_of("controller:\n  blocked_timeout_s: 1e300\n") ==
        "n.yaml:2:22: controller.blocked_timeout_s: must be in (0, 3600] (got 1e+300)");
  CHECK(error_of("controller:\n  obstacle_lookahead_m: 1e300\n") ==
        "n.yaml:2:25: controller.obstacle_lookahead_m: must be in (0, 100] (got 1e+300)");
  CHECK(error_of("planner:\n  rrt_range_m: 1e300\n") ==
        "n.yaml:2:16: planner.rrt_range_m: must be in (0, 100] (got 1e+300)");
  CHECK(error_of("planner:\n  accept_ratio: 1e300\n") ==
        "n.yaml:2:17: planner.accept_ratio: must be in [1, 100] (got 1e+300)");
  CHECK(error_of("planner:\n  places:\n    wait_lateral_m: -1e300\n") ==
        "n.yaml:3:21: planner.places.wait_lateral_m: must be in [-100, 100] (got -1e+300)");
  CHECK(error_of("planner:\n  places:\n    extra:\n      - {name: P, x: 1e300, y: 1}\n") ==
        "n.yaml:4:22: planner.places.extra[0].x: must be in [-1000, 1000] (got 1e+300)");
  // The bounds themselves load.
  CHECK(error_of("controller:\n  wait_before_replan_s: 60\n  max_speed_mps: 10\n"
                 "  blocked_timeout_s: 3600\n  backoff_max_s: 60\n") == "(no error)");
  // validate() applies them to a config built in code.
  ControllerConfig c;
  c.wait_before_replan_s = 1e300;
  CHECK_THROWS_WITH_AS(c.validate(),
                       "controller.wait_before_replan_s: must be in [0, 60] (got 1e+300)",
                       core::ConfigError);
}
