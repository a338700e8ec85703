// SPDX-License-Identifier: MIT
// `llsfsim experiment` end to end: a tiny experiment (2 short one-robot variants x 3 seeds)
// played into a store, evaluated, resumed, reported from the store only, written to markdown
// and into a marked section of a file; bad input; Ctrl-C.
#include <doctest/doctest.h>

#include <atomic>
#include <chrono>
#include <csignal>
#include <exception>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <thread>
#include <vector>

#include "app/cli_fixture.h"
#include "batch_progress.h"
#include "llsf/app/cli.h"
#include "llsf/study/stats_store.h"
#include "support/temp_dir.h"

namespace {

namespace fs = std::filesystem;

using llsf::test::has;
using llsf::test::llsfsim;
using llsf::test::Run;
using llsf::test::TempDir;

/// tiny.yaml: one robot with the 2013 team agent, 60 s of production, roles P3 or P1P2.
void write_scenario(const TempDir& dir, const std::string& seeds = "[1, 2, 3]") {
  const std::string agents = std::string(LLSF_SOURCE_DIR) + "/clips/agents";
  dir.write("tiny.yaml",
            "name: tiny\n"
            "seeds: " +
                seeds +
                "\n"
                "start: production\n"
                "duration_s: 60\n"
                "robots:\n"
                "  count: 1\n"
                "  agent: [" +
                agents + "/common, " + agents +
                "/llsf2013]\n"
                "  config: {roles: [P3], recycle: never}\n"
                "matrix:\n"
                "  config:\n"
                "    P3: {}\n"
                "    P1P2: {robots.config.roles: [P1P2]}\n");
}

/// exp.yaml: a target (every game lasts 60 s), a finding that would be reproduced (equal game
/// times) and one that would not (60 s is not longer than 60 s): with three seeds a variant, too
/// few games for any verdict (docs/statistics.md), so the report prints the numbers only.
void write_experiment(const TempDir& dir) {
  dir.write("exp.yaml",
            "name: tiny-exp\n"
            "description: Two one-robot variants, three seeds.\n"
            "batches:\n"
            "  tiny: tiny.yaml\n"
            "calibration:\n"
            "  - name: Game length\n"
            "    source: the scenario\n"
            "    batch: tiny\n"
            "    statistic: game_time_s\n"
            "    mean_in: [59.5, 60.5]\n"
            "findings:\n"
            "  - id: F1\n"
            "    claim: P3 and P1P2 play equally long\n"
            "    checks:\n"
            "      - difference_in: {batch: tiny, statistic: game_time_s, a: {config: P3},\n"
            "                        b: {config: P1P2}, range: [-0.01, 0.01]}\n"
            "      - not_greater: {batch: tiny, statistic: game_time_s, a: {config: P3},\n"
            "                      b: {config: P1P2}, margin: 1, margin_reason: one second}\n"
            "  - id: F2\n"
            "    claim: P3 plays longer than P1P2\n"
            "    checks:\n"
            "      - greater: {batch: tiny, statistic: game_time_s, a: {config: P3},\n"
            "                  b: {config: P1P2}}\n");
}

std::string slurp(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>()};
}

}  // namespace

