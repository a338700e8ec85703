// SPDX-License-Identifier: MIT
// Navigator and path follower, driving real robots in the kinematic world.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>

#include "world_fixture.h"

using namespace llsf;
using namespace llsf::planner;
using llsf::test::NavScene;
using llsf::test::test_world;

namespace {

const Pose2D kIns1{0.20, 0.40, 0.0};
const Pose2D kIns2{0.20, 1.00, 0.0};
const Pose2D kIns3{0.20, 1.60, 0.0};

}  // namespace

TEST_CASE("a robot drives from the insertion area to a machine and lands the puck spot") {
  NavScene scene(test_world({kIns1}), 1);
  const Place* m1 = scene.planner().place("M1");
  REQUIRE(m1 != nullptr);
  scene.nav(0).go_to_place("M1");
  const double t = scene.run(30.0);
  const NavStatus& st = scene.nav(0).status();
  REQUIRE(st.outcome == NavOutcome::kArrived);
  CHECK(t < 15.0);
  const Pose2D pose = scene.world().robot_pose(core::RobotId(0));
  const ControllerConfig cc;
  CHECK((pose.position() - m1->pose.position()).norm() <= cc.position_tolerance_m + 0.005);
  CHECK(std::abs(core::angle_diff(pose.theta, m1->pose.theta)) <= cc.angle_tolerance_rad + 0.01);
  // A puck held at the front would lie in M1's RFID read zone (radius 0.05 m).
  const Vec2 puck = pose.position() + 0.2225 * core::unit(pose.theta);
  CHECK((puck - m1->target).norm() < 0.03);
  CHECK(scene.static_contacts() == 0);
  CHECK(scene.nav(0).stats().plans == 1);
  // Ended: the robot stops and stays.
  for (int i = 0; i < 100; ++i) scene.step();
  CHECK(scene.world().robot_pose(core::RobotId(0)).distance_to(pose) < 0.01);
}

TEST_CASE("driving to every place of one machine row: no contact with devices or walls") {
  NavScene scene(test_world({kIns2}), 3);
  for (const char* name : {"M8_look", "M4_left", "M3_input", "M4_right", "R1", "D2", "INS_3",
                           "LATE_ORDER", "M10_look", "TST", "WAIT_DELIVERY"}) {
    INFO(name);
    scene.nav(0).go_to_place(name);
    scene.run(40.0);
    CHECK(scene.nav(0).status().outcome == NavOutcome::kArrived);
  }
  CHECK(scene.static_contacts() == 0);
}

TEST_CASE("the follower keeps within the limits the world can follow") {
  ControllerConfig cc;
  PathFollower f(cc);
  f.set_path(Path{{{0.5, 0.5}, {2.0, 0.5}, {2.0, 2.0}}, core::kPi});
  Pose2D pose{0.5, 0.5, 0.0};
  VelocityCommand prev;
  const double dt = 0.01;
  Vec2 prev_world(0.0, 0.0);
  for (int i = 0; i < 1000 && !f.arrived(); ++i) {
    const VelocityCommand c = f.update(pose, dt);
    const Vec2 vw = core::rotate(Vec2(c.vx_mps, c.vy_mps), pose.theta);
    CHECK(vw.norm() <= cc.max_speed_mps + 1e-9);
    CHECK(std::abs(c.omega_rps) <= cc.max_omega_rps + 1e-9);
    CHECK((vw - prev_world).norm() <= cc.max_accel_mps2 * dt + 1e-9);
    CHECK(std::abs(c.omega_rps - prev.omega_rps) <= cc.max_alpha_rps2 * dt + 1e-9);
    // Turning while driving stays within the budget that keeps the path straight.
    CHECK(std::abs(c.omega_rps) * vw.norm() <= cc.max_accel_mps2 * (1.0 + 1e-9));
    // Ideal kinematics: the robot does what it is told.
    pose.x += vw.x() * dt;
    pose.y += vw.y() * dt;
    pose.theta = core::normalize_angle(pose.theta + c.omega_rps * dt);
    prev = c;
    prev_world = vw;
  }
  CHECK(f.arrived());
  CHECK(pose.distance_to({2.0, 2.0, 0.0}) <= cc.position_tolerance_m);
}

