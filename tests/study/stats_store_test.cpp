// SPDX-License-Identifier: MIT
// StatsStore on both backends (SQLite and a throwaway PostgreSQL 15 cluster, tests/support/
// pg_cluster.h): schema and migrations, a run written and read back, one transaction per run,
// idempotent writes, batch identity, concurrent writers; for PostgreSQL also URLs, PG* variables,
// an unreachable server and a server restart, also in the middle of a run.
#include "llsf/study/stats_store.h"

#include <doctest/doctest.h>
#include <sqlite3.h>
#include <stdlib.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include "support/pg_cluster.h"
#include "support/temp_dir.h"

namespace {

namespace fs = std::filesystem;
using llsf::study::BatchKey;
using llsf::study::RunResult;
using llsf::study::StatsError;
using llsf::study::StatsStore;

using llsf::test::PgCluster;
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

// Rows of a run's tables in all.
std::int64_t run_rows(const StatsStore& store) {
  std::int64_t n = 0;
  for (const char* t : {"runs", "statistics", "orders", "tests", "awards", "events"}) {
    n += store.count_rows(t);
  }
  return n;
}
// Rows one sample_run() writes: the run, its statistics, 2 orders, 2 tests, 3 awards, 5 events.
std::int64_t rows_of_one_run() {
  return 1 + static_cast<std::int64_t>(llsf::study::numeric_statistics(sample_run("a", 1)).size()) +
         2 + 2 + 3 + 5;
}

// The backends the suite runs on: each makes fresh stores (`fresh()` returns what --db takes).
// The database name at the end of a test cluster's URL.
std::string db_name(const std::string& url) { return url.substr(url.rfind('/') + 1); }

struct SqliteBackend {
  static constexpr bool kPostgres = false;
  TempDir dir;
  int n = 0;
  std::string fresh() { return dir.file("stats" + std::to_string(++n) + ".db"); }
  /// Runs SQL on the store `db` behind llsfsim's back (to make an older store).
  static void sql(const std::string& db, const std::string& statements) {
    sqlite3* h = nullptr;
    REQUIRE(sqlite3_open(db.c_str(), &h) == SQLITE_OK);
    CHECK(sqlite3_exec(h, statements.c_str(), nullptr, nullptr, nullptr) == SQLITE_OK);
    sqlite3_close(h);
  }
};
struct PostgresBackend {
  static constexpr bool kPostgres = true;
  std::string fresh() { return PgCluster::shared().create_database(); }
  static void sql(const std::string& db, const std::string& statements) {
    PgCluster::shared().psql(db_name(db), statements);
  }
};

// Sets (or unsets, for nullptr) an environment variable for one scope.
struct EnvVar {
  std::string name;
  std::string old;
  bool had;
  EnvVar(std::string n, const char* value) : name(std::move(n)) {
    const char* o = ::getenv(name.c_str());
    had = o != nullptr;
    if (had) old = o;
    if (value != nullptr)
      ::setenv(name.c_str(), value, 1);
    else
      ::unsetenv(name.c_str());
  }
  ~EnvVar() {
    if (had)
      ::setenv(name.c_str(), old.c_str(), 1);
    else
      ::unsetenv(name.c_str());
  }
  EnvVar(const EnvVar&) = delete;
  EnvVar& operator=(const EnvVar&) = delete;
};

#define BACKENDS SqliteBackend, PostgresBackend

}  // namespace

// ---- Both backends ---------------------------------------------------------------------------

TEST_CASE_TEMPLATE("StatsStore creates its schema once and reopens the store", B, BACKENDS) {
  B backend;
  const std::string db = backend.fresh();
  {
    StatsStore store(db);
    CHECK(store.path() == db);
    for (const char* t : {"batches", "runs", "statistics", "orders", "tests", "awards", "events"}) {
      CHECK(store.count_rows(t) == 0);
    }
    CHECK(store.count_rows("schema_migrations") == 4);  // versions 1, 2, 3, 4
    CHECK_THROWS_AS(store.count_rows("sqlite_schema"), StatsError);
    CHECK_THROWS_AS(store.count_rows("runs; DROP TABLE runs"), StatsError);
    store.add_run(store.open_batch(sample_key()), sample_run("a", 1));
  }
  StatsStore again(db);  // the schema is there: nothing recreated, nothing lost
  CHECK(again.count_rows("runs") == 1);
  CHECK(again.count_rows("schema_migrations") == 4);
  if constexpr (!B::kPostgres) CHECK(fs::exists(db));
}

