// SPDX-License-Identifier: MIT
// The move_base-2013 navigation level in whole games (docs/planner.md, "move_base-2013"):
// other robots known only through the laser, recoveries, aborts. What happens (time to pass,
// recoveries) is measured and printed, never asserted to a target; the assertions are about
// mechanisms (a costmap that marks and clears, the recovery sequence, the abort after it).
#include <doctest/doctest.h>

#include <cmath>
#include <cstdio>
#include <memory>
#include <string>

#include "fixture.h"
#include "llsf/planner/move_base.h"
#include "llsf/sim/game.h"

using namespace llsf;
using namespace llsf::sim;

namespace {

// Two robots at the given poses, move_base-2013 navigation, the laser on, no agents. move_base
// alone (goals straight to it, as the skills' relgoto) unless `navgraph` (Fawkes' navgraph
// leads it, as ppgoto).
GameConfig two_robots(const core::Pose2D& a, const core::Pose2D& b, bool navgraph = false) {
  GameConfig c = test::small_game(2, 3);
  c.levels.move_base.navgraph = navgraph;
  c.world.sensors.laser.enabled = true;
  c.world.robots[0].pose = a;
  c.world.robots[1].pose = b;
  c.levels.navigation = NavigationLevel::kMoveBase2013;
  // The 2013 move_base limits for the world's robot as well (docs/profiles.md).
  c.world.robot.max_speed_mps = 0.5;
  c.world.robot.max_omega_rps = 0.78;
  c.world.robot.max_accel_mps2 = 2.5;
  c.world.robot.max_alpha_rps2 = 3.2;
  return c;
}

struct Run {
  double seconds = 0.0;
  planner::NavOutcome a = planner::NavOutcome::kIdle;
  planner::NavOutcome b = planner::NavOutcome::kIdle;
  planner::MoveBaseStats sa;
  planner::MoveBaseStats sb;
};

planner::MoveBaseStats stats_of(const Game& g, int i) {
  const planner::MoveBaseNavigator* m = g.robot(i).move_base();
  REQUIRE(m != nullptr);
  planner::MoveBaseStats s = m->totals();
  const planner::MoveBaseStats& c = m->stats();
  if (m->status().outcome == planner::NavOutcome::kRunning) {
    s.recoveries += c.recoveries;
    s.rotate_recoveries += c.rotate_recoveries;
    s.recovery_s += c.recovery_s;
    s.plans += c.plans;
    s.waypoints += c.waypoints;
    s.resends += c.resends;
    s.aborts += c.aborts;
  }
  return s;
}

// Plays until both navigations ended (or `max_s`), A to `ga`, B to `gb` (B stays if null).
Run play(Game& g, const core::Pose2D& ga, const core::Pose2D* gb, double max_s) {
  g.robot(0).goto_pose(ga, false);
  if (gb != nullptr) g.robot(1).goto_pose(*gb, false);
  const SimTime end = g.time() + SimTime::from_seconds(max_s);
  auto running = [&](int i) {
    return g.robot(i).nav_status().outcome == planner::NavOutcome::kRunning;
  };
  while (g.time() < end && (running(0) || running(1))) g.step();
  Run r;
  r.seconds = g.time().seconds();
  r.a = g.robot(0).nav_status().outcome;
  r.b = g.robot(1).nav_status().outcome;
  r.sa = stats_of(g, 0);
  r.sb = stats_of(g, 1);
  return r;
}

void report(const std::string& what, const Run& r) {
  MESSAGE(what << ": " << r.seconds << " s; A " << std::string(planner::to_string(r.a)) << ", "
               << r.sa.recoveries << " recoveries (" << r.sa.rotate_recoveries << " rotations), "
               << r.sa.plans << " plans; B " << std::string(planner::to_string(r.b)) << ", "
               << r.sb.recoveries << " recoveries");
}

}  // namespace

