// SPDX-License-Identifier: MIT
// The scenario budgets (docs/security.md, "Scenario budgets"): every bound of a key that can make
// a game run long or a batch large is refused at the key's file:line, and so are matrices with
// too many variants or two variants of one name, a directory given as the scenario and an agent
// directory without CLIPS files.
#include <doctest/doctest.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <string>

#include "llsf/core/error.h"
#include "llsf/study/batch.h"
#include "llsf/study/scenario.h"
#include "support/temp_dir.h"

using namespace llsf;
using namespace llsf::study;

namespace {

const llsf::test::TempDir& temp() {
  static const llsf::test::TempDir dir("llsf_scenario_budget_test");  // removed at exit
  return dir;
}

std::string scenario_file(const std::string& name, const std::string& text) {
  const std::filesystem::path p = temp().path / name;
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

/// The error of a scenario "name: b\n" + `body`; CHECKs that it names `where` (file:line:) and
/// `key`, and returns it.
std::string refused(const std::string& body, const std::string& where, const std::string& key) {
  static int n = 0;
  const std::string p = scenario_file("b" + std::to_string(n++) + ".yaml", "name: b\n" + body);
  const std::string e = error_of(p);
  INFO("scenario: " << body);
  INFO("error: " << e);
  CHECK(e.starts_with(p + ":" + where));
  CHECK(e.find(" " + key + ": ") != std::string::npos);
  return e;
}

}  // namespace

TEST_CASE("scenario budgets: duration_s has a lower and an upper bound") {
  for (const char* v : {"1e7", "1e300", "1e10", "1e-300", "0.5", "3601"}) {
    const std::string e = refused(std::string("duration_s: ") + v + "\n", "2:", "duration_s");
    CHECK(e.find("must be in [1, 3600]") != std::string::npos);
  }
  CHECK(error_of(scenario_file("d-ok.yaml", "name: d\nduration_s: 3600\n")).empty());
  CHECK(error_of(scenario_file("d-ok2.yaml", "name: d\nduration_s: 1\n")).empty());
}

TEST_CASE("scenario budgets: rates are bounded at their keys") {
  refused("rates:\n  physics_hz: 1e300\n", "3:", "rates.physics_hz");
  refused("rates:\n  physics_hz: 5\n", "3:", "rates.physics_hz");
  refused("rates:\n  skill_hz: 1e-300\n", "3:", "rates.skill_hz");
  refused("rates:\n  agent_hz: 1e300\n", "3:", "rates.agent_hz");
  refused("rates:\n  beacon_period_s: 1e300\n", "3:", "rates.beacon_period_s");
  refused("rates:\n  beacon_period_s: 1e-300\n", "3:", "rates.beacon_period_s");
  // Within the bounds, but faster than the physics: GameConfig::validate()'s error at the key.
  const std::string e = refused("rates:\n  skill_hz: 500\n", "3:", "rates.skill_hz");
  CHECK(e.find("must not exceed the physics rate 100 Hz") != std::string::npos);
  refused("rates:\n  physics_hz: 40\n  agent_hz: 50\n", "4:", "rates.agent_hz");
  // The physics slower than the default skill rate (30 Hz): at the physics rate.
  refused("rates:\n  physics_hz: 20\n", "3:", "rates.physics_hz");
}

TEST_CASE("scenario budgets: levels keys are bounded at their keys, not at the top level") {
  refused("levels:\n  light_error_rate: 2\n", "3:", "levels.light_error_rate");
  refused("levels:\n  light_delay_s: 1e300\n", "3:", "levels.light_delay_s");
  refused("levels:\n  light_delay_s: 61\n", "3:", "levels.light_delay_s");
  refused("levels:\n  cruise_speed_mps: 0\n", "3:", "levels.cruise_speed_mps");
  refused("levels:\n  cruise_speed_mps: 1e-300\n", "3:", "levels.cruise_speed_mps");
  refused("levels:\n  position_noise_m: 1e300\n", "3:", "levels.position_noise_m");
  refused("levels:\n  position_noise_m: -1\n", "3:", "levels.position_noise_m");
  refused("levels:\n  heading_noise_rad: 7\n", "3:", "levels.heading_noise_rad");
}

TEST_CASE("scenario budgets: the physics steps of one game are bounded") {
  // 3600 s at 1000 Hz: the most there is.
  CHECK(error_of(scenario_file("steps-ok.yaml",
                               "name: s\nduration_s: 3600\nrates: {physics_hz: 1000}\n"))
            .empty());
  // A step of 1 microsecond from the world: refused at the step.
  const std::string e = refused("duration_s: 60\nworld:\n  physics:\n    step_ms: 0.001\n",
                                "5:", "world.physics.step_ms");
  CHECK(e.find("physics steps") != std::string::npos);
}

TEST_CASE("scenario budgets: seeds are bounded") {
  refused("seeds: {first: 1, count: 100001}\n", "2:", "seeds.count");
  std::string list = "seeds: [";
  for (int i = 0; i <= ScenarioLimits::kMaxSeeds; ++i) list += (i ? ",1" : "1");
  const std::string e = refused(list + "]\n", "2:", "seeds");
  CHECK(e.find("at most 100000") != std::string::npos);
}

TEST_CASE("scenario budgets: a test case's deadline lies within the game") {
  refused("duration_s: 60\ntests:\n  - {points_at_least: 1, by_s: 1e300}\n", "4:", "tests[0].by_s");
  refused("duration_s: 60\ntests:\n  - {points_at_least: 1, by_s: 61}\n", "4:", "tests[0].by_s");
}

TEST_CASE("scenario budgets: the variants of a matrix are counted before they are expanded") {
  // 2^11 = 2048 variants: refused at the matrix, without playing or expanding any.
  std::string m = "matrix:\n";
  for (int a = 0; a < 11; ++a) m += "  a" + std::to_string(a) + ": {x: {}, y: {}}\n";
  std::string e = refused(m, "3:", "matrix");
  CHECK(e.find("more than 1000 variants") != std::string::npos);
  // 2^64 and more: no overflow, at once.
  m = "matrix:\n";
  for (int a = 0; a < 70; ++a) m += "  a" + std::to_string(a) + ": {x: {}, y: {}}\n";
  const auto start = std::chrono::steady_clock::now();
  e = refused(m, "3:", "matrix");
  CHECK(e.find("more than 1000 variants") != std::string::npos);
  CHECK(std::chrono::steady_clock::now() - start < std::chrono::seconds(5));
  // 1000 variants pass.
  m = "name: m\nmatrix:\n  a: {";
  for (int v = 0; v < 10; ++v) m += (v ? ", v" : "v") + std::to_string(v) + ": {}";
  m += "}\n  b: {";
  for (int v = 0; v < 100; ++v) m += (v ? ", v" : "v") + std::to_string(v) + ": {}";
  m += "}\n";
  CHECK(load_scenario(scenario_file("m1000.yaml", m)).variants.size() == 1000);
}

TEST_CASE("scenario budgets: the games of a matrix (variants x seeds) are bounded") {
  const std::string e =
      refused("seeds: {first: 1, count: 60000}\nmatrix:\n  a: {x: {}, y: {}}\n", "4:", "matrix");
  CHECK(e.find("more than 100000 games") != std::string::npos);
}

TEST_CASE("scenario budgets: two matrix variants of one name are refused with both lines") {
  const std::string p = scenario_file("dup.yaml",
                                      "name: d\n"
                                      "matrix:\n"
                                      "  a:\n"
                                      "    x: {}\n"
                                      "    'x,b=y': {}\n"
                                      "  b:\n"
                                      "    'y,b=z': {}\n"
                                      "    z: {}\n");
  const std::string e = error_of(p);
  INFO(e);
  CHECK(e.starts_with(p + ":5:"));                // the second variant's value ...
  CHECK(e.find(p + ":4:") != std::string::npos);  // ... and the first's
  CHECK(e.find("two variants are named 'a=x,b=y,b=z'") != std::string::npos);
}

TEST_CASE("scenario budgets: a directory is not a scenario file") {
  std::filesystem::create_directories(temp().path / "a-dir");
  const std::string p = (temp().path / "a-dir").string();
  CHECK(error_of(p) == p + ": is a directory, expected a scenario file");
}

TEST_CASE("scenario budgets: an agent directory without .clp files is refused at its key") {
  std::filesystem::create_directories(temp().path / "empty-agent");
  std::ofstream(temp().path / "empty-agent" / "notes.txt") << "no agent here\n";
  std::filesystem::create_directories(temp().path / "empty-agent" / "sub.clp");  // a directory
  std::string e = refused("robots:\n  count: 1\n  agent: empty-agent\n", "4:", "robots.agent");
  CHECK(e.find("has no .clp files") != std::string::npos);
  e = refused("robots:\n  count: 1\n  each:\n    - agent: [empty-agent]\n",
              "5:", "robots.each[0].agent[0]");
  CHECK(e.find("has no .clp files") != std::string::npos);
}

TEST_CASE("scenario budgets: batch --runs is bounded before any seed list is made") {
  Scenario s;
  s.file = "x.yaml";
  CHECK_THROWS_AS(batch_seeds(s, ScenarioLimits::kMaxSeeds + 1), core::ConfigError);
  CHECK(batch_seeds(s, 3).size() == 3);
}

TEST_CASE("scenario budgets: the world's errors about a robot are located at robots.each") {
  std::string e = refused("robots:\n  count: 2\n  each:\n    - {jersey: 5}\n    - {jersey: 5}\n",
                          "6:", "robots.each[1].jersey");
  CHECK(e.find("duplicate jersey number 5") != std::string::npos);
  refused("robots:\n  each:\n    - {jersey: 1000}\n", "4:", "robots.each[0].jersey");
  refused("robots:\n  each:\n    - {name: ''}\n", "4:", "robots.each[0].name");
  e = refused("robots:\n  each:\n    - start: {x: 5.5}\n", "4:", "robots.each[0].start");
  CHECK(e.find("outside the field") != std::string::npos);
  refused("robots:\n  each:\n    - start: {x: 1e300}\n", "4:", "robots.each[0].start.x");
}

TEST_CASE("scenario budgets: a profile's noises and waits are bounded") {
  refused("profile:\n  name: ideal\n  position_noise_m: 1e300\n", "4:", "profile.position_noise_m");
  refused("profile:\n  name: ideal\n  heading_noise_rad: 1e300\n",
          "4:", "profile.heading_noise_rad");
  refused("profile:\n  name: ideal\n  wait_before_replan_s: 1e300\n",
          "4:", "profile.wait_before_replan_s");
  refused("profile:\n  name: ideal\n  backoff_max_s: 1e300\n", "4:", "profile.backoff_max_s");
  refused("profile:\n  name: ideal\n  motor_max_speed_mps: 1e300\n",
          "4:", "profile.motor_max_speed_mps");
}

TEST_CASE("scenario budgets: a hackathon layout without room is an error of the file, at its key") {
  // Pucks 100 m apart cannot be placed: found by the loader (with the line), not by the game.
  std::string e = refused("hackathon:\n  puck_spacing_m: 100\n", "3:", "hackathon");
  CHECK(e.find("no free spot for puck") != std::string::npos);
  e = refused("hackathon:\n  puck_spacing_m: 100\n  colours: [{name: red, count: 3}]\n",
              "4:", "hackathon.colours");
  CHECK(e.find("no free spot for puck") != std::string::npos);
}

TEST_CASE(
    "scenario budgets: batch_games counts variants x --runs and refuses more than the budget") {
  const std::string p = scenario_file("two.yaml", "name: two\nmatrix:\n  a: {x: {}, y: {}}\n");
  const ScenarioFile f = load_scenario(p);
  CHECK(batch_games(f, 50000) == 100000);
  try {
    (void)batch_games(f, 50001);
    FAIL("no error");
  } catch (const core::ConfigError& e) {
    CHECK(std::string(e.what()) == p + ": 2 variants x --runs 50001 = 100002 games: at most 100000 "
                                       "(docs/security.md, \"Scenario budgets\")");
  }
}
