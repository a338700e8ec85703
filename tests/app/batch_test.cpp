// SPDX-License-Identifier: MIT
// `llsfsim batch` and `llsfsim run --db`: runs stored, resume, --jobs 1 vs 2 give the same
// results, interruption, bad input.
#include <doctest/doctest.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <string>
#include <tuple>
#include <vector>

#include "app/cli_fixture.h"
#include "llsf/app/cli.h"
#include "llsf/study/batch.h"
#include "llsf/study/scenario.h"
#include "llsf/study/stats_store.h"
#include "support/temp_dir.h"

namespace {

namespace fs = std::filesystem;

using llsf::test::has;
using llsf::test::llsfsim;
using llsf::test::Run;

using llsf::test::TempDir;

/// A tiny scenario: 120 s of production (a few points each), two robots with the 2013 team agent, 2
/// variants x 2 seeds. `tests` is the YAML of the test cases.
std::string write_tiny(const TempDir& dir, const std::string& tests = "  - no_agent_errors: true\n",
                       const std::string& name = "tiny.yaml") {
  const std::string agents = std::string(LLSF_SOURCE_DIR) + "/clips/agents";
  std::ofstream f(dir.file(name));
  f << "name: tiny\n"
       "seeds: [3, 4]\n"
       "start: production\n"
       "duration_s: 120\n"
       "robots:\n"
       "  count: 2\n"
       "  agent: ["
    << agents << "/common, " << agents
    << "/llsf2013]\n"
       "  config:\n"
       "    roles: [P1P2, P3]\n"
       "    recycle: never\n"
       "matrix:\n"
       "  config:\n"
       "    P3-P3: {robots.config.roles: [P3, P3]}\n"
       "    P1P2-P3: {}\n"
       "tests:\n"
    << tests;
  return dir.file(name);
}

std::string slurp(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>()};
}

using Key = std::tuple<std::string, std::uint64_t, std::uint64_t>;  // variant, seed, hash

std::vector<Key> stored_runs(const std::string& db) {
  llsf::study::StatsStore store(db);
  std::vector<Key> out;
  for (std::int64_t batch = 1; batch <= 10; ++batch) {
    for (const auto& r : store.runs(batch)) out.emplace_back(r.variant, r.seed, r.result_hash);
  }
  std::sort(out.begin(), out.end());
  return out;
}

}  // namespace