TEST_CASE("llsfsim experiment plays its batches, evaluates, resumes and reports from the store") {
  const TempDir dir;
  write_scenario(dir);
  write_experiment(dir);
  const std::string exp = dir.file("exp.yaml");
  const std::string db = dir.file("exp.db");

  Run r = llsfsim(
      {"experiment", exp, "--db", db, "--jobs", "2", "--no-record", "--out", dir.file("one.md")});
  INFO(r.out, r.err);
  CHECK(r.code == llsf::app::kExitOk);
  CHECK(has(r.err, "[6/6] "));
  CHECK(has(r.out, "batch      tiny (" + dir.file("tiny.yaml") + ") #1 in " + db +
                       ": 6 runs, 6 played, 0 stored before"));
  CHECK(has(r.out, "experiment tiny-exp (" + exp + ")"));
  CHECK(has(r.out, "  too few games Game length\n"));
  CHECK(has(r.out,
            "  F1  P3 and P1P2 play equally long\n"
            "    all: no verdict: too few games (at least 10 a side)\n"));
  CHECK(has(r.out,
            "  F2  P3 plays longer than P1P2\n"
            "    all: no verdict: too few games (at least 10 a side)\n"));
  CHECK(has(r.out,
            "difference 0, 95 % CI [0, 0], paired by seed (3 pairs); n 3 vs 3; too few "
            "games for a verdict (3, needs 10)"));
  CHECK(!has(r.out, "reproduced"));
  CHECK(has(r.out, "6 of 6 runs"));
  CHECK(!fs::exists(dir.file("exp-recordings")));
  const std::string md = slurp(dir.file("one.md"));
  CHECK(md.rfind("## Experiment tiny-exp\n\nTwo one-robot variants, three seeds.\n\n", 0) == 0);
  CHECK(has(md, "Reproduce: `llsfsim experiment " + exp + "`"));
  CHECK(has(md, "| tiny | `tiny.yaml` | 2 | 3 | 6 of 6 runs |"));
  CHECK(has(md,
            "| Game length | the scenario | all | game_time_s: mean in [59.5, 60.5] | mean "
            "60.0, 95 % CI [60.0, 60.0]; n 6; too few games for a verdict (6, needs 10) | **too "
            "few games** |"));
  CHECK(has(md,
            "| F2 | P3 plays longer than P1P2 | no verdict: too few games (at least 10 a side) |"));
  {
    const llsf::study::StatsStore store(db);
    CHECK(store.count_rows("runs") == 6);
    CHECK(!store.batch(1)->finished.empty());
  }

  // Again: nothing is played; the report is the same byte for byte.
  r = llsfsim({"experiment", exp, "--db", db, "--no-record", "--out", dir.file("two.md")});
  CHECK(r.code == llsf::app::kExitOk);
  CHECK(has(r.out, "6 runs, 0 played, 6 stored before"));
  CHECK(slurp(dir.file("two.md")) == md);

  // --report-only plays nothing, and --update writes the report between the markers only.
  const std::string head = "# Validation\n\nSome text.\n<!-- experiment tiny-exp begin -->\n";
  const std::string tail = "<!-- experiment tiny-exp end -->\n\nMore text.\n";
  dir.write("doc.md", head + "stale\n" + tail);
  r = llsfsim(
      {"experiment", exp, "--db", db, "--report-only", "--update", dir.file("doc.md"), "-q"});
  CHECK(r.code == llsf::app::kExitOk);
  CHECK(r.out.empty());
  CHECK(r.err.empty());
  CHECK(slurp(dir.file("doc.md")) == head + md + tail);

  // --report-only with another --runs: that batch is not stored; the report says so.
  r = llsfsim({"experiment", exp, "--db", db, "--report-only", "--runs", "2"});
  CHECK(r.code == llsf::app::kExitOk);
  CHECK(has(r.out, "0 of 4 runs, not in the store (stored with --runs 3)"));
  CHECK(has(r.out, "all: no data"));
  CHECK(has(r.err, "batch tiny holds 0 of 4 runs; `llsfsim experiment " + exp +
                       " --runs 2` plays the missing ones"));
  CHECK(llsf::study::StatsStore(db).count_rows("runs") == 6);
}