TEST_CASE_TEMPLATE("StatsStore writes a run and reads it back", B, BACKENDS) {
  B backend;
  StatsStore store(backend.fresh());
  const std::int64_t batch = store.open_batch(sample_key());
  CHECK(store.open_batch(sample_key()) == batch);   // same identity, same batch
  CHECK(store.open_batch(sample_key(3)) != batch);  // other runs per variant: another
  BatchKey run_key = sample_key(0);
  run_key.kind = BatchKey::Kind::kRun;
  CHECK(store.open_batch(run_key) != batch);  // single runs: another

  RunResult r = sample_run("config=a", 7);
  r.seed = 0xfedcba9876543210ULL;  // >= 2^63: kept bit for bit
  r.real_time_factor = 1.0 / 3.0;  // doubles read back exactly
  const std::int64_t id = store.add_run(batch, r);
  const auto runs = store.runs(batch);
  REQUIRE(runs.size() == 1);
  CHECK(runs[0].id == id);
  CHECK(runs[0].batch_id == batch);
  CHECK(runs[0].scenario == "tiny");
  CHECK(runs[0].variant == "config=a");
  CHECK(runs[0].seed == 0xfedcba9876543210ULL);
  CHECK(runs[0].result_hash == r.result_hash);
  CHECK(runs[0].passed);
  CHECK(runs[0].points == 28);
  CHECK(runs[0].game_time_s == 60.0);
  CHECK(runs[0].cpu_s == 0.5);
  CHECK(runs[0].real_time_factor == 1.0 / 3.0);
  CHECK(runs[0].recording.empty());
  CHECK(runs[0].llsfsim_version == llsf::study::llsfsim_version());
  CHECK(store.run_keys(batch) ==
        std::vector<std::pair<std::string, std::uint64_t>>{{"config=a", 0xfedcba9876543210ULL}});
  // The same run by its id; an unknown id: none.
  const auto one = store.run(id);
  REQUIRE(one);
  CHECK(one->variant == "config=a");
  CHECK(one->seed == 0xfedcba9876543210ULL);
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
  CHECK(stat("real_time_factor") == 1.0 / 3.0);
  // Absent is no row: sample_run() made no complex product and the storage never ran empty.
  for (const char* absent :
       {"first_complex_production_s", "first_role_change_game_s", "storage_empty_game_s"}) {
    CHECK(
        std::none_of(stats.begin(), stats.end(), [&](const auto& s) { return s.first == absent; }));
  }
  CHECK(stat("complex_made") == 0.0);
  CHECK(stat("storage_ran_empty") == 0.0);

  const auto awards = store.awards(id);
  REQUIRE(awards.size() == 3);
  CHECK(awards[0].reason == "MACHINE_COMPLETED");
  CHECK(awards[0].device == "M2");
  CHECK(awards[0].order == -1);
  CHECK(awards[0].puck == 3);
  CHECK(awards[0].time_s == 12.5);
  CHECK(awards[2].reason == "DELIVERY");
  CHECK(awards[2].order == 1);
  CHECK(awards[2].points == 12);
  CHECK(store.count_rows("orders") == 2);
  CHECK(store.count_rows("tests") == 2);
  CHECK(store.count_rows("events") == 5);  // 3 awards + 2 verdicts
  CHECK(store.awards(id + 1000).empty());
  CHECK(store.statistics(id + 1000).empty());

  const auto b = store.batch(batch);
  REQUIRE(b);
  CHECK(b->id == batch);
  CHECK(b->kind == "batch");
  CHECK(b->scenario_file == "tiny.yaml");
  CHECK(b->scenario_name == "tiny");
  CHECK(b->scenario_hash == "0123456789abcdef");
  CHECK(b->runs_per_variant == 2);
  CHECK(b->variants == 2);
  CHECK(b->seeds == "1,2");
  CHECK(b->finished.empty());
  CHECK(b->created.size() == 20);  // 2024-01-02T03:04:05Z
  CHECK(b->created[10] == 'T');
  CHECK(b->created.back() == 'Z');
  store.finish_batch(batch);
  const std::string finished = store.batch(batch)->finished;
  CHECK(finished.size() == 20);
  store.finish_batch(batch);  // once
  CHECK(store.batch(batch)->finished == finished);
  CHECK(!store.batch(12345));
  const auto all = store.batches();
  REQUIRE(all.size() == 3);
  CHECK(all[0].id == batch);
  CHECK(all[2].kind == "run");
}

TEST_CASE_TEMPLATE("StatsStore: a run is written whole or not at all, and once", B, BACKENDS) {
  B backend;
  StatsStore store(backend.fresh());
  const std::int64_t batch = store.open_batch(sample_key());
  const std::int64_t first = store.add_run(batch, sample_run("a", 1));
  const std::int64_t before = run_rows(store);
  CHECK(before == rows_of_one_run());

  // A failure in the middle of a run: the run row and its statistics are written, then an order
  // breaks the primary key. Nothing of the run may remain.
  RunResult broken = sample_run("a", 2);
  broken.orders.push_back(broken.orders.front());
  CHECK_THROWS_AS(store.add_run(batch, broken), StatsError);
  CHECK(run_rows(store) == before);
  CHECK(store.runs(batch).size() == 1);
  // A batch that does not exist: nothing written.
  CHECK_THROWS_AS(store.add_run(batch + 100, sample_run("a", 3)), StatsError);
  CHECK(run_rows(store) == before);

  // The same run again (a retried task, a merged shard): nothing written, the stored run's id.
  RunResult retried = sample_run("a", 1);
  retried.cpu_s = 7.0;  // measured again: not part of the result
  CHECK(store.add_run(batch, retried) == first);
  CHECK(run_rows(store) == before);
  CHECK(store.runs(batch)[0].cpu_s == 0.5);
  // Another result for the same (variant, seed) is an error, naming both hashes...
  RunResult changed = sample_run("a", 1);
  changed.points = 99;
  changed.result_hash = 0x1234;
  changed.awards.pop_back();
  try {
    store.add_run(batch, changed);
    FAIL("no error");
  } catch (const StatsError& e) {
    CHECK(std::string(e.what()).find("8ee4dd2ff8fea3e8") != std::string::npos);
    CHECK(std::string(e.what()).find("0000000000001234") != std::string::npos);
  }
  CHECK(run_rows(store) == before);
  // ...unless replacing: the old run and its children go, the new one is written.
  // (The id may be the old one: SQLite hands out the highest id + 1 again.)
  const std::int64_t replaced = store.add_run(batch, changed, /*replace=*/true);
  auto runs = store.runs(batch);
  REQUIRE(runs.size() == 1);
  CHECK(runs[0].id == replaced);
  CHECK(runs[0].points == 99);
  CHECK(runs[0].result_hash == 0x1234);
  CHECK(store.count_rows("awards") == 2);    // the old run's children went with it
  CHECK(run_rows(store) == before - 1 - 1);  // one award and one award event fewer
  // Replacing with the same result writes it anew as well (the latest game counts).
  changed.cpu_s = 3.0;
  const std::int64_t again = store.add_run(batch, changed, /*replace=*/true);
  REQUIRE(store.runs(batch).size() == 1);
  CHECK(store.runs(batch)[0].id == again);
  CHECK(store.runs(batch)[0].cpu_s == 3.0);
  CHECK(store.count_rows("awards") == 2);

  // The store is usable after a failed run.
  store.add_run(batch, sample_run("a", 2));
  CHECK(store.run_keys(batch).size() == 2);
}

