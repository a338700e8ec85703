// SPDX-License-Identifier: MIT
// The metric table: every statistic of a run written once -- its name, unit, time base, how it
// is computed, whether a game may lack it, and how it shows in each output. RunResult's JSON
// (to_json), the statistics store's rows (numeric_statistics), the summary of `llsfsim run`
// (app's print_summary) and the scenario's test-case kinds (`tests:`) are all made from it
// (docs/statistics.md lists the same table).
#pragma once

#include <cstdint>
#include <optional>
#include <string_view>
#include <vector>

namespace llsf::study {

struct RunResult;

/// The clock a time statistic is read on.
enum class TimeBase : std::uint8_t {
  kNone,        ///< not a time
  kGame,        ///< game time: simulated seconds since the start of the run
  kProduction,  ///< the refbox's production clock (its phase-relative game time)
  kCpu,         ///< CPU seconds of the thread that played the game (a measurement)
};
/// "", "game", "production", "cpu".
const char* to_string(TimeBase base);

/// How a metric is written in the JSON summary.
enum class JsonForm : std::uint8_t {
  kInteger,      ///< a whole number
  kNumber,       ///< a number; null when absent or not finite
  kBool,         ///< true / false (a 0/1 share in the store)
  kArrayLength,  ///< the length of the array to_json writes under `json` (orders, tests)
};

/// The direction of a test case on a metric.
enum class Bound : std::uint8_t { kAtLeast, kAtMost };

/// One statistic of a run.
struct Metric {
  std::string_view name;  ///< the store's statistic name (and the JSON key unless `json` says)
  std::string_view unit;  ///< "points", "products", "s", "" for a count of itself, ...
  TimeBase time_base = TimeBase::kNone;
  std::string_view how;        ///< how it is computed (one sentence)
  bool may_be_absent = false;  ///< a time of something a game may lack: absent, not a value
  /// The value in a result; nullopt when absent (only if may_be_absent).
  std::optional<double> (*value)(const RunResult&) = nullptr;

  // ---- JSON (to_json) ----
  /// The key path: "points", "locks.grants" (a key of an object "locks"), "products.P1".
  std::string_view json;
  JsonForm json_form = JsonForm::kInteger;

  // ---- the summary (`llsfsim run`, app's print_summary) ----
  /// The summary line it is printed on (a label of summary_lines()); "" with `summary_same_as`.
  std::string_view line;
  /// Its part of that line: a {fmt} format with one field for the value ("   recycled {}").
  std::string_view summary;
  /// Its part when absent (may_be_absent metrics; "" prints nothing).
  std::string_view summary_absent;
  /// Its place on the line: parts are printed by rank, then in table order (deliveries, early in
  /// the table, ends the products line).
  int summary_rank = 0;
  /// A metric the summary shows only through another one's (a 0/1 share of whether a time is
  /// present: complex_made through first_complex_production_s).
  std::string_view summary_same_as;

  // ---- a test case of a scenario (`tests:`, docs/scenarios.md) ----
  /// The test case's key ("deliveries_at_least"); "" if no test case judges this metric.
  std::string_view test_key;
  Bound bound = Bound::kAtLeast;
  bool test_by_s = false;       ///< the case may name a deadline (by_s), judged during the game
  std::string_view test_value;  ///< the verdict's value, a {fmt} format: "{} deliveries"
  std::string_view test_need;   ///< the condition, a {fmt} format for the limit: ">= {} points"
};

/// Every metric, in the store's order (docs/statistics.md).
const std::vector<Metric>& metrics();
/// The metric named `name` (store name), or nullptr.
const Metric* find_metric(std::string_view name);
/// The metric a test-case key judges ("points_at_least"), or nullptr.
const Metric* find_metric_by_test_key(std::string_view key);

/// A line of the summary that metrics are printed on, in print order.
struct SummaryLine {
  std::string_view label;  ///< "points", "products", ... (padded to 11 columns)
  enum class Show : std::uint8_t {
    kAlways,
    kIfAnyNonZero,  ///< only if one of its metrics is present and not 0 (locks, orders)
    kIfProfile,     ///< a robot profile other than `ideal`, or a jam (profiles.md)
  };
  Show show = Show::kAlways;
};
/// The summary's metric lines, in print order.
const std::vector<SummaryLine>& summary_lines();

}  // namespace llsf::study