TEST_CASE("llsfsim experiment: bad input exits 2 before anything is played") {
  const TempDir dir;
  write_scenario(dir);
  write_experiment(dir);
  const std::string exp = dir.file("exp.yaml");
  const std::string db = dir.file("bad.db");

  // An unknown axis value names the experiment file's line.
  std::string text = slurp(exp);
  text.replace(text.find("a: {config: P3},\n                  b:"), 16, "a: {config: P4},");
  dir.write("typo.yaml", text);
  Run r = llsfsim({"experiment", dir.file("typo.yaml"), "--db", db});
  CHECK(r.code == llsf::app::kExitBadInput);
  CHECK(has(r.err, dir.file("typo.yaml") + ":22:"));
  CHECK(has(r.err, "axis 'config' of batch 'tiny' has no value 'P4' (values: P3, P1P2)"));
  CHECK(!fs::exists(db));

  // --update into a file without the markers: refused before playing, the file untouched.
  dir.write("plain.md", "no markers\n");
  r = llsfsim({"experiment", exp, "--db", db, "--update", dir.file("plain.md")});
  CHECK(r.code == llsf::app::kExitBadInput);
  CHECK(has(r.err, "no line '<!-- experiment tiny-exp begin -->'"));
  CHECK(slurp(dir.file("plain.md")) == "no markers\n");
  CHECK(!fs::exists(db));

  // --report-only without a store; --runs over the budget; options that exclude each other.
  r = llsfsim({"experiment", exp, "--db", db, "--report-only"});
  CHECK(r.code == llsf::app::kExitBadInput);
  CHECK(has(r.err, "no statistics store"));
  r = llsfsim({"experiment", exp, "--db", db, "--runs", "100001"});
  CHECK(r.code == llsf::app::kExitBadInput);
  CHECK(has(r.err, "at most 100000 seeds per variant"));
  CHECK(llsfsim({"experiment", exp, "--report-only", "--jobs", "2"}).code ==
        llsf::app::kExitBadInput);
  CHECK(llsfsim({"experiment", dir.file("missing.yaml")}).code == llsf::app::kExitBadInput);
  CHECK(!fs::exists(db));

  r = llsfsim({"experiment", "--help"});
  CHECK(r.code == llsf::app::kExitOk);
  CHECK(has(r.out, "--report-only"));
  CHECK(has(r.out, "130 interrupted"));
  CHECK(has(llsfsim({"--help"}).out, "experiment"));
}

// The first Ctrl-C: no new game, the running ones stored, exit 130; the next call plays the rest.
extern "C" void ignore_sigint(int) {}

TEST_CASE("llsfsim experiment: Ctrl-C keeps the stored runs and exits 130") {
  const TempDir dir;
  write_scenario(dir, "{first: 1, count: 30}");
  write_experiment(dir);
  const std::string db = dir.file("int.db");
  // Should the signal come after the command restored the handler, it must not end the tests.
  const auto old = std::signal(SIGINT, ignore_sigint);
  std::atomic<bool> done{false};
  std::thread ctrl_c([&] {
    while (!done) {
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
      if (!fs::exists(db)) continue;
      try {
        if (llsf::study::StatsStore(db).count_rows("runs") < 1) continue;
      } catch (const std::exception&) {
        continue;  // the command is still creating the store
      }
      std::raise(SIGINT);  // to this thread; the handler sets the command's flag
      return;
    }
  });
  const Run r =
      llsfsim({"experiment", dir.file("exp.yaml"), "--db", db, "--jobs", "1", "--no-record"});
  done = true;
  ctrl_c.join();
  std::signal(SIGINT, old);
  INFO(r.out, r.err);
  CHECK(r.code == llsf::app::kExitInterrupted);
  CHECK(has(r.err, "llsfsim experiment: interrupted"));
  CHECK(has(r.out, "result     interrupted"));
  CHECK(!has(r.out, "findings"));
  const std::int64_t stored = llsf::study::StatsStore(db).count_rows("runs");
  CHECK(stored >= 1);
  CHECK(stored < 60);
}

