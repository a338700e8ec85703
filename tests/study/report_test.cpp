// SPDX-License-Identifier: MIT
// Batch reports: quantiles, per-variant summaries, bootstrap differences, CSV.
#include <doctest/doctest.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <string>
#include <vector>

#include "llsf/study/report.h"
#include "llsf/study/stats_store.h"

using namespace llsf;
using namespace llsf::sim;
using namespace llsf::study;

TEST_CASE("quantiles interpolate between order statistics (R type 7)") {
  const std::vector<double> v{1, 2, 3, 4};
  CHECK(quantile(v, 0.0) == 1.0);
  CHECK(quantile(v, 1.0) == 4.0);
  CHECK(quantile(v, 0.5) == doctest::Approx(2.5));
  CHECK(quantile(v, 0.25) == doctest::Approx(1.75));
  CHECK(quantile({}, 0.5) == 0.0);
  CHECK(quantile({7}, 0.9) == 7.0);
}

TEST_CASE("a report summarises each variant and bounds the difference of means") {
  const std::string path = (std::filesystem::temp_directory_path() /
                            ("llsf_report_test_" + std::to_string(::getpid()) + ".db"))
                               .string();
  std::filesystem::remove(path);
  {
    StatsStore store(path);
    BatchKey key;
    key.kind = BatchKey::Kind::kBatch;
    key.scenario_file = "x.yaml";
    key.scenario_name = "x";
    key.scenario_hash = "h";
    key.runs_per_variant = 5;
    key.variants = 2;
    const std::int64_t b = store.open_batch(key);
    // Variant "b" scores 100 more than "a" in every run; "a" fails one test.
    for (int seed = 1; seed <= 5; ++seed) {
      for (const char* v : {"b", "a"}) {
        RunResult r;
        r.scenario = "x";
        r.variant = v;
        r.seed = static_cast<std::uint64_t>(seed);
        r.points = (std::string(v) == "a" ? 10 : 110) + seed;
        r.tests.push_back({"t", !(std::string(v) == "a" && seed == 3), "", 0.0});
        store.add_run(b, r);
      }
    }
  }
  const StatsStore store(path);
  const BatchReport r = make_report(store, store.batches().front().id);
  REQUIRE(r.variants.size() == 2);
  CHECK(r.variants[0].variant == "a");  // name order
  CHECK(r.variants[0].runs == 5);
  CHECK(r.variants[0].passed == 4);
  const StatSummary* pa = r.variants[0].find("points");
  REQUIRE(pa != nullptr);
  CHECK(pa->n == 5);
  CHECK(pa->mean == doctest::Approx(13.0));
  CHECK(pa->median == doctest::Approx(13.0));
  CHECK(pa->min == 11.0);
  CHECK(pa->max == 15.0);
  bool found = false;
  for (const Difference& d : r.differences) {
    if (d.statistic != "points") continue;
    found = true;
    CHECK(d.variant == "b");
    CHECK(d.baseline == "a");
    CHECK(d.diff == doctest::Approx(100.0));
    CHECK(d.ci_low > 97.0);
    CHECK(d.ci_high < 103.0);
    CHECK(d.ci_low <= d.diff);
    CHECK(d.ci_high >= d.diff);
  }
  CHECK(found);
  // Deterministic: the same store gives the same report.
  CHECK(to_text(make_report(store, r.batch.id)) == to_text(r));
  const std::string csv = to_csv(r);
  CHECK(csv.rfind("variant,statistic,n,mean,median,q1,q3,min,max,pass_rate,runs\n", 0) == 0);
  CHECK(csv.find("\"a\",points,5,13,13,12,14,11,15,0.8,5\n") != std::string::npos);
  // A quote in a variant name is doubled (RFC 4180), not left to end the field.
  BatchReport quoted = r;
  quoted.variants[0].variant = "config=\"P3\"";
  CHECK(to_csv(quoted).find("\"config=\"\"P3\"\"\",points,") != std::string::npos);
  CHECK_THROWS_AS(make_report(store, 999), StatsError);
  std::filesystem::remove(path);
}