TEST_CASE("outcomes: no path, invalid goal, unknown place, aborted") {
  SUBCASE("no path") {
    // A pen of four boards: free inside, closed all round.
    FieldMap f;
    auto board = [&](const char* name, double x, double y, double hx, double hy) {
      f.obstacles.push_back({name, OrientedBox{Pose2D{x, y, 0.0}, Vec2(hx, hy)}});
    };
    board("pen south", 2.8, 2.0, 0.9, 0.05);
    board("pen north", 2.8, 3.6, 0.9, 0.05);
    board("pen west", 2.0, 2.8, 0.05, 0.85);
    board("pen east", 3.6, 2.8, 0.05, 0.85);
    Planner p(f, PlannerConfig{});
    Navigator nav(p, ControllerConfig{}, core::RandomStream(1));
    nav.go_to({2.8, 2.8, 0.0});
    const VelocityCommand c = nav.update(core::SimTime{}, {0.6, 0.6, 0.0}, {});
    CHECK(nav.status().outcome == NavOutcome::kNoPath);
    CHECK(nav.status().message.find("no path") != std::string::npos);
    CHECK(c == VelocityCommand{});
  }
  SUBCASE("invalid goal") {
    NavScene scene(test_world({kIns1}), 1);
    scene.nav(0).go_to({2.8, 2.8, 0.0});  // M5's centre
    scene.step();
    CHECK(scene.nav(0).status().outcome == NavOutcome::kInvalidGoal);
    CHECK(scene.nav(0).status().message.find("inside M5") != std::string::npos);
  }
  SUBCASE("unknown place") {
    NavScene scene(test_world({kIns1}), 1);
    scene.nav(0).go_to_place("M11");
    CHECK(scene.nav(0).status().outcome == NavOutcome::kInvalidGoal);
    CHECK(scene.nav(0).status().message == "unknown place 'M11'");
  }
  SUBCASE("aborted") {
    NavScene scene(test_world({kIns1}), 1);
    scene.nav(0).go_to_place("D1");
    for (int i = 0; i < 150; ++i) scene.step();
    scene.nav(0).abort();
    CHECK(scene.nav(0).status().outcome == NavOutcome::kAborted);
    for (int i = 0; i < 200; ++i) scene.step();
    CHECK(scene.world().robot_velocity(core::RobotId(0)).norm() < 1e-3);
  }
}

TEST_CASE("a robot standing in the way causes a replan") {
  // robot2 stands in the lane between the M8/M4 row and the M9/M5 row; robot1 crosses it.
  NavScene scene(test_world({{0.9, 2.25, 0.0}, {2.2, 2.25, 0.0}}), 5);
  scene.nav(0).go_to({4.6, 2.25, 0.0});
  scene.run(40.0);
  const Navigator& n = scene.nav(0);
  CHECK(n.status().outcome == NavOutcome::kArrived);
  CHECK(n.stats().replans >= 1);
  CHECK(n.stats().blocked_s > 0.5);
  CHECK(scene.robot_contacts() == 0);
  CHECK(scene.static_contacts() == 0);
  CHECK(scene.min_robot_distance() > 0.5);
}

TEST_CASE("a robot holding the goal: blocked, naming it, after the timeout") {
  // robot2 stands on M3's input place; robot1 wants to go there.
  const Pose2D m3{2.80, 0.56 + 0.14 + 0.2225, -core::kPi / 2};
  ControllerConfig cc;
  cc.blocked_timeout_s = 6.0;
  NavScene scene(test_world({{0.8, 0.5, 0.0}, m3}), 2, PlannerConfig{}, cc);
  scene.nav(0).go_to_place("M3");
  const double t = scene.run(60.0);
  const NavStatus& st = scene.nav(0).status();
  CHECK(st.outcome == NavOutcome::kBlocked);
  CHECK(st.blocked_by == 1);
  CHECK(st.message.rfind("held back by robot 1 for ", 0) == 0);  // no names given
  CHECK(t < 30.0);
  CHECK(scene.nav(0).stats().blocked_s > 6.0);
  CHECK(scene.robot_contacts() == 0);
}

TEST_CASE("a blocked navigation names the robot when the names are known") {
  const Pose2D m3{2.80, 0.56 + 0.14 + 0.2225, -core::kPi / 2};
  ControllerConfig cc;
  cc.blocked_timeout_s = 3.0;
  NavScene scene(test_world({{0.8, 0.5, 0.0}, m3}), 2, PlannerConfig{}, cc);
  scene.nav(0).set_obstacle_names({"alpha", "beta"});
  scene.nav(0).go_to_place("M3");
  scene.run(60.0);
  CHECK(scene.nav(0).status().message.rfind("held back by beta for ", 0) == 0);
}

