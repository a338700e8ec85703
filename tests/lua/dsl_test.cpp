// SPDX-License-Identifier: MIT
// The skill DSL: transitions by function, string and timeout; preconditions; default
// transitions; sub-skills through SkillJumpState; FAILED propagation with the error text.
#include <doctest/doctest.h>

#include "lua/fake_robot.h"

using namespace llsf;
using lua::SkillStatus;
using test::FakeRobot;

namespace {

lua::SkillEngineConfig config() {
  lua::SkillEngineConfig cfg;
  cfg.skill_dirs = {test::example_skills_dir(), test::test_skills_dir()};
  cfg.instruction_budget = 200'000;
  return cfg;
}

}  // namespace

TEST_CASE("the example skills load without errors and declare their dependencies") {
  FakeRobot robot;
  lua::SkillEngineConfig cfg;
  cfg.skill_dirs = {test::example_skills_dir()};
  lua::SkillEngine engine(cfg, robot);
  CHECK(engine.load_errors().empty());
  const auto skills = engine.skills();
  REQUIRE(skills.size() == 4);
  CHECK(skills[0].name == "goto_place");
  CHECK(skills[0].documentation.find("@param place") != std::string::npos);
  CHECK(skills[2].name == "visit_place");
  CHECK(skills[2].depends_skills == std::vector<std::string>{"goto_place", "wait_for"});
  CHECK(engine.status() == SkillStatus::kInactive);
  CHECK(engine.cycle_period() == core::SimTime::period_of_hz(30.0));
}

TEST_CASE("transitions by true, function, string and timeout, in order") {
  FakeRobot robot;
  lua::SkillEngine engine(config(), robot);
  test::LogCapture log;
  log.attach(engine);
  REQUIRE(engine.exec("dsl_probe{}"));

  // cond=true: START -> BY_FUNCTION within the first cycle.
  CHECK(test::run_cycles(engine, robot, 1) == SkillStatus::kRunning);
  CHECK(log.contains("START init"));
  CHECK(engine.skill_state("dsl_probe") == "BY_FUNCTION");
  CHECK(engine.skill_status("dsl_probe") == SkillStatus::kRunning);

  // Function condition: nothing happens until the puck is in the holder.
  test::run_cycles(engine, robot, 5);
  CHECK(engine.skill_state("dsl_probe") == "BY_FUNCTION");
  robot.puck = true;
  test::run_cycles(engine, robot, 1);
  CHECK(engine.skill_state("dsl_probe") == "BY_STRING");

  // String condition "vars.loops >= limit" (limit = 3 from the closure): the loop hook ran once
  // on entry, twice more now.
  test::run_cycles(engine, robot, 1);
  CHECK(engine.skill_state("dsl_probe") == "BY_STRING");
  test::run_cycles(engine, robot, 1);
  CHECK(engine.skill_state("dsl_probe") == "BY_TIMEOUT");
  CHECK(log.contains("BY_STRING exit after 3 loops"));

  // Timeout 0.5 s of simulated time: a 30 Hz period is 33,333,333 ns, so 15 cycles are 1 ns
  // short of it and the 16th leaves.
  test::run_cycles(engine, robot, 15);
  CHECK(engine.status() == SkillStatus::kRunning);
  CHECK(engine.skill_state("dsl_probe") == "BY_TIMEOUT");
  CHECK(test::run_cycles(engine, robot, 1) == SkillStatus::kFinal);
  CHECK(engine.error().empty());
  // The string is done: its skills are reset.
  CHECK(engine.skill_status("dsl_probe") == SkillStatus::kInactive);
  CHECK(engine.cycle() == SkillStatus::kFinal);
}

TEST_CASE("a precondition jumps before init; a default transition fails from any state") {
  FakeRobot robot;
  lua::SkillEngine engine(config(), robot);
  test::LogCapture log;
  log.attach(engine);

  SUBCASE("precondition") {
    REQUIRE(engine.exec("dsl_probe{skip=true}"));
    CHECK(test::run_cycles(engine, robot, 1) == SkillStatus::kFinal);
    CHECK(log.contains("SKIPPED init"));
    CHECK_FALSE(log.contains("START init"));
  }
  SUBCASE("default transition with its error text") {
    REQUIRE(engine.exec("dsl_probe{}"));
    test::run_cycles(engine, robot, 3);
    robot.optical_sensors.left = true;
    CHECK(test::run_cycles(engine, robot, 1) == SkillStatus::kFailed);
    CHECK(engine.error() == "dsl_probe: left optical sensor tripped");
  }
}

TEST_CASE("wait_for: string condition on the clock; bad arguments fail by precondition") {
  FakeRobot robot;
  lua::SkillEngine engine(config(), robot);
  REQUIRE(engine.exec("wait_for{secs=1}"));
  // The deadline is set in the first cycle; 30 periods later are 10 ns short of 1 s.
  CHECK(test::run_cycles(engine, robot, 31) == SkillStatus::kRunning);
  CHECK(test::run_cycles(engine, robot, 1) == SkillStatus::kFinal);

  REQUIRE(engine.exec("wait_for{secs='soon'}"));
  CHECK(test::run_cycles(engine, robot, 1) == SkillStatus::kFailed);
  CHECK(engine.error() == "wait_for: wait_for needs secs=<number >= 0>");
}