TEST_CASE_TEMPLATE("StatsStore keeps recording paths", B, BACKENDS) {
  B backend;
  const TempDir dir;
  const std::string db = B::kPostgres ? backend.fresh() : dir.file("stats.db");
  StatsStore store(db);
  const std::int64_t batch = store.open_batch(sample_key());
  RunResult inside = sample_run("a", 1);
  inside.recording = dir.file("recordings/batch1/a-seed1.jsonl.gz");
  RunResult outside = sample_run("a", 2);
  outside.recording = "/var/tmp/elsewhere.jsonl.gz";
  RunResult none = sample_run("b", 1);
  RunResult relative = sample_run("b", 2);
  relative.recording = "rec/b-seed2.jsonl.gz";  // relative to the working directory
  store.add_run(batch, inside);
  store.add_run(batch, outside);
  store.add_run(batch, none);
  store.add_run(batch, relative);
  const auto runs = store.runs(batch);
  REQUIRE(runs.size() == 4);
  CHECK(runs[0].recording == inside.recording);
  CHECK(runs[1].recording == outside.recording);
  CHECK(runs[2].recording.empty());
  // What the store holds: relative to the file's directory (SQLite, when inside it), absolute
  // (PostgreSQL: a server has no directory).
  const std::string cwd_relative = (fs::current_path() / relative.recording).string();
  if constexpr (B::kPostgres) {
    CHECK(runs[3].recording == cwd_relative);
    CHECK(PgCluster::shared().psql(db_name(db), "SELECT recording FROM runs ORDER BY id LIMIT 1") ==
          inside.recording);
    CHECK(PgCluster::shared().psql(db_name(db),
                                   "SELECT count(*) FROM runs WHERE recording IS NULL") == "1");
  } else {
    CHECK(fs::path(runs[3].recording).lexically_normal() ==
          fs::path(cwd_relative).lexically_normal());
    sqlite3* h = nullptr;
    REQUIRE(sqlite3_open(db.c_str(), &h) == SQLITE_OK);
    sqlite3_stmt* q = nullptr;
    REQUIRE(sqlite3_prepare_v2(h, "SELECT recording FROM runs ORDER BY id", -1, &q, nullptr) ==
            SQLITE_OK);
    REQUIRE(sqlite3_step(q) == SQLITE_ROW);
    CHECK(std::string(reinterpret_cast<const char*>(sqlite3_column_text(q, 0))) ==
          "recordings/batch1/a-seed1.jsonl.gz");
    sqlite3_finalize(q);
    sqlite3_close(h);
  }
}

