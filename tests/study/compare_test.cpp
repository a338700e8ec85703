// SPDX-License-Identifier: MIT
// Comparing variants on synthetic data with a known difference: the intervals cover it at the
// nominal rate, equivalence accepts and rejects at the right rates, Holm controls a family, and
// one game gives no verdict. Pure statistics, no games.
#include <doctest/doctest.h>

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "llsf/core/rng.h"
#include "llsf/study/compare.h"

using namespace llsf;
using namespace llsf::study;

namespace {

/// `n` games of a variant with mean `mean`: per seed a shared part (the seed's orders and
/// machines, sd `shared_sd`) plus the variant's own noise (sd `own_sd`). `shared` holds the seeds'
/// shared parts, the same for both variants of one simulated experiment.
std::vector<KeyedValue> games(const std::vector<double>& shared, double mean, double own_sd,
                              core::RandomStream& rng) {
  std::vector<KeyedValue> out;
  for (std::size_t i = 0; i < shared.size(); ++i) {
    out.push_back({"seed=" + std::to_string(i + 1), mean + shared[i] + rng.normal(0.0, own_sd)});
  }
  return out;
}

std::vector<double> seed_parts(int n, double sd, core::RandomStream& rng) {
  std::vector<double> out;
  for (int i = 0; i < n; ++i) out.push_back(rng.normal(0.0, sd));
  return out;
}

/// A skewed game outcome: most games score about `mean`, one in five far below (a jammed robot).
double skewed(double mean, core::RandomStream& rng) {
  return rng.uniform01() < 0.2 ? mean - 40.0 + rng.normal(0.0, 5.0) : mean + rng.normal(0.0, 8.0);
}

struct Rates {
  int covered = 0;
  int experiments = 0;
  double rate() const { return static_cast<double>(covered) / experiments; }
};

/// The share of `experiments` simulated paired experiments of `n` seeds whose 95 % interval holds
/// the true difference `diff` (shared seed part sd 20, own noise sd 6).
Rates paired_coverage(int n, double diff, int experiments, const char* stream) {
  core::RandomStream data = core::Rng(7).stream(stream);
  core::RandomStream boot = core::Rng(8).stream(stream);
  Rates r;
  for (int k = 0; k < experiments; ++k) {
    const std::vector<double> shared = seed_parts(n, 20.0, data);
    const Comparison c =
        compare_means(games(shared, 50.0 + diff, 6.0, data), games(shared, 50.0, 6.0, data), boot);
    REQUIRE(c.pairing == Pairing::kPaired);
    r.covered += c.ci.low <= diff && diff <= c.ci.high ? 1 : 0;
    ++r.experiments;
  }
  return r;
}

}  // namespace

TEST_CASE("games_to_separate: ((1.96 + 0.84) sd / d)^2, at least the minimum, none for 0") {
  CHECK(games_to_separate(0.0, 5.0) == std::nullopt);
  CHECK(games_to_separate(2.0, 0.0) == kMinGamesForVerdict);
  // (1.96 + 0.84)^2 * (10 / 2)^2 = 196.2 -> 197
  CHECK(games_to_separate(2.0, 10.0) == 197);
  CHECK(games_to_separate(-2.0, 10.0) == 197);
}

TEST_CASE("paired 95 % intervals cover a known difference in at least 93 % of 1,000 experiments") {
  // Seeds shared, as in every batch: 20 seeds, true difference +4.
  const Rates r = paired_coverage(20, 4.0, 1000, "coverage/paired");
  MESSAGE("paired, 20 seeds: " << r.covered << " of " << r.experiments);
  CHECK(r.rate() >= 0.93);
  CHECK(r.rate() <= 0.975);  // not wider than it should be either
}

TEST_CASE("paired 95 % intervals at the minimum number of games still cover at 93 %") {
  const Rates r = paired_coverage(kMinGamesForVerdict, -3.0, 1000, "coverage/paired-min");
  MESSAGE("paired, " << kMinGamesForVerdict << " seeds: " << r.covered << " of " << r.experiments);
  CHECK(r.rate() >= 0.93);
}