TEST_CASE("move_base-2013: a lone robot crosses the field and stops within the 2013 tolerance") {
  GameConfig c = two_robots({0.8, 0.8, 0.0}, {0.5, 5.0, 0.0});
  Game g(c);
  const core::Pose2D goal{4.6, 4.6, core::kPi / 2};
  const Run r = play(g, goal, nullptr, 60.0);
  report("lone robot", r);
  CHECK(r.a == planner::NavOutcome::kArrived);
  const core::Pose2D p = g.world().robot_pose(core::RobotId(0));
  CHECK((p.position() - goal.position()).norm() <= 0.15 + 0.02);
  CHECK(r.sa.recoveries == 0);
}

TEST_CASE("move_base-2013: a pose at a machine is reached by move_base, then a straight approach") {
  GameConfig c = two_robots({1.2, 0.6, 0.0}, {0.5, 5.0, 0.0});
  Game g(c);
  const planner::Place* m4 = g.planner().place("M4_input");
  REQUIRE(m4 != nullptr);
  // The input place lies inside move_base's inscribed radius of M4's footprint.
  const planner::MoveBaseNavigator* m = g.robot(0).move_base();
  REQUIRE(m != nullptr);
  CHECK(m->global_costmap().cost_at(m4->pose.position()) >= planner::Costmap::kInscribed);
  const Run r = play(g, m4->pose, nullptr, 60.0);
  report("to M4_input", r);
  CHECK(r.a == planner::NavOutcome::kArrived);
  const core::Pose2D p = g.world().robot_pose(core::RobotId(0));
  CHECK((p.position() - m4->pose.position()).norm() <= 0.03);
}

TEST_CASE("move_base-2013: two robots meet head-on, each going to the other's start") {
  struct Meeting {
    const char* where;
    core::Pose2D a;
    core::Pose2D b;
  };
  const Meeting meetings[] = {
      // The 0.87 m gap between M8 (x <= 1.78) and M4 (x >= 2.65).
      {"between M8 and M4", {2.215, 0.95, core::kPi / 2}, {2.215, 2.45, -core::kPi / 2}},
      // Along M5's front, one from below, one from above.
      {"beside M5", {2.2, 2.0, core::kPi / 2}, {2.2, 3.5, -core::kPi / 2}},
  };
  for (const Meeting& m : meetings) {
    CAPTURE(std::string(m.where));
    GameConfig c = two_robots(m.a, m.b);
    Game g(c);
    const Run r = play(g, m.b, &m.a, 240.0);
    report(std::string("head-on ") + m.where, r);
    // Both navigations end: arrived, or aborted after move_base's recovery sequence.
    CHECK(r.a != planner::NavOutcome::kRunning);
    CHECK(r.b != planner::NavOutcome::kRunning);
  }
}

TEST_CASE("move_base-2013: a parked robot in the gap is seen, marked and driven round") {
  const core::Pose2D a{2.215, 0.95, core::kPi / 2};
  const core::Pose2D parked{2.215, 1.68, 0.0};
  GameConfig c = two_robots(a, parked);
  Game g(c);
  const core::Pose2D goal{2.215, 2.45, core::kPi / 2};
  g.robot(0).goto_pose(goal, false);
  // Within a second the laser has put the parked robot into both costmaps.
  for (int i = 0; i < 100; ++i) g.step();
  const planner::MoveBaseNavigator* m = g.robot(0).move_base();
  REQUIRE(m != nullptr);
  CHECK(m->local_costmap().cost_at(parked.position(), false) >= planner::Costmap::kInscribed);
  CHECK(m->global_costmap().cost_at(parked.position()) >= planner::Costmap::kInscribed);
  const Run r = play(g, goal, nullptr, 240.0);
  report("parked robot in the gap", r);
  CHECK(r.a != planner::NavOutcome::kRunning);
}

