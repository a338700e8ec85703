// SPDX-License-Identifier: MIT
// The LLSF skill library (lua/skills) in the game loop, at the physical and symbolic levels:
// S0 -> S1 at a T1, the P3 chain and its delivery, recycling, exploration, failures.
#include <doctest/doctest.h>

#include <cstdio>
#include <optional>
#include <string>

#include "fixture.h"
#include "llsf/sim/game.h"
#include "llsf/sim/skill_brain.h"

using namespace llsf;
using namespace llsf::sim;

namespace {

struct Outcome {
  lua::SkillStatus status = lua::SkillStatus::kRunning;
  std::string error;
  std::string result;
  double seconds = 0.0;
};

/// Runs `skill_string` on `brain` until it ends or `max_s` pass.
Outcome run_skill(Game& g, SkillBrain& brain, const std::string& skill_string, double max_s) {
  const SimTime start = g.time();
  REQUIRE(brain.exec(skill_string).ok);
  const SimTime end = start + SimTime::from_seconds(max_s);
  while (g.time() < end && brain.engine().status() == lua::SkillStatus::kRunning) g.step();
  Outcome o;
  o.status = brain.engine().status();
  o.error = brain.engine().error();
  o.result = brain.engine().result();
  o.seconds = (g.time() - start).seconds();
  return o;
}

std::string machine_name(int index) {
  return std::string(kinematic::device_name(core::DeviceId(index)));
}

/// The refbox state of the puck in robot `r`'s holder.
std::optional<refbox::PuckState> held_state(const Game& g, int r) {
  const auto p = g.puck_in_pocket(r);
  if (!p) return std::nullopt;
  return g.refbox().puck_state(*p);
}

}  // namespace

TEST_CASE("the skill library loads at both levels") {
  for (const SkillLevel level : {SkillLevel::kPhysical, SkillLevel::kSymbolic}) {
    GameConfig config = test::small_game(1);
    config.levels.skill = level;
    Game g(config);
    SkillBrain brain(g, 0);
    g.set_brain(0, &brain);
    CHECK(brain.engine().load_errors().empty());
    for (const auto& e : brain.engine().load_errors()) MESSAGE(e);
    CHECK(brain.engine().skills().size() >= 11);
  }
}

TEST_CASE("get_s0 then finish_puck_at a T1: the refbox makes it an S1") {
  for (const SkillLevel level : {SkillLevel::kPhysical, SkillLevel::kSymbolic}) {
    CAPTURE(to_string(level));
    GameConfig config = test::small_game(1, 7);
    config.levels.skill = level;
    Game g(config);
    test::start_phase(g, refbox::GamePhase::kProduction);
    g.step();
    const auto t1 = test::machine_of_type(g.refbox(), refbox::MachineType::kT1, 200);
    REQUIRE(t1);
    SkillBrain brain(g, 0);
    g.set_brain(0, &brain);
    Outcome o = run_skill(g, brain, "get_s0{}", 120);
    INFO(o.error);
    REQUIRE(o.status == lua::SkillStatus::kFinal);
    REQUIRE(held_state(g, 0) == refbox::PuckState::kS0);
    MESSAGE(std::string(to_string(level)), " get_s0 took ", o.seconds, " s");
    o = run_skill(g, brain, "finish_puck_at{place=\"" + machine_name(*t1) + "\"}", 120);
    INFO(o.error);
    REQUIRE(o.status == lua::SkillStatus::kFinal);
    CHECK(o.result == "DONE");
    CHECK(held_state(g, 0) == refbox::PuckState::kS1);
    MESSAGE(std::string(to_string(level)), " finish_puck_at took ", o.seconds, " s");
  }
}

