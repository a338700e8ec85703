// SPDX-License-Identifier: MIT
// Scenario files: keys, matrix expansion, errors with file:line; running one game of a scenario
// with test-case verdicts and a result hash.
#include <doctest/doctest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "llsf/core/error.h"
#include "llsf/sim/agent_brain.h"
#include "llsf/sim/game.h"
#include "llsf/study/player.h"
#include "llsf/study/runner.h"
#include "llsf/study/scenario.h"
#include "support/temp_dir.h"

using namespace llsf;
using namespace llsf::sim;
using namespace llsf::study;

namespace {

/// Writes `text` to a scenario file in a temp directory next to links to the agents.
std::string scenario_file(const std::string& name, const std::string& text) {
  static const llsf::test::TempDir dir("llsf_scenario_test");  // removed at exit
  const std::filesystem::path p = dir.path / name;
  std::ofstream(p) << text;
  return p.string();
}

std::string error_of(const std::string& path) {
  try {
    load_scenario(path);
  } catch (const core::ConfigError& e) {
    return e.what();
  }
  return "";
}

const std::string kAgent = "  agent: [" LLSF_SOURCE_DIR "/clips/agents/common, " LLSF_SOURCE_DIR
                           "/clips/agents/llsf2013]\n";

}  // namespace

TEST_CASE("the shipped scenarios load; matrices expand in file order") {
  const ScenarioFile d = load_scenario(LLSF_SOURCE_DIR "/scenarios/default.yaml");
  REQUIRE(d.variants.size() == 1);
  CHECK(d.variants[0].robots.size() == 3);
  CHECK(d.variants[0].duration == SimTime::from_sec(1080));
  CHECK(d.variants[0].tests.size() == 4);
  const ScenarioFile two = load_scenario(LLSF_SOURCE_DIR "/scenarios/thesis-two-robots.yaml");
  REQUIRE(two.variants.size() == 5);
  CHECK(two.variants[0].variant == "config=P3-P3");
  CHECK(two.variants[4].variant == "config=P1P2-P3-RD");
  CHECK(two.variants[0].seeds.size() == 20);
  // The override reached the robots' confval entries.
  bool p3p3 = false;
  for (const auto& e : two.variants[0].robots[0].config) {
    if (e.path == "/clips-agent/roles") p3p3 = e.values.at(0) == clips::Value::string("P3");
  }
  CHECK(p3p3);
  const ScenarioFile loss = load_scenario(LLSF_SOURCE_DIR "/scenarios/packet-loss.yaml");
  REQUIRE(loss.variants.size() == 5);
  CHECK(loss.variants[2].game.hub.loss_probability == doctest::Approx(0.2));
}

TEST_CASE("scenario errors name file, line and key") {
  std::string e = error_of(scenario_file("a.yaml", "name: a\nrobotz: {}\n"));
  CHECK(e.find("a.yaml:") != std::string::npos);
  CHECK(e.find("robotz") != std::string::npos);
  e = error_of(scenario_file("b.yaml", "name: b\nrobots:\n  count: 7\n"));
  CHECK(e.find("b.yaml:3:") != std::string::npos);
  CHECK(e.find("robots.count") != std::string::npos);
  e = error_of(scenario_file("c.yaml", "name: c\nrobots:\n  agent: [no/such/dir]\n"));
  CHECK(e.find("c.yaml:3:") != std::string::npos);
  CHECK(e.find("not found") != std::string::npos);
  e = error_of(scenario_file("d.yaml", "name: d\nlevels: {light: laser}\n"));
  CHECK(e.find("unknown detection level 'laser' (expected one of: ground_truth, vision)") !=
        std::string::npos);
  e = error_of(scenario_file("e.yaml",
                             "name: e\nmatrix:\n  loss:\n    bad: {radio.loss: {model: lossy}}\n"));
  CHECK(e.find("e.yaml:4:") != std::string::npos);  // the override's line
  e = error_of(scenario_file(
      "f.yaml", "name: f\ntests:\n  - {points_at_least: 3, deliveries_at_least: 1}\n"));
  CHECK(e.find("exactly one condition") != std::string::npos);
  e = error_of(scenario_file("g.yaml", "name: g\nseed: 1\nseeds: [2]\n"));
  CHECK(e.find("either 'seed' or 'seeds'") != std::string::npos);
  CHECK(error_of(scenario_file("h.yaml", "name: [\n")).find("YAML syntax error") !=
        std::string::npos);
  CHECK(error_of("/no/such/file.yaml").find("cannot read") != std::string::npos);
}

