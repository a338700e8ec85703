// SPDX-License-Identifier: MIT
// Reports over a batch of stored runs: per variant the distribution of every statistic (mean,
// median, quartiles, min, max) and the pass rate, and the difference of each variant's mean
// from the first variant's with a bootstrap 95 % confidence interval; as text, CSV, JSON and a
// self-contained HTML page with box plots (the viewer's bundle, viewer/README.md).
#pragma once

#include <cstdint>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "llsf/core/error.h"
#include "llsf/core/rng.h"
#include "llsf/study/compare.h"
#include "llsf/study/stats_store.h"

namespace llsf::study {

/// Distribution of one statistic over a variant's runs.
struct StatSummary {
  std::string name;
  int n = 0;
  double mean = 0.0, median = 0.0, q1 = 0.0, q3 = 0.0, min = 0.0, max = 0.0;
};

struct VariantReport {
  std::string variant;
  int runs = 0;
  int passed = 0;
  std::vector<StatSummary> stats;  ///< by statistic name
  const StatSummary* find(const std::string& name) const;
};

/// mean(variant) - mean(baseline) of one statistic (compare_means: paired by seed when both
/// played the same seeds) with an expanded percentile-bootstrap 95 % interval.
struct Difference {
  std::string variant;
  std::string baseline;
  std::string statistic;
  double diff = 0.0;
  double ci_low = 0.0, ci_high = 0.0;
  Comparison comparison;  ///< the method, the counts, p, the smallest detectable difference
  /// Holm's correction over this statistic's comparisons (each variant against the first):
  /// separated at the 5 % family-wise level, and enough games for a verdict.
  bool separated = false;
  int comparisons = 0;  ///< the size of the Holm family
};

struct BatchReport {
  StoredBatch batch;
  std::vector<VariantReport> variants;  ///< in name order (independent of --jobs)
  std::vector<Difference> differences;  ///< every variant after the first against the first
};

/// Builds the report of batch `batch_id` (StatsError if there is no such batch). The bootstrap
/// (2,000 resamples) of each difference draws from its own stream of `seed`, named after the
/// variant and the statistic: the same store gives the same report.
/// Runs are paired by their seed (docs/statistics.md, "Comparing variants").
BatchReport make_report(const StatsStore& store, std::int64_t batch_id, std::uint64_t seed = 1);

/// One line per (variant, statistic): variant,statistic,n,mean,median,q1,q3,min,max,pass_rate,
/// runs -- n of runs: a statistic a game may lack counts the games that have it.
std::string to_csv(const BatchReport& r);
/// A readable table: per variant the pass rate and points, then the differences.
std::string to_text(const BatchReport& r);

/// One stored run with every statistic of it: the raw values behind a report.
struct RunValues {
  std::string variant;
  std::uint64_t seed = 0;
  bool passed = false;
  std::uint64_t result_hash = 0;
  std::vector<std::pair<std::string, double>> statistics;  ///< by name (StatsStore::statistics)
};

/// Every run of batch `batch_id` with its statistics, in (variant, seed) order (independent of
/// the order in which a batch's workers stored them).
std::vector<RunValues> run_values(const StatsStore& store, std::int64_t batch_id);

/// The report and its runs as one JSON object (docs/llsfsim.md, "report --html"): `format`,
/// `llsfsim_version`, `batch` (id, kind, scenario, runs per variant, seeds; no wall-clock time),
/// `variants` (runs, passed, pass_rate, statistics by name), `differences` and `runs` (variant,
/// seed, passed, result_hash, statistics by name). Non-finite numbers are written as null; the
/// same report and runs give the same bytes.
std::string to_json(const BatchReport& r, const std::vector<RunValues>& runs);

/// The viewer's bundle (`report.js`) is not in the viewer directory.
class ViewerBundleMissing : public core::UserError {
 public:
  using core::UserError::UserError;
};

/// Where the viewer's bundle is looked for: $LLSF_VIEWER_DIR if set and not empty, else
/// viewer/dist under core::data_dir() (built by `make viewer`).
std::string viewer_dir();

/// A self-contained HTML page of the report: a small template, `dir`/report.js inlined, and
/// `json` (to_json's output) in `<script id="llsf-report-data" type="application/json">`; the
/// text report in a <noscript>. Throws ViewerBundleMissing if `dir`/report.js cannot be read.
std::string to_html(const BatchReport& r, const std::string& json, const std::string& dir);

}  // namespace llsf::study