TEST_CASE("unpaired 95 % intervals cover a known difference, also for skewed outcomes") {
  core::RandomStream data = core::Rng(9).stream("coverage/unpaired");
  core::RandomStream boot = core::Rng(10).stream("coverage/unpaired");
  // Different seeds on the two sides: no pairing. Skewed outcomes: mean(skewed(m)) = m - 8.
  Rates r;
  for (int k = 0; k < 1000; ++k) {
    std::vector<KeyedValue> a, b;
    for (int i = 0; i < 30; ++i) a.push_back({"a" + std::to_string(i), skewed(60.0, data)});
    for (int i = 0; i < 25; ++i) b.push_back({"b" + std::to_string(i), skewed(55.0, data)});
    const Comparison c = compare_means(a, b, boot);
    REQUIRE(c.pairing == Pairing::kUnpaired);
    r.covered += c.ci.low <= 5.0 && 5.0 <= c.ci.high ? 1 : 0;
    ++r.experiments;
  }
  MESSAGE("unpaired skewed, 30 vs 25 games: " << r.covered << " of " << r.experiments);
  CHECK(r.rate() >= 0.93);
}

TEST_CASE("pairing by seed is much sharper when the seed explains most of the spread") {
  core::RandomStream data = core::Rng(11).stream("sharpness");
  core::RandomStream boot = core::Rng(12).stream("sharpness");
  const std::vector<double> shared = seed_parts(30, 20.0, data);
  const std::vector<KeyedValue> a = games(shared, 55.0, 3.0, data);
  const std::vector<KeyedValue> b = games(shared, 50.0, 3.0, data);
  const Comparison paired = compare_means(a, b, boot);
  CHECK(paired.pairing == Pairing::kPaired);
  CHECK(paired.pairs == 30);
  CHECK(paired.separated());
  // The same values with their seeds hidden: the seed-to-seed spread swamps the +5.
  std::vector<KeyedValue> hidden_b = b;
  for (KeyedValue& v : hidden_b) v.key = "other-" + v.key;
  const Comparison unpaired = compare_means(a, hidden_b, boot);
  CHECK(unpaired.pairing == Pairing::kUnpaired);
  CHECK(unpaired.diff == doctest::Approx(paired.diff));
  CHECK(!unpaired.separated());
  CHECK(*paired.detectable < *unpaired.detectable / 3.0);
}

TEST_CASE("pairing: duplicate seeds or too few partners fall back to unpaired") {
  core::RandomStream boot = core::Rng(1).stream("pairing");
  std::vector<KeyedValue> a, b;
  for (int i = 0; i < 10; ++i) {
    a.push_back({"s" + std::to_string(i), 10.0 + i});
    b.push_back({"s" + std::to_string(i), 8.0 + i});
  }
  Comparison c = compare_means(a, b, boot);
  CHECK(c.pairing == Pairing::kPaired);
  CHECK(c.diff == doctest::Approx(2.0));
  CHECK(c.ci.low == doctest::Approx(2.0));  // every seed +2: no spread
  CHECK(c.enough);
  // Two runs without a partner are left out and counted.
  std::vector<KeyedValue> a2 = a;
  a2.push_back({"x1", 100.0});
  a2.push_back({"x2", 100.0});
  c = compare_means(a2, b, boot);
  CHECK(c.pairing == Pairing::kPaired);
  CHECK(c.pairs == 10);
  CHECK(c.unmatched == 2);
  CHECK(c.diff == doctest::Approx(2.0));
  // A seed twice on one side (pooled variants): unpaired.
  std::vector<KeyedValue> dup = b;
  dup.push_back(b.front());
  CHECK(compare_means(a, dup, boot).pairing == Pairing::kUnpaired);
  // Fewer than half of the runs with a partner: unpaired.
  std::vector<KeyedValue> few = b;
  for (std::size_t i = 0; i < 6; ++i) few[i].key = "other" + std::to_string(i);
  CHECK(compare_means(a, few, boot).pairing == Pairing::kUnpaired);
}

