// SPDX-License-Identifier: MIT
// RefboxConfig::validate(), the YAML loader with its error messages, the example config, and the
// game report's JSON rendering.
#include <doctest/doctest.h>

#include <algorithm>
#include <nlohmann/json.hpp>
#include <string>

#include "fixture.h"
#include "llsf/core/error.h"
#include "llsf/refbox/config.h"

using namespace llsf;
using namespace llsf::refbox;
using namespace llsf::refbox::test;
using core::ConfigError;
using core::ConfigNode;

namespace {

std::string validate_error(const RefboxConfig& c) {
  try {
    c.validate();
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "";
}

std::string load_error(const std::string& yaml) {
  try {
    load_refbox_config(ConfigNode::parse(yaml, "rb.yaml"));
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "";
}

const char* kParams = R"(
params:
  machine_types: {M1: T1, M2: T2, M3: T3, M4: T4, M5: T5, M6: T1, M7: T2, M8: T1, M9: T2, M10: T1}
  proc_time_s: {T1: 4, T2: 20, T3: 50, T4: 45, T5: 30}
  light_codes: {T1: G, T2: Y, T3: R, T4: RG, T5: RY}
  order_quantities: [3, 2, 4, 1, 6, 2, 3, 3, 3]
  late_order_start_s: [200, 600]
  down_times: []
  gate_schedule:
    - {gate: D1, start_s: 0, end_s: 300}
    - {gate: D2, start_s: 300, end_s: 600}
    - {gate: D3, start_s: 600, end_s: 900}
)";

}  // namespace

TEST_CASE("RefboxConfig defaults are valid; validate() names the bad field") {
  RefboxConfig c;
  CHECK(validate_error(c).empty());
  CHECK(c.rules == "refbox-0.6.1");
  c.rules = "rulebook-2014";
  CHECK(validate_error(c).find("refbox.rules: unknown rules variant 'rulebook-2014'") == 0);
  c = RefboxConfig();
  c.production_duration = SimTime();
  CHECK(validate_error(c).find("refbox.production_s: must be > 0") == 0);
  c = RefboxConfig();
  c.exploration_duration = SimTime::from_sec(200);
  CHECK(validate_error(c).find("refbox.exploration_s: must be > 0 and <= 180 s") == 0);
  c = RefboxConfig();
  c.pucks = {1, 2, 2};
  CHECK(validate_error(c).find("refbox.pucks[2]: duplicate puck id 2") == 0);
  c = RefboxConfig();
  c.pucks = {0};
  CHECK(validate_error(c).find("refbox.pucks[0]") == 0);
  c = test_config();
  c.params->proc_time_s[1] = -1;
  CHECK(validate_error(c).find("refbox.params.proc_time_s.T2: must be > 0") == 0);
  // The Refbox constructor validates too.
  CHECK_THROWS_AS(Refbox(c, core::Rng(1)), ConfigError);
}

TEST_CASE("YAML loader: values, params and file:line errors") {
  const RefboxConfig c = load_refbox_config(ConfigNode::parse(
      std::string("rules: rulebook-2013\nteam: X\nskip_setup: true\nproduction_s: 120.5\n"
                  "pucks: [5, 6]\nlearn_unknown_pucks: false\n") +
          kParams,
      "rb.yaml"));
  CHECK(c.rules == "rulebook-2013");
  CHECK(c.team == "X");
  CHECK(c.skip_setup);
  CHECK(c.production_duration == SimTime::from_ms(120500));
  CHECK(c.pucks == std::vector<int>{5, 6});
  CHECK_FALSE(c.learn_unknown_pucks);
  REQUIRE(c.params.has_value());
  CHECK(*c.params == test_params());
  // An empty document gives the defaults.
  CHECK(load_refbox_config(ConfigNode::parse("", "rb.yaml")).rules == "refbox-0.6.1");

  CHECK(load_error("rulez: x\n").find("rb.yaml:1:8: rulez: unknown key 'rulez'") == 0);
  CHECK(load_error("rules: nope\n").find("rb.yaml:1:8: rules: unknown rules variant") == 0);
  CHECK(load_error("production_s: 0\n") ==
        "rb.yaml:1:15: production_s: must be in (0, 900] (got 0)");
  CHECK(load_error("pucks: [1, 2, 1]\n").find("rb.yaml:1:15: pucks[2]: duplicate puck id 1") == 0);
  CHECK(load_error("production_s: fast\n").find("rb.yaml:1:15") == 0);
  // The phase times are checked at their key before the conversion to the game clock: 1e300 s
  // used to overflow it into "got -9223372036.854 s".
  CHECK(load_error("exploration_s: 1e300\n") ==
        "rb.yaml:1:16: exploration_s: must be in (0, 180] (got 1e+300)");
  CHECK(load_error("setup_s: 301\n") == "rb.yaml:1:10: setup_s: must be in (0, 300] (got 301)");
  CHECK(load_error("production_s: 1e19\n") ==
        "rb.yaml:1:15: production_s: must be in (0, 900] (got 1e+19)");
  CHECK(load_error("overtime_s: -1e300\n") ==
        "rb.yaml:1:13: overtime_s: must be in (0, 300] (got -1e+300)");
  CHECK(load_error("pucks: [1, 10000000000]\n") ==
        "rb.yaml:1:12: pucks[1]: must be in [-1000000000, 1000000000] (got 10000000000)");
  // The bounds themselves load.
  CHECK(
      load_error("setup_s: 300\nexploration_s: 180\nproduction_s: 900\novertime_s: 300\n").empty());
  std::string bad = kParams;
  bad.replace(bad.find("T5: RY"), 6, "T5: RX");
  CHECK(load_error(bad).find("light code letters are R, Y, G") != std::string::npos);
  CHECK(load_error(bad).find("rb.yaml:5:") == 0);
  bad = kParams;
  bad.replace(bad.find("M10: T1"), 7, "M10: T5");
  CHECK(load_error(bad).find("params.machine_types: needs 4 T1") != std::string::npos);
  bad = kParams;
  bad.replace(bad.find("end_s: 900"), 10, "end_s: 800");
  CHECK(load_error(bad).find("params.gate_schedule: must cover production") != std::string::npos);
  bad = kParams;
  bad.replace(bad.find("down_times: []"), 14, "down_times: [{machine: D1, start_s: 1, end_s: 5}]");
  const std::string e = load_error(bad);
  CHECK(e.find("rb.yaml:8:26: params.down_times[0].machine") == 0);
  CHECK(e.find("must be one of M1..M10, R1, R2") != std::string::npos);
  bad = kParams;
  bad.replace(bad.find("M1: T1"), 6, "MX: T1");
  CHECK(load_error(bad).find("keys must be M1..M10") != std::string::npos);
}

TEST_CASE("the example config loads") {
  const RefboxConfig c =
      load_refbox_config_file(std::string(LLSF_SOURCE_DIR) + "/config/refbox-example.yaml");
  REQUIRE(c.params.has_value());
  CHECK(c.params->down_times.size() == 2);
  CHECK(c.params->machine_types == test_params().machine_types);
}

TEST_CASE("the game report holds plan, awards, totals, orders, deliveries and machine history") {
  Game g(test_config());
  g.start_production();
  g.enter(M(5), 1);
  g.step();
  g.run_s(30.1);
  g.leave(M(5), 1);
  g.enter(dev(kD1), 1);
  g.step();
  g.run_s(1.1);
  const GameReport r = g.rb.report();
  CHECK(r.rules == "refbox-0.6.1");
  CHECK(r.team == "Carologistics");
  CHECK(r.seed == 1);
  REQUIRE(r.params.has_value());
  CHECK(*r.params == test_params());
  REQUIRE(r.awards.size() == 2);  // T5 completion (0) and the delivery (10)
  CHECK(r.total_points == 10);
  CHECK(r.orders.size() == 11);
  CHECK(r.orders[2].delivered == 1);
  REQUIRE(r.deliveries.size() == 1);
  CHECK(r.deliveries[0].gate == dev(kD1));
  // M5: IDLE -> PROCESSING -> IDLE; D1: IDLE -> PROCESSING -> IDLE; D2/D3 went DOWN at start.
  int m5 = 0;
  for (const MachineHistoryEntry& h : r.machine_history) m5 += h.device == M(5);
  CHECK(m5 == 2);
  const std::string json = to_json(r);
  CHECK(json == to_json(g.rb.report()));
  const nlohmann::ordered_json j = nlohmann::ordered_json::parse(json);
  CHECK(j.begin().key() == "rules");
  CHECK(j["total_points"] == 10);
  CHECK(j["awards"][1]["reason"] == "DELIVERY");
  CHECK(j["params"]["machine_types"].begin().key() == "M1");
  CHECK(j["params"]["machine_types"]["M1"] == "T1");
  const auto& gates = j["params"]["gate_schedule"];
  CHECK(std::find(gates.begin(), gates.end(),
                  nlohmann::ordered_json{{"gate", "D1"}, {"start_s", 0}, {"end_s", 300}}) !=
        gates.end());
  bool m5_processing = false;
  for (const auto& h : j["machine_history"]) {
    m5_processing =
        m5_processing || (h["device"] == "M5" && h["from"] == "IDLE" && h["to"] == "PROCESSING");
  }
  CHECK(m5_processing);
}
