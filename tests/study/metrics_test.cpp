// SPDX-License-Identifier: MIT
// The metric table (study/metrics.h) drives the outputs: every metric is in to_json at its key
// with its value, in the store's statistics, in docs/statistics.md, and -- with a test-case key
// -- a test case of a scenario. (The summary's lines: tests/app/summary_test.cpp.) And role
// changes are counted from the events an agent declares, not from its log lines.
#include <doctest/doctest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <set>
#include <string>

#include "llsf/core/config.h"
#include "llsf/study/metrics.h"
#include "llsf/study/runner.h"
#include "llsf/study/scenario.h"
#include "llsf/study/stats_store.h"

using namespace llsf;
using namespace llsf::study;
using Json = nlohmann::ordered_json;

namespace {

// A result in which every metric has a value of its own (no two alike, none 0 but the shares).
RunResult full_result() {
  RunResult r;
  r.game_time_s = 1080.5;
  r.points = 101;
  r.exploration_points = 37;
  r.production_points = 64;
  r.exploration_reports = 9;
  r.exploration_correct = 29;
  r.deliveries = 7;
  r.products_p1 = 32;
  r.products_p2 = 33;
  r.products_p3 = 34;
  r.recycled = 35;
  r.recycle_points = 15;
  r.collisions = 6;
  r.skill_failures = 11;
  r.agent_runtime_errors = 12;
  r.lock_grants = 13;
  r.lock_refusals = 14;
  r.lock_waits = 16;
  r.lock_wait_s = 17.5;
  r.lock_wait_max_s = 18.25;
  r.lock_hold_max_s = 19.75;
  r.first_complex_production_s = 303.5;
  r.role_changes = 21;
  r.first_role_change_game_s = 750.5;
  r.storage_min = 22;
  r.storage_empty_game_s = 820.5;
  r.jams = 23;
  r.jammed_at_end = 24;
  r.skill_failure_streak_max = 25;
  r.messages_sent = 26000;
  r.messages_dropped = 27;
  r.cpu_s = 28.5;
  r.real_time_factor = 37.9;
  r.orders.push_back({1, "P1", 3, 1, 0, 299});
  r.orders.push_back({2, "P3", 5, 4, 0, 899});
  r.awards.resize(31);
  r.tests.push_back({"a", true, "", 0.0});
  r.tests.push_back({"b", false, "", 0.0});
  r.tests.push_back({"c", false, "", 0.0});
  r.tests.push_back({"d", false, "", 0.0});
  return r;
}

// The JSON value at a metric's key path ("locks.grants").
const Json* at(const Json& j, std::string_view path) {
  const Json* p = &j;
  for (std::size_t dot = path.find('.');; dot = path.find('.')) {
    const std::string key(path.substr(0, dot));
    if (!p->is_object() || !p->contains(key)) return nullptr;
    p = &(*p)[key];
    if (dot == std::string_view::npos) return p;
    path.remove_prefix(dot + 1);
  }
}

std::string read(const std::string& path) {
  std::ifstream in(path);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

}  // namespace

TEST_CASE("metric table: every metric in the JSON, the store and the docs, by its one value") {
  const RunResult r = full_result();
  const Json j = Json::parse(to_json(r));
  const auto stats = numeric_statistics(r);
  const std::string docs = read(LLSF_SOURCE_DIR "/docs/statistics.md");
  std::set<std::string_view> names;
  std::set<double> values;
  for (const Metric& m : metrics()) {
    CAPTURE(m.name);
    CHECK(names.insert(m.name).second);  // one row per name
    CHECK_FALSE(m.how.empty());
    const std::optional<double> v = m.value(r);
    REQUIRE(v);
    if (m.json_form != JsonForm::kBool) CHECK(values.insert(*v).second);  // its own field
    // JSON
    const Json* x = at(j, m.json);
    REQUIRE(x != nullptr);
    switch (m.json_form) {
      case JsonForm::kInteger:
        CHECK(x->is_number_integer());
        CHECK(x->get<double>() == *v);
        break;
      case JsonForm::kNumber:
        CHECK(x->get<double>() == doctest::Approx(*v));
        break;
      case JsonForm::kBool:
        CHECK(x->get<bool>() == (*v != 0.0));
        break;
      case JsonForm::kArrayLength:
        CHECK(x->size() == static_cast<std::size_t>(*v));
        break;
    }
    // the store: its row, in the table's order
    bool stored = false;
    for (const auto& [name, value] : stats) stored = stored || (name == m.name && value == *v);
    CHECK(stored);
    // the docs: its row in the table of docs/statistics.md
    CHECK(docs.find("`" + std::string(m.name) + "`") != std::string::npos);
    // the summary: a part on a line (or shown through the metric it is a share of)
    if (m.summary_same_as.empty()) {
      CHECK_FALSE(m.line.empty());
      CHECK_FALSE(m.summary.empty());
    } else {
      CHECK(find_metric(m.summary_same_as) != nullptr);
    }
  }
  REQUIRE(stats.size() == metrics().size());
  for (std::size_t i = 0; i < stats.size(); ++i) CHECK(stats[i].first == metrics()[i].name);
  REQUIRE(statistic_infos().size() == metrics().size());

  // Absent: null in the JSON, no row in the store; only metrics that may be absent are.
  RunResult none = r;
  none.first_complex_production_s.reset();
  none.first_role_change_game_s.reset();
  none.storage_empty_game_s.reset();
  const Json k = Json::parse(to_json(none));
  const auto kept = numeric_statistics(none);
  for (const Metric& m : metrics()) {
    CAPTURE(m.name);
    const bool absent = !m.value(none);
    CHECK(absent == m.may_be_absent);
    if (!absent) continue;
    CHECK(at(k, m.json)->is_null());
    for (const auto& [name, value] : kept) CHECK(name != m.name);
  }
  CHECK(kept.size() == stats.size() - 3);
}

TEST_CASE("metric table: each test-case key is a scenario's test case of its metric") {
  int keys = 0;
  for (const Metric& m : metrics()) {
    if (m.test_key.empty()) continue;
    ++keys;
    CAPTURE(m.name);
    CHECK(find_metric_by_test_key(m.test_key) == &m);
    const std::string yaml = "name: t\nduration_s: 100\ntests:\n  - {" + std::string(m.test_key) +
                             ": 3}\n  - {" + std::string(m.test_key) + ": 2, by_s: 50}\n";
    if (m.test_by_s) {
      const Scenario s = read_scenario_map(core::ConfigNode::parse(yaml, "t.yaml"), "t.yaml");
      REQUIRE(s.tests.size() == 2);
      CHECK(s.tests[0].metric == &m);
      CHECK(s.tests[0].value == 3.0);
      CHECK(s.tests[1].by_s == 50.0);
      CHECK(s.tests[0].name == describe(s.tests[0]));
    } else {
      CHECK_THROWS_WITH_AS(read_scenario_map(core::ConfigNode::parse(yaml, "t.yaml"), "t.yaml"),
                           doctest::Contains("by_s works with points_at_least and "
                                             "deliveries_at_least"),
                           core::ConfigError);
    }
    CHECK(describe(TestCase{"", &m, 3.0, {}}).find('3') != std::string::npos);
  }
  CHECK(keys == 7);
  CHECK(find_metric_by_test_key("no_agent_errors") == nullptr);  // no metric: its own kind
}

namespace {

std::string write(const std::filesystem::path& p, const std::string& text) {
  std::filesystem::create_directories(p.parent_path());
  std::ofstream(p) << text;
  return p.string();
}

// A one-robot game of 4 s whose agent declares `events` role changes (one per second from 1 s
// on) and logs `log` with each -- or only logs it.
RunResult role_game(const std::string& name, int events, const std::string& log, bool declare) {
  const auto dir = std::filesystem::temp_directory_path() / ("llsf_roles_" + name);
  std::filesystem::remove_all(dir);
  write(dir / "agent" / "roles.clp",
        "(deftemplate changed (slot n))\n"
        "(defrule change (time ?s ?) (test (>= ?s 1)) (not (changed (n " +
            std::to_string(events) +
            ")))\n"
            "  ?c <- (changed (n ?n)) (test (>= ?s (+ ?n 1)))\n"
            "  => (modify ?c (n (+ ?n 1)))\n" +
            (declare ? "  (agent-event role-change P1P2 P3 \"time\")\n" : "") + "  (log-info \"" +
            log + "\"))\n(deffacts start (changed (n 0)))\n");
  const std::string scenario = write(dir / "roles.yaml",
                                     "name: roles\nduration_s: 4\nstart: production\n"
                                     "robots:\n  count: 1\n  agent: [agent]\n");
  const RunResult r = run_game(load_scenario(scenario).variants.at(0), 1);
  std::filesystem::remove_all(dir);
  return r;
}

}  // namespace

TEST_CASE("role changes: counted from the agent's events, whatever its log lines say") {
  const RunResult worded = role_game("worded", 3, "production: role change P1P2 -> P3", true);
  const RunResult reworded = role_game("reworded", 3, "switching to P3 now", true);
  CHECK(worded.agent_runtime_errors == 0);
  CHECK(worded.role_changes == 3);
  CHECK(reworded.role_changes == 3);
  REQUIRE(worded.first_role_change_game_s);
  CHECK(*worded.first_role_change_game_s == doctest::Approx(1.0).epsilon(0.2));
  CHECK(reworded.first_role_change_game_s == worded.first_role_change_game_s);
  // The old log line alone is no role change.
  const RunResult only_logged = role_game("logged", 3, "production: role change P1P2 -> P3", false);
  CHECK(only_logged.role_changes == 0);
  CHECK_FALSE(only_logged.first_role_change_game_s);
}
