// SPDX-License-Identifier: MIT
// A runaway agent (a rule that re-fires forever, an endless loop in a rule's actions) is halted
// after a bounded number of runaway cycles: its robot stops, one agent-halted issue says why, the
// no_agent_errors test case and the run fail; --fail-fast (RunHooks::stop_at_agent_error) ends
// the game at the first agent error.
#include <doctest/doctest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <string>

#include "llsf/kinematic/world.h"
#include "llsf/sim/agent_brain.h"
#include "llsf/study/runner.h"
#include "llsf/study/scenario.h"

using namespace llsf;
using namespace llsf::study;

namespace {

std::string write(const std::filesystem::path& p, const std::string& text) {
  std::filesystem::create_directories(p.parent_path());
  std::ofstream(p) << text;
  return p.string();
}

/// A one-robot scenario of `duration_s` whose agent drives towards M10 and, from 2 s on, runs
/// away with `runaway` (the actions of a rule that fires once at 2 s, or rules of their own).
ScenarioFile runaway_scenario(const std::filesystem::path& dir, const std::string& runaway,
                              int duration_s) {
  write(dir / "agent" / "a.clp",
        "(defrule go (time $?) (not (went)) => (assert (went))\n"
        "  (skill-call drive_to place \"M10\"))\n" +
            runaway);
  return load_scenario(
      write(dir / "s.yaml", "name: runaway\nduration_s: " + std::to_string(duration_s) +
                                "\nstart: production\n"
                                "robots: {count: 1, agent: [agent]}\n"
                                "tests:\n  - no_agent_errors: true\n"));
}

const char* const kSpin =
    "(defrule start-spin (time ?s ?) (test (>= ?s 2)) (not (spun)) => (assert (spun) (spin 0)))\n"
    "(defrule spin ?f <- (spin ?n) => (retract ?f) (assert (spin (+ ?n 1))))\n";

}  // namespace

TEST_CASE("a rule that re-fires forever: the agent is halted, its robot stops, the run fails") {
  const auto dir = std::filesystem::temp_directory_path() / "llsf_runaway_spin";
  std::filesystem::remove_all(dir);
  const ScenarioFile f = runaway_scenario(dir, kSpin, 12);
  // The robot's speed after the halt: it must stand still.
  double halt_s = -1.0;
  double speed_after_halt = 0.0;
  RunHooks hooks;
  hooks.tick = [&](const sim::Game& g) {
    if (halt_s < 0.0 || g.time().seconds() < halt_s + 1.0) return;
    const core::Vec2 v = g.world().robot_velocity(core::RobotId(0));
    speed_after_halt = std::max(speed_after_halt, v.norm());
  };
  hooks.note = [&](core::SimTime t, const std::string& robot, const std::string& text) {
    CHECK(robot == "robot1");
    CHECK(text.find("agent halted after 10 runaway cycles (10 cut by the rule firing limit") !=
          std::string::npos);
    halt_s = t.seconds();
  };
  const RunResult r = run_game(f.variants.at(0), 1, hooks);
  int loops = 0;
  int halts = 0;
  for (const RunIssue& i : r.issues) {
    if (i.kind == IssueKind::kRuleLoop) ++loops;
    if (i.kind == IssueKind::kAgentHalted) {
      ++halts;
      CHECK(i.robot == "robot1");
      CHECK(i.is_mistake());
      CHECK(i.text.find("the robot stops") != std::string::npos);
    }
  }
  CHECK(loops == sim::AgentBrainConfig{}.max_runaway_cycles);  // bounded: no more cycles
  CHECK(halts == 1);
  REQUIRE(halt_s > 2.0);
  CHECK(halt_s < 5.0);
  CHECK(speed_after_halt < 1e-6);
  CHECK(r.agent_error());
  CHECK_FALSE(r.passed());
  REQUIRE(r.tests.size() == 2);
  CHECK_FALSE(r.tests[0].passed);  // no_agent_errors: a halted agent is an agent error
  CHECK(r.tests[0].detail.find("1 agent(s) halted") != std::string::npos);
  CHECK(r.tests[1].name == "no agent halted");
  CHECK_FALSE(r.tests[1].passed);
  std::filesystem::remove_all(dir);
}

TEST_CASE("an endless loop in every cycle's actions: halted after the same bound") {
  const auto dir = std::filesystem::temp_directory_path() / "llsf_runaway_while";
  std::filesystem::remove_all(dir);
  const ScenarioFile f = runaway_scenario(
      dir, "(defrule forever (time ?s ?) (test (>= ?s 2)) => (while TRUE (bind ?x 1)))\n", 6);
  const RunResult r = run_game(f.variants.at(0), 1);
  int budget = 0;
  int halts = 0;
  for (const RunIssue& i : r.issues) {
    if (i.kind == IssueKind::kRuntimeError && i.rule == "forever") ++budget;
    if (i.kind == IssueKind::kAgentHalted) ++halts;
  }
  CHECK(budget == sim::AgentBrainConfig{}.max_runaway_cycles);
  CHECK(halts == 1);
  CHECK_FALSE(r.passed());
  std::filesystem::remove_all(dir);
}

TEST_CASE("stop_at_agent_error (--fail-fast) ends the game at the first agent error") {
  const auto dir = std::filesystem::temp_directory_path() / "llsf_runaway_fail_fast";
  std::filesystem::remove_all(dir);
  const ScenarioFile f = runaway_scenario(
      dir,
      "(defrule oops (time ?s ?) (test (>= ?s 3)) (not (oops)) => (assert (oops))\n"
      "  (eval \"(no-such-fn 1)\"))\n",
      30);
  const RunResult plain = run_game(f.variants.at(0), 1);
  CHECK(plain.game_time_s == doctest::Approx(30.0));
  CHECK(plain.agent_runtime_errors == 1);
  RunHooks hooks;
  hooks.stop_at_agent_error = true;
  const RunResult r = run_game(f.variants.at(0), 1, hooks);
  CHECK(r.game_time_s >= 3.0);
  CHECK(r.game_time_s < 4.0);
  CHECK_FALSE(r.passed());
  REQUIRE(!r.tests.empty());
  CHECK(r.tests.back().name == "fail-fast: no agent error");
  CHECK(r.tests.back().detail.find("stopped at the first agent error: robot1 at 3.") !=
        std::string::npos);
  std::filesystem::remove_all(dir);
}