TEST_CASE_TEMPLATE("StatsStore: two writers at once", B, BACKENDS) {
  B backend;
  const std::string db = backend.fresh();
  { StatsStore init(db); }  // the schema (a new store created by two at once: below, PostgreSQL)
  constexpr int kRuns = 12;
  SUBCASE("two batches") {
    std::vector<std::thread> writers;
    std::atomic<int> errors{0};
    for (int w = 0; w < 2; ++w) {
      writers.emplace_back([&, w] {
        try {
          StatsStore store(db);
          const std::int64_t batch = store.open_batch(sample_key(10 + w));
          for (int i = 0; i < kRuns; ++i) store.add_run(batch, sample_run("v", i));
          store.finish_batch(batch);
        } catch (const std::exception&) {
          ++errors;
        }
      });
    }
    for (std::thread& t : writers) t.join();
    CHECK(errors == 0);
    const StatsStore store(db);
    const auto batches = store.batches();
    REQUIRE(batches.size() == 2);
    for (const auto& b : batches) {
      CHECK(store.runs(b.id).size() == kRuns);
      CHECK(!b.finished.empty());
    }
    CHECK(run_rows(store) == 2 * kRuns * rows_of_one_run());
  }
  SUBCASE("the same batch's runs: exactly one copy each") {
    // Both writers open the same new batch and write the same runs, in opposite orders.
    std::vector<std::thread> writers;
    std::atomic<int> errors{0};
    std::vector<std::vector<std::int64_t>> ids(2, std::vector<std::int64_t>(kRuns));
    for (int w = 0; w < 2; ++w) {
      writers.emplace_back([&, w] {
        try {
          StatsStore store(db);
          const std::int64_t batch = store.open_batch(sample_key());
          for (int k = 0; k < kRuns; ++k) {
            const int i = w == 0 ? k : kRuns - 1 - k;
            ids[w][i] = store.add_run(batch, sample_run("v", i));
          }
        } catch (const std::exception&) {
          ++errors;
        }
      });
    }
    for (std::thread& t : writers) t.join();
    CHECK(errors == 0);
    CHECK(ids[0] == ids[1]);  // both got the one stored run's id
    const StatsStore store(db);
    REQUIRE(store.batches().size() == 1);
    CHECK(store.runs(store.batches()[0].id).size() == kRuns);
    CHECK(run_rows(store) == kRuns * rows_of_one_run());
  }
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

// ---- SQLite ----------------------------------------------------------------------------------

TEST_CASE("StatsStore (SQLite) refuses files that are not a statistics store") {
  const TempDir dir;
  { std::ofstream(dir.file("text.db")) << "not a database, just text that is long enough......"; }
  CHECK_THROWS_AS(StatsStore(dir.file("text.db")), StatsError);
  // A missing directory is an error naming it (it is not created: docs/llsfsim.md), as is a
  // "directory" that is a file.
  const std::string missing = "the folder " + dir.file("missing/dir") + " does not exist";
  CHECK_THROWS_WITH_AS(StatsStore(dir.file("missing/dir/x.db")), doctest::Contains(missing.c_str()),
                       StatsError);
  CHECK_FALSE(std::filesystem::exists(dir.file("missing")));
  CHECK_THROWS_AS(StatsStore(dir.file("text.db/x.db")), StatsError);
  // Another program's database.
  sqlite3* h = nullptr;
  REQUIRE(sqlite3_open(dir.file("other.db").c_str(), &h) == SQLITE_OK);
  CHECK(sqlite3_exec(h, "CREATE TABLE notes (t TEXT)", nullptr, nullptr, nullptr) == SQLITE_OK);
  sqlite3_close(h);
  CHECK_THROWS_WITH_AS(StatsStore(dir.file("other.db")),
                       doctest::Contains("not an llsfsim statistics store"), StatsError);
}

TEST_CASE_TEMPLATE("StatsStore migrates -1 placeholders to absent values and shares", B, BACKENDS) {
  B backend;
  const std::string db = backend.fresh();
  {
    StatsStore store(db);
    const std::int64_t batch = store.open_batch(sample_key());
    store.add_run(batch, sample_run("a", 1));
    store.add_run(batch, sample_run("b", 2));
  }
  // Back to version 3 as an llsfsim before issue #33 wrote it: the time statistics under their
  // old names, -1 for "never", no shares.
  B::sql(db,
         "DELETE FROM schema_migrations WHERE version = 4;"
         "DELETE FROM statistics WHERE name IN ('complex_made', 'storage_ran_empty');"
         "INSERT INTO statistics (run_id, name, value) VALUES (1, 'first_complex_s', -1),"
         " (1, 'first_role_change_s', 750), (1, 'storage_empty_s', -1),"
         " (2, 'first_complex_s', 412.5), (2, 'first_role_change_s', -1),"
         " (2, 'storage_empty_s', 900);" +
             std::string(B::kPostgres ? "" : "PRAGMA user_version = 3;"));
  const StatsStore store(db);
  CHECK(store.count_rows("schema_migrations") == 4);
  auto stats = [&](std::int64_t run) {
    std::map<std::string, double> out;
    for (const auto& [name, value] : store.statistics(run)) out[name] = value;
    return out;
  };
  const std::map<std::string, double> one = stats(1), two = stats(2);
  for (const char* old : {"first_complex_s", "first_role_change_s", "storage_empty_s"}) {
    CHECK(one.count(old) == 0);
    CHECK(two.count(old) == 0);
  }
  CHECK(one.count("first_complex_production_s") == 0);  // -1: absent
  CHECK(one.at("complex_made") == 0.0);
  CHECK(one.at("first_role_change_game_s") == 750.0);
  CHECK(one.count("storage_empty_game_s") == 0);
  CHECK(one.at("storage_ran_empty") == 0.0);
  CHECK(two.at("first_complex_production_s") == 412.5);
  CHECK(two.at("complex_made") == 1.0);
  CHECK(two.count("first_role_change_game_s") == 0);
  CHECK(two.at("storage_empty_game_s") == 900.0);
  CHECK(two.at("storage_ran_empty") == 1.0);
  CHECK(one.at("points") == 28.0);  // the rest untouched
}

namespace {
// The schema of llsfsim's stores before schema_migrations (version 2, `PRAGMA user_version`),
// as that llsfsim created it.
constexpr const char* kSchemaVersion2 = R"sql(
CREATE TABLE batches (
  id               INTEGER PRIMARY KEY,
  kind             TEXT    NOT NULL CHECK (kind IN ('batch', 'run')),
  created          TEXT    NOT NULL DEFAULT (strftime('%Y-%m-%dT%H:%M:%SZ', 'now')),
  finished         TEXT,
  scenario_file    TEXT    NOT NULL,
  scenario_name    TEXT    NOT NULL,
  scenario_hash    TEXT    NOT NULL,
  runs_per_variant INTEGER NOT NULL CHECK (runs_per_variant >= 0),
  variants         INTEGER NOT NULL CHECK (variants >= 1),
  seeds            TEXT    NOT NULL,
  llsfsim_version  TEXT    NOT NULL,
  UNIQUE (kind, scenario_hash, runs_per_variant)
);
CREATE TABLE runs (
  id               INTEGER PRIMARY KEY,
  batch_id         INTEGER NOT NULL REFERENCES batches (id) ON DELETE CASCADE,
  scenario         TEXT    NOT NULL,
  variant          TEXT    NOT NULL,
  seed             INTEGER NOT NULL,
  llsfsim_version  TEXT    NOT NULL,
  result_hash      TEXT    NOT NULL,
  passed           INTEGER NOT NULL CHECK (passed IN (0, 1)),
  points           INTEGER NOT NULL,
  game_time_s      REAL    NOT NULL,
  cpu_s            REAL    NOT NULL,
  real_time_factor REAL    NOT NULL,
  recording        TEXT,
  created          TEXT    NOT NULL DEFAULT (strftime('%Y-%m-%dT%H:%M:%SZ', 'now')),
  UNIQUE (batch_id, variant, seed)
);
CREATE TABLE statistics (
  run_id INTEGER NOT NULL REFERENCES runs (id) ON DELETE CASCADE,
  name   TEXT    NOT NULL,
  value  REAL    NOT NULL,
  PRIMARY KEY (run_id, name)
) WITHOUT ROWID;
CREATE INDEX statistics_by_name ON statistics (name);
CREATE TABLE orders (
  run_id         INTEGER NOT NULL REFERENCES runs (id) ON DELETE CASCADE,
  order_id       INTEGER NOT NULL,
  product        TEXT    NOT NULL,
  requested      INTEGER NOT NULL,
  delivered      INTEGER NOT NULL,
  window_begin_s INTEGER NOT NULL,
  window_end_s   INTEGER NOT NULL,
  PRIMARY KEY (run_id, order_id)
) WITHOUT ROWID;
CREATE TABLE tests (
  run_id INTEGER NOT NULL REFERENCES runs (id) ON DELETE CASCADE,
  idx    INTEGER NOT NULL,
  name   TEXT    NOT NULL,
  passed INTEGER NOT NULL CHECK (passed IN (0, 1)),
  detail TEXT    NOT NULL,
  at_s   REAL    NOT NULL,
  PRIMARY KEY (run_id, idx)
) WITHOUT ROWID;
CREATE TABLE awards (
  run_id      INTEGER NOT NULL REFERENCES runs (id) ON DELETE CASCADE,
  idx         INTEGER NOT NULL,
  time_s      REAL    NOT NULL,
  game_time_s REAL    NOT NULL,
  phase       TEXT    NOT NULL,
  points      INTEGER NOT NULL,
  reason      TEXT    NOT NULL,
  device      TEXT,
  order_id    INTEGER,
  puck        INTEGER,
  PRIMARY KEY (run_id, idx)
) WITHOUT ROWID;
CREATE TABLE events (
  run_id INTEGER NOT NULL REFERENCES runs (id) ON DELETE CASCADE,
  idx    INTEGER NOT NULL,
  time_s REAL    NOT NULL,
  kind   TEXT    NOT NULL,
  name   TEXT    NOT NULL,
  value  REAL,
  detail TEXT    NOT NULL,
  PRIMARY KEY (run_id, idx)
) WITHOUT ROWID;
CREATE INDEX runs_by_variant ON runs (batch_id, variant);
)sql";

// A store file as llsfsim before schema_migrations wrote it: version 2, or version 1 (without
// runs.recording), with one batch and one run.
void write_old_store(const std::string& db, int version) {
  sqlite3* h = nullptr;
  REQUIRE(sqlite3_open(db.c_str(), &h) == SQLITE_OK);
  REQUIRE(sqlite3_exec(h, kSchemaVersion2, nullptr, nullptr, nullptr) == SQLITE_OK);
  const std::string fill =
      "INSERT INTO batches (kind, scenario_file, scenario_name, scenario_hash, runs_per_variant, "
      "variants, seeds, llsfsim_version) VALUES ('batch', 'tiny.yaml', 'tiny', "
      "'0123456789abcdef', 2, 2, '1,2', '0.1.0');"
      "INSERT INTO runs (batch_id, scenario, variant, seed, llsfsim_version, result_hash, passed, "
      "points, game_time_s, cpu_s, real_time_factor) VALUES (1, 'tiny', 'a', 1, '0.1.0', "
      "'8ee4dd2ff8fea3e8', 1, 28, 60, 0.5, 120);"
      "INSERT INTO statistics VALUES (1, 'points', 28);" +
      std::string(version == 1 ? "ALTER TABLE runs DROP COLUMN recording;" : "") +
      "PRAGMA user_version = " + std::to_string(version) + ";";
  REQUIRE(sqlite3_exec(h, fill.c_str(), nullptr, nullptr, nullptr) == SQLITE_OK);
  sqlite3_close(h);
}

std::int64_t sqlite_int(const std::string& db, const char* sql) {
  sqlite3* h = nullptr;
  REQUIRE(sqlite3_open(db.c_str(), &h) == SQLITE_OK);
  sqlite3_stmt* q = nullptr;
  REQUIRE(sqlite3_prepare_v2(h, sql, -1, &q, nullptr) == SQLITE_OK);
  REQUIRE(sqlite3_step(q) == SQLITE_ROW);
  const std::int64_t v = sqlite3_column_int64(q, 0);
  sqlite3_finalize(q);
  sqlite3_close(h);
  return v;
}
}  // namespace

