// SPDX-License-Identifier: MIT
// Comparing two variants of a study: the difference of their means paired by seed (common random
// numbers) where they played the same seeds, unpaired otherwise, with percentile-bootstrap
// intervals, a bootstrap p-value, the smallest difference the runs could detect and the games a
// difference would need; equivalence within a margin (two one-sided tests) and Holm's correction
// for many comparisons. Pure functions: docs/statistics.md, "Comparing variants".
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "llsf/core/rng.h"

namespace llsf::study {

/// Resamples of the percentile bootstrap (reports, experiments).
constexpr int kBootstrapResamples = 2000;

/// Fewest games per variant (with a paired design: seed pairs) for a verdict. Below it reports
/// print the numbers without a star or a verdict: with fewer games the 95 % interval is too
/// short -- it held the true difference in 91 % of simulated experiments with 5 games and 78 %
/// with 3, against 92-95 % with 10 (normal and skewed outcomes; docs/statistics.md) -- and one
/// game has no spread at all.
constexpr int kMinGamesForVerdict = 10;

/// The level of every test: two-sided 5 % (95 % intervals); equivalence: 5 % per side (90 %).
constexpr double kAlpha = 0.05;

/// What a bootstrap interval is taken of.
enum class Estimator : std::uint8_t { kMean, kMedian };

/// A percentile-bootstrap interval.
struct Interval {
  double low = 0.0;
  double high = 0.0;
};

/// Percentile-bootstrap 95 % interval of estimator(a) - estimator(b), or of estimator(a) if `b`
/// is empty: `resamples` times, a and then b are resampled with replacement (independently, each
/// to its own size) from `rng`; the interval is the 2.5 % and 97.5 % quantiles of the resampled
/// values. `a` must not be empty.
Interval bootstrap_interval(const std::vector<double>& a, const std::vector<double>& b,
                            Estimator estimator, core::RandomStream& rng,
                            int resamples = kBootstrapResamples);

/// Quantile `q` in [0, 1] of sorted values, linear interpolation between order statistics
/// (R's type 7); 0 for an empty vector.
double quantile(const std::vector<double>& sorted, double q);

/// One run's value of a statistic and the key that pairs it with the other side's run of the
/// same seed ("seed=101", or with the values of pooled axes: "seed=101,loss=20").
struct KeyedValue {
  std::string key;
  double value = 0.0;
};

/// How a difference was estimated.
enum class Pairing : std::uint8_t {
  kPaired,    ///< mean of the per-seed differences; the bootstrap resamples seed pairs
  kUnpaired,  ///< difference of the two means; each side resampled on its own
};

/// "paired by seed" or "unpaired".
std::string to_string(Pairing p);

/// mean(a) - mean(b) and what the runs can say about it.
struct Comparison {
  Pairing pairing = Pairing::kUnpaired;
  int n_a = 0, n_b = 0;   ///< values per side
  int pairs = 0;          ///< paired: seeds with a value on both sides (the values used)
  int unmatched = 0;      ///< paired: values without a partner on the other side, left out
  double diff = 0.0;      ///< paired: mean of the per-seed differences
  double alpha = kAlpha;  ///< the test's level: ci is the 1 - alpha interval (95 %)
  Interval ci;            ///< expanded percentile bootstrap, alpha / 2 .. 1 - alpha / 2
  Interval ci_tost;       ///< alpha .. 1 - alpha (90 %): the two one-sided tests of equivalence
  double p_value = 1.0;   ///< two-sided bootstrap p-value of "no difference"
  /// Standard error of `diff` (normal approximation); unset with fewer than 2 values a side.
  std::optional<double> se;
  /// The smallest difference these runs detect 4 times in 5 at the 5 % level: 2.80 se.
  std::optional<double> detectable;
  /// Games per variant (pairs, if paired) that would separate a difference of `diff`'s size 4
  /// times in 5 (normal approximation, at least kMinGamesForVerdict); unset if the spread is
  /// unknown (one game) or `diff` is 0.
  std::optional<int> games_needed;
  /// Enough games for a verdict: games() is at least the minimum (kMinGamesForVerdict).
  bool enough = false;