TEST_CASE("move_base-2013: the costmap clears once the other robot has left") {
  const core::Pose2D a{1.0, 0.7, 0.0};
  const core::Pose2D b{1.0, 1.3, 0.0};
  GameConfig c = two_robots(a, b);
  Game g(c);
  // A turns on the spot (a long, slow navigation goal beside it keeps its costmaps running).
  g.robot(0).goto_pose({1.0, 0.7, core::kPi}, false);
  for (int i = 0; i < 60; ++i) g.step();
  const planner::MoveBaseNavigator* m = g.robot(0).move_base();
  REQUIRE(m != nullptr);
  CHECK(m->local_costmap().cost_at(b.position(), false) >= planner::Costmap::kInscribed);
  // B leaves; once it is gone, A drives along (its costmaps update only while it navigates)
  // and its beams pass through B's old place.
  g.robot(1).goto_pose({0.6, 4.6, 0.0}, false);
  for (int i = 0; i < 500; ++i) g.step();
  g.robot(0).goto_pose({2.2, 0.7, 0.0}, false);
  for (int i = 0; i < 300; ++i) g.step();
  CHECK(m->global_costmap().cost_at(b.position()) < planner::Costmap::kInscribed);
}

TEST_CASE("move_base-2013: a goal another robot stands on ends in move_base's abort") {
  const core::Pose2D a{1.0, 0.7, 0.0};
  const core::Pose2D parked{3.4, 0.7, 0.0};
  GameConfig c = two_robots(a, parked);
  Game g(c);
  const Run r = play(g, parked, nullptr, 300.0);
  report("goal occupied", r);
  // The whole default sequence ran (conservative reset, rotation, aggressive reset, rotation;
  // a plan found in between -- the aggressive reset forgets the other robot until the laser
  // marks it again -- starts it over), then move_base gave up: no plan.
  CHECK(r.a == planner::NavOutcome::kNoPath);
  CHECK(r.sa.recoveries >= 4);
  CHECK(r.sa.rotate_recoveries >= 2);
  CHECK(r.sa.recovery_s > 10.0);  // full turns at up to 0.78 rad/s
  CHECK(g.robot(0).nav_status().message.find("even after executing recovery behaviors") !=
        std::string::npos);
}

// A, led by the navigation graph, to `goal`; B stands at `b`.
Run graph_run(const char* what, const core::Pose2D& a, const core::Pose2D& b,
              const core::Pose2D& goal, Game*& game, std::unique_ptr<Game>& holder) {
  holder = std::make_unique<Game>(two_robots(a, b, true));
  game = holder.get();
  const Run r = play(*game, goal, nullptr, 120.0);
  report(what, r);
  MESSAGE("  ", r.sa.waypoints, " nodes passed, ", r.sa.resends, " resends, ", r.sa.aborts,
          " aborts outlived");
  return r;
}

TEST_CASE("move_base-2013 with the navigation graph: corridor nodes, resends, no abort") {
  Game* g = nullptr;
  std::unique_ptr<Game> holder;
  // Across the field: the route passes the graph's corridor nodes and arrives.
  const core::Pose2D far{4.7, 4.4, 0.0};
  const Run across =
      graph_run("graph across the field", {1.0, 0.7, 0.0}, {0.5, 5.0, 0.0}, far, g, holder);
  CHECK(across.a == planner::NavOutcome::kArrived);
  CHECK(across.sa.waypoints >= 3);
  CHECK((g->world().robot_pose(core::RobotId(0)).position() - far.position()).norm() <=
        0.25 + 1e-9);
  // A goal another robot stands on: move_base plans in vain and starts its recoveries; the graph
  // sends the goal again every 6 s (which starts move_base over before its sequence can end in
  // an abort) and never gives up -- the 2013 robot had no timeout (thesis section 6.2).
  const core::Pose2D occupied{3.4, 2.15, 0.0};
  const Run blocked =
      graph_run("graph, goal occupied", {1.0, 0.7, 0.0}, occupied, occupied, g, holder);
  CHECK(blocked.a == planner::NavOutcome::kRunning);
  CHECK(blocked.sa.recoveries >= 1);
  CHECK(blocked.sa.resends >= 5);
}