TEST_CASE("a report does not depend on the order in which the runs were stored") {
  // Workers, Slurm array tasks and merges store runs in any order; the bootstrap's intervals
  // must come out the same (the cluster test compares a local and a cluster batch's reports).
  const std::filesystem::path dir = std::filesystem::temp_directory_path();
  std::vector<std::string> texts;
  for (const bool reversed : {false, true}) {
    const std::string path =
        (dir / ("llsf_report_order_" + std::to_string(::getpid()) + (reversed ? "r" : "f") + ".db"))
            .string();
    std::filesystem::remove(path);
    {
      StatsStore store(path);
      BatchKey key;
      key.scenario_file = "x.yaml";
      key.scenario_name = "x";
      key.scenario_hash = "h";
      key.runs_per_variant = 12;
      key.variants = 2;
      const std::int64_t b = store.open_batch(key);
      std::vector<RunResult> runs;
      for (int seed = 1; seed <= 12; ++seed) {
        for (const char* v : {"a", "b"}) {
          RunResult r;
          r.scenario = "x";
          r.variant = v;
          r.seed = static_cast<std::uint64_t>(seed);
          r.points = (seed * 37) % 23 + (std::string(v) == "b" ? 5 : 0);
          runs.push_back(r);
        }
      }
      if (reversed) std::reverse(runs.begin(), runs.end());
      for (const RunResult& r : runs) store.add_run(b, r);
    }
    const StatsStore store(path);
    texts.push_back(to_text(make_report(store, store.batches().front().id)));
    std::filesystem::remove(path);
  }
  CHECK(texts[0] == texts[1]);
}

namespace {

/// A store at `path` with one batch: variants "a" and "b", `seeds` seeds each, b's points
/// `points_b(seed)`, a's `points_a(seed)`.
template <class A, class B>
std::int64_t make_two_variants(const std::string& path, int seeds, A points_a, B points_b) {
  std::filesystem::remove(path);
  StatsStore store(path);
  BatchKey key;
  key.scenario_file = "x.yaml";
  key.scenario_name = "x";
  key.scenario_hash = "h";
  key.runs_per_variant = seeds;
  key.variants = 2;
  const std::int64_t b = store.open_batch(key);
  for (int seed = 1; seed <= seeds; ++seed) {
    for (const char* v : {"a", "b"}) {
      RunResult r;
      r.scenario = "x";
      r.variant = v;
      r.seed = static_cast<std::uint64_t>(100 + seed);
      r.points = std::string(v) == "a" ? points_a(seed) : points_b(seed);
      store.add_run(b, r);
    }
  }
  return b;
}

const Difference& points_difference(const BatchReport& r) {
  for (const Difference& d : r.differences) {
    if (d.statistic == "points") return d;
  }
  FAIL("no points difference");
  return r.differences.front();
}

}  // namespace

TEST_CASE("one game per variant: the report prints the numbers but no star and no verdict") {
  const std::string path = (std::filesystem::temp_directory_path() /
                            ("llsf_report_single_" + std::to_string(::getpid()) + ".db"))
                               .string();
  const std::int64_t id = make_two_variants(
      path, 1, [](int) { return 41; }, [](int) { return 28; });
  const StatsStore store(path);
  const BatchReport r = make_report(store, id);
  const Difference& d = points_difference(r);
  CHECK(d.diff == doctest::Approx(-13.0));
  CHECK(!d.separated);
  CHECK(!d.comparison.enough);
  const std::string text = to_text(r);
  CHECK(text.find("-13.0") != std::string::npos);
  CHECK(text.find("]  *") == std::string::npos);  // no star after the interval
  CHECK(text.find("too few for a verdict, which needs 10") != std::string::npos);
  CHECK(text.find("the spread is unknown with one game") != std::string::npos);
  std::filesystem::remove(path);
}

