// SPDX-License-Identifier: MIT
// Robot profiles (docs/profiles.md): loading, what they set, and the handling mechanisms they
// switch on in RobotStack -- alignment after a drive, motor caps, jams at devices.
#include <doctest/doctest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include "llsf/core/error.h"
#include "llsf/lua/skill_engine.h"
#include "llsf/study/profile.h"
#include "llsf/study/runner.h"
#include "llsf/study/scenario.h"
#include "sim/fixture.h"
#include "support/temp_dir.h"

namespace llsf {
namespace {

study::ScenarioFile load_text(const test::TempDir& dir, const std::string& text) {
  const std::string path = dir.file("s.yaml");
  std::ofstream(path) << text;
  return study::load_scenario(path);
}

std::string error_of(const test::TempDir& dir, const std::string& text) {
  try {
    load_text(dir, text);
  } catch (const core::ConfigError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST_CASE(
    "profiles: ideal is the game loop's defaults, the robotino-2013 profiles set their figures") {
  const sim::GameConfig defaults;
  sim::GameConfig g;
  lua::SkillEngineConfig skills;
  study::RobotProfile::named("ideal").apply(g, skills);
  CHECK(g.world.robot.max_speed_mps == defaults.world.robot.max_speed_mps);
  CHECK(g.controller.max_speed_mps == defaults.controller.max_speed_mps);
  CHECK(g.controller.blocked_timeout_s == defaults.controller.blocked_timeout_s);
  CHECK(g.levels.light.level == defaults.levels.light.level);
  CHECK(g.levels.light.frame_rate_hz == defaults.levels.light.frame_rate_hz);
  CHECK(g.levels.localization.level == defaults.levels.localization.level);
  CHECK(g.world.sensors.laser.rate_hz == defaults.world.sensors.laser.rate_hz);
  CHECK(g.handling.align_s == 0.0);
  CHECK(g.handling.jam_probability == 0.0);
  CHECK(g.handling.stuck_detection);
  CHECK(skills.stuck_detection);

  // The old robotino-2013: an omniscient navigator, jam dice, a calibrated alignment.
  sim::GameConfig t;
  study::RobotProfile::named("robotino-2013-omniscient").apply(t, skills);
  CHECK(t.profile == "robotino-2013-omniscient");
  CHECK(skills.profile == "robotino-2013-omniscient");
  CHECK_FALSE(skills.stuck_detection);
  CHECK_FALSE(t.handling.stuck_detection);
  // Thesis §6.1.1: webcam 2 Hz, light detection about 1 s late, laser 5 Hz.
  CHECK(t.levels.light.level == sim::DetectionLevel::kVision);
  CHECK(t.levels.light.frame_rate_hz == 2.0);
  CHECK(t.levels.light.delay == core::SimTime::from_sec(1));
  CHECK(t.world.sensors.laser.rate_hz == 5.0);
  CHECK(t.world.robot.max_speed_mps == t.controller.max_speed_mps);
  CHECK(t.world.robot.max_speed_mps < defaults.world.robot.max_speed_mps);
  CHECK(t.handling.align_s > 0.0);
  CHECK(t.handling.jam_probability > 0.0);
  CHECK(t.levels.navigation == sim::NavigationLevel::kIdeal);
  CHECK(skills.motions == "llsfsim");
  CHECK(t.world.robot.laser_radius_m == 0.0);
  CHECK(t.world.devices[0].body_depth_m == defaults.world.devices[0].body_depth_m);
  CHECK_NOTHROW(t.validate());

  // robotino-2013: the team's move_base, the laser, the Gazebo machines, no dice.
  sim::GameConfig m;
  study::RobotProfile::named("robotino-2013").apply(m, skills);
  CHECK(m.profile == "robotino-2013");
  CHECK_FALSE(m.handling.stuck_detection);
  CHECK(m.levels.navigation == sim::NavigationLevel::kMoveBase2013);
  CHECK(m.world.sensors.laser.enabled);
  CHECK(m.world.robot.max_accel_mps2 == 2.5);
  CHECK(m.world.robot.max_alpha_rps2 == 3.2);
  CHECK(m.handling.jam_probability == 0.0);
  CHECK(skills.motions == "carologistics-2013");
  CHECK(m.world.sensors.laser.mount_x_m == 0.085);
  CHECK(m.world.robot.laser_radius_m == 0.12);
  CHECK(m.world.robot.laser_offset_m == -0.05);
  // The machines' bodies change; their fronts (0.04 m behind the read zone) and the gates stay.
  for (int i = 0; i < kinematic::kDeviceCount; ++i) {
    const auto& d = m.world.devices[static_cast<std::size_t>(i)];
    const auto& w = defaults.world.devices[static_cast<std::size_t>(i)];
    CAPTURE(i);
    CHECK(d.body_offset_m + 0.5 * d.body_depth_m ==
          doctest::Approx(w.body_offset_m + 0.5 * w.body_depth_m));
    CHECK(d.rfid_offset_m == w.rfid_offset_m);
    if (kinematic::device_kind(core::DeviceId(i)) == kinematic::DeviceKind::kDelivery) {
      CHECK(d.body_depth_m == w.body_depth_m);
    } else {
      CHECK(d.body_depth_m == 0.11);
      CHECK(d.body_width_m == 0.16);
    }
  }
  CHECK_NOTHROW(m.validate());
  CHECK_THROWS_AS(study::RobotProfile::named("robotino-2099"), std::invalid_argument);
}

TEST_CASE("profiles: the scenario key, overrides, and keys that win over the profile") {
  const test::TempDir dir("llsf-profile");
  const std::string head = "name: p\nduration_s: 10\nrobots: {count: 1}\n";
  study::ScenarioFile f = load_text(dir, head + "profile: robotino-2013\n");
  CHECK(f.variants.front().game.profile == "robotino-2013");
  CHECK(f.variants.front().game.controller.max_speed_mps == 0.5);
  CHECK_FALSE(f.variants.front().skills.stuck_detection);

  f = load_text(dir, head +
                         "profile: {name: robotino-2013-omniscient, max_speed_mps: 0.3, "
                         "jam_probability: 0}\n");
  CHECK(f.variants.front().game.controller.max_speed_mps == 0.3);
  CHECK(f.variants.front().game.world.robot.max_speed_mps == 0.3);
  CHECK(f.variants.front().game.handling.jam_probability == 0.0);
  CHECK(f.variants.front().game.handling.align_s > 0.0);  // the rest stays the profile's

  // world/navigation/levels keys are read on top of the profile.
  f = load_text(dir, head +
                         "profile: robotino-2013\nnavigation: {controller: {max_speed_mps: 0.7}}\n"
                         "levels: {light: ground_truth}\nskills: {rate_hz: 15}\n");
  CHECK(f.variants.front().game.controller.max_speed_mps == 0.7);
  CHECK(f.variants.front().game.levels.light.level == sim::DetectionLevel::kGroundTruth);
  CHECK_FALSE(f.variants.front().skills.stuck_detection);  // a skills: key keeps the profile's

  // A matrix axis over profiles.
  f = load_text(dir, head +
                         "matrix:\n  profile:\n    a: {profile: ideal}\n"
                         "    b: {profile: robotino-2013}\n");
  REQUIRE(f.variants.size() == 2);
  CHECK(f.variants[0].game.profile == "ideal");
  CHECK(f.variants[1].game.profile == "robotino-2013");

  // Errors name the file, line and key.
  std::string e = error_of(dir, head + "profile: robotino-2099\n");
  CHECK(e.find("s.yaml:4:") != std::string::npos);
  CHECK(e.find("unknown profile 'robotino-2099' (known: ideal, robotino-2013, "
               "robotino-2013-omniscient)") != std::string::npos);
  for (const std::string& name : study::RobotProfile::names()) {
    CAPTURE(name);
    CHECK(study::RobotProfile::named(name).name == name);  // the list is the names named() knows
  }
  e = error_of(dir, head + "profile: {name: ideal, max_speed_mps: -1}\n");
  CHECK(e.find("s.yaml:4:") != std::string::npos);
  CHECK(e.find("max_speed_mps") != std::string::npos);
  CHECK(e.find("must be > 0") != std::string::npos);
  e = error_of(dir, head + "profile: {name: ideal, top_speed: 1}\n");
  CHECK(e.find("unknown key 'top_speed'") != std::string::npos);
  e = error_of(dir, head + "profile: {jam_probability: 1.5}\n");
  CHECK(e.find("jam_probability") != std::string::npos);
  e = error_of(dir, head + "profile: {name: robotino-2013, motions: festo}\n");
  CHECK(e.find("unknown skill motions 'festo' (expected one of: llsfsim, carologistics-2013)") !=
        std::string::npos);
  f = load_text(dir, head + "profile: {name: robotino-2013, motions: llsfsim}\n");
  CHECK(f.variants.front().skills.motions == "llsfsim");
  e = error_of(dir, head + "profile: {light: camera}\n");
  CHECK(e.find("unknown detection level 'camera' (expected one of: ground_truth, vision)") !=
        std::string::npos);
}

TEST_CASE("profiles: an unknown key or a bad figure is reported at its file:line:column") {
  const test::TempDir dir("llsf-profile");
  const std::string head = "name: p\nduration_s: 10\nrobots: {count: 1}\n";
  CHECK(error_of(dir, head + "profile: {name: ideal, max_sped_mps: 1}\n") ==
        dir.file("s.yaml") +
            ":4:38: profile.max_sped_mps: unknown key 'max_sped_mps' (did you mean "
            "'max_speed_mps'?)");
  CHECK(error_of(dir, head + "profile:\n  name: robotino-2013\n  align_s: 90\n") ==
        dir.file("s.yaml") + ":6:12: profile.align_s: must be at most 60 (got 90)");
  CHECK(error_of(dir, head + "profile:\n  jam_probability: 1.5\n") ==
        dir.file("s.yaml") + ":5:20: profile.jam_probability: must be in [0, 1] (got 1.5)");
  // A bound between two keys: at the key validate() names.
  CHECK(error_of(dir, head + "profile:\n  backoff_min_s: 5\n  backoff_max_s: 4\n") ==
        dir.file("s.yaml") + ":6:18: profile.backoff_max_s: must be >= backoff_min_s (got 4)");
}

TEST_CASE("profiles: the ideal profile leaves the game as it was") {
  const test::TempDir dir("llsf-profile");
  const std::string body =
      "name: p\nseed: 3\nstart: production\nduration_s: 120\nrates: {physics_hz: 60, "
      "skill_hz: 15}\nworld: {sensors: {laser: {enabled: false}}}\nrobots:\n  count: 2\n"
      "  agent: [" LLSF_SOURCE_DIR "/clips/agents/common, " LLSF_SOURCE_DIR
      "/clips/agents/llsf2013]\n  config: {roles: [P1P2, P3]}\n";
  const study::RunResult plain = study::run_game(load_text(dir, body).variants.front(), 3);
  const study::RunResult ideal =
      study::run_game(load_text(dir, body + "profile: ideal\n").variants.front(), 3);
  CHECK(plain.result_hash == ideal.result_hash);
  CHECK(ideal.profile == "ideal");
  CHECK(ideal.jams == 0);
  const study::RunResult slow = study::run_game(
      load_text(dir, body + "profile: robotino-2013-omniscient\n").variants.front(), 3);
  CHECK(slow.result_hash != ideal.result_hash);
  CHECK(slow.profile == "robotino-2013-omniscient");
  // robotino-2013's navigation sees with the laser: a scenario that turns it off is told so.
  CHECK(error_of(dir, body + "profile: robotino-2013\n")
            .find("move_base-2013 sees obstacles only with the laser") != std::string::npos);
}

TEST_CASE("handling: the fine alignment holds the arrival back after a drive, not after a push") {
  sim::GameConfig c = test::small_game(1);
  c.handling.align_s = 2.5;
  sim::Game g(c);
  double arrived_at = -1.0;
  double pushed_at = -1.0;
  double push_started = -1.0;
  bool nav_arrived_early = false;
  test::StepBrain brain({
      [&](lua::RobotApi& r) {
        r.goto_place("M8_look", false);
        return true;
      },
      [&](lua::RobotApi& r) {
        const lua::NavState s = r.navigator();
        // The planner arrives first; the robot stands still while it aligns.
        if (g.robot(0).nav().status().outcome == planner::NavOutcome::kArrived &&
            s.status == lua::NavStatus::kRunning) {
          nav_arrived_early = true;
        }
        if (s.status == lua::NavStatus::kRunning) return false;
        CHECK(s.status == lua::NavStatus::kArrived);
        arrived_at = r.now().seconds();
        return true;
      },
      [&](lua::RobotApi& r) {
        const core::Pose2D p = r.pose().pose;
        r.goto_pose({p.x + 0.1 * std::cos(p.theta), p.y + 0.1 * std::sin(p.theta), p.theta}, true);
        push_started = r.now().seconds();
        return true;
      },
      [&](lua::RobotApi& r) {
        const lua::NavState s = r.navigator();
        if (s.status == lua::NavStatus::kRunning) return false;
        CHECK(s.status == lua::NavStatus::kArrived);
        pushed_at = r.now().seconds();
        return true;
      },
  });
  g.set_brain(0, &brain);
  while (!brain.done() && g.time() < core::SimTime::from_sec(60)) g.step();
  g.set_brain(0, nullptr);
  REQUIRE(brain.done());
  CHECK(nav_arrived_early);
  CHECK(arrived_at > 2.5);
  // A 10 cm move is not aligned again: it ends well within the alignment time.
  CHECK(pushed_at - push_started < 2.5);
}

TEST_CASE("handling: motor commands are capped") {
  sim::GameConfig c = test::small_game(1);
  c.handling.motor_max_speed_mps = 0.1;
  c.handling.motor_max_omega_rps = 0.2;
  sim::Game g(c);
  const core::Pose2D start = g.world().robot_pose(core::RobotId(0));
  test::StepBrain brain({[&](lua::RobotApi& r) {
    r.set_velocity(0.5, 0.0, 1.0);
    return r.now() >= core::SimTime::from_sec(2);
  }});
  g.set_brain(0, &brain);
  while (!brain.done()) g.step();
  g.set_brain(0, nullptr);
  const core::Pose2D end = g.world().robot_pose(core::RobotId(0));
  // About 2 s at 0.1 m/s and 0.2 rad/s, not at 0.5 m/s and 1 rad/s.
  CHECK((end.position() - start.position()).norm() < 0.25);
  CHECK(std::abs(core::angle_diff(end.theta, start.theta)) < 0.45);
}

TEST_CASE(
    "handling: a jam at a device holds the robot until it moves away (or, with stuck "
    "detection, until the recovery time)") {
  for (const bool detection : {false, true}) {
    CAPTURE(detection);
    sim::GameConfig c = test::small_game(1);
    c.handling.jam_probability = 1.0;  // every approach near a device jams
    c.handling.stuck_detection = detection;
    c.handling.jam_recovery_s = 5.0;
    sim::Game g(c);
    auto pose = [&g] { return g.world().robot_pose(core::RobotId(0)); };
    core::Pose2D before;
    double turned_jammed = 0.0, turned_later = 0.0, backed = 0.0;
    int cycles = 0;
    test::StepBrain brain({
        test::go("M8_input"),
        [&](lua::RobotApi& r) {  // turn in place for 3 s: jammed, nothing moves
          if (cycles == 0) before = pose();
          r.set_velocity(0.0, 0.0, 0.3);
          if (++cycles < 90) return false;
          turned_jammed = std::abs(core::angle_diff(pose().theta, before.theta));
          before = pose();
          cycles = 0;
          return true;
        },
        [&](lua::RobotApi& r) {  // 4 s more: past the recovery time
          r.set_velocity(0.0, 0.0, 0.3);
          if (++cycles < 120) return false;
          turned_later = std::abs(core::angle_diff(pose().theta, before.theta));
          before = pose();
          cycles = 0;
          return true;
        },
        [&](lua::RobotApi& r) {  // back off for 1 s: free in any case
          r.set_velocity(-0.1, 0.0, 0.0);
          if (++cycles < 30) return false;
          backed = (pose().position() - before.position()).norm();
          r.stop();
          return true;
        },
    });
    g.set_brain(0, &brain);
    while (!brain.done() && g.time() < core::SimTime::from_sec(60)) g.step();
    g.set_brain(0, nullptr);
    REQUIRE(brain.done());
    CHECK(g.robot(0).jams() == 1);
    CHECK(turned_jammed < 0.01);
    if (detection) {
      CHECK(turned_later > 0.3);  // the recovery freed it after 5 s
    } else {
      CHECK(turned_later < 0.01);  // no stuck detection: still jammed
    }
    CHECK(backed > 0.05);
    CHECK_FALSE(g.robot(0).jammed());
  }
}

TEST_CASE("handling: jams are drawn from the seed's own stream") {
  auto jams = [](std::uint64_t seed) {
    sim::GameConfig c = test::small_game(1, seed);
    c.handling.jam_probability = 0.5;
    sim::Game g(c);
    int approaches = 0;
    int cycles = 0;
    std::vector<int> pattern;
    test::StepBrain brain({
        test::go("M8_input"),
        [&](lua::RobotApi& r) {
          // Ten approaches: a motor run near the device, then the robot idles (a new run).
          if (cycles++ % 2 == 0) {
            r.set_velocity(0.0, 0.0, 0.1);
            return false;
          }
          pattern.push_back(g.robot(0).jams());
          r.stop();
          return ++approaches >= 10;
        },
    });
    g.set_brain(0, &brain);
    while (!brain.done() && g.time() < core::SimTime::from_sec(60)) g.step();
    g.set_brain(0, nullptr);
    return pattern;
  };
  CHECK(jams(5) == jams(5));
  const std::vector<int> a = jams(5);
  REQUIRE(!a.empty());
  CHECK(a.back() >= 1);
}

}  // namespace llsf
