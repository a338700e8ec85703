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
  CHECK(csv.rfind("variant,statistic,n,mean,median,q1,q3,min,max,pass_rate\n", 0) == 0);
  CHECK(csv.find("\"a\",points,5,13,13,12,14,11,15,0.8") != std::string::npos);
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
  CHECK(text.find("b                                +0.3  [-0.3, +0.8]\n") != std::string::npos);
}