  /// Games per variant the verdict rests on: pairs, or the smaller side.
  int games() const { return pairing == Pairing::kPaired ? pairs : (n_a < n_b ? n_a : n_b); }
  /// The 1 - alpha interval excludes 0 (not yet corrected for many comparisons).
  bool separated() const { return ci.low > 0.0 || ci.high < 0.0; }
};

/// Compares a with b. Paired when the sides share their seeds: no key twice on a side, and at
/// least half of each side's values have a partner (the others are left out and counted in
/// `unmatched`); unpaired otherwise. The bootstrap draws from `rng`; `enough` is games() >=
/// `min_games`; the intervals are at level `alpha` (0 < alpha < 0.5). Both sides must have
/// values.
Comparison compare_means(const std::vector<KeyedValue>& a, const std::vector<KeyedValue>& b,
                         core::RandomStream& rng, int min_games = kMinGamesForVerdict,
                         int resamples = kBootstrapResamples, double alpha = kAlpha);

/// Games per variant that would separate `diff` 4 times in 5 at the 5 % level, with the
/// per-game standard deviation `sd` of the difference (paired: of the per-seed differences;
/// unpaired: sqrt(sd_a^2 + sd_b^2)); at least kMinGamesForVerdict; unset if `diff` is 0.
std::optional<int> games_to_separate(double diff, double sd);

/// Equivalence and one-sided non-superiority with a margin, on the ci_tost interval (two
/// one-sided tests at alpha each: 90 % by default).
enum class MarginTest : std::uint8_t {
  kSame,      ///< -margin < low and high < margin
  kNotAbove,  ///< high < margin: a is not better than b by margin or more
  kNotBelow,  ///< low > -margin: a is not worse than b by margin or more
};

/// Whether `c`'s ci_tost interval lies inside the margin as `test` asks (margin > 0).
bool within_margin(const Comparison& c, MarginTest test, double margin);

/// Playing until the answer is known (`llsfsim batch --until`): at most `max_runs` seeds a
/// variant, looked at `looks` times, after equally spaced numbers of seeds (look_sizes()). Each
/// look tests at alpha / looks -- Bonferroni's alpha spending: whatever the looks see, the chance
/// that any of them separates two equal variants (or calls two variants equivalent whose
/// difference is the margin) is at most alpha in all, although the same games are looked at again
/// and again. Looking at 5 % each time would not keep it (tests/study/compare_test.cpp).
struct SequentialPlan {
  int max_runs = 100;            ///< seeds a variant at most (>= kMinGamesForVerdict)
  int looks = 5;                 ///< 1..max_runs
  std::optional<double> margin;  ///< if set (> 0): stop as well when equivalent within it

  /// Seeds a variant at each look: ceil(k * max_runs / looks), k = 1..looks.
  std::vector<int> look_sizes() const;
  /// The level of each look's test.
  double look_alpha() const { return kAlpha / looks; }
  /// Empty, or what is wrong with the plan ("--max-runs must be at least 10").
  std::string problem() const;
};

/// What a look decided.
enum class SequentialOutcome : std::uint8_t {
  kContinue,    ///< play the next round
  kSeparated,   ///< the look's interval excludes 0 (enough games)
  kEquivalent,  ///< the look's equivalence interval lies inside +-margin (enough games)
  kUndecided,   ///< the last look, neither
};

/// "continue", "separated", "equivalent within the margin", "undecided".
std::string to_string(SequentialOutcome o);

/// One look: the comparison at the look's level (compare_means with alpha = look_alpha()).
struct SequentialLook {
  int look = 0;   ///< 1-based
  int seeds = 0;  ///< seeds a variant looked at
  Comparison comparison;
  SequentialOutcome outcome = SequentialOutcome::kContinue;
};

/// Look number `look` (1-based) of `plan` at the runs `a` and `b` of its first seeds.
SequentialLook sequential_look(const SequentialPlan& plan, int look,
                               const std::vector<KeyedValue>& a, const std::vector<KeyedValue>& b,
                               core::RandomStream& rng);

/// Holm's step-down correction: which of the p-values are rejected at family-wise level `alpha`
/// (sorted ascending, the k-th smallest against alpha / (m - k), stopping at the first that
/// is not). The result is in the order of `p`.
std::vector<bool> holm(const std::vector<double>& p, double alpha = kAlpha);

}  // namespace llsf::study
