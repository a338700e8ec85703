// SPDX-License-Identifier: MIT
// Reports over a batch of stored runs: per variant the distribution of every statistic (mean,
// median, quartiles, min, max) and the pass rate, and the difference of each variant's mean
// from the first variant's with a bootstrap 95 % confidence interval.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "llsf/sim/stats_store.h"

namespace llsf::sim {

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

/// mean(variant) - mean(baseline) of one statistic with a percentile-bootstrap 95 % interval.
struct Difference {
  std::string variant;
  std::string baseline;
  std::string statistic;
  double diff = 0.0;
  double ci_low = 0.0, ci_high = 0.0;
};

struct BatchReport {
  StoredBatch batch;
  std::vector<VariantReport> variants;  ///< in name order (independent of --jobs)
  std::vector<Difference> differences;  ///< every variant after the first against the first
};

/// Builds the report of batch `batch_id` (StatsError if there is no such batch). The bootstrap
/// (2,000 resamples) draws from a stream seeded with `seed`: the same store gives the same report.
BatchReport make_report(const StatsStore& store, std::int64_t batch_id, std::uint64_t seed = 1);

/// One line per (variant, statistic): variant,statistic,n,mean,median,q1,q3,min,max,pass_rate.
std::string to_csv(const BatchReport& r);
/// A readable table: per variant the pass rate and points, then the differences.
std::string to_text(const BatchReport& r);

/// Quantile `q` in [0, 1] of sorted values, linear interpolation between order statistics
/// (R's type 7); 0 for an empty vector.
double quantile(const std::vector<double>& sorted, double q);

}  // namespace llsf::sim