TEST_CASE("pushing against an obstacle the map does not know: stuck") {
  // The planner's map lacks M5, the world has it: the robot drives into it and makes no
  // progress.
  kinematic::WorldConfig w = test_world({{2.8, 2.1, core::kPi / 2}});
  core::Rng rng(1);
  kinematic::World world(w, rng);
  FieldMap f = sim::field_map_from_world(w);
  f.devices.erase(f.devices.begin() + 4);  // M5
  PlannerConfig pc;
  pc.places.look_distance_m = 0.6;
  Planner p(f, pc);
  ControllerConfig cc;
  cc.stuck_timeout_s = 2.0;
  Navigator nav(p, cc, core::RandomStream(1));
  nav.go_to({2.8, 3.5, core::kPi / 2});
  bool touched = false;
  for (int i = 0; i < 2000 && nav.status().outcome != NavOutcome::kStuck; ++i) {
    const core::RobotId id(0);
    world.set_command(id, test::to_motor(nav.update(world.time(), world.robot_pose(id), {})));
    for (const auto& c : world.step().collisions)
      touched |= c.kind == kinematic::CollisionKind::kRobotDevice;
    REQUIRE(nav.status().outcome != NavOutcome::kArrived);
  }
  CHECK(touched);
  CHECK(nav.status().outcome == NavOutcome::kStuck);
  CHECK(nav.status().message.rfind("no progress for 2.0", 0) == 0);
  CHECK(world.time().seconds() < 10.0);
}

TEST_CASE("two robots swapping places through the gap between M8 and M4, 50 seeds") {
  // The gap between M8 (x <= 1.78) and M4 (x >= 2.65) is 0.87 m: one robot at a time.
  int total_replans = 0, total_backoffs = 0;
  double worst_time = 0.0, closest = 1e9;
  std::vector<double> times;
  for (std::uint64_t seed = 1; seed <= 50; ++seed) {
    core::RandomStream jitter(seed);
    const Pose2D a{2.2 + jitter.uniform(-0.1, 0.1), 1.0 + jitter.uniform(-0.1, 0.1), core::kPi / 2};
    const Pose2D b{2.2 + jitter.uniform(-0.1, 0.1), 2.35 + jitter.uniform(-0.1, 0.1),
                   -core::kPi / 2};
    NavScene scene(test_world({a, b}), seed);
    scene.nav(0).go_to(b);
    scene.nav(1).go_to(a);
    const double t = scene.run(60.0);
    INFO("seed " << seed);
    CHECK(scene.nav(0).status().outcome == NavOutcome::kArrived);
    CHECK(scene.nav(1).status().outcome == NavOutcome::kArrived);
    CHECK(scene.robot_contacts() == 0);
    CHECK(scene.static_contacts() == 0);
    CHECK(t < 45.0);  // the bound: simulated seconds until both have arrived
    times.push_back(t);
    worst_time = std::max(worst_time, t);
    closest = std::min(closest, scene.min_robot_distance());
    total_replans += scene.nav(0).stats().replans + scene.nav(1).stats().replans;
    total_backoffs += scene.nav(0).stats().backoffs + scene.nav(1).stats().backoffs;
  }
  std::sort(times.begin(), times.end());
  MESSAGE("median time " << times[times.size() / 2] << " s, worst " << worst_time << " s, closest "
                         << closest << " m, replans " << total_replans << ", backoffs "
                         << total_backoffs);
  CHECK(total_replans >= 50);  // they did meet: at least one of each pair planned around
}

TEST_CASE("three robots crossing the field to each other's start all terminate") {
  // Two layouts: a triangle across the field's middle, and a line in the single-lane corridor
  // between the machine rows at y = 1.68 and y = 2.8 (robot 3 has to pass both others).
  const std::vector<std::vector<Pose2D>> layouts{
      {{1.1, 1.1, 0.0}, {4.5, 1.1, core::kPi}, {2.25, 4.5, -1.57}},
      {{0.8, 2.25, 0.0}, {2.2, 2.25, 0.0}, {4.6, 2.25, core::kPi}}};
  int arrived = 0, blocked = 0, replans = 0, backoffs = 0;
  double worst = 0.0;
  for (const auto& starts : layouts) {
    for (std::uint64_t seed = 1; seed <= 10; ++seed) {
      NavScene scene(test_world(starts), seed);
      for (int i = 0; i < 3; ++i) scene.nav(i).go_to(starts[(i + 1) % 3]);
      const double t = scene.run(150.0);
      INFO("layout " << (&starts - layouts.data()) << " seed " << seed);
      for (int i = 0; i < 3; ++i) {
        const NavOutcome o = scene.nav(i).status().outcome;
        CHECK((o == NavOutcome::kArrived || o == NavOutcome::kBlocked));
        arrived += o == NavOutcome::kArrived;
        blocked += o == NavOutcome::kBlocked;
        replans += scene.nav(i).stats().replans;
        backoffs += scene.nav(i).stats().backoffs;
      }
      // Everyone terminated well before the test's own limit: blocked_timeout_s bounds the
      // time held back, the rest is driving.
      CHECK(t < 100.0);
      worst = std::max(worst, t);
      CHECK(scene.robot_contacts() == 0);
      CHECK(scene.static_contacts() == 0);
    }
  }
  MESSAGE("arrived " << arrived << ", blocked " << blocked << ", replans " << replans
                     << ", backoffs " << backoffs << ", worst " << worst << " s");
  CHECK(replans + backoffs > 10);  // they did get in each other's way
}