namespace {

/// until.yaml: tiny.yaml (P3 and P1P2 play equally long: a `greater` between them is never
/// separated) and len.yaml (30 s against 20 s games: separated at the first look with enough
/// seeds), both at 30 s or less so that 80 games stay quick.
void write_until_experiment(const TempDir& dir) {
  write_scenario(dir);
  std::string tiny = slurp(dir.file("tiny.yaml"));
  tiny.replace(tiny.find("duration_s: 60"), 14, "duration_s: 30");
  dir.write("tiny.yaml", tiny);
  std::string len = tiny;
  len.replace(len.find("matrix:"), std::string::npos,
              "matrix:\n"
              "  length:\n"
              "    long: {}\n"
              "    short: {duration_s: 20}\n");
  dir.write("len.yaml", len);
  dir.write("until.yaml",
            "name: until-exp\n"
            "description: Two small batches played until the answer is known.\n"
            "batches:\n"
            "  tiny: tiny.yaml\n"
            "  len: len.yaml\n"
            "findings:\n"
            "  - id: F1\n"
            "    claim: Longer games last longer\n"
            "    checks:\n"
            "      - greater: {batch: len, statistic: game_time_s, a: {length: long},\n"
            "                  b: {length: short}}\n"
            "      - mean_in: {batch: len, statistic: game_time_s, where: {length: short},\n"
            "                  range: [19.5, 20.5]}\n"
            "  - id: F2\n"
            "    claim: P3 plays longer than P1P2\n"
            "    checks:\n"
            "      - greater: {batch: tiny, statistic: game_time_s, a: {config: P3},\n"
            "                  b: {config: P1P2}}\n"
            "  - id: F3\n"
            "    claim: Games last 30 s\n"
            "    checks:\n"
            "      - mean_in: {batch: tiny, statistic: game_time_s, range: [29.5, 30.5]}\n");
}

}  // namespace

TEST_CASE("llsfsim experiment --until plays in rounds until the findings are decided") {
  const TempDir dir;
  write_until_experiment(dir);
  const std::string exp = dir.file("until.yaml");
  const std::string db = dir.file("until.db");

  // F1 separates at the first look (10 of at most 20 seeds): the batches stop there.
  Run r = llsfsim({"experiment", exp, "--db", db, "--no-record", "--jobs", "2", "--until", "F1",
                   "--max-runs", "20", "--looks", "2", "--out", dir.file("f1.md")});
  INFO(r.out, r.err);
  CHECK(r.code == llsf::app::kExitOk);
  CHECK(has(r.out,
            "until      F1: at most 20 seeds a variant, looks after 10, 20 seeds; each "
            "comparison check at 2.5 % a look (5 % in all per check: Bonferroni over the 2 "
            "looks; not corrected over the checks)"));
  CHECK(has(r.out,
            "look 1/2   10 seeds, 1 comparison checks, 0 open:\n"
            "  F1 check 1 (all): +10.00 [+10.00, +10.00] (97.5 % interval, paired by seed): "
            "holds\n"));
  CHECK(!has(r.out, "look 2/2"));
  CHECK(has(r.out, "finding    F1 decided after 10 seeds (check 1 holds)\n"));
  // The report covers what was played; the non-comparison check is evaluated on it.
  CHECK(has(r.out, "mean 20.0, 95 % CI [20.0, 20.0]; n 10 (10 of 20 runs)"));
  CHECK(has(r.out, "  F1  Longer games last longer\n    all: reproduced\n"));
  CHECK(has(slurp(dir.file("f1.md")),
            "Reproduce: `llsfsim experiment " + exp + " --until F1 --max-runs 20 --looks 2`"));
  CHECK(llsf::study::StatsStore(db).count_rows("runs") == 40);  // 2 batches x 2 variants x 10

  // Every finding: F1 is decided again at the first look, F2's equal game times never separate
  // (the 10 seeds stored are not played again), F3 has no comparison to look at.
  r = llsfsim({"experiment", exp, "--db", db, "--no-record", "--jobs", "2", "--until", "--max-runs",
               "20", "--looks", "2"});
  INFO(r.out, r.err);
  CHECK(r.code == llsf::app::kExitOk);
  CHECK(has(r.out, "until      F1, F2: at most 20 seeds"));
  CHECK(has(r.out, "0 played, 20 stored before"));
  CHECK(has(r.out,
            "look 1/2   10 seeds, 2 comparison checks, 1 open:\n"
            "  F1 check 1 (all): +10.00 [+10.00, +10.00] (97.5 % interval, paired by seed): "
            "holds\n"
            "  F2 check 1 (all): +0.00 [+0.00, +0.00] (97.5 % interval, paired by seed): open\n"));
  CHECK(has(r.out,
            "look 2/2   20 seeds, 2 comparison checks, 1 open:\n"
            "  F1 check 1 (all): holds since 10 seeds\n"
            "  F2 check 1 (all): +0.00 [+0.00, +0.00] (97.5 % interval, paired by seed): open\n"));
  CHECK(has(r.out, "finding    F1 decided after 10 seeds (check 1 holds)\n"));
  CHECK(has(r.out, "finding    F2 undecided after 20 seeds (check 1 open)\n"));
  CHECK(has(r.out, "n 20 vs 20"));
  CHECK(llsf::study::StatsStore(db).count_rows("runs") == 80);

  // Bad input: named, exit 2, nothing played.
  const std::string bad_db = dir.file("bad.db");
  auto bad = [&](std::vector<std::string> extra, const std::string& what) {
    std::vector<std::string> a{"experiment", exp, "--db", bad_db, "--no-record"};
    a.insert(a.end(), extra.begin(), extra.end());
    const Run b = llsfsim(a);
    INFO(b.out, b.err);
    CHECK(b.code == llsf::app::kExitBadInput);
    CHECK(has(b.err, what));
  };
  bad({"--until"}, "--until needs --max-runs N");
  bad({"--until", "F9", "--max-runs", "20"},
      "--until: the experiment has no finding 'F9' (findings: F1, F2, F3)");
  bad({"--until", "F1,F3", "--max-runs", "20"},
      "--until: finding F3 has no greater, not_greater, not_less or equivalent check");
  bad({"--until", "--max-runs", "5"}, "--max-runs must be at least 10");
  bad({"--until", "--max-runs", "20", "--runs", "3"}, "excludes");
  CHECK(!fs::exists(bad_db));
  bad({"--until", "--max-runs", "20", "--report-only"}, "excludes");
  bad({"--max-runs", "20"}, "--max-runs requires --until");
  CHECK(!fs::exists(bad_db));
  const Run help = llsfsim({"experiment", "--help"});
  CHECK(has(help.out, "--until [ID,...]"));
  CHECK(has(help.out, "--max-runs"));
}