TEST_CASE("llsfsim batch plays variants x seeds once, stores them, and resumes") {
  const TempDir dir;
  const std::string scenario = write_tiny(dir);
  const std::string db1 = dir.file("one.db");
  const std::string db2 = dir.file("two.db");

  Run r = llsfsim({"batch", scenario, "--jobs", "2", "--db", db2});
  INFO(r.out, r.err);
  CHECK(r.code == llsf::app::kExitOk);
  CHECK(has(r.out, "4 runs, 4 played, 0 stored before"));
  CHECK(has(r.out, "config=P3-P3"));
  CHECK(has(r.out, "config=P1P2-P3"));
  CHECK(has(r.out, "all 4 runs passed"));
  CHECK(has(r.err, "[4/4] "));
  const std::vector<Key> two = stored_runs(db2);
  REQUIRE(two.size() == 4);
  CHECK(std::get<0>(two[0]) == "config=P1P2-P3");
  CHECK(std::get<1>(two[0]) == 3);
  CHECK(std::get<1>(two[1]) == 4);
  {
    llsf::study::StatsStore store(db2);
    CHECK(store.count_rows("batches") == 1);
    CHECK(!store.batch(1)->finished.empty());
    // Every statistic a game always has, and those it may lack (absent: no row) where it has them.
    const auto& infos = llsf::study::statistic_infos();
    const auto always =
        std::count_if(infos.begin(), infos.end(), [](const auto& s) { return !s.may_be_absent; });
    CHECK(store.count_rows("statistics") >= 4 * static_cast<std::int64_t>(always));
    CHECK(store.count_rows("statistics") <= 4 * static_cast<std::int64_t>(infos.size()));
    CHECK(store.count_rows("tests") == 4);
    CHECK(store.count_rows("awards") > 0);  // machines completed, products delivered
    CHECK(store.count_rows("events") == store.count_rows("awards") + 4);
  }

  // Again: nothing new is played, the summary covers the stored runs.
  r = llsfsim({"batch", scenario, "--jobs", "2", "--db", db2});
  CHECK(r.code == llsf::app::kExitOk);
  CHECK(has(r.out, "4 runs, 0 played, 4 stored before"));
  CHECK(stored_runs(db2) == two);

  // One worker: the same result hashes, and byte for byte the same recordings.
  r = llsfsim({"batch", scenario, "--jobs", "1", "--db", db1});
  CHECK(r.code == llsf::app::kExitOk);
  CHECK(stored_runs(db1) == two);
  CHECK(has(r.out, "recordings " + dir.file("one-recordings") + "/batch1/"));
  {
    const llsf::study::StatsStore s1(db1), s2(db2);
    const auto runs1 = s1.runs(1), runs2 = s2.runs(1);
    REQUIRE(runs1.size() == 4);
    REQUIRE(runs2.size() == 4);
    for (const auto& a : runs1) {
      const auto b = std::find_if(runs2.begin(), runs2.end(), [&](const auto& x) {
        return x.variant == a.variant && x.seed == a.seed;
      });
      REQUIRE(b != runs2.end());
      INFO(a.recording, " vs ", b->recording);
      CHECK(a.recording.find("one-recordings/batch1/tiny-config_") != std::string::npos);
      CHECK(fs::file_size(a.recording) > 1000);
      CHECK(slurp(a.recording) == slurp(b->recording));
    }
  }

  // --runs 1: another batch (first seed of each variant), same results for those seeds.
  r = llsfsim({"batch", scenario, "--runs", "1", "--db", db1});
  CHECK(r.code == llsf::app::kExitOk);
  CHECK(has(r.out, "2 runs, 2 played, 0 stored before"));
  CHECK(stored_runs(db1).size() == 6);
}

TEST_CASE("llsfsim batch: an interrupted batch keeps its runs and the next call plays the rest") {
  const TempDir dir;
  const std::string scenario = write_tiny(dir);
  const llsf::study::ScenarioFile file = llsf::study::load_scenario(scenario);
  const std::string hash = llsf::study::batch_identity_hash(scenario, file);
  llsf::study::StatsStore store(dir.file("stats.db"));

  std::atomic<bool> stop{false};
  llsf::study::BatchHooks hooks;
  hooks.stop = &stop;
  hooks.stored = [&](const llsf::study::RunResult&, const llsf::study::BatchProgress&) {
    stop = true;  // as a Ctrl-C after the first stored run
  };
  llsf::study::BatchOptions options;
  options.jobs = 1;
  llsf::study::BatchResult b = llsf::study::run_batch(file, hash, store, options, hooks);
  CHECK(b.interrupted);
  // The one worker may have started the next game before the first was stored; it finishes.
  const int first = b.played;
  CHECK(first >= 1);
  CHECK(first <= 2);
  CHECK(b.total == 4);
  CHECK(store.count_rows("runs") == first);
  CHECK(store.batch(b.batch_id)->finished.empty());

  b = llsf::study::run_batch(file, hash, store, options);
  CHECK(!b.interrupted);
  CHECK(b.skipped == first);
  CHECK(b.played == 4 - first);
  CHECK(store.count_rows("runs") == 4);
  CHECK(!store.batch(b.batch_id)->finished.empty());
  REQUIRE(b.variants.size() == 2);
  CHECK(b.variants[0].variant == "config=P3-P3");  // matrix order
  CHECK(b.variants[0].runs == 2);
  CHECK(b.all_passed());
}

