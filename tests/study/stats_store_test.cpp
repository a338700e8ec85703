// SPDX-License-Identifier: MIT
// StatsStore: schema, a run written and read back, one transaction per run, batch identity.
#include "llsf/study/stats_store.h"
#include "support/temp_dir.h"

#include <doctest/doctest.h>
#include <sqlite3.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

namespace {

namespace fs = std::filesystem;
using llsf::study::BatchKey;
using llsf::study::RunResult;
using llsf::study::StatsError;
using llsf::study::StatsStore;

using llsf::test::TempDir;

RunResult sample_run(const std::string& variant, std::uint64_t seed) {
  RunResult r;
  r.scenario = "tiny";
  r.variant = variant;
  r.seed = seed;
  r.game_time_s = 60.0;
  r.points = 28;
  r.exploration_points = 0;
  r.production_points = 28;
  r.deliveries = 1;
  r.products_p3 = 2;
  r.collisions = 3;
  r.messages_sent = 1234;
  r.cpu_s = 0.5;
  r.real_time_factor = 120.0;
  r.result_hash = 0x8ee4dd2ff8fea3e8ULL;
  r.orders.push_back({1, "P3", 2, 1, 0, 299});
  r.orders.push_back({2, "P1", 1, 0, 100, 400});
  r.tests.push_back({"some points", true, "28 points (need >= 10)", 60.0});
  r.tests.push_back({"few collisions", true, "3 collisions (need <= 5)", 60.0});
  r.awards.push_back({12.5, 12.5, "PRODUCTION", 4, "MACHINE_COMPLETED", "M2", -1, 3});
  r.awards.push_back({40.0, 40.0, "PRODUCTION", 12, "MACHINE_COMPLETED", "M5", -1, 3});
  r.awards.push_back({55.0, 55.0, "PRODUCTION", 12, "DELIVERY", "D1", 1, 3});
  return r;
}

BatchKey sample_key(int runs = 2) {
  BatchKey k;
  k.scenario_file = "tiny.yaml";
  k.scenario_name = "tiny";
  k.scenario_hash = "0123456789abcdef";
  k.runs_per_variant = runs;
  k.variants = 2;
  k.seeds = {1, 2};
  return k;
}

}  // namespace

TEST_CASE("StatsStore creates its schema once and reopens the file") {
  const TempDir dir;
  const std::string db = dir.file("stats.db");
  {
    StatsStore store(db);
    CHECK(store.path() == db);
    for (const char* t : {"batches", "runs", "statistics", "orders", "tests", "awards", "events"}) {
      CHECK(store.count_rows(t) == 0);
    }
    CHECK_THROWS_AS(store.count_rows("sqlite_schema"), StatsError);
    store.add_run(store.open_batch(sample_key()), sample_run("a", 1));
  }
  StatsStore again(db);  // the schema is there: nothing recreated, nothing lost
  CHECK(again.count_rows("runs") == 1);
  CHECK(fs::exists(db));
}

TEST_CASE("StatsStore refuses files that are not a statistics store") {
  const TempDir dir;
  { std::ofstream(dir.file("text.db")) << "not a database, just text that is long enough......"; }
  CHECK_THROWS_AS(StatsStore(dir.file("text.db")), StatsError);
  // A missing directory is created; one that cannot be (below a file) is an error.
  CHECK_NOTHROW(StatsStore(dir.file("missing/dir/x.db")));
  CHECK_THROWS_AS(StatsStore(dir.file("text.db/x.db")), StatsError);
}

TEST_CASE("StatsStore keeps recording paths relative to its directory, and reads schema 1") {
  const TempDir dir;
  const std::string db = dir.file("stats.db");
  {
    StatsStore store(db);
    const std::int64_t batch = store.open_batch(sample_key());
    RunResult inside = sample_run("a", 1);
    inside.recording = dir.file("recordings/batch1/a-seed1.jsonl.gz");
    RunResult outside = sample_run("a", 2);
    outside.recording = "/var/tmp/elsewhere.jsonl.gz";
    RunResult none = sample_run("b", 1);
    store.add_run(batch, inside);
    store.add_run(batch, outside);
    store.add_run(batch, none);
    const auto runs = store.runs(batch);
    REQUIRE(runs.size() == 3);
    CHECK(runs[0].recording == inside.recording);
    CHECK(runs[1].recording == outside.recording);
    CHECK(runs[2].recording.empty());
  }
  // What the file holds: the path relative to the database's directory.
  sqlite3* h = nullptr;
  REQUIRE(sqlite3_open(db.c_str(), &h) == SQLITE_OK);
  sqlite3_stmt* q = nullptr;
  REQUIRE(sqlite3_prepare_v2(h, "SELECT recording FROM runs ORDER BY id", -1, &q, nullptr) ==
          SQLITE_OK);
  REQUIRE(sqlite3_step(q) == SQLITE_ROW);
  CHECK(std::string(reinterpret_cast<const char*>(sqlite3_column_text(q, 0))) ==
        "recordings/batch1/a-seed1.jsonl.gz");
  sqlite3_finalize(q);
  // Schema 1 (before runs.recording): the store adds the column and keeps the runs.
  CHECK(sqlite3_exec(h, "ALTER TABLE runs DROP COLUMN recording; PRAGMA user_version = 1", nullptr,
                     nullptr, nullptr) == SQLITE_OK);
  sqlite3_close(h);
  StatsStore old(db);
  const std::int64_t batch = old.open_batch(sample_key());
  CHECK(old.runs(batch).size() == 3);
  CHECK(old.runs(batch)[0].recording.empty());
  RunResult again = sample_run("b", 2);
  again.recording = dir.file("r.jsonl.gz");
  old.add_run(batch, again);
  CHECK(old.runs(batch).back().recording == again.recording);
}