TEST_CASE("one game a side: numbers, no spread, no verdict, no estimate of the games needed") {
  core::RandomStream boot = core::Rng(1).stream("single");
  const Comparison c = compare_means({{"seed=1", 41.0}}, {{"seed=1", 28.0}}, boot);
  CHECK(c.pairing == Pairing::kPaired);
  CHECK(c.pairs == 1);
  CHECK(c.diff == doctest::Approx(13.0));
  CHECK(!c.enough);
  CHECK(!c.se);
  CHECK(!c.detectable);
  CHECK(!c.games_needed);
  // Few games: not enough, but the games a difference of this size would need are estimated.
  std::vector<KeyedValue> a, b;
  for (int i = 0; i < 4; ++i) {
    a.push_back({"s" + std::to_string(i), 30.0 + 7.0 * (i % 2)});
    b.push_back({"s" + std::to_string(i), 28.0});
  }
  const Comparison few = compare_means(a, b, boot);
  CHECK(!few.enough);
  REQUIRE(few.games_needed);
  CHECK(*few.games_needed >= kMinGamesForVerdict);
}

TEST_CASE("equivalence within a margin: accepts when the difference is 0, rejects at the margin") {
  // 1,000 simulated paired experiments of 30 seeds each: with a true difference of 0 and a margin
  // of 5, a test of this power should accept nearly always; with a true difference of exactly
  // the margin it must accept at most 5 % of the time (its error rate).
  core::RandomStream data = core::Rng(13).stream("equivalence");
  core::RandomStream boot = core::Rng(14).stream("equivalence");
  const double margin = 5.0;
  int same_at_0 = 0, same_at_margin = 0, not_above_at_margin = 0, not_below_at_minus = 0;
  const int experiments = 1000;
  for (int k = 0; k < experiments; ++k) {
    const std::vector<double> shared = seed_parts(30, 20.0, data);
    const std::vector<KeyedValue> b = games(shared, 50.0, 6.0, data);
    const Comparison zero = compare_means(games(shared, 50.0, 6.0, data), b, boot);
    const Comparison at = compare_means(games(shared, 50.0 + margin, 6.0, data), b, boot);
    const Comparison below = compare_means(games(shared, 50.0 - margin, 6.0, data), b, boot);
    same_at_0 += within_margin(zero, MarginTest::kSame, margin) ? 1 : 0;
    same_at_margin += within_margin(at, MarginTest::kSame, margin) ? 1 : 0;
    not_above_at_margin += within_margin(at, MarginTest::kNotAbove, margin) ? 1 : 0;
    not_below_at_minus += within_margin(below, MarginTest::kNotBelow, margin) ? 1 : 0;
  }
  MESSAGE("accepted as same: " << same_at_0 << " at 0, " << same_at_margin << " at +margin; "
                               << "not above at +margin: " << not_above_at_margin
                               << "; not below at -margin: " << not_below_at_minus);
  // sd of a difference 6 * sqrt(2) = 8.5, se 1.55, the 90 % interval's half-width about 2.7:
  // accepted when |estimate| < 2.3, in about 86 % of experiments.
  CHECK(same_at_0 >= 0.8 * experiments);
  // The error rate at the margin: 5 % nominal; 1,000 experiments allow about 1.4 % of chance.
  CHECK(same_at_margin <= 0.065 * experiments);
  CHECK(not_above_at_margin <= 0.065 * experiments);
  CHECK(not_below_at_minus <= 0.065 * experiments);
}