TEST_CASE("StatsStore (SQLite) opens and migrates the files of older llsfsim") {
  for (const int version : {1, 2}) {
    CAPTURE(version);
    const TempDir dir;
    const std::string db = dir.file("old.db");
    write_old_store(db, version);
    {
      StatsStore store(db);
      const std::int64_t batch = store.open_batch(sample_key());
      CHECK(batch == 1);  // found again: the same identity
      REQUIRE(store.runs(batch).size() == 1);
      CHECK(store.runs(batch)[0].points == 28);
      CHECK(store.runs(batch)[0].recording.empty());
      CHECK(store.count_rows("schema_migrations") == 4);
      // The stored run again: nothing written; a new run with a recording.
      CHECK(store.add_run(batch, sample_run("a", 1)) == 1);
      RunResult again = sample_run("b", 2);
      again.recording = dir.file("r.jsonl.gz");
      store.add_run(batch, again);
      CHECK(store.runs(batch).back().recording == again.recording);
    }
    CHECK(sqlite_int(db, "PRAGMA user_version") == 4);
    CHECK(sqlite_int(db, "SELECT max(version) FROM schema_migrations") == 4);
    // Versions applied now carry the time; older ones (applied before the table) do not.
    CHECK(sqlite_int(db, "SELECT count(*) FROM schema_migrations WHERE applied IS NULL") ==
          version);
    StatsStore reopened(db);  // nothing more to migrate
    CHECK(reopened.count_rows("runs") == 2);
  }
}