namespace {

/// A game in PRODUCTION with robot 0 running the skill library at `level`.
struct ProductionGame {
  explicit ProductionGame(SkillLevel level, std::uint64_t seed = 7) : game(config(level, seed)) {
    test::start_phase(game, refbox::GamePhase::kProduction);
    game.step();
    brain = std::make_unique<SkillBrain>(game, 0);
    game.set_brain(0, brain.get());
  }
  static GameConfig config(SkillLevel level, std::uint64_t seed) {
    GameConfig c = test::small_game(1, seed);
    c.levels.skill = level;
    return c;
  }
  Outcome run(const std::string& s, double max_s = 180) {
    Outcome o = run_skill(game, *brain, s, max_s);
    MESSAGE(std::string(to_string(game.config().levels.skill)), " ", s, ": ",
            lua::to_string(o.status), " after ", o.seconds, " s ", o.result, " ", o.error);
    return o;
  }
  std::string machine(refbox::MachineType type) {
    auto m = test::machine_of_type(game.refbox(), type, 150);
    if (!m) m = test::machine_of_type(game.refbox(), type, 0);
    REQUIRE(m);
    return machine_name(*m);
  }
  Game game;
  std::unique_ptr<SkillBrain> brain;
};

#define REQUIRE_FINAL(o)                            \
  do {                                              \
    const Outcome& o_ = (o);                        \
    INFO(o_.error);                                 \
    REQUIRE(o_.status == lua::SkillStatus::kFinal); \
  } while (false)

}  // namespace

TEST_CASE("the P3 chain: get_s0, finish_puck_at the T5, deliver scores the order") {
  for (const SkillLevel level : {SkillLevel::kPhysical, SkillLevel::kSymbolic}) {
    CAPTURE(std::string(to_string(level)));
    ProductionGame pg(level);
    const std::string t5 = pg.machine(refbox::MachineType::kT5);
    REQUIRE_FINAL(pg.run("get_s0{}"));
    const Outcome made = pg.run("finish_puck_at{place=\"" + t5 + "\"}");
    REQUIRE_FINAL(made);
    CHECK(made.result == "DONE");
    REQUIRE(held_state(pg.game, 0) == refbox::PuckState::kP3);
    const int before = pg.game.summary().production_points;
    const Outcome d = pg.run("deliver{}", 240);
    REQUIRE_FINAL(d);
    CHECK(d.result.rfind("DELIVERED D", 0) == 0);
    CHECK(pg.game.summary().production_points >= before + 10);
    int delivered = 0;
    for (const auto& o : pg.game.refbox().orders()) {
      if (o.product == refbox::PuckState::kP3) delivered += o.quantity_delivered;
    }
    CHECK(delivered == 1);
    CHECK_FALSE(pg.game.puck_in_pocket(0).has_value());
  }
}

TEST_CASE("a T2 chain leaves a consumed puck beside the machine; recycle makes it an S0") {
  for (const SkillLevel level : {SkillLevel::kPhysical, SkillLevel::kSymbolic}) {
    CAPTURE(std::string(to_string(level)));
    ProductionGame pg(level);
    const std::string t1 = pg.machine(refbox::MachineType::kT1);
    const std::string t2 = pg.machine(refbox::MachineType::kT2);
    // S1 first: the T2 takes it as its first input and waits; the skill puts it aside.
    REQUIRE_FINAL(pg.run("get_s0{}"));
    REQUIRE_FINAL(pg.run("finish_puck_at{place=\"" + t1 + "\"}"));
    REQUIRE(held_state(pg.game, 0) == refbox::PuckState::kS1);
    const core::PuckId s1 = *pg.game.puck_in_pocket(0);
    const Outcome waiting = pg.run("finish_puck_at{place=\"" + t2 + "\"}");
    REQUIRE_FINAL(waiting);
    CHECK(waiting.result == "WAITING");
    CHECK_FALSE(pg.game.puck_in_pocket(0).has_value());
    // An S0 completes the set: S2 in the holder, the S1 beside the machine is CONSUMED.
    REQUIRE_FINAL(pg.run("get_s0{}"));
    const Outcome done = pg.run("finish_puck_at{place=\"" + t2 + "\"}");
    REQUIRE_FINAL(done);
    CHECK(done.result == "DONE");
    CHECK(held_state(pg.game, 0) == refbox::PuckState::kS2);
    CHECK(pg.game.refbox().puck_state(s1) == refbox::PuckState::kConsumed);
    // Put the S2 down out of the way (facing the wall of the insertion area), then recycle the
    // consumed puck.
    REQUIRE_FINAL(pg.run("drive_to{x=0.7, y=1.2, ori=math.pi}"));
    REQUIRE_FINAL(pg.run("leave_puck{}"));
    const int before = pg.game.summary().production_points;
    const Outcome r = pg.run("recycle{from=\"" + t2 + "\"}");
    REQUIRE_FINAL(r);
    CHECK(r.result == "DONE");
    REQUIRE(pg.game.puck_in_pocket(0) == s1);
    CHECK(pg.game.refbox().puck_state(s1) == refbox::PuckState::kS0);
    CHECK(pg.game.summary().production_points >= before + 3);
  }
}

