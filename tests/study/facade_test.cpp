// SPDX-License-Identifier: MIT
// The installed interface (llsfsim/llsfsim.h, docs/install.md) against the library it wraps: the
// same game, its statistics by name, bad input as llsfsim::Error. (tests/install/
// out_of_tree_test.sh builds a program against the installed package with this header alone.)
#include <doctest/doctest.h>

#include <llsfsim/llsfsim.h>

#include <cstdio>
#include <string>

#include "llsf/core/version.h"
#include "llsf/study/runner.h"
#include "llsf/study/scenario.h"

namespace {
const std::string kDefault = std::string(LLSF_SOURCE_DIR) + "/scenarios/default.yaml";
}

TEST_CASE("llsfsim.h: a scenario plays the same game as the library's runner") {
  std::vector<llsfsim::Scenario> variants = llsfsim::Scenario::load(kDefault);
  REQUIRE(variants.size() == 1);
  llsfsim::Scenario s = variants.front();
  CHECK(s.name() == "default");
  CHECK(s.variant().empty());
  CHECK(s.duration_s() > 60.0);
  s.set_duration_s(90.0);
  CHECK(s.duration_s() == 90.0);
  const llsfsim::Result r = llsfsim::play(s, 3);

  llsf::study::Scenario direct = llsf::study::load_scenario(kDefault).variants.front();
  direct.duration = llsf::core::SimTime::from_sec(90.0);
  const llsf::study::RunResult want = llsf::study::run_game(direct, 3);
  CHECK(r.hash == want.result_hash);
  CHECK(r.points == want.points);
  CHECK(r.game_time_s == doctest::Approx(90.0));
  CHECK(r.passed == want.passed());
  CHECK(r.statistics.at("points") == want.points);
  CHECK(r.statistics.at("exploration_points") == want.exploration_points);
  // A statistic the game lacks is left out, not given a value: no complex product in 90 s.
  CHECK(r.statistics.count("first_complex_production_s") == 0);
  CHECK(r.statistics.at("complex_made") == 0.0);
  // The summary `run --json` prints, with this game's hash.
  char hex[17];
  std::snprintf(hex, sizeof hex, "%016llx", static_cast<unsigned long long>(want.result_hash));
  CHECK(r.json.front() == '{');
  CHECK(r.json.find(std::string("\"result_hash\":\"") + hex + "\"") != std::string::npos);
  CHECK(llsfsim::version() == std::string(llsf::core::kVersion));
}

TEST_CASE("llsfsim.h: bad input is an llsfsim::Error naming the place") {
  CHECK_THROWS_WITH_AS(llsfsim::Scenario::load("/nonexistent/llsfsim.yaml"),
                       doctest::Contains("/nonexistent/llsfsim.yaml"), llsfsim::Error);
  llsfsim::Scenario s = llsfsim::Scenario::load(kDefault).front();
  CHECK_THROWS_WITH_AS(s.set_duration_s(0.0),
                       "set_duration_s: 0 s is outside [1, 3600] s (the scenario limits)",
                       llsfsim::Error);
  CHECK_THROWS_AS(s.set_duration_s(1e9), llsfsim::Error);
}
