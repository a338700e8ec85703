// SPDX-License-Identifier: MIT
#include "llsf/study/compare.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>
#include <numeric>

#include "llsf/core/assert.h"

namespace llsf::study {

namespace {

/// z of 97.5 % and of 80 %: a two-sided 5 % test that detects a difference 4 times in 5.
constexpr double kZ975 = 1.959963984540054;
constexpr double kZ80 = 0.8416212335729143;

double mean_of(const std::vector<double>& x) {
  return std::accumulate(x.begin(), x.end(), 0.0) / static_cast<double>(x.size());
}

/// Sample variance (n - 1); requires at least 2 values.
double variance_of(const std::vector<double>& x) {
  const double m = mean_of(x);
  double s = 0.0;
  for (const double v : x) s += (v - m) * (v - m);
  return s / static_cast<double>(x.size() - 1);
}

// The estimator of one resample (sorted in place for the median).
double estimate(std::vector<double>& x, Estimator e) {
  if (e == Estimator::kMean) return mean_of(x);
  std::sort(x.begin(), x.end());
  return quantile(x, 0.5);
}

void resample(const std::vector<double>& from, std::vector<double>& to, core::RandomStream& rng) {
  to.resize(from.size());
  const auto last = static_cast<std::int64_t>(from.size()) - 1;
  for (double& x : to) x = from[static_cast<std::size_t>(rng.uniform_int(0, last))];
}

/// The sorted bootstrap distribution of estimator(a) - estimator(b) (of estimator(a) if `b` is
/// empty), a and b resampled independently.
std::vector<double> bootstrap_values(const std::vector<double>& a, const std::vector<double>& b,
                                     Estimator estimator, core::RandomStream& rng, int resamples) {
  LLSF_DEMAND(!a.empty());
  LLSF_DEMAND(resamples > 0);
  std::vector<double> values;
  values.reserve(static_cast<std::size_t>(resamples));
  std::vector<double> ra, rb;
  for (int k = 0; k < resamples; ++k) {
    resample(a, ra, rng);
    resample(b, rb, rng);
    const double ea = estimate(ra, estimator);
    values.push_back(b.empty() ? ea : ea - estimate(rb, estimator));
  }
  std::sort(values.begin(), values.end());
  return values;
}

/// P(|T| < t) for Student's t with `df` degrees of freedom (closed forms for integer df,
/// Abramowitz & Stegun 26.7.3 and 26.7.4).
double t_two_sided_cdf(double t, int df) {
  const double theta = std::atan(t / std::sqrt(static_cast<double>(df)));
  const double c2 = std::cos(theta) * std::cos(theta);
  const double sn = std::sin(theta);
  double sum = 1.0, term = 1.0;
  if (df % 2 == 1) {
    if (df == 1) return 2.0 * theta / std::numbers::pi;
    for (int k = 2; k <= df - 3; k += 2) {
      term *= c2 * k / (k + 1.0);
      sum += term;
    }
    return 2.0 / std::numbers::pi * (theta + sn * std::cos(theta) * sum);
  }
  for (int k = 1; k <= df - 3; k += 2) {
    term *= c2 * k / (k + 1.0);
    sum += term;
  }
  return sn * sum;
}

/// The t with P(|T| < t) = `level`, by bisection (df >= 1, 0 < level < 1).
double t_quantile_two_sided(double level, int df) {
  double lo = 0.0, hi = 1.0;
  while (t_two_sided_cdf(hi, df) < level) hi *= 2.0;
  for (int i = 0; i < 100 && hi - lo > 1e-12 * hi; ++i) {
    const double mid = 0.5 * (lo + hi);
    (t_two_sided_cdf(mid, df) < level ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

double normal_cdf(double x) { return 0.5 * std::erfc(-x / std::sqrt(2.0)); }

/// The x with normal_cdf(x) = p, by bisection (0 < p < 1).
double normal_quantile(double p) {
  double lo = -40.0, hi = 40.0;
  for (int i = 0; i < 200 && hi - lo > 1e-13; ++i) {
    const double mid = 0.5 * (lo + hi);
    (normal_cdf(mid) < p ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

/// The lower tail of an expanded percentile interval of two-sided level 1 - `alpha`
/// (Hesterberg's "expanded percentile": the bootstrap distribution is too narrow by the factor
/// se_plugin / se and has normal instead of t tails; both are undone by taking the quantiles at
/// Phi(-(se / se_plugin) t(df))). The plain alpha / 2 if df < 1 or the spread is 0.
double expanded_tail(double alpha, double se_over_plugin, int df) {
  if (df < 1 || !std::isfinite(se_over_plugin) || se_over_plugin <= 0.0) return alpha / 2.0;
  return normal_cdf(-se_over_plugin * t_quantile_two_sided(1.0 - alpha, df));
}

}  // namespace

Interval bootstrap_interval(const std::vector<double>& a, const std::vector<double>& b,
                            Estimator estimator, core::RandomStream& rng, int resamples) {
  const std::vector<double> values = bootstrap_values(a, b, estimator, rng, resamples);
  return {quantile(values, 0.025), quantile(values, 0.975)};
}

double quantile(const std::vector<double>& sorted, double q) {
  if (sorted.empty()) return 0.0;
  const double h = (static_cast<double>(sorted.size()) - 1.0) * std::clamp(q, 0.0, 1.0);
  const auto lo = static_cast<std::size_t>(std::floor(h));
  const std::size_t hi = std::min(lo + 1, sorted.size() - 1);
  return sorted[lo] + (h - static_cast<double>(lo)) * (sorted[hi] - sorted[lo]);
}

std::string to_string(Pairing p) { return p == Pairing::kPaired ? "paired by seed" : "unpaired"; }

std::optional<int> games_to_separate(double diff, double sd) {
  if (diff == 0.0 || !std::isfinite(diff) || !std::isfinite(sd)) return std::nullopt;
  const double n = std::pow((kZ975 + kZ80) * sd / diff, 2.0);
  if (n >= 1e9) return std::nullopt;
  return std::max(kMinGamesForVerdict, static_cast<int>(std::ceil(n)));
}

Comparison compare_means(const std::vector<KeyedValue>& a, const std::vector<KeyedValue>& b,
                         core::RandomStream& rng, int min_games, int resamples, double alpha) {
  LLSF_DEMAND(!a.empty() && !b.empty());
  LLSF_DEMAND(alpha > 0.0 && alpha < 0.5);
  Comparison c;
  c.alpha = alpha;
  c.n_a = static_cast<int>(a.size());
  c.n_b = static_cast<int>(b.size());

  // Pair by key: paired only if no key repeats on a side and at least half of each side's values
  // find a partner (a design that shares its seeds, perhaps with a few runs missing).
  std::map<std::string, double> by_key_b;
  bool unique = true;
  for (const KeyedValue& v : b) unique = by_key_b.emplace(v.key, v.value).second && unique;
  std::map<std::string, double> by_key_a;
  for (const KeyedValue& v : a) unique = by_key_a.emplace(v.key, v.value).second && unique;
  std::vector<double> diffs;  // in key order: independent of the order the runs came in
  if (unique) {
    for (const auto& [key, va] : by_key_a) {
      const auto it = by_key_b.find(key);
      if (it != by_key_b.end()) diffs.push_back(va - it->second);
    }
  }
  const auto shared = static_cast<int>(diffs.size());
  const bool paired = unique && shared > 0 && 2 * shared >= std::max(c.n_a, c.n_b);

  std::vector<double> values;  // the sorted bootstrap distribution of the difference
  double sd = NAN;             // per-game standard deviation of the difference
  double widen = NAN;          // se / the bootstrap's plug-in se (expanded percentile)
  int df = 0;                  // degrees of freedom of the t behind the expansion
  if (paired) {
    c.pairing = Pairing::kPaired;
    c.pairs = shared;
    c.unmatched = c.n_a + c.n_b - 2 * shared;
    c.diff = mean_of(diffs);
    values = bootstrap_values(diffs, {}, Estimator::kMean, rng, resamples);
    if (shared >= 2) {
      const double n = shared;
      sd = std::sqrt(variance_of(diffs));
      c.se = sd / std::sqrt(n);
      widen = std::sqrt(n / (n - 1.0));
      df = shared - 1;
    }
  } else {
    std::vector<double> va, vb;
    for (const KeyedValue& v : a) va.push_back(v.value);
    for (const KeyedValue& v : b) vb.push_back(v.value);
    c.diff = mean_of(va) - mean_of(vb);
    values = bootstrap_values(va, vb, Estimator::kMean, rng, resamples);
    if (va.size() >= 2 && vb.size() >= 2) {
      const double na = c.n_a, nb = c.n_b;
      const double ua = variance_of(va) / na, ub = variance_of(vb) / nb;  // se^2 of each mean
      sd = std::sqrt(variance_of(va) + variance_of(vb));
      c.se = std::sqrt(ua + ub);
      // The bootstrap's plug-in variance divides by n, not n - 1; Welch-Satterthwaite's df.
      widen = *c.se / std::sqrt(ua * (na - 1.0) / na + ub * (nb - 1.0) / nb);
      const double welch = (ua + ub) * (ua + ub) / (ua * ua / (na - 1.0) + ub * ub / (nb - 1.0));
      df = std::isfinite(welch) ? std::max(1, static_cast<int>(std::floor(welch))) : 0;
    }
  }
  const double two_sided = expanded_tail(alpha, widen, df);
  const double one_sided = expanded_tail(2.0 * alpha, widen, df);
  c.ci = {quantile(values, two_sided), quantile(values, 1.0 - two_sided)};
  c.ci_tost = {quantile(values, one_sided), quantile(values, 1.0 - one_sided)};
  // Two-sided p: the level at which the expanded interval's end reaches 0, so that p < 5 % where
  // the 95 % interval excludes 0. The share of resampled differences beyond 0 (ties count on both
  // sides) is the tail Phi(-widen t) of that level; none beyond 0: p = 0, as every interval
  // excludes 0.
  const auto below = std::upper_bound(values.begin(), values.end(), 0.0) - values.begin();
  const auto above = values.end() - std::lower_bound(values.begin(), values.end(), 0.0);
  const double tail = std::min(
      0.5, static_cast<double>(std::min(below, above)) / static_cast<double>(values.size()));
  if (tail <= 0.0) {
    c.p_value = 0.0;
  } else if (df >= 1 && std::isfinite(widen) && widen > 0.0) {
    c.p_value = 1.0 - t_two_sided_cdf(-normal_quantile(tail) / widen, df);
  } else {
    c.p_value = 2.0 * tail;
  }
  if (c.se) c.detectable = (kZ975 + kZ80) * *c.se;
  if (std::isfinite(sd)) c.games_needed = games_to_separate(c.diff, sd);
  c.enough = c.games() >= min_games;
  return c;
}

bool within_margin(const Comparison& c, MarginTest test, double margin) {
  LLSF_DEMAND(margin > 0.0);
  switch (test) {
    case MarginTest::kSame:
      return -margin < c.ci_tost.low && c.ci_tost.high < margin;
    case MarginTest::kNotAbove:
      return c.ci_tost.high < margin;
    case MarginTest::kNotBelow:
      return c.ci_tost.low > -margin;
  }
  return false;
}

std::vector<int> SequentialPlan::look_sizes() const {
  std::vector<int> out;
  for (int k = 1; k <= looks; ++k) {
    const std::int64_t n = (static_cast<std::int64_t>(k) * max_runs + looks - 1) / looks;
    out.push_back(static_cast<int>(n));
  }
  return out;
}

std::string SequentialPlan::problem() const {
  if (max_runs < kMinGamesForVerdict) {
    return "--max-runs must be at least " + std::to_string(kMinGamesForVerdict) +
           " (no verdict from fewer games)";
  }
  if (looks < 1 || looks > max_runs) return "--looks must be 1..--max-runs";
  if (margin && !(*margin > 0.0 && std::isfinite(*margin))) return "--margin must be above 0";
  return "";
}

std::string to_string(SequentialOutcome o) {
  switch (o) {
    case SequentialOutcome::kContinue:
      return "continue";
    case SequentialOutcome::kSeparated:
      return "separated";
    case SequentialOutcome::kEquivalent:
      return "equivalent within the margin";
    case SequentialOutcome::kUndecided:
      return "undecided";
  }
  return "?";
}

SequentialLook sequential_look(const SequentialPlan& plan, int look,
                               const std::vector<KeyedValue>& a, const std::vector<KeyedValue>& b,
                               core::RandomStream& rng) {
  LLSF_DEMAND(plan.problem().empty());
  LLSF_DEMAND(look >= 1 && look <= plan.looks);
  SequentialLook l;
  l.look = look;
  l.seeds = plan.look_sizes()[static_cast<std::size_t>(look - 1)];
  l.comparison =
      compare_means(a, b, rng, kMinGamesForVerdict, kBootstrapResamples, plan.look_alpha());
  const Comparison& c = l.comparison;
  if (c.enough && c.separated()) {
    l.outcome = SequentialOutcome::kSeparated;
  } else if (c.enough && plan.margin && within_margin(c, MarginTest::kSame, *plan.margin)) {
    l.outcome = SequentialOutcome::kEquivalent;
  } else {
    l.outcome = look == plan.looks ? SequentialOutcome::kUndecided : SequentialOutcome::kContinue;
  }
  return l;
}

std::vector<bool> holm(const std::vector<double>& p, double alpha) {
  std::vector<std::size_t> order(p.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t x, std::size_t y) { return p[x] < p[y]; });
  std::vector<bool> rejected(p.size(), false);
  const auto m = static_cast<double>(p.size());
  for (std::size_t k = 0; k < order.size(); ++k) {
    if (p[order[k]] > alpha / (m - static_cast<double>(k))) break;
    rejected[order[k]] = true;
  }
  return rejected;
}

}  // namespace llsf::study
