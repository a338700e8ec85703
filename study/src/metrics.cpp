// SPDX-License-Identifier: MIT
#include "llsf/study/metrics.h"

#include "llsf/study/runner.h"

namespace llsf::study {

const char* to_string(TimeBase base) {
  switch (base) {
    case TimeBase::kNone:
      return "";
    case TimeBase::kGame:
      return "game";
    case TimeBase::kProduction:
      return "production";
    case TimeBase::kCpu:
      return "cpu";
  }
  return "";
}

namespace {

using Value = std::optional<double> (*)(const RunResult&);

// A metric with its outputs; the test-case fields are set by `test` below.
Metric metric(std::string_view name, std::string_view unit, TimeBase base, std::string_view how,
              Value value, std::string_view json, JsonForm form, std::string_view line,
              std::string_view summary) {
  Metric m;
  m.name = name;
  m.unit = unit;
  m.time_base = base;
  m.how = how;
  m.value = value;
  m.json = json.empty() ? name : json;
  m.json_form = form;
  m.line = line;
  m.summary = summary;
  return m;
}

Metric absent_ok(Metric m, std::string_view summary_absent) {
  m.may_be_absent = true;
  m.summary_absent = summary_absent;
  return m;
}

Metric test(Metric m, std::string_view key, Bound bound, bool by_s, std::string_view value,
            std::string_view need) {
  m.test_key = key;
  m.bound = bound;
  m.test_by_s = by_s;
  m.test_value = value;
  m.test_need = need;
  return m;
}

// A metric printed last on its summary line.
Metric last_on_line(Metric m) {
  m.summary_rank = 1;
  return m;
}

// A 0/1 share of whether `of` is present; the summary shows it through `of`.
Metric share(std::string_view name, std::string_view how, Value value, std::string_view of) {
  Metric m = metric(name, "", TimeBase::kNone, how, value, "", JsonForm::kBool, "", "");
  m.summary_same_as = of;
  return m;
}

double d(auto x) { return static_cast<double>(x); }
std::optional<double> flag(bool b) { return b ? 1.0 : 0.0; }

std::vector<Metric> make_metrics() {
  constexpr auto kInt = JsonForm::kInteger;
  constexpr auto kNum = JsonForm::kNumber;
  constexpr auto kNo = TimeBase::kNone;
  constexpr auto kGame = TimeBase::kGame;
  std::vector<Metric> m;
  m.push_back(metric(
      "game_time_s", "s", kGame,
      "the game time played: the scenario's duration, less if the game was stopped",
      [](const RunResult& r) -> std::optional<double> { return r.game_time_s; }, "", kNum, "speed",
      "{:.0f} s of game"));
  m.push_back(test(metric(
                       "points", "points", kNo, "the refbox's total",
                       [](const RunResult& r) -> std::optional<double> { return d(r.points); }, "",
                       kInt, "points", "{:4}"),
                   "points_at_least", Bound::kAtLeast, true, "{} points", ">= {} points"));
  m.push_back(
      test(metric(
               "exploration_points", "points", kNo, "the refbox's awards in the exploration phase",
               [](const RunResult& r) -> std::optional<double> { return d(r.exploration_points); },
               "", kInt, "points", "   exploration {:4}"),
           "exploration_points_at_least", Bound::kAtLeast, false, "{} exploration points",
           ">= {} exploration points"));
  m.push_back(
      test(metric(
               "production_points", "points", kNo, "the refbox's awards in the production phase",
               [](const RunResult& r) -> std::optional<double> { return d(r.production_points); },
               "", kInt, "points", "   production {:4}"),
           "production_points_at_least", Bound::kAtLeast, false, "{} production points",
           ">= {} production points"));
  m.push_back(metric(
      "exploration_reports", "machines", kNo,
      "machines reported in the exploration phase (correct and wrong reports)",
      [](const RunResult& r) -> std::optional<double> { return d(r.exploration_reports); }, "",
      kInt, "explored", "{:4} machines reported"));
  m.push_back(metric(
      "exploration_correct", "machines", kNo, "machines reported with the right type",
      [](const RunResult& r) -> std::optional<double> { return d(r.exploration_correct); }, "",
      kInt, "explored", ", {} correct"));
  m.push_back(last_on_line(
      test(metric(
               "deliveries", "products", kNo,
               "products a delivery gate took (the refbox's delivery records), whether an order "
               "was credited with them or not",
               [](const RunResult& r) -> std::optional<double> { return d(r.deliveries); }, "",
               kInt, "products", "   deliveries {}"),
           "deliveries_at_least", Bound::kAtLeast, true, "{} deliveries", ">= {} deliveries")));
  m.push_back(metric(
      "products_p1", "products", kNo, "P1 made: T3 completions",
      [](const RunResult& r) -> std::optional<double> { return d(r.products_p1); }, "products.P1",
      kInt, "products", "P1 {}"));
  m.push_back(metric(
      "products_p2", "products", kNo, "P2 made: T4 completions",
      [](const RunResult& r) -> std::optional<double> { return d(r.products_p2); }, "products.P2",
      kInt, "products", "  P2 {}"));
  m.push_back(metric(
      "products_p3", "products", kNo, "P3 made: T5 completions",
      [](const RunResult& r) -> std::optional<double> { return d(r.products_p3); }, "products.P3",
      kInt, "products", "  P3 {}"));
  m.push_back(metric(
      "recycled", "pucks", kNo, "consumed pucks recycled to S0",
      [](const RunResult& r) -> std::optional<double> { return d(r.recycled); }, "", kInt,
      "products", "   recycled {}"));
  m.push_back(metric(
      "recycle_points", "points", kNo, "the points the recycling awards gave",
      [](const RunResult& r) -> std::optional<double> { return d(r.recycle_points); }, "", kInt,
      "products", " ({} points)"));
  m.push_back(test(metric(
                       "collisions", "contacts", kNo,
                       "robot-robot, robot-wall and robot-device contacts (each contact once)",
                       [](const RunResult& r) -> std::optional<double> { return d(r.collisions); },
                       "", kInt, "robots", "{} collisions"),
                   "collisions_at_most", Bound::kAtMost, false, "{} collisions",
                   "<= {} collisions"));
  m.push_back(metric(
      "skill_failures", "skill strings", kNo, "skill strings that ended FAILED",
      [](const RunResult& r) -> std::optional<double> { return d(r.skill_failures); }, "", kInt,
      "robots", ", {} skill failures"));
  m.push_back(metric(
      "agent_runtime_errors", "errors", kNo,
      "the agents' runtime errors (a rule's actions failed or were stopped by a budget)",
      [](const RunResult& r) -> std::optional<double> { return d(r.agent_runtime_errors); }, "",
      kInt, "robots", ", {} agent runtime errors"));
  m.push_back(metric(
      "lock_grants", "grants", kNo, "locks granted",
      [](const RunResult& r) -> std::optional<double> { return d(r.lock_grants); }, "locks.grants",
      kInt, "locks", "{} grants"));
  m.push_back(metric(
      "lock_refusals", "refusals", kNo, "lock requests refused",
      [](const RunResult& r) -> std::optional<double> { return d(r.lock_refusals); },
      "locks.refusals", kInt, "locks", ", {} refusals"));
  m.push_back(metric(
      "lock_waits", "waits", kNo,
      "waits for a lock that took time (a request to its grant, through refusals "
      "answered by asking again within 5 s)",
      [](const RunResult& r) -> std::optional<double> { return d(r.lock_waits); }, "locks.waits",
      kInt, "locks", "; {} waits"));
  m.push_back(metric(
      "lock_wait_s", "s", kGame, "the waits' game time, summed over robots",
      [](const RunResult& r) -> std::optional<double> { return r.lock_wait_s; }, "locks.wait_s",
      kNum, "locks", ", {:.1f} s waited in all"));
  m.push_back(metric(
      "lock_wait_max_s", "s", kGame, "the longest single wait",
      [](const RunResult& r) -> std::optional<double> { return r.lock_wait_max_s; },
      "locks.wait_max_s", kNum, "locks", ", longest {:.1f} s"));
  m.push_back(
      test(metric(
               "lock_hold_max_s", "s", kGame,
               "the longest time one robot held one lock (grant to release or the end), not "
               "counting holds of a jammed robot",
               [](const RunResult& r) -> std::optional<double> { return r.lock_hold_max_s; },
               "locks.hold_max_s", kNum, "locks", "; longest hold {:.1f} s"),
           "lock_hold_at_most_s", Bound::kAtMost, false, "{:.1f} s the longest lock hold",
           "no lock held longer than {} s"));
  m.push_back(share(
      "complex_made", "1 if a complex product (P1 or P2) was made, else 0",
      [](const RunResult& r) { return flag(r.first_complex_production_s.has_value()); },
      "first_complex_production_s"));
  m.push_back(absent_ok(
      metric(
          "first_complex_production_s", "s", TimeBase::kProduction,
          "when the first complex product (a T3 or T4 completion) was made; absent if none",
          [](const RunResult& r) { return r.first_complex_production_s; }, "", kNum, "production",
          "first complex product at {:.0f} s of production"),
      "first complex product none"));
  m.push_back(metric(
      "role_changes", "role changes", kNo,
      "role changes the agents declared, (agent-event role-change FROM TO) (docs/clips.md)",
      [](const RunResult& r) -> std::optional<double> { return d(r.role_changes); }, "", kInt,
      "production", ", {} role changes"));
  m.push_back(absent_ok(metric(
                            "first_role_change_game_s", "s", kGame,
                            "when the first role change was declared; absent if none",
                            [](const RunResult& r) { return r.first_role_change_game_s; }, "", kNum,
                            "production", " (first at {:.0f} s of the game)"),
                        ""));
  m.push_back(metric(
      "storage_min", "pucks", kNo,
      "the fewest pucks in the input storage (its area grown by 0.1 m, sampled every second, "
      "pucks held by a robot not counted)",
      [](const RunResult& r) -> std::optional<double> { return d(r.storage_min); }, "", kInt,
      "production", ", storage low {} pucks"));
  m.push_back(share(
      "storage_ran_empty", "1 if the input storage ran empty, else 0",
      [](const RunResult& r) { return flag(r.storage_empty_game_s.has_value()); },
      "storage_empty_game_s"));
  m.push_back(absent_ok(metric(
                            "storage_empty_game_s", "s", kGame,
                            "when the input storage first was empty; absent if never",
                            [](const RunResult& r) { return r.storage_empty_game_s; }, "", kNum,
                            "production", " (empty at {:.0f} s of the game)"),
                        ""));
  m.push_back(metric(
      "jams", "jams", kNo, "jams at devices (robot profiles)",
      [](const RunResult& r) -> std::optional<double> { return d(r.jams); }, "", kInt, "profile",
      "{} jams"));
  m.push_back(metric(
      "jammed_at_end", "robots", kNo, "robots still jammed at the end",
      [](const RunResult& r) -> std::optional<double> { return d(r.jammed_at_end); }, "", kInt,
      "profile", ", {} robots jammed at the end"));
  m.push_back(test(
      metric(
          "skill_failure_streak_max", "failures", kNo,
          "the longest run of failures of one skill by one robot without a success of it in "
          "between (not counting a jammed robot's, and failures for the reasons aborted and "
          "not-found)",
          [](const RunResult& r) -> std::optional<double> { return d(r.skill_failure_streak_max); },
          "", kInt, "profile", ", {} failures of one skill in a row at most"),
      "skill_failure_streak_at_most", Bound::kAtMost, false, "{} failures of one skill in a row",
      "<= {} failures of one skill in a row"));
  m.push_back(metric(
      "messages_sent", "copies", kNo, "radio copies sent (one per receiver)",
      [](const RunResult& r) -> std::optional<double> { return d(r.messages_sent); }, "", kInt,
      "radio", "{} copies sent"));
  m.push_back(metric(
      "messages_dropped", "copies", kNo, "radio copies dropped (loss, range, bandwidth)",
      [](const RunResult& r) -> std::optional<double> { return d(r.messages_dropped); }, "", kInt,
      "radio", ", {} dropped"));
  m.push_back(metric(
      "cpu_s", "s", TimeBase::kCpu, "CPU time the game took (a measurement)",
      [](const RunResult& r) -> std::optional<double> { return r.cpu_s; }, "", kNum, "speed",
      " in {:.2f} s CPU"));
  m.push_back(metric(
      "real_time_factor", "x", kNo, "game time / CPU time (a measurement)",
      [](const RunResult& r) -> std::optional<double> { return r.real_time_factor; }, "", kNum,
      "speed", ": {:.0f}x real time"));
  m.push_back(metric(
      "orders", "orders", kNo, "the orders of the game (active ones)",
      [](const RunResult& r) -> std::optional<double> { return d(r.orders.size()); }, "orders",
      JsonForm::kArrayLength, "orders", "{} orders"));
  m.push_back(metric(
      "order_units_requested", "products", kNo, "the units the orders asked for",
      [](const RunResult& r) -> std::optional<double> {
        int n = 0;
        for (const OrderResult& o : r.orders) n += o.requested;
        return d(n);
      },
      "", kInt, "orders", ", {} units ordered"));
  m.push_back(metric(
      "order_units_delivered", "products", kNo,
      "the units the orders were credited with (deliveries in an order's window, extra units "
      "included)",
      [](const RunResult& r) -> std::optional<double> {
        int n = 0;
        for (const OrderResult& o : r.orders) n += o.delivered;
        return d(n);
      },
      "", kInt, "orders", ", {} credited to them"));
  m.push_back(metric(
      "awards", "awards", kNo, "the refbox's points awards",
      [](const RunResult& r) -> std::optional<double> { return d(r.awards.size()); }, "", kInt,
      "points", "   ({} awards)"));
  m.push_back(metric(
      "tests", "test cases", kNo, "the run's test cases",
      [](const RunResult& r) -> std::optional<double> { return d(r.tests.size()); }, "tests",
      JsonForm::kArrayLength, "tests", "{} test cases"));
  m.push_back(metric(
      "tests_failed", "test cases", kNo, "the test cases that failed",
      [](const RunResult& r) -> std::optional<double> {
        int n = 0;
        for (const TestVerdict& t : r.tests) n += t.passed ? 0 : 1;
        return d(n);
      },
      "", kInt, "tests", ", {} failed"));
  m.push_back(metric(
      "passed", "", kNo, "1 if every test case passed, else 0",
      [](const RunResult& r) { return flag(r.passed()); }, "", JsonForm::kBool, "tests",
      ", passed: {}"));
  return m;
}

}  // namespace

const std::vector<Metric>& metrics() {
  static const std::vector<Metric> table = make_metrics();
  return table;
}

const Metric* find_metric(std::string_view name) {
  for (const Metric& m : metrics()) {
    if (m.name == name) return &m;
  }
  return nullptr;
}

const Metric* find_metric_by_test_key(std::string_view key) {
  if (key.empty()) return nullptr;
  for (const Metric& m : metrics()) {
    if (m.test_key == key) return &m;
  }
  return nullptr;
}

const std::vector<SummaryLine>& summary_lines() {
  using Show = SummaryLine::Show;
  static const std::vector<SummaryLine> lines = {
      {"points", Show::kAlways},      {"explored", Show::kAlways},
      {"products", Show::kAlways},    {"orders", Show::kIfAnyNonZero},
      {"robots", Show::kAlways},      {"locks", Show::kIfAnyNonZero},
      {"production", Show::kAlways},  {"profile", Show::kIfProfile},
      {"radio", Show::kAlways},       {"speed", Show::kAlways},
      {"tests", Show::kIfAnyNonZero},
  };
  return lines;
}

}  // namespace llsf::study