TEST_CASE("llsfsim batch: a failed test case exits 1, bad input exits 2") {
  const TempDir dir;
  const std::string failing = write_tiny(dir, "  - points_at_least: 1000\n", "failing.yaml");
  Run r = llsfsim({"batch", failing, "--runs", "1", "--db", dir.file("f.db")});
  CHECK(r.code == llsf::app::kExitFailed);
  CHECK(has(r.out, "2 of 2 runs failed"));
  CHECK(has(r.err, "FAIL"));

  std::ofstream(dir.file("bad.yaml")) << "name: bad\nduration_s: -5\n";
  r = llsfsim({"batch", dir.file("bad.yaml"), "--db", dir.file("b.db")});
  CHECK(r.code == llsf::app::kExitBadInput);
  CHECK(has(r.err, "duration_s"));
  CHECK(!fs::exists(dir.file("b.db")));  // nothing written before the input is checked

  const std::string tiny = write_tiny(dir);
  r = llsfsim({"batch", tiny, "--seeds", "3,3", "--db", dir.file("b.db")});
  CHECK(r.code == llsf::app::kExitBadInput);
  CHECK(has(r.err, "seed 3 is given twice"));
  r = llsfsim({"batch", tiny, "--jobs", "0"});
  CHECK(r.code == llsf::app::kExitBadInput);
  r = llsfsim({"batch", dir.file("missing.yaml")});
  CHECK(r.code == llsf::app::kExitBadInput);
  r = llsfsim({"batch", tiny, "--db", dir.file("tiny.yaml/x.db")});  // below a file
  CHECK(r.code == llsf::app::kExitBadInput);
  CHECK(has(r.err, "x.db"));
}

TEST_CASE("llsfsim run stores its game with --db, not with --no-db") {
  const TempDir dir;
  const std::string scenario = write_tiny(dir);
  const std::string db = dir.file("run.db");
  Run r = llsfsim({"run", scenario, "--quiet", "--db", db});
  CHECK(r.code == llsf::app::kExitOk);
  std::vector<Key> runs = stored_runs(db);
  REQUIRE(runs.size() == 1);
  CHECK(std::get<0>(runs[0]) == "config=P3-P3");
  CHECK(std::get<1>(runs[0]) == 3);
  // Recorded beside the store, and the summary says where.
  CHECK(fs::file_size(dir.file("run-recordings/tiny-config_P3-P3-seed3.jsonl.gz")) > 1000);
  r = llsfsim({"run", scenario, "--db", db, "--no-record"});
  CHECK(has(r.out, "database   " + db + " (batch 1, run "));
  CHECK(!has(r.out, "recording  "));
  CHECK(llsf::study::StatsStore(db).runs(1).back().recording.empty());
  r = llsfsim({"run", scenario, "--db", db});
  CHECK(has(r.out, "recording  " + dir.file("run-recordings/tiny-config_P3-P3-seed3.jsonl.gz")));
  CHECK(llsf::study::StatsStore(db).runs(1).back().recording ==
        dir.file("run-recordings/tiny-config_P3-P3-seed3.jsonl.gz"));

  // The same game again replaces the stored one; another seed adds one.
  CHECK(llsfsim({"run", scenario, "--quiet", "--db", db}).code == llsf::app::kExitOk);
  CHECK(stored_runs(db) == runs);
  CHECK(llsfsim({"run", scenario, "--quiet", "--seed", "9", "--db", db}).code ==
        llsf::app::kExitOk);
  CHECK(stored_runs(db).size() == 2);
  {
    llsf::study::StatsStore store(db);
    CHECK(store.batch(1)->kind == "run");
  }

  const std::string other = dir.file("other.db");
  CHECK(llsfsim({"run", scenario, "--quiet", "--no-db", "--db", other}).code ==
        llsf::app::kExitBadInput);  // they exclude each other
  CHECK(llsfsim({"run", scenario, "--quiet", "--no-db", "--no-record"}).code == llsf::app::kExitOk);
  CHECK(!fs::exists(other));
}