TEST_CASE("StatsStore (SQLite) refuses a store of a newer schema") {
  const TempDir dir;
  const std::string db = dir.file("new.db");
  { StatsStore store(db); }
  sqlite3* h = nullptr;
  REQUIRE(sqlite3_open(db.c_str(), &h) == SQLITE_OK);
  CHECK(sqlite3_exec(h, "INSERT INTO schema_migrations VALUES (5, 'future', NULL)", nullptr,
                     nullptr, nullptr) == SQLITE_OK);
  sqlite3_close(h);
  CHECK_THROWS_WITH_AS(StatsStore{db}, doctest::Contains("schema version 5"), StatsError);
}

// ---- PostgreSQL ------------------------------------------------------------------------------

TEST_CASE("masked_database_url hides passwords") {
  using llsf::study::masked_database_url;
  CHECK(masked_database_url("postgresql://ann:s3cret@db.lab:5432/study") ==
        "postgresql://ann:***@db.lab:5432/study");
  CHECK(masked_database_url("postgres://ann@db.lab/study?password=s3cret&sslmode=require") ==
        "postgres://ann@db.lab/study?password=***&sslmode=require");
  CHECK(masked_database_url("postgresql://ann:p%40ss@h/db?sslmode=disable&password=x") ==
        "postgresql://ann:***@h/db?sslmode=disable&password=***");
  CHECK(masked_database_url("postgresql://ann@h:5432/db") == "postgresql://ann@h:5432/db");
  CHECK(masked_database_url("postgresql:///db") == "postgresql:///db");
  CHECK(masked_database_url("dir/user:pw@x.db") == "dir/user:pw@x.db");  // a file name
  CHECK(llsf::study::is_database_url("postgresql://h/db"));
  CHECK(llsf::study::is_database_url("postgres://h/db"));
  CHECK_FALSE(llsf::study::is_database_url("llsfsim.db"));
  CHECK_FALSE(llsf::study::is_database_url("postgresql.db"));
  // Another scheme is not taken for a file name; the password masked there as well.
  const TempDir dir;
  const fs::path cwd = fs::current_path();
  fs::current_path(dir.path);
  for (const char* other : {"mysql://ann:s3cret@h/db", "POSTGRESQL://ann:s3cret@h/db"}) {
    CAPTURE(other);
    CHECK_THROWS_WITH_AS(StatsStore{other}, doctest::Contains("not a statistics store"),
                         StatsError);
    try {
      StatsStore store{other};
    } catch (const StatsError& e) {
      CHECK(std::string(e.what()).find("s3cret") == std::string::npos);
      CHECK(std::string(e.what()).find("ann:***@h/db") != std::string::npos);
    }
  }
  CHECK(fs::is_empty(dir.path));  // no file or directory made
  fs::current_path(cwd);
}

