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