namespace {

/// "M3 red=ON yellow=OFF green=BLINK" for the refbox's exploration code of machine `i`.
std::string expected_code(const Game& g, int i) {
  const refbox::Lights l = g.refbox().machine(core::DeviceId(i)).lights;
  auto name = [](refbox::LightState s) {
    return s == refbox::LightState::kOn ? "ON" : s == refbox::LightState::kBlink ? "BLINK" : "OFF";
  };
  return machine_name(i) + " red=" + name(l.red) + " yellow=" + name(l.yellow) +
         " green=" + name(l.green);
}

/// Explores all ten machines with one robot; returns how many codes were read correctly.
int explore_all(DetectionLevel light, std::uint64_t seed) {
  GameConfig c = test::small_game(1, seed);
  c.levels.light.level = light;
  Game g(c);
  test::start_phase(g, refbox::GamePhase::kExploration);
  g.step();
  SkillBrain brain(g, 0);
  g.set_brain(0, &brain);
  int correct = 0;
  for (int i = 0; i < refbox::kProductionMachineCount; ++i) {
    const Outcome o = run_skill(g, brain, "explore_machine{place=\"" + machine_name(i) + "\"}", 60);
    INFO(machine_name(i), ": ", o.error);
    CHECK(o.status == lua::SkillStatus::kFinal);
    if (o.result == expected_code(g, i)) {
      ++correct;
    } else {
      MESSAGE("read ", o.result, ", expected ", expected_code(g, i));
    }
  }
  return correct;
}

}  // namespace

TEST_CASE("explore_machine reads all ten codes at ground truth, most of them at vision") {
  CHECK(explore_all(DetectionLevel::kGroundTruth, 7) == 10);
  int vision = 0;
  for (const std::uint64_t seed : {7, 8}) vision += explore_all(DetectionLevel::kVision, seed);
  MESSAGE("vision: ", vision, " of 20 codes correct");
  CHECK(vision >= 16);
}

// finish_puck_at with a puck knocked out of the holder on the way, once the robot is 1 m away
// from the input storage: to `to` in the robot's frame (x ahead, y left). Returns the skill's
// status after at most `max_s` seconds more.
lua::SkillStatus knock_on_the_way(ProductionGame& pg, const core::Vec2& to, double max_s) {
  REQUIRE_FINAL(pg.run("get_s0{}"));
  const core::PuckId puck = *pg.game.puck_in_pocket(0);
  REQUIRE(pg.brain->exec("finish_puck_at{place=\"M10\"}").ok);
  const SimTime give_up = pg.game.time() + SimTime::from_sec(60);
  while (pg.game.time() < give_up &&
         pg.game.world().robot_pose(core::RobotId(0)).position().x() < 1.4) {
    pg.game.step();
  }
  REQUIRE(pg.brain->engine().status() == lua::SkillStatus::kRunning);
  const core::Pose2D r = pg.game.world().robot_pose(core::RobotId(0));
  pg.game.world().teleport_puck(puck, r.to_parent(to));
  const SimTime end = pg.game.time() + SimTime::from_seconds(max_s);
  while (pg.game.time() < end && pg.brain->engine().status() == lua::SkillStatus::kRunning) {
    pg.game.step();
  }
  MESSAGE(std::string(lua::to_string(pg.brain->engine().status())), " ",
          pg.brain->engine().error());
  return pg.brain->engine().status();
}

TEST_CASE("a puck knocked out of the holder and out of reach fails the skill with a reason") {
  for (const SkillLevel level : {SkillLevel::kPhysical, SkillLevel::kSymbolic}) {
    CAPTURE(std::string(to_string(level)));
    ProductionGame pg(level);
    CHECK(knock_on_the_way(pg, {0.0, 1.0}, 30) == lua::SkillStatus::kFailed);
    CHECK(pg.brain->engine().error().find("lost the puck (none seen within") != std::string::npos);
  }
}

TEST_CASE("a puck knocked out of the holder nearby is fetched again, as take_puck_to did") {
  // The physical level: the robot stands 3 s, takes the puck (ahead, beside its path, where the
  // camera sees it) again and goes on to M10.
  ProductionGame pg(SkillLevel::kPhysical);
  const lua::SkillStatus status = knock_on_the_way(pg, {0.35, 0.25}, 120);
  CHECK(status == lua::SkillStatus::kFinal);
}