TEST_CASE("StatsStore (PostgreSQL): the cluster of the tests") {
  PgCluster& pg = PgCluster::shared();
  MESSAGE("initdb took " << pg.initdb_seconds() << " s; the server accepted connections after "
                         << pg.startup_seconds() << " s");
  CHECK(pg.psql("postgres", "SELECT 1") == "1");
}

TEST_CASE("scripts/test-postgres: a server for shell tests, stopped and removed afterwards") {
  const std::string dir =
      (fs::temp_directory_path() / ("llsf_pg_script_" + std::to_string(::getpid()))).string();
  std::string out;
  // CMD sees the URL; its exit status is the script's; DIR is gone afterwards.
  const int rc = PgCluster::run(
      {"/bin/bash", std::string(LLSF_SOURCE_DIR) + "/scripts/test-postgres", "run", dir, "/bin/sh",
       "-c", PgCluster::bin_dir() + "/psql -X -A -t -c 'SELECT 6 * 7' \"$LLSF_PG_URL\"; exit 3"},
      out);
  CHECK(rc == 3);
  CHECK(out.find("42") != std::string::npos);
  CHECK_FALSE(fs::exists(dir));
}

TEST_CASE("StatsStore (PostgreSQL): bad URLs and unreachable servers are clear errors") {
  PgCluster& pg = PgCluster::shared();
  const EnvVar no_password("PGPASSWORD", nullptr);
  auto error_of = [](const std::string& url) {
    try {
      StatsStore store(url);
    } catch (const StatsError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  // Not a URL libpq understands.
  const std::string bad = error_of("postgresql://llsf:hunter2@127.0.0.1:5432/db?nonsense=1");
  CHECK(bad.find("not a valid PostgreSQL URL") != std::string::npos);
  CHECK(bad.find("nonsense") != std::string::npos);
  CHECK(bad.find("hunter2") == std::string::npos);
  CHECK(bad.find("llsf:***@") != std::string::npos);
  // A closed port: refused at once, the password masked.
  const int closed = pg.port() == 1 ? 2 : 1;
  const std::string refused =
      error_of("postgresql://llsf:hunter2@127.0.0.1:" + std::to_string(closed) + "/x");
  CHECK(refused.find("cannot connect to the PostgreSQL server") != std::string::npos);
  CHECK(refused.find("hunter2") == std::string::npos);
  CHECK(refused.find("postgresql://llsf:***@127.0.0.1:" + std::to_string(closed) + "/x") !=
        std::string::npos);
  // Garbage: a StatsError each, never a crash or another exception.
  for (const std::string& garbage :
       std::vector<std::string>{"postgresql://[::1", "postgresql://a@b:99999999/x",
                                "postgres://%zz@/", "postgresql://h/db?sslmode=nonsense",
                                "postgresql://:@:/?&=", std::string("postgres://\x01\xff"),
                                "postgresql://" + std::string(5000, 'a')}) {
    CAPTURE(garbage);
    CHECK(error_of(garbage) != "no error");
  }
  // A database that does not exist, a role that does not exist.
  CHECK(error_of(pg.url("missing")).find("\"missing\" does not exist") != std::string::npos);
  CHECK(error_of("postgresql://nobody@127.0.0.1:" + std::to_string(pg.port()) + "/postgres")
            .find("\"nobody\" does not exist") != std::string::npos);
}

TEST_CASE("StatsStore (PostgreSQL): what the URL leaves out comes from PG* variables") {
  PgCluster& pg = PgCluster::shared();
  const std::string url = pg.create_database();
  { StatsStore(url).open_batch(sample_key()); }
  const EnvVar host("PGHOST", "127.0.0.1");
  const EnvVar port("PGPORT", std::to_string(pg.port()).c_str());
  const EnvVar user("PGUSER", "llsf");
  const EnvVar database("PGDATABASE", db_name(url).c_str());
  const StatsStore store("postgresql://");
  CHECK(store.path() == "postgresql://");
  CHECK(store.batches().size() == 1);
  const StatsStore other("postgres:///" + db_name(url));  // host, port, user from the variables
  CHECK(other.batches().size() == 1);
}

TEST_CASE("StatsStore (PostgreSQL): refuses databases that are not a store, or newer") {
  PgCluster& pg = PgCluster::shared();
  const std::string url = pg.create_database();
  pg.psql(db_name(url), "CREATE TABLE runs (id int)");
  CHECK_THROWS_WITH_AS(StatsStore{url}, doctest::Contains("not an llsfsim statistics store"),
                       StatsError);
  const std::string newer = pg.create_database();
  { StatsStore store(newer); }
  pg.psql(db_name(newer), "INSERT INTO schema_migrations VALUES (5, 'future', NULL)");
  CHECK_THROWS_WITH_AS(StatsStore{newer}, doctest::Contains("schema version 5"), StatsError);
  // Other tables of the database do not matter (a lab's shared database).
  const std::string shared = pg.create_database();
  pg.psql(db_name(shared), "CREATE TABLE notes (t text)");
  CHECK_NOTHROW(StatsStore{shared});
}

TEST_CASE("StatsStore (PostgreSQL): a new store created by two processes at once") {
  PgCluster& pg = PgCluster::shared();
  const std::string url = pg.create_database();
  // Two processes (fork before any connection), each creating the schema and writing one run.
  std::vector<pid_t> children;
  for (int w = 0; w < 2; ++w) {
    const pid_t pid = ::fork();
    if (pid == 0) {
      int code = 0;
      try {
        StatsStore store(url);
        store.add_run(store.open_batch(sample_key()), sample_run("v", static_cast<unsigned>(w)));
      } catch (...) {
        code = 1;
      }
      ::_exit(code);
    }
    children.push_back(pid);
  }
  for (const pid_t pid : children) {
    int status = -1;
    ::waitpid(pid, &status, 0);
    CHECK((WIFEXITED(status) && WEXITSTATUS(status) == 0));
  }
  const StatsStore store(url);
  CHECK(store.count_rows("schema_migrations") == 4);
  REQUIRE(store.batches().size() == 1);
  CHECK(store.runs(store.batches()[0].id).size() == 2);
}

TEST_CASE("StatsStore (PostgreSQL): a read-only role cannot write") {
  PgCluster& pg = PgCluster::shared();
  const std::string url = pg.create_database();
  { StatsStore(url).open_batch(sample_key()); }
  pg.psql(db_name(url),
          "DO $$ BEGIN IF NOT EXISTS (SELECT FROM pg_roles WHERE rolname = 'reader') THEN "
          "CREATE ROLE reader LOGIN; END IF; END $$; GRANT SELECT ON ALL TABLES IN SCHEMA public "
          "TO reader");
  const StatsStore store("postgresql://reader@127.0.0.1:" + std::to_string(pg.port()) + "/" +
                         db_name(url));
  CHECK(store.batches().size() == 1);  // reading works
  CHECK_THROWS_WITH_AS(store.require_writable(), doctest::Contains("reader may not write"),
                       StatsError);
  CHECK_NOTHROW(StatsStore{url}.require_writable());
}

TEST_CASE("StatsStore (PostgreSQL): a server restart between writes and in the middle of a run") {
  PgCluster& pg = PgCluster::shared();
  const std::string url = pg.create_database();
  StatsStore store(url);
  const std::int64_t batch = store.open_batch(sample_key());
  store.add_run(batch, sample_run("a", 1));

  // Between writes: the store's connection is gone; the next write reconnects.
  pg.stop("fast");
  pg.start();
  store.add_run(batch, sample_run("a", 2));
  CHECK(store.runs(batch).size() == 2);

  // Down for good: an error once the retry window (LLSF_DB_RETRY_S) has passed.
  {
    const EnvVar window("LLSF_DB_RETRY_S", "0.5");
    StatsStore short_window(url);
    pg.stop("fast");
    CHECK_THROWS_WITH_AS(short_window.add_run(batch, sample_run("a", 3)),
                         doctest::Contains("could not reconnect within"), StatsError);
    pg.start();
    short_window.add_run(batch, sample_run("a", 3));  // and back again
  }

  // In the middle of a run: another session locks `events`, so the run's transaction waits
  // there with its run, statistics, orders, tests and awards written; then the server stops.
  // The half-written run is rolled back; the store reconnects and writes it whole, once.
  const std::int64_t before = run_rows(store);
  const std::string lock_file = pg.dir() + "/lock.sql";
  std::atomic<bool> locked{false};
  std::thread locker([&] {
    std::string out;
    // psql holds the lock inside a transaction until the server goes away.
    PgCluster::run({PgCluster::bin_dir() + "/psql", "-X", "-q", "-d", url, "-c",
                    "BEGIN; LOCK TABLE events IN ACCESS EXCLUSIVE MODE; SELECT pg_sleep(60);"},
                   out);
  });
  // Wait for the lock to be held.
  for (int i = 0; i < 200 && !locked; ++i) {
    locked = pg.psql(db_name(url),
                     "SELECT count(*) FROM pg_locks l JOIN pg_class c ON c.oid = l.relation "
                     "WHERE c.relname = 'events' AND l.mode = 'AccessExclusiveLock' AND "
                     "l.granted") == "1";
    if (!locked) std::this_thread::sleep_for(std::chrono::milliseconds(25));
  }
  REQUIRE(locked);
  std::atomic<bool> stored{false};
  std::string write_error;
  std::thread writer([&] {
    try {
      store.add_run(batch, sample_run("b", 1));
      stored = true;
    } catch (const std::exception& e) {
      write_error = e.what();
    }
  });
  // Wait until the run's transaction waits for the lock (its other rows written).
  bool waiting = false;
  for (int i = 0; i < 400 && !waiting; ++i) {
    waiting = pg.psql(db_name(url),
                      "SELECT count(*) FROM pg_stat_activity WHERE application_name = 'llsfsim' "
                      "AND wait_event_type = 'Lock' AND query LIKE 'INSERT INTO events%'") == "1";
    if (!waiting) std::this_thread::sleep_for(std::chrono::milliseconds(25));
  }
  CHECK(waiting);
  CHECK_FALSE(stored);
  pg.stop("fast");  // ends both sessions: the run's transaction is rolled back
  locker.join();
  pg.start();
  writer.join();
  CHECK(write_error.empty());
  CHECK(stored);
  CHECK(run_rows(store) == before + rows_of_one_run());  // the run once, whole
  CHECK(store.runs(batch).size() == 4);
}