TEST_CASE("llsfsim experiment --until: Ctrl-C keeps the stored runs, the next call resumes") {
  const TempDir dir;
  write_until_experiment(dir);
  const std::string db = dir.file("int.db");
  const std::vector<std::string> args{"experiment",
                                      dir.file("until.yaml"),
                                      "--db",
                                      db,
                                      "--jobs",
                                      "1",
                                      "--no-record",
                                      "--until",
                                      "F1",
                                      "--max-runs",
                                      "20",
                                      "--looks",
                                      "2"};
  const auto old = std::signal(SIGINT, ignore_sigint);
  std::atomic<bool> done{false};
  std::thread ctrl_c([&] {
    while (!done) {
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
      if (!fs::exists(db)) continue;
      try {
        if (llsf::study::StatsStore(db).count_rows("runs") < 1) continue;
      } catch (const std::exception&) {
        continue;
      }
      std::raise(SIGINT);
      return;
    }
  });
  Run r = llsfsim(args);
  done = true;
  ctrl_c.join();
  std::signal(SIGINT, old);
  INFO(r.out, r.err);
  CHECK(r.code == llsf::app::kExitInterrupted);
  CHECK(has(r.out, "result     interrupted"));
  CHECK(!has(r.out, "finding    F1"));
  const std::int64_t stored = llsf::study::StatsStore(db).count_rows("runs");
  CHECK(stored >= 1);
  CHECK(stored < 40);
  // The same command plays the rest of the first round and comes to the answer.
  r = llsfsim(args);
  INFO(r.out, r.err);
  CHECK(r.code == llsf::app::kExitOk);
  CHECK(has(r.out, "finding    F1 decided after 10 seeds (check 1 holds)\n"));
  CHECK(llsf::study::StatsStore(db).count_rows("runs") == 40);
}