TEST_CASE("skill failures name their reason: bad arguments, unknown places, empty holder") {
  ProductionGame pg(SkillLevel::kPhysical);
  auto failed_with = [&](const std::string& s, const std::string& text) {
    const Outcome o = run_skill(pg.game, *pg.brain, s, 30);
    INFO(s, " -> ", o.error);
    CHECK(o.status == lua::SkillStatus::kFailed);
    CHECK(o.error.find(text) != std::string::npos);
  };
  failed_with("drive_to{place=\"M11\"}", "unknown place 'M11'");
  failed_with("drive_to{}", "drive_to needs place=<name> or x=, y=");
  // What was wrong with the arguments, not only what is needed.
  failed_with("drive_to{x=\"1.5\", y=2}",
              "drive_to needs place=<name> or x=, y=: x= and y= must be numbers (got x=\"1.5\" "
              "(a string), y=2)");
  failed_with("drive_to{place=3}", "place= must be a place name, not 3");
  failed_with("finish_puck_at{place=\"M3\"}", "no puck in the holder");
  failed_with("deliver{}", "deliver: no puck in the holder");
  failed_with("get_s0{place=\"NOWHERE\"}", "get_s0: unknown place 'NOWHERE'");
  failed_with("explore_machine{place=\"X1\"}", "unknown device 'X1'");
  failed_with("get_consumed{place=\"D1\"}", "unknown machine 'D1'");
  failed_with("recycle{}", "recycle: no puck in the holder");
  failed_with("motor_move{x=\"far\"}", "motor_move needs numbers");
}

TEST_CASE("carologistics-2013 motions: get_consumed and recycle move as the team's skills did") {
  // lua/skills get_consumed.lua, take_puck.lua, finish_puck_at.lua with profile.motions
  // "carologistics-2013" (the robotino-2013 profile): the front, the side move, the turn to the
  // puck, the leave turn; leave_area_recycle at the recycler. No stuck detection, as the profile.
  GameConfig c = ProductionGame::config(SkillLevel::kPhysical, 7);
  c.handling.stuck_detection = false;
  c.handling.motor_max_speed_mps = 0.4;
  c.handling.motor_max_omega_rps = 2.2;
  c.world.robot.max_accel_mps2 = 2.5;
  c.world.robot.max_alpha_rps2 = 3.2;
  c.world.robot.max_omega_rps = 2.2;
  Game game(c);
  test::start_phase(game, refbox::GamePhase::kProduction);
  game.step();
  lua::SkillEngineConfig skills;
  skills.stuck_detection = false;
  skills.motions = "carologistics-2013";
  SkillBrain brain(game, 0, skills);
  game.set_brain(0, &brain);
  auto run = [&](const std::string& s) {
    const Outcome o = run_skill(game, brain, s, 180);
    MESSAGE(s, ": ", std::string(lua::to_string(o.status)), " after ", o.seconds, " s ", o.result,
            " ", o.error, " holder ", game.puck_in_pocket(0).has_value());
    return o;
  };
  auto m = test::machine_of_type(game.refbox(), refbox::MachineType::kT1, 150);
  auto m2 = test::machine_of_type(game.refbox(), refbox::MachineType::kT2, 150);
  REQUIRE(m);
  REQUIRE(m2);
  const std::string t1 = machine_name(*m);
  const std::string t2 = machine_name(*m2);
  REQUIRE_FINAL(run("get_s0{}"));
  REQUIRE_FINAL(run("finish_puck_at{place=\"" + t1 + "\"}"));
  REQUIRE(run("finish_puck_at{place=\"" + t2 + "\"}").result == "WAITING");
  REQUIRE_FINAL(run("get_s0{}"));
  REQUIRE(run("finish_puck_at{place=\"" + t2 + "\"}").result == "DONE");
  REQUIRE_FINAL(run("drive_to{x=0.7, y=1.2, ori=math.pi}"));
  REQUIRE_FINAL(run("leave_puck{}"));
  const Outcome got = run("get_consumed{place=\"" + t2 + "\"}");
  REQUIRE_FINAL(got);
  CHECK(game.puck_in_pocket(0).has_value());
  const Outcome r = run("finish_puck_at{place=\"R1\"}");
  CHECK(r.status == lua::SkillStatus::kFinal);
}