TEST_CASE("scenario: an unknown key is reported at its file:line:column with a hint") {
  std::string p = scenario_file("k1.yaml", "name: k\ndurration_s: 5\n");
  CHECK(error_of(p) ==
        p + ":2:14: durration_s: unknown key 'durration_s' (did you mean 'duration_s'?)");
  p = scenario_file("k2.yaml",
                    "name: k\nrobots:\n  count: 1\n  each:\n    - {start: {x: 1, yy: 2}}\n");
  CHECK(error_of(p) == p + ":5:26: robots.each[0].start.yy: unknown key 'yy' (did you mean 'y'?)");
  // Before the count of conditions: the misspelt condition is the cause.
  p = scenario_file("k3.yaml", "name: k\ntests:\n  - {point_at_least: 3}\n");
  CHECK(error_of(p) == p + ":3:22: tests[0].point_at_least: unknown key 'point_at_least' (did you "
                           "mean 'points_at_least'?)");
  p = scenario_file("k4.yaml", "name: k\nseeds: {first: 3, count: 2, step: 1}\n");
  CHECK(error_of(p) == p + ":2:35: seeds.step: unknown key 'step' (allowed: first, count)");
  // In a matrix cell: the key of the override.
  p = scenario_file("k5.yaml", "name: k\nmatrix:\n  r:\n    a: {rates.skil_hz: 5}\n");
  CHECK(error_of(p) ==
        p + ":4:24: rates.skil_hz: unknown key 'skil_hz' (did you mean 'skill_hz'?)");
  // Bounds: at the value, with what was given.
  p = scenario_file("k6.yaml", "name: k\nrates: {physics_hz: -5}\n");
  CHECK(error_of(p) == p + ":2:21: rates.physics_hz: must be in [10, 1000] (got -5)");
  p = scenario_file("k7.yaml", "name: k\nseeds: {count: 0}\n");
  CHECK(error_of(p) == p + ":2:16: seeds.count: must be in [1, 100000] (got 0)");
}

TEST_CASE("jersey numbers: per robot in `each`, in the agent, the beacons and the recording") {
  const ScenarioFile f = load_scenario(scenario_file(
      "jersey.yaml", "name: j\nstart: production\nduration_s: 3\nrobots:\n  count: 2\n" + kAgent +
                         "  each:\n    - {jersey: 7}\n    - {name: beta, jersey: 3}\n"));
  const Scenario& s = f.variants[0];
  CHECK(s.game.world.robots[0].jersey_or(0) == 7);
  CHECK(s.game.world.robots[1].name == "beta");
  Game game(s.game);
  AgentBrain brain(game, 1, agent_config(s, s.robots[1]));
  game.set_brain(1, &brain);
  brain.agent().start(SimTime{});  // (reset): the identity globals
  CHECK(brain.agent().eval("?*ROBOT-NUMBER*").number() == doctest::Approx(3.0));
  std::string header;
  RunHooks hooks;
  hooks.record_sink = [&](std::string_view line) {
    if (header.empty()) header = line;
  };
  run_game(s, 1, hooks);
  CHECK(nlohmann::json::parse(header)["jerseys"] == nlohmann::json{7, 3});
  // Unique; 1..99.
  std::string e = error_of(
      scenario_file("jersey2.yaml", "name: j\nrobots:\n  count: 2\n  each:\n    - {jersey: 2}\n"));
  CHECK(e.find("duplicate jersey number 2") != std::string::npos);
  e = error_of(scenario_file("jersey3.yaml",
                             "name: j\nrobots:\n  count: 1\n  each:\n    - {jersey: 120}\n"));
  CHECK(e.find("must be in 1..99") != std::string::npos);
}

TEST_CASE("run_game: a short production game, verdicts judged at their deadline, same hash") {
  const std::string path =
      scenario_file("run.yaml",
                    "name: short\nseed: 7\nstart: production\nduration_s: 240\nrobots:\n"
                    "  count: 2\n" +
                        kAgent +
                        "  config: {roles: [P3, P3]}\n"
                        "tests:\n"
                        "  - {name: early, points_at_least: 1000, by_s: 60}\n"
                        "  - {deliveries_at_least: 1}\n"
                        "  - {no_agent_errors: true}\n");
  const ScenarioFile f = load_scenario(path);
  const RunResult a = run_game(f.variants[0], 7);
  CHECK(a.seed == 7);
  CHECK(a.game_time_s == doctest::Approx(240.0));
  REQUIRE(a.tests.size() == 3);
  CHECK_FALSE(a.tests[0].passed);
  CHECK(a.tests[0].detail.find("by 60 s") != std::string::npos);
  CHECK(a.tests[1].passed);
  CHECK(a.tests[2].passed);
  CHECK_FALSE(a.passed());
  CHECK(a.deliveries >= 1);
  const RunResult b = run_game(f.variants[0], 7);
  CHECK(a.result_hash == b.result_hash);
  CHECK(a.points == b.points);
  const RunResult c = run_game(f.variants[0], 8);
  CHECK(c.result_hash != a.result_hash);
  const nlohmann::ordered_json json = nlohmann::ordered_json::parse(to_json(a));
  CHECK(json.begin().key() == "scenario");
  CHECK(json["scenario"] == "short");
  CHECK(json["passed"] == false);
}