TEST_CASE("StatsStore writes a run and reads it back") {
  const TempDir dir;
  StatsStore store(dir.file("stats.db"));
  const std::int64_t batch = store.open_batch(sample_key());
  CHECK(store.open_batch(sample_key()) == batch);   // same identity, same batch
  CHECK(store.open_batch(sample_key(3)) != batch);  // other runs per variant: another
  BatchKey run_key = sample_key(0);
  run_key.kind = BatchKey::Kind::kRun;
  CHECK(store.open_batch(run_key) != batch);  // single runs: another

  const RunResult r = sample_run("config=a", 7);
  const std::int64_t id = store.add_run(batch, r);
  const auto runs = store.runs(batch);
  REQUIRE(runs.size() == 1);
  CHECK(runs[0].id == id);
  CHECK(runs[0].scenario == "tiny");
  CHECK(runs[0].variant == "config=a");
  CHECK(runs[0].seed == 7);
  CHECK(runs[0].result_hash == r.result_hash);
  CHECK(runs[0].passed);
  CHECK(runs[0].points == 28);
  CHECK(runs[0].game_time_s == 60.0);
  CHECK(runs[0].llsfsim_version == llsf::study::llsfsim_version());
  // The same run by its id; an unknown id: none.
  const auto one = store.run(id);
  REQUIRE(one);
  CHECK(one->variant == "config=a");
  CHECK(one->seed == 7);
  CHECK(one->batch_id == batch);
  CHECK_FALSE(store.run(id + 1000));

  // Every numeric statistic, by name.
  const auto stats = store.statistics(id);
  CHECK(stats.size() == llsf::study::numeric_statistics(r).size());
  auto stat = [&](const std::string& name) {
    for (const auto& [n, v] : stats) {
      if (n == name) return v;
    }
    FAIL("no statistic ", name);
    return 0.0;
  };
  CHECK(stat("points") == 28.0);
  CHECK(stat("production_points") == 28.0);
  CHECK(stat("collisions") == 3.0);
  CHECK(stat("messages_sent") == 1234.0);
  CHECK(stat("products_p3") == 2.0);
  CHECK(stat("order_units_requested") == 3.0);
  CHECK(stat("passed") == 1.0);

  const auto awards = store.awards(id);
  REQUIRE(awards.size() == 3);
  CHECK(awards[0].reason == "MACHINE_COMPLETED");
  CHECK(awards[0].device == "M2");
  CHECK(awards[0].order == -1);
  CHECK(awards[2].reason == "DELIVERY");
  CHECK(awards[2].order == 1);
  CHECK(awards[2].points == 12);
  CHECK(store.count_rows("orders") == 2);
  CHECK(store.count_rows("tests") == 2);
  CHECK(store.count_rows("events") == 5);  // 3 awards + 2 verdicts

  const auto b = store.batch(batch);
  REQUIRE(b);
  CHECK(b->kind == "batch");
  CHECK(b->seeds == "1,2");
  CHECK(b->finished.empty());
  CHECK(b->created.size() == 20);  // 2024-01-02T03:04:05Z
  store.finish_batch(batch);
  CHECK(!store.batch(batch)->finished.empty());
  CHECK(!store.batch(12345));
}

TEST_CASE("StatsStore: a run is written whole or not at all") {
  const TempDir dir;
  StatsStore store(dir.file("stats.db"));
  const std::int64_t batch = store.open_batch(sample_key());
  store.add_run(batch, sample_run("a", 1));
  const auto rows = [&] {
    std::int64_t n = 0;
    for (const char* t : {"runs", "statistics", "orders", "tests", "awards", "events"}) {
      n += store.count_rows(t);
    }
    return n;
  };
  const std::int64_t before = rows();

  // A failure in the middle of a run: the run row and its statistics are written, then an order
  // breaks the primary key. Nothing of the run may remain.
  RunResult broken = sample_run("a", 2);
  broken.orders.push_back(broken.orders.front());
  CHECK_THROWS_AS(store.add_run(batch, broken), StatsError);
  CHECK(rows() == before);
  CHECK(store.runs(batch).size() == 1);

  // The same (variant, seed) again is an error, unless replacing.
  CHECK_THROWS_AS(store.add_run(batch, sample_run("a", 1)), StatsError);
  CHECK(rows() == before);
  RunResult changed = sample_run("a", 1);
  changed.points = 99;
  changed.awards.pop_back();
  store.add_run(batch, changed, /*replace=*/true);
  const auto runs = store.runs(batch);
  REQUIRE(runs.size() == 1);
  CHECK(runs[0].points == 99);
  CHECK(store.count_rows("awards") == 2);  // the old run's children went with it

  // The store is usable after a failed run.
  store.add_run(batch, sample_run("a", 2));
  CHECK(store.run_keys(batch).size() == 2);
}

TEST_CASE("file_content_hash identifies a file's bytes") {
  const TempDir dir;
  std::ofstream(dir.file("a.yaml")) << "name: a\n";
  std::ofstream(dir.file("b.yaml")) << "name: a\n";
  std::ofstream(dir.file("c.yaml")) << "name: c\n";
  const std::string a = llsf::study::file_content_hash(dir.file("a.yaml"));
  CHECK(a.size() == 16);
  CHECK(a == llsf::study::file_content_hash(dir.file("b.yaml")));
  CHECK(a != llsf::study::file_content_hash(dir.file("c.yaml")));
  CHECK_THROWS_AS(llsf::study::file_content_hash(dir.file("missing.yaml")), StatsError);
}
