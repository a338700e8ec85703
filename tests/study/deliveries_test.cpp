// SPDX-License-Identifier: MIT
// Deliveries are counted one way (docs/statistics.md, "Deliveries"): the products the delivery
// gates took, in the statistic, the summary, the JSON and the test case deliveries_at_least. The
// game: the default scenario under the rule book's rules (no pending credit for a product
// delivered outside every window), seed 104, where one of the ten products reached a gate in the
// second between two order windows: ten deliveries, nine units credited to orders. Before issue
// #34 the test case counted the nine, so `deliveries_at_least: 10` failed beside a summary of 10.
#include <doctest/doctest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "llsf/study/runner.h"
#include "llsf/study/scenario.h"

using namespace llsf;
using namespace llsf::study;

TEST_CASE("deliveries: the test case counts what the gates took, as the summary does") {
  const auto dir = std::filesystem::temp_directory_path() / "llsf_deliveries";
  std::filesystem::create_directories(dir);
  const std::string path = (dir / "rulebook.yaml").string();
  std::ofstream(path) << "name: default-rulebook\n"
                         "rates: {physics_hz: 60, skill_hz: 15}\n"
                         "world: {sensors: {laser: {enabled: false}}}\n"
                         "refbox: {rules: rulebook-2013}\n"
                         "robots:\n"
                         "  count: 3\n"
                         "  locks: true\n"
                         "  agent: [" LLSF_SOURCE_DIR "/clips/agents/common, " LLSF_SOURCE_DIR
                         "/clips/agents/llsf2013]\n"
                         "  config: {roles: [P1P2, P3, P3], recycle: never}\n"
                         "tests:\n"
                         "  - deliveries_at_least: 10\n"
                         "  - {name: ten by the end of production, deliveries_at_least: 10, "
                         "by_s: 1080}\n"
                         "  - deliveries_at_least: 11\n";
  const RunResult r = run_game(load_scenario(path).variants.at(0), 104);
  int credited = 0;
  for (const OrderResult& o : r.orders) credited += o.delivered;
  CHECK(r.deliveries == 10);
  CHECK(credited == 9);  // one product outside every window: no order was credited with it
  REQUIRE(r.tests.size() == 3);
  CHECK(r.tests[0].passed);
  CHECK(r.tests[0].detail == "10 deliveries (need >= 10 deliveries)");
  CHECK(r.tests[1].passed);
  CHECK_FALSE(r.tests[2].passed);
  CHECK(r.tests[2].detail == "10 deliveries (need >= 11 deliveries)");
  std::filesystem::remove_all(dir);
}