TEST_CASE("radio lock_messages: 2013 changes the numbers on the wire, not the game") {
  // Locks on: the agents' LockMessage and LockMasterAnnounce go through the hub as (2000, 1337)
  // and (2000, 1338); the refbox, which hears component 2000, must ignore them as it ignores
  // (2100, 1|2), so the game (world, refbox, messages sent) is the same.
  const std::string body =
      "seed: 3\nstart: production\nduration_s: 90\nrobots:\n  count: 2\n"
      "  locks: true\n" +
      kAgent + "  config: {roles: [P3, P3]}\n";
  const ScenarioFile ours = load_scenario(scenario_file("locks-llsfsim.yaml", "name: l\n" + body));
  const ScenarioFile old = load_scenario(
      scenario_file("locks-2013.yaml", "name: l\nradio: {lock_messages: 2013}\n" + body));
  CHECK(ours.variants[0].game.hub.lock_messages == comm::LockNumbering::kLlsfsim);
  REQUIRE(old.variants[0].game.hub.lock_messages == comm::LockNumbering::k2013);
  const RunResult a = run_game(ours.variants[0], 3);
  const RunResult b = run_game(old.variants[0], 3);
  CHECK(a.lock_grants > 0);
  CHECK(b.lock_grants == a.lock_grants);
  CHECK(b.lock_refusals == a.lock_refusals);
  CHECK(b.points == a.points);
  CHECK(b.messages_sent == a.messages_sent);
  CHECK(b.result_hash == a.result_hash);

  // The key is checked where it stands.
  const std::string p =
      scenario_file("locks-bad.yaml", "name: l\nradio:\n  lock_messages: 2014\n" + body);
  CHECK(error_of(p) == p + ":3:18: radio.lock_messages: unknown lock message numbering '2014' "
                           "(expected llsfsim: component 2100, or 2013: component 2000, types "
                           "1337 and 1338)");
}

TEST_CASE("scenario: refbox.known_teams fills GameInfo's known teams; bad lists are refused") {
  const ScenarioFile f = load_scenario(scenario_file(
      "t1.yaml",
      "name: t\nrefbox: {team: Carologistics, known_teams: [Carologistics, Solidus]}\n"));
  const std::vector<std::string> want = {"Carologistics", "Solidus"};
  CHECK(f.variants.at(0).game.protocol.known_teams == want);
  CHECK(f.variants.at(0).game.refbox.team == "Carologistics");
  CHECK(load_scenario(scenario_file("t2.yaml", "name: t\n"))
            .variants.at(0)
            .game.protocol.known_teams.empty());
  std::string p = scenario_file("t3.yaml", "name: t\nrefbox: {known_teams: Solidus}\n");
  CHECK(error_of(p).find("refbox.known_teams: a list of team names") != std::string::npos);
  p = scenario_file("t4.yaml", "name: t\nrefbox: {known_teams: [A, B, A]}\n");
  CHECK(error_of(p).find("'A' is listed twice") != std::string::npos);
  p = scenario_file("t5.yaml", "name: t\nrefbox: {known_teams: [\"\"]}\n");
  CHECK(error_of(p).find("a team name has 1 to 64 characters") != std::string::npos);
}

TEST_CASE("scenario: each[i].agent_start_s, referee.remove_delay_s, levels.light_view") {
  const ScenarioFile f = load_scenario(
      scenario_file("start.yaml",
                    "name: s\nstart: production\nduration_s: 3\nreferee: {remove_delay_s: 5}\n"
                    "levels: {light_view: laser_cluster}\nrobots:\n  count: 2\n" +
                        kAgent + "  each:\n    - {}\n    - {agent_start_s: 1.5}\n"));
  const Scenario& s = f.variants[0];
  CHECK(s.game.referee_remove_delay == SimTime::from_sec(5));
  CHECK(s.game.levels.light.view == LightView::kLaserCluster);
  CHECK(s.robots[0].agent_start == SimTime());
  CHECK(s.robots[1].agent_start == SimTime::from_ms(1500));
  // The late robot's agent neither cycles nor fires a rule before its start.
  Game game(s.game);
  AgentBrain brain(game, 1, agent_config(s, s.robots[1]));
  game.set_brain(1, &brain);
  brain.agent().start(SimTime{});
  const std::int64_t fired = brain.agent().rules_fired();
  game.run_until(SimTime::from_ms(1400));
  CHECK(brain.agent().rules_fired() == fired);
  game.run_until(SimTime::from_ms(1700));
  CHECK(brain.agent().rules_fired() > fired);
  game.set_brain(1, nullptr);
  // Bad values name the key.
  std::string e = error_of(scenario_file(
      "start2.yaml", "name: s\nrobots:\n  count: 1\n  each:\n    - {agent_start_s: -1}\n"));
  CHECK(e.find("agent_start_s") != std::string::npos);
  e = error_of(scenario_file("start3.yaml", "name: s\nreferee: {remove_delay_s: 61}\n"));
  CHECK(e.find("remove_delay_s") != std::string::npos);
  e = error_of(scenario_file("start4.yaml", "name: s\nlevels: {light_view: sideways}\n"));
  CHECK(e.find("light_view") != std::string::npos);
}