TEST_CASE("the report pairs by seed: a small gain on every seed is separated") {
  // Seeds differ by up to 60 points, b gains 3 to 5 on each: unpaired this is noise, paired
  // it is clear.
  const std::string path = (std::filesystem::temp_directory_path() /
                            ("llsf_report_paired_" + std::to_string(::getpid()) + ".db"))
                               .string();
  const std::int64_t id = make_two_variants(
      path, 12, [](int s) { return (s * 37) % 61; },
      [](int s) { return (s * 37) % 61 + 3 + s % 3; });
  const StatsStore store(path);
  const BatchReport r = make_report(store, id);
  const Difference& d = points_difference(r);
  CHECK(d.comparison.pairing == Pairing::kPaired);
  CHECK(d.comparison.pairs == 12);
  CHECK(d.ci_low >= 3.0);
  CHECK(d.ci_high <= 5.0);
  CHECK(d.separated);
  CHECK(d.comparisons == 1);
  const std::string text = to_text(r);
  CHECK(text.find("paired by seed") != std::string::npos);
  CHECK(text.find("(paired by seed: 12 pairs)") != std::string::npos);
  CHECK(text.find("]  *") != std::string::npos);
  std::filesystem::remove(path);
}

TEST_CASE("the report's stars are corrected for many comparisons (Holm)") {
  // Five variants against the first, each 2 points better per seed give or take a few (t about
  // 2.6 with 12 seeds, p about 0.03): each alone would be starred, but five comparisons at once
  // need p < 0.01 for the first star (Holm), and none has it.
  const std::string path = (std::filesystem::temp_directory_path() /
                            ("llsf_report_holm_" + std::to_string(::getpid()) + ".db"))
                               .string();
  std::filesystem::remove(path);
  {
    StatsStore store(path);
    BatchKey key;
    key.scenario_file = "x.yaml";
    key.scenario_name = "x";
    key.scenario_hash = "h";
    key.runs_per_variant = 12;
    key.variants = 6;
    const std::int64_t b = store.open_batch(key);
    const int noise[12] = {-3, 3, -2, 4, -4, 1, 3, -3, 2, -1, 0, 0};  // mean 0, sd 2.66
    for (int seed = 1; seed <= 12; ++seed) {
      for (int v = 0; v < 6; ++v) {
        RunResult r;
        r.scenario = "x";
        r.variant = std::string(1, static_cast<char>('a' + v));
        r.seed = static_cast<std::uint64_t>(seed);
        r.points = 50 + (seed * 37) % 61 + (v > 0 ? 2 + noise[(seed + v) % 12] : 0);
        store.add_run(b, r);
      }
    }
  }
  const StatsStore store(path);
  const BatchReport r = make_report(store, store.batches().front().id);
  int uncorrected = 0, starred = 0;
  for (const Difference& d : r.differences) {
    if (d.statistic != "points") continue;
    CHECK(d.comparisons == 5);
    CHECK(d.comparison.pairing == Pairing::kPaired);
    uncorrected += d.comparison.p_value < 0.05 ? 1 : 0;
    starred += d.separated ? 1 : 0;
  }
  CHECK(uncorrected == 5);
  CHECK(starred == 0);
  CHECK(to_text(r).find("after Holm's correction for 5 comparisons") != std::string::npos);
  std::filesystem::remove(path);
}

TEST_CASE("the text report rounds as the HTML page does: an exact tie away from zero") {
  BatchReport r;
  r.batch.id = 1;
  r.batch.scenario_name = "x";
  VariantReport v;
  v.variant = "a";
  v.runs = 8;
  v.passed = 5;  // 62.5 %: the page's Math.round shows 63
  StatSummary p;
  p.name = "points";
  p.n = 8;
  p.mean = 2.25;    // exact in binary: toFixed(1) "2.3", printf "%.1f" "2.2"
  p.median = 0.35;  // not a tie in binary (0.34999...): "0.3" in both
  p.q1 = -2.25;     // "-2.3"
  p.q3 = 10.75;     // "10.8"
  p.min = 2.5;      // "3" with no decimals
  p.max = 3.5;      // "4"
  v.stats.push_back(p);
  r.variants.push_back(v);
  Difference d;
  d.variant = "b";
  d.baseline = "a";
  d.statistic = "points";
  d.diff = 0.25;
  d.ci_low = -0.25;
  d.ci_high = 0.75;
  r.differences.push_back(d);
  const std::string text = to_text(r);
  INFO(text);
  CHECK(text.find("a                                8    63%      2.3     0.3    -2.3    10.8      "
                  " 3       4\n") != std::string::npos);
  CHECK(text.find("b                                +0.3  [-0.3, +0.8]") != std::string::npos);
}