TEST_CASE("goto_place drives with the navigator and reports its failure") {
  FakeRobot robot;
  robot.nav_steps = 10;
  lua::SkillEngine engine(config(), robot);
  REQUIRE(engine.exec("goto_place{place='M2'}"));
  CHECK(test::run_cycles(engine, robot, 5) == SkillStatus::kRunning);
  CHECK(robot.nav_goal == "M2");
  CHECK(robot.nav.goal_id == 1);  // the goal is sent once, on entry
  CHECK(test::run_until_done(engine, robot) == SkillStatus::kFinal);
  CHECK(robot.stops == 0);

  REQUIRE(engine.exec("goto_place{place='M11'}"));
  CHECK(test::run_until_done(engine, robot) == SkillStatus::kFailed);
  CHECK(engine.error() == "goto_place: navigator INVALID_GOAL: unknown place 'M11'");
}

TEST_CASE("sub-skills through SkillJumpState: args, per-skill status, chained states") {
  FakeRobot robot;
  robot.nav_steps = 6;
  lua::SkillEngine engine(config(), robot);
  REQUIRE(engine.exec("visit_place{place='D1', secs=0.5}"));
  test::run_cycles(engine, robot, 2);
  CHECK(engine.skill_state("visit_place") == "GOTO");
  CHECK(engine.skill_status("goto_place") == SkillStatus::kRunning);
  CHECK(engine.skill_status("wait_for") == SkillStatus::kInactive);
  CHECK(robot.nav_goal == "D1");
  test::run_cycles(engine, robot, 5);
  CHECK(engine.skill_state("visit_place") == "WAIT");
  CHECK(engine.skill_status("goto_place") == SkillStatus::kFinal);
  CHECK(engine.skill_status("wait_for") == SkillStatus::kRunning);
  CHECK(test::run_until_done(engine, robot) == SkillStatus::kFinal);
  CHECK(engine.skill_status("visit_place") == SkillStatus::kInactive);
}

TEST_CASE("a failing sub-skill fails its parent with state, sub-skill and reason") {
  FakeRobot robot;
  lua::SkillEngine engine(config(), robot);
  REQUIRE(engine.exec("visit_place{place='M11'}"));
  CHECK(test::run_until_done(engine, robot) == SkillStatus::kFailed);
  CHECK(engine.error() ==
        "visit_place: GOTO()/goto_place failed: navigator INVALID_GOAL: unknown place 'M11'");
}

TEST_CASE("several skills in one string: FAILED wins over RUNNING, RUNNING over FINAL") {
  FakeRobot robot;
  robot.nav_steps = 100;
  lua::SkillEngine engine(config(), robot);
  REQUIRE(engine.exec("say_hello{} goto_place{place='M1'}"));
  CHECK(test::run_cycles(engine, robot, 3) == SkillStatus::kRunning);
  CHECK(engine.skill_status("say_hello") == SkillStatus::kFinal);
  REQUIRE(engine.exec("goto_place{place='M1'} wait_for{secs=-1}"));
  CHECK(test::run_cycles(engine, robot, 1) == SkillStatus::kFailed);
  CHECK(engine.error().find("wait_for: wait_for needs secs") == 0);
}

TEST_CASE("the skill string may branch on skill statuses") {
  FakeRobot robot;
  lua::SkillEngine engine(config(), robot);
  test::LogCapture log;
  log.attach(engine);
  REQUIRE(engine.exec("if wait_for{secs=0.1} == S_FINAL then say_hello{who='after'} end"));
  CHECK(test::run_until_done(engine, robot) == SkillStatus::kFinal);
  CHECK(log.contains("robot1 says hello to after"));
}

TEST_CASE("failure texts without error=: the state and the condition or timeout") {
  FakeRobot robot;
  lua::SkillEngine engine(config(), robot);
  REQUIRE(engine.exec("fail_texts{mode='precond'}"));
  CHECK(engine.cycle() == SkillStatus::kFailed);
  CHECK(engine.error() == "fail_texts: CHECK: precondition vars.mode == 'precond'");
  REQUIRE(engine.exec("fail_texts{mode='cond'}"));
  CHECK(engine.cycle() == SkillStatus::kFailed);
  CHECK(engine.error() == "fail_texts: CHECK: vars.mode == 'cond'");
  REQUIRE(engine.exec("fail_texts{mode='hook'}"));
  CHECK(engine.cycle() == SkillStatus::kFailed);
  CHECK(engine.error() == "fail_texts: set by the loop hook");
  REQUIRE(engine.exec("fail_texts{mode='wait'}"));
  // Entered in cycle 1; 3 periods later are 1 ns short of 0.1 s, 4 are past it.
  CHECK(test::run_cycles(engine, robot, 4) == SkillStatus::kRunning);
  CHECK(test::run_cycles(engine, robot, 1) == SkillStatus::kFailed);
  CHECK(engine.error() == "fail_texts: CHECK: timeout after 0.1 s");
}
