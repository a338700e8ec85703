// SPDX-License-Identifier: MIT
// Experiments: loading errors name file:line, every check kind holds and fails on a store filled
// with known values, groups, sweeps, incomplete batches, a deterministic report, the markers of
// --update, and the shared bootstrap.
#include <doctest/doctest.h>

#include <cmath>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "llsf/core/error.h"
#include "llsf/core/rng.h"
#include "llsf/study/experiment.h"
#include "llsf/study/report.h"
#include "llsf/study/stats_store.h"
#include "support/temp_dir.h"

using namespace llsf;
using namespace llsf::sim;
using namespace llsf::study;
using llsf::test::TempDir;

namespace {

bool has(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

// Two scenario files without agents (never played here): `conf.yaml` with the axes profile x
// config and 4 seeds, `sweep.yaml` with speed x config and 3 seeds.
void write_scenarios(const TempDir& dir) {
  dir.write("conf.yaml",
            "name: conf\n"
            "seeds: {first: 1, count: 4}\n"
            "start: production\n"
            "duration_s: 60\n"
            "robots: {count: 1}\n"
            "matrix:\n"
            "  profile:\n"
            "    ideal: {}\n"
            "    real: {}\n"
            "  config:\n"
            "    A: {}\n"
            "    B: {}\n");
  dir.write("sweep.yaml",
            "name: sweep\n"
            "seeds: {first: 1, count: 3}\n"
            "start: production\n"
            "duration_s: 60\n"
            "robots: {count: 1}\n"
            "matrix:\n"
            "  speed:\n"
            "    slow: {}\n"
            "    mid: {}\n"
            "    fast: {}\n"
            "  config:\n"
            "    A: {}\n"
            "    B: {}\n"
            "    C: {}\n");
}

/// Stores runs of a scenario file as `llsfsim batch` would (identity: content hash, runs per
/// variant); `fill` sets each run's results from its variant and seed.
void store_runs(StatsStore& store, const std::string& file, int runs_per_variant,
                const std::vector<std::string>& variants, int seeds,
                const std::function<void(RunResult&)>& fill) {
  BatchKey key;
  key.kind = BatchKey::Kind::kBatch;
  key.scenario_file = file;
  key.scenario_name = "x";
  key.scenario_hash = batch_identity_hash(file, load_scenario(file));
  key.runs_per_variant = runs_per_variant;
  key.variants = static_cast<int>(variants.size());
  const std::int64_t batch = store.open_batch(key);
  // Stored seed-major and in reverse variant order: the evaluation must not depend on it.
  for (int seed = seeds; seed >= 1; --seed) {
    for (auto v = variants.rbegin(); v != variants.rend(); ++v) {
      RunResult r;
      r.scenario = "x";
      r.variant = *v;
      r.seed = static_cast<std::uint64_t>(seed);
      fill(r);
      store.add_run(batch, r);
    }
  }
}

bool variant_has(const RunResult& r, const std::string& part) { return has(r.variant, part); }

// conf: in `ideal` A scores ~100 and B ~50 (A clearly better); in `real` both score the same on
// average. lock_wait_max_s of ideal/A: 600, 620, -1 (never), 640. exploration_points: -1 except
// one run (real/B, seed 2): 300.
void fill_conf(RunResult& r) {
  const int s = static_cast<int>(r.seed);
  const bool ideal = variant_has(r, "profile=ideal");
  const bool a = variant_has(r, "config=A");
  if (ideal) {
    r.points = a ? 100 + s : 50 + s;
  } else {
    r.points = a ? 60 + s : 65 - s;
  }
  // (Statistics of every store version: the values are made up, only the names are real.)
  r.lock_wait_max_s = -1.0;
  if (ideal && a) r.lock_wait_max_s = s == 3 ? -1.0 : 580.0 + 20.0 * s - (s == 4 ? 20.0 : 0.0);
  r.exploration_points = (!ideal && !a && s == 2) ? 300 : -1;
  // Irregular values: resamples of them have many distinct means.
  r.lock_wait_s = std::sqrt(7.3 * s + (ideal ? 1.1 : 2.9) + (a ? 0.0 : 13.7));
}

// sweep: at slow and mid A > B > C (A far ahead at slow, only just at mid); at fast B > A > C.
void fill_sweep(RunResult& r) {
  const int s = static_cast<int>(r.seed);
  const bool slow = variant_has(r, "speed=slow");
  const bool mid = variant_has(r, "speed=mid");
  int base = 0;
  if (variant_has(r, "config=A")) base = slow ? 200 : mid ? 101 : 100;
  if (variant_has(r, "config=B")) base = slow ? 150 : mid ? 100 : 180;
  if (variant_has(r, "config=C")) base = 20;
  r.points = base + (s - 2) * 10;  // seeds 1..3: base - 10, base, base + 10
}

const std::vector<std::string> kConfVariants{"profile=ideal,config=A", "profile=ideal,config=B",
                                             "profile=real,config=A", "profile=real,config=B"};

std::vector<std::string> sweep_variants() {
  std::vector<std::string> out;
  for (const char* speed : {"slow", "mid", "fast"}) {
    for (const char* c : {"A", "B", "C"}) {
      out.push_back(std::string("speed=") + speed + ",config=" + c);
    }
  }
  return out;
}

/// A store holding the complete batches of both scenario files, written once (a batch is found
/// by its file's content, not its path: fixtures copy it).
const std::string& template_db() {
  static const TempDir dir{"llsf_experiment_template"};
  static const std::string db = [] {
    write_scenarios(dir);
    StatsStore store(dir.file("study.db"));
    store_runs(store, dir.file("conf.yaml"), 4, kConfVariants, 4, fill_conf);
    store_runs(store, dir.file("sweep.yaml"), 3, sweep_variants(), 3, fill_sweep);
    return dir.file("study.db");
  }();
  return db;
}

/// A directory with both scenario files and a store holding their complete batches.
struct StudyFixture {
  TempDir dir{"llsf_experiment"};
  std::string db = dir.file("study.db");
  StudyFixture() {
    write_scenarios(dir);
    std::filesystem::copy_file(template_db(), db);
  }
  /// Writes exp.yaml: the header (batches, group_by) and then `body`.
  std::string experiment(const std::string& body, bool group_by = true) const {
    dir.write("exp.yaml",
              "name: tiny-study\n"
              "description: A study of known values.\n"
              "batches:\n"
              "  conf: conf.yaml\n"
              "  sweep: sweep.yaml\n" +
                  std::string(group_by ? "group_by: profile\n" : "") + body);
    return dir.file("exp.yaml");
  }
  /// Loads exp.yaml with `body` and evaluates it against the store. The fixture's batches hold
  /// 3 and 4 seeds: the checks' mechanics are tested with a minimum of 2 games a side (the
  /// minimum itself has tests of its own).
  ExperimentResult evaluate_body(const std::string& body, Experiment& keep, bool group_by = true,
                                 EvaluateOptions o = few_games()) const {
    keep = load_experiment(experiment(body, group_by));
    const StatsStore store(db);
    return evaluate(keep, store, o);
  }
  static EvaluateOptions few_games() {
    EvaluateOptions o;
    o.min_games = 2;
    return o;
  }
};

/// The load error of exp.yaml with `body` ("" if it loads).
std::string load_error(const StudyFixture& f, const std::string& body) {
  try {
    (void)load_experiment(f.experiment(body));
  } catch (const core::ConfigError& e) {
    return e.what();
  }
  return "";
}

const FindingGroupResult& group(const FindingResult& f, const std::string& g) {
  for (const FindingGroupResult& r : f.groups) {
    if (r.group == g) return r;
  }
  FAIL("no group " << g);
  return f.groups.front();
}

}  // namespace

TEST_CASE("bootstrap_interval: constant samples give a point, resampling is seeded") {
  const std::vector<double> a{110, 110, 110};
  const std::vector<double> b{10, 10};
  core::RandomStream rng(1);
  const Interval d = bootstrap_interval(a, b, Estimator::kMean, rng);
  CHECK(d.low == 100.0);
  CHECK(d.high == 100.0);
  const std::vector<double> x{1, 2, 3, 4, 5, 6, 7, 8, 9, 10};
  core::RandomStream r1(7), r2(7), r3(8);
  const Interval m1 = bootstrap_interval(x, {}, Estimator::kMean, r1);
  const Interval m2 = bootstrap_interval(x, {}, Estimator::kMean, r2);
  const Interval m3 = bootstrap_interval(x, {}, Estimator::kMean, r3);
  CHECK(m1.low == m2.low);
  CHECK(m1.high == m2.high);
  CHECK((m1.low != m3.low || m1.high != m3.high));
  CHECK(m1.low < 5.5);
  CHECK(m1.high > 5.5);
  CHECK(m1.low > 3.0);
  CHECK(m1.high < 8.0);
  core::RandomStream r4(7);
  const Interval med = bootstrap_interval(x, {}, Estimator::kMedian, r4);
  CHECK(med.low <= 5.5);
  CHECK(med.high >= 5.5);
}

TEST_CASE("experiment files: errors name file:line and the key") {
  const StudyFixture f;
  const std::string file = f.dir.file("exp.yaml");
  // The header has 6 lines (with group_by); the body starts on line 7.
  struct Case {
    std::string body;
    std::string where;
    std::string what;
  };
  const std::vector<Case> cases{
      {"findings: []\nfrobnicate: 1\n", ":8:", "unknown key 'frobnicate'"},
      {"findings: []\n", ":1:", "nothing to evaluate"},
      {"findngs: []\n", ":7:10:", "findngs: unknown key 'findngs' (did you mean 'findings'?)"},
      {"calibration:\n  - name: t\n    batch: conf\n    statistic: points\n    mean_in: [1, 2]\n"
       "    ignore_belo: 3\n",
       ":12:18:",
       "calibration[0].ignore_belo: unknown key 'ignore_belo' (did you mean 'ignore_below'?)"},
      {"findings:\n  - id: F1\n    claim: c\n    checks:\n"
       "      - mean_in: {batch: conf, statistic: points, range: [1, 2], wher: {config: A}}\n",
       ":11:", "unknown key 'wher' (did you mean 'where'?)"},
      {"findings:\n  - id: F1\n    claim: c\n    checks:\n"
       "      - greater: {batch: conf, statistic: points, a: {config: A}, b: {config: B}, "
       "where: {config: A}}\n",
       ":11:", "unknown key 'where' (allowed: batch, statistic, ignore_below, above, a, b)"},
      {"calibration:\n  - name: t\n    batch: nope\n    statistic: points\n    mean_in: [1, 2]\n",
       ":9:", "unknown batch 'nope' (batches: conf, sweep)"},
      {"calibration:\n  - name: t\n    batch: conf\n    where: {speed: slow}\n"
       "    statistic: points\n    mean_in: [1, 2]\n",
       ":10:", "batch 'conf' has no axis 'speed' (axes: profile, config)"},
      {"calibration:\n  - name: t\n    batch: conf\n    where: {config: Z}\n"
       "    statistic: points\n    mean_in: [1, 2]\n",
       ":10:", "axis 'config' of batch 'conf' has no value 'Z' (values: A, B)"},
      {"calibration:\n  - name: t\n    batch: conf\n    statistic: pionts\n    mean_in: [1, 2]\n",
       ":10:", "unknown statistic 'pionts'"},
      {"calibration:\n  - name: t\n    batch: conf\n    statistic: points\n    groups: [fake]\n"
       "    mean_in: [1, 2]\n",
       ":11:", "unknown group 'fake' (values of 'profile': ideal, real)"},
      {"calibration:\n  - name: t\n    batch: conf\n    statistic: points\n    mean_in: [1, 2]\n"
       "    median_in: [1, 2]\n",
       ":8:", "give exactly one of mean_in"},
      {"calibration:\n  - name: t\n    batch: conf\n    statistic: points\n    mean_in: [3, 2]\n",
       ":11:", "low end is above its high end"},
      {"calibration:\n  - name: t\n    batch: conf\n    statistic: points\n    above: 1\n"
       "    mean_in: [1, 2]\n",
       ":11:", "only share_at_most and share_at_least take `above`"},
      {"calibration:\n  - name: t\n    batch: conf\n    where: {profile: ideal}\n"
       "    statistic: points\n    mean_in: [1, 2]\n",
       ":10:", "is the group_by axis"},
      {"findings:\n  - id: F1\n    claim: c\n    checks:\n"
       "      - greater: {batch: conf, statistic: points, a: {config: A}}\n",
       ":11:", "missing key 'b'"},
      {"findings:\n  - id: F1\n    claim: c\n    checks:\n"
       "      - greatest: {batch: conf, statistic: points}\n",
       ":11:", "unknown check 'greatest'"},
      {"findings:\n  - id: F1\n    claim: c\n    checks:\n"
       "      - share_at_most: {batch: conf, statistic: points, value: 2}\n",
       ":11:64:", "share_at_most.value: must be in [0, 1] (got 2)"},
      {"findings:\n  - id: F1\n    claim: c\n    checks:\n"
       "      - greater: {batch: conf, statistic: points, a: {config: A}, b: {config: A}}\n",
       ":11:", "'a' and 'b' select the same runs"},
      {"sweeps:\n  - name: s\n    batch: sweep\n    axis: speed\n    compare: config\n"
       "    statistic: points\n    baseline: warp\n",
       ":13:", "axis 'speed' of batch 'sweep' has no value 'warp'"},
      {"sweeps:\n  - name: s\n    batch: conf\n    axis: config\n    compare: profile\n"
       "    statistic: points\n",
       ":11:", "is the group_by axis"},
      {"tables:\n  - name: t\n    batch: conf\n    rows: config\n    statistics: [points, "
       "pionts]\n",
       ":11:", "unknown statistic 'pionts'"},
      {"tables:\n  - name: t\n    batch: conf\n    rows: config\n",
       ":8:", "missing key 'statistics'"},
      {"tables:\n  - name: t\n    batch: conf\n    rows: profile\n    statistics: [points]\n",
       ":10:", "is the group_by axis"},
      {"tables:\n  - name: t\n    batch: conf\n    rows: config\n    values: [A, Z]\n"
       "    statistics: [points]\n",
       ":11:", "axis 'config' of batch 'conf' has no value 'Z'"},
      {"tables:\n  - name: t\n    batch: sweep\n    rows: config\n    statistics: [points]\n",
       ":8:", "axis 'speed' of batch 'sweep' is neither the rows nor fixed"},
  };
  for (const Case& c : cases) {
    const std::string e = load_error(f, c.body);
    INFO(c.body, " -> ", e);
    CHECK(has(e, file + c.where));
    CHECK(has(e, c.what));
  }
  // A sweep must fix the batch's other axes.
  f.dir.write("sweep3.yaml",
              "name: s3\nmatrix:\n  speed: {slow: {}, fast: {}}\n  config: {A: {}, B: {}}\n"
              "  loss: {'0': {}, '20': {}}\n");
  f.dir.write("exp.yaml",
              "name: x\nbatches: {s3: sweep3.yaml}\nsweeps:\n  - name: s\n"
              "    batch: s3\n    axis: speed\n    compare: config\n"
              "    statistic: points\n");
  try {
    (void)load_experiment(file);
    FAIL("loaded");
  } catch (const core::ConfigError& e) {
    CHECK(has(e.what(), file + ":4:"));
    CHECK(has(e.what(), "axis 'loss' of batch 's3' is neither swept, compared nor fixed"));
  }
  // A scenario file that does not load: the experiment's line, then the scenario's error.
  f.dir.write("bad.yaml", "name: bad\nduration_s: -5\n");
  f.dir.write("exp.yaml", "name: x\nbatches:\n  bad: bad.yaml\nfindings: []\n");
  try {
    (void)load_experiment(file);
    FAIL("loaded");
  } catch (const core::ConfigError& e) {
    CHECK(has(e.what(), file + ":3:8: batches.bad: "));
    CHECK(has(e.what(), "bad.yaml:2:"));
    CHECK(has(e.what(), "duration_s"));
  }
  f.dir.write("exp.yaml", "name: x y\nbatches: {conf: conf.yaml}\n");
  try {
    (void)load_experiment(file);
    FAIL("loaded");
  } catch (const core::ConfigError& e) {
    CHECK(has(e.what(), file + ":1:7: name: "));
  }
}

TEST_CASE("experiment checks: greater, not_greater and difference_in per group") {
  const StudyFixture f;
  Experiment e;
  const ExperimentResult r = f.evaluate_body(
      "findings:\n"
      "  - id: F1\n"
      "    claim: A beats B\n"
      "    source: a test\n"
      "    checks:\n"
      "      - greater: {batch: conf, statistic: points, a: {config: A}, b: {config: B}}\n"
      "  - id: F2\n"
      "    claim: B is not better than A\n"
      "    checks:\n"
      "      - not_greater: {batch: conf, statistic: points, a: {config: B}, b: {config: A},\n"
      "                      margin: 10, margin_reason: a test}\n"
      "      - difference_in: {batch: conf, statistic: points, a: {config: A}, b: {config: B},\n"
      "                        range: [45, 55]}\n",
      e);
  REQUIRE(r.findings.size() == 2);
  const FindingResult& f1 = r.findings[0];
  REQUIRE(f1.groups.size() == 2);  // ideal, real
  const FindingGroupResult& ideal = group(f1, "ideal");
  CHECK(ideal.verdict == Verdict::kHolds);
  REQUIRE(ideal.checks.size() == 1);
  CHECK(ideal.checks[0].value == doctest::Approx(50.0));
  CHECK(ideal.checks[0].ci_low > 48.0);  // A - B is 50 in every run pair, +-1.5 by seed
  CHECK(ideal.checks[0].ci_high < 52.0);
  CHECK(ideal.checks[0].a.used == 4);
  CHECK(ideal.checks[0].b.used == 4);
  CHECK(ideal.checks[0].description == "points: config=A > config=B");
  const FindingGroupResult& real = group(f1, "real");
  CHECK(real.verdict == Verdict::kFails);  // equal means: not shown greater
  CHECK(real.failed == std::vector<int>{1});
  CHECK(real.checks[0].value == doctest::Approx(0.0));
  CHECK(real.checks[0].ci_low < 0.0);

  const FindingResult& f2 = r.findings[1];
  const FindingGroupResult& ideal2 = group(f2, "ideal");
  CHECK(ideal2.checks[0].holds());  // B - A: interval far below 0
  CHECK(ideal2.checks[1].holds());  // 50 in [45, 55]
  CHECK(ideal2.verdict == Verdict::kHolds);
  const FindingGroupResult& real2 = group(f2, "real");
  CHECK(real2.checks[0].holds());   // B not shown better than A
  CHECK(!real2.checks[1].holds());  // 0 not in [45, 55]
  CHECK(real2.verdict == Verdict::kFails);
  CHECK(real2.failed == std::vector<int>{2});

  const std::string text = to_text(r);
  CHECK(has(text, "ideal: reproduced"));
  CHECK(has(text, "real: not reproduced (check 2 failed)"));
  const std::string md = to_markdown(r);
  CHECK(has(md, "## Experiment tiny-study\n"));
  CHECK(has(md, "Reproduce: `llsfsim experiment " + f.dir.file("exp.yaml") + "`"));
  CHECK(has(md, "| F1 | A beats B | ideal: reproduced; real: not reproduced (check 1 failed) |"));
  CHECK(has(md, "#### F2: B is not better than A"));
  CHECK(has(md, "| conf | `conf.yaml` | 4 | 4 | 16 of 16 runs |"));
}

TEST_CASE("experiment targets: mean_in with ignore_below, median_in, shares, groups") {
  const StudyFixture f;
  Experiment e;
  const ExperimentResult r = f.evaluate_body(
      "calibration:\n"
      "  - name: First complex\n"
      "    source: thesis 5.3.3\n"
      "    batch: conf\n"
      "    where: {config: A}\n"
      "    groups: [ideal]\n"
      "    statistic: lock_wait_max_s\n"
      "    ignore_below: 0\n"
      "    mean_in: [600, 640]\n"
      "  - name: First complex too early\n"
      "    batch: conf\n"
      "    where: {config: A}\n"
      "    groups: [ideal]\n"
      "    statistic: lock_wait_max_s\n"
      "    ignore_below: 0\n"
      "    median_in: [0, 500]\n"
      "  - name: Storage runs empty\n"
      "    batch: conf\n"
      "    statistic: exploration_points\n"
      "    above: -0.5\n"
      "    share_at_most: 0.2\n"
      "  - name: Storage always lasts\n"
      "    batch: conf\n"
      "    statistic: exploration_points\n"
      "    above: -0.5\n"
      "    share_at_least: 0.1\n",
      e);
  REQUIRE(r.calibration.size() == 6);  // 1 + 1 + 2 groups + 2 groups
  const TargetResult& first = r.calibration[0];
  CHECK(first.group == "ideal");
  CHECK(first.verdict == Verdict::kHolds);
  CHECK(first.check.value == doctest::Approx(620.0));  // 600, 620, 640; the -1 left out
  CHECK(first.check.a.used == 3);
  CHECK(first.check.a.stored == 4);
  CHECK(first.check.a.expected == 4);
  CHECK(has(first.check.measured, "mean 620.0, 95 % CI ["));
  CHECK(has(first.check.measured, "n 3 of 4"));
  CHECK(first.check.ci_low >= 600.0);
  CHECK(first.check.ci_high <= 640.0);
  const TargetResult& median = r.calibration[1];
  CHECK(median.verdict == Verdict::kFails);
  CHECK(median.check.value == doctest::Approx(620.0));
  CHECK(has(median.check.measured, "median 620.0"));

  // exploration_points > -0.5 in one run of real (real/B seed 2) and none of ideal.
  const TargetResult& most_ideal = r.calibration[2];
  CHECK(most_ideal.group == "ideal");
  CHECK(most_ideal.check.value == 0.0);
  CHECK(most_ideal.verdict == Verdict::kHolds);
  CHECK(most_ideal.check.ci_low == 0.0);
  CHECK(most_ideal.check.ci_high == doctest::Approx(0.3244).epsilon(0.001));  // Wilson, 0 of 8
  const TargetResult& most_real = r.calibration[3];
  CHECK(most_real.check.value == doctest::Approx(0.125));  // 1 of 8 <= 0.2
  CHECK(most_real.verdict == Verdict::kHolds);
  CHECK(has(most_real.check.measured, "share 0.125 (1 of 8), Wilson 95 % CI [0.022, 0.471]"));
  CHECK(r.calibration[4].verdict == Verdict::kFails);  // ideal: 0 < 0.1
  CHECK(r.calibration[5].verdict == Verdict::kHolds);  // real: 0.125 >= 0.1

  const std::string md = to_markdown(r);
  CHECK(has(md, "| target | source | group | condition | measured | verdict |"));
  CHECK(has(md,
            "| First complex | thesis 5.3.3 | ideal | lock_wait_max_s: mean of config=A in "
            "[600, 640] (values below 0 left out) | mean 620.0, 95 % CI ["));
  CHECK(has(md, "| **met** |"));
  CHECK(has(md, "| **not met** |"));
}

TEST_CASE("experiment: an incomplete or missing batch is evaluated with what is stored") {
  const StudyFixture f;
  // Another store holding only seeds 1..2 of conf (a stopped batch), and no sweep batch.
  const std::string db = f.dir.file("partial.db");
  {
    StatsStore store(db);
    BatchKey key;
    key.kind = BatchKey::Kind::kBatch;
    key.scenario_file = f.dir.file("conf.yaml");
    key.scenario_name = "conf";
    key.scenario_hash = batch_identity_hash(key.scenario_file, load_scenario(key.scenario_file));
    key.runs_per_variant = 4;
    key.variants = 4;
    const std::int64_t b = store.open_batch(key);
    for (int seed = 1; seed <= 2; ++seed) {
      for (const std::string& v : kConfVariants) {
        RunResult r;
        r.variant = v;
        r.seed = static_cast<std::uint64_t>(seed);
        fill_conf(r);
        store.add_run(b, r);
      }
    }
    key.runs_per_variant = 2;  // the sweep file played with --runs 2
    key.scenario_file = f.dir.file("sweep.yaml");
    key.scenario_hash = batch_identity_hash(key.scenario_file, load_scenario(key.scenario_file));
    store.open_batch(key);
  }
  const Experiment e = load_experiment(f.experiment(
      "findings:\n  - id: F1\n    claim: A beats B\n    checks:\n"
      "      - greater: {batch: conf, statistic: points, a: {config: A}, b: {config: B}}\n"
      "      - mean_in: {batch: sweep, statistic: points, range: [0, 1000]}\n"
      "sweeps:\n  - {name: S, batch: sweep, axis: speed, compare: config, statistic: points}\n"));
  const StatsStore store(db);
  const ExperimentResult r = evaluate(e, store, StudyFixture::few_games());
  REQUIRE(r.batches.size() == 2);
  CHECK(r.batches[0].stored == 8);
  CHECK(r.batches[0].expected == 16);
  CHECK(r.batches[1].batch_id == 0);
  CHECK(r.batches[1].other_runs_per_variant == std::vector<int>{2});
  const FindingGroupResult& ideal = group(r.findings[0], "ideal");
  CHECK(ideal.checks[0].a.used == 2);
  CHECK(ideal.checks[0].a.expected == 4);
  CHECK(has(ideal.checks[0].measured, "n 2 (2 of 4 runs) vs 2 (2 of 4 runs)"));
  CHECK(ideal.checks[0].holds());
  CHECK(ideal.checks[1].outcome == CheckResult::Outcome::kNoData);
  CHECK(ideal.checks[1].measured == "no data: 0 of 27 runs stored");
  CHECK(ideal.verdict == Verdict::kNoData);
  const std::string text = to_text(r);
  CHECK(has(text, "8 of 16 runs, incomplete"));
  CHECK(has(text, "0 of 27 runs, not in the store (stored with --runs 2)"));
  CHECK(has(text, "ideal: no data"));
  REQUIRE(r.sweeps.size() == 1);
  REQUIRE(r.sweeps[0].rows.size() == 3);
  CHECK(!r.sweeps[0].rows[1].comparable);
  CHECK(!r.sweeps[0].rows[1].differs);
  CHECK(has(text, "    mid    -  -  -  -  (-; top two -)\n"));
}

TEST_CASE("experiment sweeps: rankings per row, flips against the baseline, top two") {
  const StudyFixture f;
  Experiment e;
  const ExperimentResult r = f.evaluate_body(
      "sweeps:\n"
      "  - name: Speed\n"
      "    source: beyond the thesis\n"
      "    batch: sweep\n"
      "    axis: speed\n"
      "    compare: config\n"
      "    statistic: points\n"
      "    baseline: mid\n",
      e);
  REQUIRE(r.sweeps.size() == 1);  // the sweep batch has no profile axis: one table
  const SweepResult& s = r.sweeps[0];
  CHECK(s.group.empty());
  CHECK(s.compare_values == std::vector<std::string>{"A", "B", "C"});
  REQUIRE(s.rows.size() == 3);
  CHECK(s.rows[0].value == "slow");
  CHECK(s.rows[0].ranking == "A > B > C");
  CHECK(!s.rows[0].differs);
  CHECK(s.rows[0].separated);  // 200 vs 150
  CHECK(s.rows[0].means[0] == doctest::Approx(200.0));
  CHECK(s.rows[0].n[0].used == 3);
  CHECK(s.rows[1].ranking == "A > B > C");
  // 101 vs 100 with a spread of +-10 by seed, but +1 on every seed: paired by seed, separated.
  CHECK(s.rows[1].separated);
  CHECK(s.rows[1].top->pairing == Pairing::kPaired);
  CHECK(s.rows[2].ranking == "B > A > C");
  CHECK(s.rows[2].differs);
  CHECK(s.rows[2].top_diff == doctest::Approx(80.0));
  const std::string md = to_markdown(r);
  CHECK(has(md,
            "| speed | A | B | C | ranking | vs baseline | top two |\n"
            "|---|---:|---:|---:|---|---|---|\n"
            "| slow | 200.0 (n 3) | 150.0 (n 3) | 20.0 (n 3) | A > B > C | same | separated: "));
  CHECK(has(md,
            "| mid | 101.0 (n 3) | 100.0 (n 3) | 20.0 (n 3) | A > B > C | baseline | separated: "
            "+1.00 [+1.00, +1.00] |"));
  CHECK(has(md, "| fast | 100.0 (n 3) | 180.0 (n 3) | 20.0 (n 3) | B > A > C | **differs** |"));
}

TEST_CASE("experiment tables: means per row and group, left-out values counted") {
  const StudyFixture f;
  Experiment e;
  const ExperimentResult r = f.evaluate_body(
      "tables:\n"
      "  - name: Why\n"
      "    source: the mechanisms\n"
      "    batch: conf\n"
      "    rows: config\n"
      "    values: [B, A]\n"
      "    statistics: [points, lock_wait_max_s]\n"
      "    ignore_below: 0\n",
      e);
  REQUIRE(r.tables.size() == 2);  // per profile
  const TableResult& ideal = r.tables[0];
  CHECK(ideal.group == "ideal");
  REQUIRE(ideal.rows.size() == 2);
  CHECK(ideal.rows[0].value == "B");
  CHECK(ideal.rows[0].runs == 4);
  CHECK(ideal.rows[0].means[0] == doctest::Approx(52.5));   // 51..54
  CHECK(ideal.rows[0].n[1] == 0);                           // lock_wait_max_s -1: left out
  CHECK(ideal.rows[1].means[0] == doctest::Approx(102.5));  // 101..104
  CHECK(ideal.rows[1].n[1] == 3);                           // seed 3 never waited
  CHECK(ideal.rows[1].means[1] == doctest::Approx(620.0));
  CHECK(r.tables[1].group == "real");
  CHECK(r.tables[1].rows[1].means[0] == doctest::Approx(62.5));
  const std::string md = to_markdown(r);
  CHECK(has(md, "#### Why (ideal)\n\nSource: the mechanisms\n\n"));
  CHECK(has(md,
            "| config | runs | points | lock_wait_max_s |\n|---|---:|---:|---:|\n"
            "| B | 4 | 52.5 | - |\n| A | 4 | 102.5 | 620.0 (n 3 of 4) |\n"));
  const std::string text = to_text(r);
  CHECK(has(text,
            "  Why [real]: Mean per run by `config` of batch `conf`, values below 0 left out.\n"));
  CHECK(has(text, "    A       4     62.5"));
}

TEST_CASE("experiment reports are deterministic and seeded per check") {
  const StudyFixture f;
  const std::string body =
      "findings:\n  - id: F1\n    claim: B waits longer\n    checks:\n"
      "      - greater: {batch: conf, statistic: lock_wait_s, a: {config: B}, b: {config: A}}\n"
      "sweeps:\n  - {name: Speed, batch: sweep, axis: speed, compare: config, "
      "statistic: points}\n";
  Experiment e1, e2;
  const ExperimentResult r1 = f.evaluate_body(body, e1);
  const ExperimentResult r2 = f.evaluate_body(body, e2);
  CHECK(to_markdown(r1) == to_markdown(r2));
  CHECK(to_text(r1) == to_text(r2));
  // Another seed draws other resamples.
  Experiment e6;
  const ExperimentResult r6 = f.evaluate_body(
      "findings:\n  - id: F1\n    claim: c\n    checks:\n"
      "      - greater: {batch: conf, statistic: lock_wait_s, a: {config: B}, b: {config: A}}\n",
      e6, false);
  const StatsStore store(f.db);
  EvaluateOptions o = StudyFixture::few_games();
  o.seed = 2;
  const ExperimentResult r3 = evaluate(e6, store, o);
  const CheckResult& c6 = r6.findings[0].groups[0].checks[0];
  const CheckResult& c3 = r3.findings[0].groups[0].checks[0];
  CHECK(c6.value == c3.value);
  CHECK(c6.a.used == 8);
  CHECK((c6.ci_low != c3.ci_low || c6.ci_high != c3.ci_high));
  CHECK(c6.ci_low == evaluate(e6, store).findings[0].groups[0].checks[0].ci_low);
  // A check's interval does not depend on the checks before it.
  Experiment e4;
  const ExperimentResult r4 = f.evaluate_body(
      "findings:\n  - id: F0\n    claim: first\n    checks:\n"
      "      - greater: {batch: conf, statistic: points, a: {config: B}, b: {config: A}}\n" +
          body.substr(std::string("findings:\n").size()),
      e4);
  const CheckResult& c4 = group(r4.findings[1], "real").checks[0];
  const CheckResult& c1 = group(r1.findings[0], "real").checks[0];
  CHECK(c4.ci_low == c1.ci_low);
  CHECK(c4.ci_high == c1.ci_high);
  // Without group_by: one evaluation over both profiles.
  Experiment e5;
  const ExperimentResult r5 = f.evaluate_body(body, e5, false);
  REQUIRE(r5.findings[0].groups.size() == 1);
  CHECK(r5.findings[0].groups[0].group.empty());
  CHECK(r5.findings[0].groups[0].checks[0].a.used == 8);
}

TEST_CASE("replace_between_markers keeps everything outside the markers byte for byte") {
  const std::string before = "# Validation\r\n\nIntro.\n<!-- experiment tiny begin -->\n";
  const std::string after = "<!-- experiment tiny end -->\nTail, no newline";
  const std::string doc = before + "old\nreport\n" + after;
  const std::string out = replace_between_markers(doc, "tiny", "## new\n");
  CHECK(out == before + "## new\n" + after);
  CHECK(replace_between_markers(out, "tiny", "## new\n") == out);  // idempotent
  CHECK(replace_between_markers(doc, "tiny", "x") == before + "x\n" + after);
  CHECK(replace_between_markers(before + after, "tiny", "y\n") == before + "y\n" + after);
  // Other experiments' sections are left alone.
  const std::string two = doc +
                          "\n<!-- experiment other begin -->\nkeep\n"
                          "<!-- experiment other end -->\n";
  CHECK(replace_between_markers(two, "tiny", "z\n") ==
        before + "z\n" + after +
            "\n<!-- experiment other begin -->\nkeep\n"
            "<!-- experiment other end -->\n");
  CHECK_THROWS_WITH_AS(replace_between_markers("no markers\n", "tiny", ""),
                       "no line '<!-- experiment tiny begin -->'", std::invalid_argument);
  CHECK_THROWS_AS(replace_between_markers(before, "tiny", ""), std::invalid_argument);
  CHECK_THROWS_AS(replace_between_markers(after + "\n" + before, "tiny", ""),
                  std::invalid_argument);
  CHECK_THROWS_AS(replace_between_markers(doc + "\n" + doc, "tiny", ""), std::invalid_argument);
  // A marker inside a line does not count.
  CHECK_THROWS_AS(
      replace_between_markers("see <!-- experiment tiny begin --> here\n" + after, "tiny", ""),
      std::invalid_argument);
}

TEST_CASE("experiment: no better, no worse and same need a margin and its reason") {
  const StudyFixture f;
  const std::string file = f.dir.file("exp.yaml");
  struct Case {
    const char* check;
    const char* what;
  };
  const std::vector<Case> cases{
      {"not_greater: {batch: conf, statistic: points, a: {config: A}, b: {config: B}}",
       "missing key 'margin' (the difference, in the statistic's unit, that still counts"},
      {"equivalent: {batch: conf, statistic: points, a: {config: A}, b: {config: B}, margin: 0, "
       "margin_reason: r}",
       "margin: must be a number above 0"},
      {"not_less: {batch: conf, statistic: points, a: {config: A}, b: {config: B}, margin: 5}",
       "missing key 'margin_reason' (why this margin"},
      {"not_less: {batch: conf, statistic: points, a: {config: A}, b: {config: B}, margin: 5, "
       "margin_reason: ''}",
       "margin_reason: must not be empty"},
      {"greater: {batch: conf, statistic: points, a: {config: A}, b: {config: B}, margin: 5}",
       "unknown key 'margin'"},
  };
  for (const Case& c : cases) {
    const std::string e =
        load_error(f, std::string("findings:\n  - id: F\n    claim: c\n    checks:\n      - ") +
                          c.check + "\n");
    INFO(c.check, " -> ", e);
    CHECK(has(e, file + ":"));
    CHECK(has(e, c.what));
  }
}

TEST_CASE("experiment: equivalence within a margin, both one-sided forms, paired by seed") {
  const StudyFixture f;
  Experiment e;
  // real: A - B per seed -3, -1, +1, +3 (mean 0); ideal: A - B = +50 on every seed.
  const ExperimentResult r = f.evaluate_body(
      "findings:\n"
      "  - id: S\n"
      "    claim: A and B score the same\n"
      "    checks:\n"
      "      - equivalent: {batch: conf, statistic: points, a: {config: A}, b: {config: B},\n"
      "                     margin: 10, margin_reason: one delivery}\n"
      "      - equivalent: {batch: conf, statistic: points, a: {config: A}, b: {config: B},\n"
      "                     margin: 1, margin_reason: too strict}\n"
      "      - not_less: {batch: conf, statistic: points, a: {config: A}, b: {config: B},\n"
      "                   margin: 10, margin_reason: one delivery}\n"
      "      - not_greater: {batch: conf, statistic: points, a: {config: A}, b: {config: B},\n"
      "                      margin: 10, margin_reason: one delivery}\n",
      e);
  const FindingGroupResult& real = group(r.findings[0], "real");
  REQUIRE(real.checks.size() == 4);
  CHECK(real.checks[0].holds());
  CHECK(!real.checks[1].holds());
  CHECK(real.checks[2].holds());
  CHECK(real.checks[3].holds());
  REQUIRE(real.checks[0].comparison);
  CHECK(real.checks[0].comparison->pairing == Pairing::kPaired);
  CHECK(real.checks[0].comparison->pairs == 4);
  CHECK(real.checks[0].ci_low == real.checks[0].comparison->ci_tost.low);  // the 90 % interval
  CHECK(has(real.checks[0].description,
            "points: config=A = config=B within ±10 (margin: one delivery)"));
  CHECK(has(real.checks[0].measured, "difference 0, 90 % CI ["));
  CHECK(has(real.checks[0].measured, "paired by seed (4 pairs)"));
  CHECK(has(real.checks[0].measured, "smallest detectable "));
  CHECK(real.failed == std::vector<int>{2});
  const FindingGroupResult& ideal = group(r.findings[0], "ideal");
  CHECK(!ideal.checks[0].holds());  // +50 is not within 10
  CHECK(ideal.checks[2].holds());   // A is not worse than B
  CHECK(!ideal.checks[3].holds());  // but it is better
  CHECK(ideal.failed == std::vector<int>{1, 2, 4});
}

TEST_CASE("experiment: a comparison pools an axis pairwise: the key is the seed and the axis") {
  const StudyFixture f;
  Experiment e;
  // Without group_by: A against B over both profiles, each seed once per profile.
  const ExperimentResult r = f.evaluate_body(
      "findings:\n  - id: F\n    claim: c\n    checks:\n"
      "      - greater: {batch: conf, statistic: points, a: {config: A}, b: {config: B}}\n",
      e, false);
  const CheckResult& c = r.findings[0].groups[0].checks[0];
  REQUIRE(c.comparison);
  CHECK(c.comparison->pairing == Pairing::kPaired);
  CHECK(c.comparison->pairs == 8);
  CHECK(c.comparison->unmatched == 0);
}

TEST_CASE("experiment: too few games give the numbers and no verdict") {
  const StudyFixture f;
  Experiment e;
  // The default minimum (10 a side) against the fixture's 4 seeds: A clearly beats B in ideal,
  // yet no verdict; the calibration target and the sweep likewise.
  const ExperimentResult r = f.evaluate_body(
      "calibration:\n"
      "  - {name: Pace, batch: conf, where: {config: A}, groups: [ideal], statistic: points,\n"
      "     mean_in: [0, 1000]}\n"
      "findings:\n  - id: F1\n    claim: A beats B\n    checks:\n"
      "      - greater: {batch: conf, statistic: points, a: {config: A}, b: {config: B}}\n"
      "sweeps:\n  - {name: Speed, batch: sweep, axis: speed, compare: config, "
      "statistic: points}\n",
      e, true, EvaluateOptions{});
  const FindingGroupResult& ideal = group(r.findings[0], "ideal");
  CHECK(ideal.checks[0].outcome == CheckResult::Outcome::kTooFew);
  CHECK(ideal.verdict == Verdict::kTooFew);
  CHECK(ideal.checks[0].value == doctest::Approx(50.0));
  CHECK(has(ideal.checks[0].measured, "difference +50.0, 95 % CI [+50.0, +50.0]"));
  CHECK(has(ideal.checks[0].measured, "too few games for a verdict (4, needs 10)"));
  REQUIRE(r.calibration.size() == 1);
  CHECK(r.calibration[0].verdict == Verdict::kTooFew);
  CHECK(has(r.calibration[0].check.measured, "too few games for a verdict (4, needs 10)"));
  for (const SweepRow& row : r.sweeps[0].rows) CHECK(!row.separated);
  const std::string text = to_text(r);
  CHECK(has(text, "ideal: no verdict: too few games (at least 10 a side)"));
  CHECK(!has(text, "reproduced"));
  CHECK(has(text, "too few games (3): "));
  CHECK(has(to_markdown(r), "| **too few games** |"));
}

TEST_CASE("experiment sweeps: Holm's correction over the rows, named with the count") {
  const StudyFixture f;
  Experiment e;
  const ExperimentResult r = f.evaluate_body(
      "sweeps:\n  - {name: Speed, batch: sweep, axis: speed, compare: config, "
      "statistic: points}\n",
      e);
  const SweepResult& s = r.sweeps[0];
  CHECK(s.comparisons == 3);
  REQUIRE(s.rows[1].top);
  CHECK(s.rows[1].top->pairing == Pairing::kPaired);
  // mid: A 101 against B 100 on every seed: a constant +1, every resample above 0: p = 0,
  // below Holm's first bound 5 % / 3.
  CHECK(s.rows[1].top->p_value == 0.0);
  CHECK(s.rows[1].separated);
  CHECK(has(to_text(r), "top two paired by seed, Holm's correction over 3 comparisons"));
}

TEST_CASE("experiment --until: each comparison check is decided either way, or left open") {
  const StudyFixture f;
  Experiment e = load_experiment(f.experiment(
      "findings:\n"
      "  - id: U\n"
      "    claim: mixed\n"
      "    checks:\n"
      "      - greater: {batch: conf, statistic: points, a: {config: A}, b: {config: B}}\n"
      "      - greater: {batch: conf, statistic: points, a: {config: B}, b: {config: A}}\n"
      "      - not_greater: {batch: conf, statistic: points, a: {config: A}, b: {config: B},\n"
      "                      margin: 10, margin_reason: one delivery}\n"
      "      - not_less: {batch: conf, statistic: points, a: {config: A}, b: {config: B},\n"
      "                   margin: 10, margin_reason: one delivery}\n"
      "      - equivalent: {batch: conf, statistic: points, a: {config: A}, b: {config: B},\n"
      "                     margin: 1, margin_reason: strict}\n"
      "      - mean_in: {batch: conf, statistic: points, range: [0, 1000]}\n"
      "  - id: V\n"
      "    claim: only a mean\n"
      "    checks:\n"
      "      - mean_in: {batch: conf, statistic: points, range: [0, 1000]}\n"));
  const StatsStore store(f.db);
  SequentialPlan plan;
  plan.max_runs = 10;  // the fixture holds 4 seeds: the look takes what there is
  plan.looks = 1;
  const std::vector<CheckLook> looks =
      look_at_findings(e, store, StudyFixture::few_games(), {0, 1}, plan, 1);
  // Per group (ideal, real) the five comparison checks; the mean_in and finding V have none.
  REQUIRE(looks.size() == 10);
  using D = CheckLook::Decision;
  auto decision = [&](const std::string& g, int check) {
    for (const CheckLook& l : looks) {
      if (l.group == g && l.check == check) return l.decision;
    }
    FAIL("no look at check " << check << " in " << g);
    return D::kOpen;
  };
  // ideal: A - B = +50 on every seed.
  CHECK(decision("ideal", 1) == D::kHolds);
  CHECK(decision("ideal", 2) == D::kFails);
  CHECK(decision("ideal", 3) == D::kFails);  // better by far more than 10
  CHECK(decision("ideal", 4) == D::kHolds);
  CHECK(decision("ideal", 5) == D::kFails);  // wholly beyond +1
  // real: A - B = -3, -1, +1, +3: neither greater, within 10 both ways, not provably within 1.
  CHECK(decision("real", 1) == D::kOpen);
  CHECK(decision("real", 2) == D::kOpen);
  CHECK(decision("real", 3) == D::kHolds);
  CHECK(decision("real", 4) == D::kHolds);
  CHECK(decision("real", 5) == D::kOpen);
  for (const CheckLook& l : looks) {
    REQUIRE(l.comparison);
    CHECK(l.comparison->alpha == doctest::Approx(0.05));
    CHECK(l.comparison->pairs == 4);
  }
  // With 5 looks the level is 1 %: the same data give the same decisions here, each at 1 %.
  plan.looks = 5;
  const std::vector<CheckLook> first =
      look_at_findings(e, store, StudyFixture::few_games(), {0}, plan, 1);  // 2 seeds of 10
  REQUIRE(first.size() == 10);
  CHECK(first.front().comparison->alpha == doctest::Approx(0.01));
  CHECK(first.front().comparison->pairs == 2);
  CHECK(to_string(D::kOpen) == "open");
  CHECK(is_sequential(Check::Kind::kEquivalent));
  CHECK(!is_sequential(Check::Kind::kDifferenceIn));
}