TEST_CASE("equivalence does not hold by absence of evidence: fewer games make it harder") {
  core::RandomStream boot = core::Rng(1).stream("absence");
  core::RandomStream data = core::Rng(2).stream("absence");
  // The same true difference 0 and noise sd 10 (a difference's sd 14), margin 10, in 300
  // simulated experiments each: 40 seeds show "same within 10" nearly always, 6 seeds rarely
  // (their 90 % interval is about +-11 wide on average) -- the opposite of a check that holds
  // whenever the interval reaches 0.
  int many_accepted = 0, few_accepted = 0, few_reach_0 = 0;
  const int experiments = 300;
  for (int k = 0; k < experiments; ++k) {
    const std::vector<double> s40 = seed_parts(40, 20.0, data);
    const Comparison many =
        compare_means(games(s40, 50.0, 10.0, data), games(s40, 50.0, 10.0, data), boot);
    const std::vector<double> s6 = seed_parts(6, 20.0, data);
    const Comparison few =
        compare_means(games(s6, 50.0, 10.0, data), games(s6, 50.0, 10.0, data), boot);
    many_accepted += within_margin(many, MarginTest::kSame, 10.0) ? 1 : 0;
    few_accepted += within_margin(few, MarginTest::kSame, 10.0) ? 1 : 0;
    few_reach_0 += few.ci.low <= 0.0 && few.ci.high >= 0.0 ? 1 : 0;
  }
  MESSAGE("same within 10: " << many_accepted << " of " << experiments << " with 40 seeds, "
                             << few_accepted << " with 6; 6 seeds' interval reaches 0 in "
                             << few_reach_0);
  CHECK(many_accepted >= 0.95 * experiments);
  CHECK(few_accepted <= 0.5 * experiments);
  CHECK(few_reach_0 >= 0.9 * experiments);  // the old rule would have said "no better" here
}

TEST_CASE("Holm's correction: step-down over the sorted p-values") {
  // m = 4: 0.01 <= 0.05/4 fails (0.0125 is the bound: 0.01 passes), 0.02 <= 0.05/3 = 0.0167
  // fails: only the first is rejected, and nothing after the first failure.
  CHECK(holm({0.04, 0.01, 0.02, 0.03}) == std::vector<bool>{false, true, false, false});
  CHECK(holm({0.001, 0.01, 0.02, 0.04}) == std::vector<bool>{true, true, true, true});
  CHECK(holm({0.3, 0.001}) == std::vector<bool>{false, true});
  CHECK(holm({}).empty());
  // The family-wise error rate: 1,000 families of 5 true null comparisons, uniform p-values.
  core::RandomStream rng = core::Rng(3).stream("holm");
  int families_with_error = 0;
  for (int k = 0; k < 1000; ++k) {
    std::vector<double> p;
    for (int i = 0; i < 5; ++i) p.push_back(rng.uniform01());
    bool any = false;
    for (const bool rejected : holm(p)) any = any || rejected;
    families_with_error += any ? 1 : 0;
  }
  MESSAGE("families with a false separation: " << families_with_error << " of 1000");
  CHECK(families_with_error <= 65);
}

TEST_CASE("the bootstrap p-value agrees with the interval") {
  core::RandomStream data = core::Rng(4).stream("p");
  core::RandomStream boot = core::Rng(5).stream("p");
  int agree = 0;
  for (int k = 0; k < 200; ++k) {
    const std::vector<double> shared = seed_parts(20, 10.0, data);
    const Comparison c = compare_means(games(shared, 50.0 + 0.1 * (k % 40), 6.0, data),
                                       games(shared, 50.0, 6.0, data), boot);
    agree += (c.p_value < kAlpha) == c.separated() ? 1 : 0;
  }
  // Both come from the same expanded tails: they differ only by the quantiles' interpolation.
  CHECK(agree >= 197);
}