TEST_CASE("same seed, same game; another seed, another game") {
  auto run = [](std::uint64_t seed) {
    const std::vector<Pose2D> starts{{1.1, 1.1, 0.0}, {4.5, 1.1, core::kPi}, {2.25, 4.5, -1.57}};
    NavScene scene(test_world(starts), seed);
    for (int i = 0; i < 3; ++i) scene.nav(i).go_to(starts[(i + 1) % 3]);
    scene.run(60.0);
    return scene.world().state_hash();
  };
  CHECK(run(4) == run(4));
  CHECK(run(4) != run(5));
}

TEST_CASE("carrying a puck: forward mode keeps it in the holder and lands it in the RFID zone") {
  // robot1 faces west with a puck in its holder; M1 lies to the east: the robot has to turn.
  auto run = [](bool forward) {
    kinematic::WorldConfig w = test_world({{1.0, 2.25, core::kPi}});
    const Vec2 puck_at = Vec2(1.0, 2.25) + 0.2225 * core::unit(core::kPi);
    w.pucks.push_back({1, puck_at});
    NavScene scene(w, 1);
    for (int i = 0; i < 20; ++i) scene.step();  // the assisted holder takes the puck
    REQUIRE(scene.world().held_puck(core::RobotId(0)) == core::PuckId(1));
    scene.nav(0).go_to_place("M1", forward);
    scene.run(40.0);
    CHECK(scene.nav(0).status().outcome == NavOutcome::kArrived);
    return scene.world().puck_zone(core::PuckId(1));
  };
  const auto zone = run(true);
  REQUIRE(zone.has_value());
  CHECK(*zone == core::DeviceId(0));  // M1
  // Holonomic driving with the heading turned on the way backs up at the start: the holder
  // lets the puck go.
  CHECK_FALSE(run(false).has_value());
}

TEST_CASE("forward mode reaches places from any side, coming in straight at the end") {
  NavScene scene(test_world({kIns3}), 4);
  for (const char* name : {"M3_left", "D1", "M9", "R2", "INS_2", "M7_right", "LATE_ORDER", "R1"}) {
    INFO(name);
    scene.nav(0).go_to_place(name, /*forward=*/true);
    scene.run(60.0);
    REQUIRE(scene.nav(0).status().outcome == NavOutcome::kArrived);
    // The last stretch is straight along the goal heading.
    const Path& path = scene.nav(0).path();
    const Vec2 last = path.points.back() - path.points[path.points.size() - 2];
    CHECK(last.norm() >= 0.39);
    CHECK(std::abs(core::angle_diff(std::atan2(last.y(), last.x()), path.goal_theta)) < 1e-6);
  }
  CHECK(scene.static_contacts() == 0);
}

TEST_CASE("a robot following another down a lane slows down behind it, then arrives") {
  // Both drive east along the lane between the machine rows at y = 1.68 and 2.8; robot 2
  // starts 1 m behind at full speed, robot 1 drives at 0.4 m/s: robot 2 closes up.
  ControllerConfig slow;
  slow.max_speed_mps = 0.4;
  kinematic::WorldConfig w = test_world({{1.6, 2.25, 0.0}, {0.6, 2.25, 0.0}});
  NavScene scene(w, 9, PlannerConfig{}, ControllerConfig{});
  // Robot 1 drives slowly: a navigator of its own with the slow config.
  Navigator lead(scene.planner(), slow, core::RandomStream(3));
  lead.go_to({4.6, 2.25, 0.0});
  scene.nav(1).go_to({4.0, 2.25, 0.0});
  for (int k = 0; k < 4000 && scene.nav(1).status().outcome == NavOutcome::kRunning; ++k) {
    const core::SimTime now = scene.world().time();
    const core::RobotId r0(0);
    scene.world().set_command(
        r0, test::to_motor(lead.update(now, scene.world().robot_pose(r0), scene.others(0))));
    const core::RobotId r1(1);
    scene.world().set_command(r1, test::to_motor(scene.nav(1).update(
                                      now, scene.world().robot_pose(r1), scene.others(1))));
    const auto& ev = scene.world().step();
    for (const auto& c : ev.collisions) CHECK(c.kind != kinematic::CollisionKind::kRobotRobot);
  }
  CHECK(scene.nav(1).status().outcome == NavOutcome::kArrived);
  CHECK(scene.nav(1).stats().replans == 0);  // it followed, it did not go round
}