TEST_CASE("llsfsim batch --until plays in rounds until the answer is known, and resumes") {
  const TempDir dir;
  const std::string agents = std::string(LLSF_SOURCE_DIR) + "/clips/agents";
  dir.write("pair.yaml",
            "name: pair\nseeds: {first: 1, count: 10}\nstart: production\n"
            "duration_s: 30\nrobots:\n  count: 1\n  agent: [" +
                agents + "/common, " + agents +
                "/llsf2013]\n  config: {roles: [P3], recycle: never}\n"
                "matrix:\n  config:\n    P3: {}\n"
                "    P1P2: {robots.config.roles: [P1P2]}\n");
  const std::string file = dir.file("pair.yaml");
  const std::string db = dir.file("until.db");
  // Every game lasts 30 s (short: this binary also runs under ThreadSanitizer): equivalent within
  // 1 s at the first look (10 seeds of at most 20).
  const std::vector<std::string> args{"batch",
                                      file,
                                      "--db",
                                      db,
                                      "--no-record",
                                      "--jobs",
                                      "2",
                                      "--until",
                                      "config=P3>config=P1P2",
                                      "--statistic",
                                      "game_time_s",
                                      "--margin",
                                      "1",
                                      "--max-runs",
                                      "20",
                                      "--looks",
                                      "2"};
  Run r = llsfsim(args);
  INFO(r.out, r.err);
  CHECK(r.code == llsf::app::kExitOk);
  CHECK(has(r.out,
            "until      config=P3 > config=P1P2 on game_time_s: at most 20 seeds, looks "
            "after 10, 20 seeds, each at 2.5 % (5 % in all: Bonferroni); equivalent if "
            "inside +-1\n"));
  CHECK(has(r.out,
            "look 1/2   10 seeds: +0.00 [+0.00, +0.00] (97.5 % interval, paired by seed; "
            "equivalence [+0.00, +0.00]): equivalent within the margin\n"));
  CHECK(has(r.out,
            "answer     config=P3 and config=P1P2 are equivalent within +-1 game_time_s "
            "after 10 seeds\n"));
  CHECK(!has(r.out, "look 2/2"));
  {
    llsf::study::StatsStore store(db);
    CHECK(store.count_rows("runs") == 20);    // stopped at the first look
    CHECK(store.batch(1)->finished.empty());  // of a batch of 2 x 20
    CHECK(store.batch(1)->runs_per_variant == 20);
  }
  // Again: nothing played, the same looks and answer.
  const Run again = llsfsim(args);
  CHECK(again.code == llsf::app::kExitOk);
  CHECK(has(again.out, "20 runs, 0 played, 20 stored before"));
  CHECK(has(again.out, "equivalent within +-1 game_time_s after 10 seeds"));

  // Without a margin the equal game times are never separated: every look, then undecided, and
  // the batch complete.
  r = llsfsim({"batch", file, "--db", db, "--no-record", "--jobs", "2", "--until",
               "config=P3>config=P1P2", "--statistic", "game_time_s", "--max-runs", "20", "--looks",
               "2"});
  INFO(r.out, r.err);
  CHECK(r.code == llsf::app::kExitOk);
  CHECK(has(r.out, "look 2/2   20 seeds: "));
  CHECK(has(r.out, "answer     undecided after 20 seeds (neither separated)\n"));
  CHECK(!llsf::study::StatsStore(db).batch(1)->finished.empty());

  // Bad input: named, exit 2, nothing played.
  const std::string bad_db = dir.file("bad.db");
  auto bad = [&](std::vector<std::string> extra, const std::string& what) {
    std::vector<std::string> a{"batch", file, "--db", bad_db, "--no-record"};
    a.insert(a.end(), extra.begin(), extra.end());
    const Run b = llsfsim(a);
    INFO(b.out, b.err);
    CHECK(b.code == llsf::app::kExitBadInput);
    CHECK(has(b.err, what));
  };
  bad({"--until", "config=P4>config=P3", "--max-runs", "10"},
      "--until: the scenario has no variant 'config=P4' (variants: config=P3, config=P1P2)");
  bad({"--until", "config=P3", "--max-runs", "10"}, "--until: expected VARIANT_A>VARIANT_B");
  bad({"--until", "config=P3>config=P1P2"}, "--until needs --max-runs N");
  bad({"--until", "config=P3>config=P1P2", "--max-runs", "5"}, "--max-runs must be at least 10");
  bad({"--until", "config=P3>config=P1P2", "--max-runs", "10", "--statistic", "pionts"},
      "--statistic: unknown statistic 'pionts'");
  bad({"--until", "config=P3>config=P1P2", "--max-runs", "10", "--runs", "3"}, "excludes");
  CHECK(!fs::exists(bad_db));
}