TEST_CASE("playing until the answer is known keeps its error rate despite the repeated looks") {
  // 300 simulated batches of at most 40 seeds, looked at after 10, 20, 30 and 40: with two equal
  // variants, a batch that stops "separated" is an error; with a true difference of exactly the
  // margin, one that stops "equivalent" is. Both must stay at or below 5 % (the plan's level);
  // looking at 5 % each time would not keep it.
  SequentialPlan plan;
  plan.max_runs = 40;
  plan.looks = 4;
  plan.margin = 5.0;
  CHECK(plan.problem().empty());
  CHECK(plan.look_sizes() == std::vector<int>{10, 20, 30, 40});
  CHECK(plan.look_alpha() == doctest::Approx(0.0125));
  core::RandomStream data = core::Rng(21).stream("sequential");
  core::RandomStream boot = core::Rng(22).stream("sequential");
  auto first = [](const std::vector<KeyedValue>& v, int n) {
    return std::vector<KeyedValue>(v.begin(), v.begin() + n);
  };
  const int batches = 300;
  int false_separations = 0, naive_false_separations = 0, false_equivalences = 0;
  for (int k = 0; k < batches; ++k) {
    const std::vector<double> shared = seed_parts(plan.max_runs, 20.0, data);
    const std::vector<KeyedValue> b = games(shared, 50.0, 6.0, data);
    const std::vector<KeyedValue> same = games(shared, 50.0, 6.0, data);
    const std::vector<KeyedValue> at_margin = games(shared, 55.0, 6.0, data);
    bool naive = false, separated = false, equivalent = false;
    for (int look = 1; look <= plan.looks; ++look) {
      const int n = plan.look_sizes()[static_cast<std::size_t>(look - 1)];
      if (!separated) {
        const SequentialLook l = sequential_look(plan, look, first(same, n), first(b, n), boot);
        separated = l.outcome == SequentialOutcome::kSeparated;
      }
      naive = naive || compare_means(first(same, n), first(b, n), boot).separated();
      if (!equivalent) {
        const SequentialLook l =
            sequential_look(plan, look, first(at_margin, n), first(b, n), boot);
        equivalent = l.outcome == SequentialOutcome::kEquivalent;
        if (l.outcome == SequentialOutcome::kSeparated) break;  // stopped: another answer
      }
    }
    false_separations += separated ? 1 : 0;
    naive_false_separations += naive ? 1 : 0;
    false_equivalences += equivalent ? 1 : 0;
  }
  MESSAGE("of " << batches << " batches: false separations " << false_separations
                << " (looking at 5 % each time: " << naive_false_separations
                << "), false equivalences " << false_equivalences);
  CHECK(false_separations <= 0.05 * batches);
  CHECK(false_equivalences <= 0.05 * batches);
  CHECK(naive_false_separations > false_separations);
}

TEST_CASE("playing until the answer is known stops early when the difference is clear") {
  SequentialPlan plan;
  plan.max_runs = 50;
  plan.looks = 5;
  core::RandomStream data = core::Rng(23).stream("sequential-power");
  core::RandomStream boot = core::Rng(24).stream("sequential-power");
  // +8 points with a per-seed sd of 8.5: separated at the first look (10 seeds) in most batches.
  int separated = 0, seeds = 0;
  const int batches = 50;
  for (int k = 0; k < batches; ++k) {
    const std::vector<double> shared = seed_parts(plan.max_runs, 20.0, data);
    const std::vector<KeyedValue> a = games(shared, 58.0, 6.0, data);
    const std::vector<KeyedValue> b = games(shared, 50.0, 6.0, data);
    for (int look = 1; look <= plan.looks; ++look) {
      const int n = plan.look_sizes()[static_cast<std::size_t>(look - 1)];
      const SequentialLook l =
          sequential_look(plan, look, std::vector<KeyedValue>(a.begin(), a.begin() + n),
                          std::vector<KeyedValue>(b.begin(), b.begin() + n), boot);
      if (l.outcome == SequentialOutcome::kContinue) continue;
      separated += l.outcome == SequentialOutcome::kSeparated ? 1 : 0;
      seeds += n;
      break;
    }
  }
  MESSAGE("separated " << separated << " of " << batches << ", " << seeds / batches
                       << " seeds a batch on average (of at most 50)");
  CHECK(separated >= 0.9 * batches);
  CHECK(seeds <= 25 * batches);
  // Bad plans are named.
  plan.max_runs = 5;
  CHECK(plan.problem() == "--max-runs must be at least 10 (no verdict from fewer games)");
  plan.max_runs = 20;
  plan.looks = 0;
  CHECK(plan.problem() == "--looks must be 1..--max-runs");
  plan.looks = 2;
  plan.margin = -1.0;
  CHECK(plan.problem() == "--margin must be above 0");
}
