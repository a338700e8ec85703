// SPDX-License-Identifier: MIT
#include "llsf/study/stats_store.h"

#include <sqlite3.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <cinttypes>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <optional>
#include <set>
#include <sstream>

#include "llsf/core/data_dir.h"
#include "llsf/core/input_file.h"
#include "llsf/core/rng.h"
#include "llsf/core/version.h"
#include "llsf/sim/agent_brain.h"
#include "llsf/sim/skill_brain.h"

namespace llsf::study {

namespace {

// The schema (docs/statistics.md explains every column). `PRAGMA user_version` holds
// kSchemaVersion; a file with another version is refused rather than misread.
constexpr int kSchemaVersion = 2;
constexpr const char* kSchema = R"sql(
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

constexpr std::array<std::string_view, 7> kTables = {"batches", "runs",   "statistics", "orders",
                                                     "tests",   "awards", "events"};

std::string hex16(std::uint64_t v) {
  char buf[17];
  std::snprintf(buf, sizeof buf, "%016" PRIx64, v);
  return buf;
}

std::uint64_t parse_hex16(const std::string& s) {
  return s.empty() ? 0 : std::stoull(s, nullptr, 16);
}

// ---- RAII wrappers of the SQLite C API -------------------------------------------------------

struct DbCloser {
  void operator()(sqlite3* db) const { sqlite3_close_v2(db); }
};
struct StmtFinalizer {
  void operator()(sqlite3_stmt* s) const { sqlite3_finalize(s); }
};
using DbHandle = std::unique_ptr<sqlite3, DbCloser>;

// A prepared statement. start() resets it and clears its bindings; a Statement that returned
// rows is reset by the next start() or by finish().
class Statement {
 public:
  Statement(sqlite3* db, const std::string& path, std::string_view sql) : db_(db), path_(&path) {
    sqlite3_stmt* s = nullptr;
    if (sqlite3_prepare_v3(db, sql.data(), static_cast<int>(sql.size()), SQLITE_PREPARE_PERSISTENT,
                           &s, nullptr) != SQLITE_OK) {
      fail("prepare");
    }
    stmt_.reset(s);
  }

  Statement& start() {
    sqlite3_reset(stmt_.get());
    sqlite3_clear_bindings(stmt_.get());
    next_ = 1;
    return *this;
  }
  Statement& bind(std::int64_t v) { return check(sqlite3_bind_int64(stmt_.get(), next_++, v)); }
  Statement& bind(int v) { return bind(static_cast<std::int64_t>(v)); }
  Statement& bind(double v) { return check(sqlite3_bind_double(stmt_.get(), next_++, v)); }
  Statement& bind(std::string_view v) {
    return check(sqlite3_bind_text(stmt_.get(), next_++, v.data(), static_cast<int>(v.size()),
                                   SQLITE_TRANSIENT));
  }
  Statement& bind_null() { return check(sqlite3_bind_null(stmt_.get(), next_++)); }

  // One step: true if a row is ready, false when done.
  bool step() {
    const int rc = sqlite3_step(stmt_.get());
    if (rc == SQLITE_ROW) return true;
    if (rc == SQLITE_DONE) return false;
    fail("step");
  }
  // Runs a statement that returns no rows.
  void run() {
    while (step()) {
    }
    finish();
  }
  void finish() { sqlite3_reset(stmt_.get()); }

  std::int64_t int64(int col) const { return sqlite3_column_int64(stmt_.get(), col); }
  double real(int col) const { return sqlite3_column_double(stmt_.get(), col); }
  bool null(int col) const { return sqlite3_column_type(stmt_.get(), col) == SQLITE_NULL; }
  std::string text(int col) const {
    const auto* p = sqlite3_column_text(stmt_.get(), col);
    return p ? std::string(reinterpret_cast<const char*>(p),
                           static_cast<std::size_t>(sqlite3_column_bytes(stmt_.get(), col)))
             : std::string();
  }

 private:
  Statement& check(int rc) {
    if (rc != SQLITE_OK) fail("bind");
    return *this;
  }
  [[noreturn]] void fail(const char* what) const {
    // Reset so that a failed statement does not keep the database locked.
    if (stmt_) sqlite3_reset(stmt_.get());
    throw StatsError(*path_ + ": " + what + ": " + sqlite3_errmsg(db_));
  }

  sqlite3* db_;
  const std::string* path_;
  std::unique_ptr<sqlite3_stmt, StmtFinalizer> stmt_;
  int next_ = 1;
};

void exec(sqlite3* db, const std::string& path, const char* sql) {
  char* msg = nullptr;
  if (sqlite3_exec(db, sql, nullptr, nullptr, &msg) != SQLITE_OK) {
    std::string text = msg ? msg : sqlite3_errmsg(db);
    sqlite3_free(msg);
    throw StatsError(path + ": " + text);
  }
}

// BEGIN IMMEDIATE .. COMMIT; rolled back unless committed (also when an exception unwinds).
class Transaction {
 public:
  Transaction(sqlite3* db, const std::string& path) : db_(db), path_(path) {
    exec(db_, path_, "BEGIN IMMEDIATE");
  }
  ~Transaction() {
    if (!done_) sqlite3_exec(db_, "ROLLBACK", nullptr, nullptr, nullptr);
  }
  Transaction(const Transaction&) = delete;
  Transaction& operator=(const Transaction&) = delete;
  void commit() {
    exec(db_, path_, "COMMIT");
    done_ = true;
  }

 private:
  sqlite3* db_;
  const std::string& path_;
  bool done_ = false;
};

std::string join_seeds(const std::vector<std::uint64_t>& seeds) {
  std::string out;
  for (std::size_t i = 0; i < seeds.size(); ++i) {
    if (i > 0) out += ',';
    out += std::to_string(seeds[i]);
  }
  return out;
}

}  // namespace

std::string_view llsfsim_version() { return core::kVersion; }

// ---- StatsStore ------------------------------------------------------------------------------

struct StatsStore::Impl {
  std::string path;
  DbHandle db;
  // Prepared once, used for every run.
  std::unique_ptr<Statement> list_batches;
  std::unique_ptr<Statement> find_batch, insert_batch, finish_batch, get_batch, delete_run,
      insert_run, insert_stat, insert_order, insert_test, insert_award, insert_event, select_runs,
      select_run, select_stats, select_awards;

  explicit Impl(std::string p) : path(std::move(p)) {
    sqlite3* raw = nullptr;
    const int rc =
        sqlite3_open_v2(path.c_str(), &raw, SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE, nullptr);
    db.reset(raw);  // closed even if opening failed
    if (rc != SQLITE_OK) {
      throw StatsError(path + ": cannot open the statistics store: " +
                       (raw ? sqlite3_errmsg(raw) : "out of memory"));
    }
    sqlite3_extended_result_codes(db.get(), 1);
    sqlite3_busy_timeout(db.get(), 10000);
    exec(db.get(), path, "PRAGMA foreign_keys = ON");
    create_schema();
    prepare();
  }

  Statement stmt(std::string_view sql) { return Statement(db.get(), path, sql); }
  std::unique_ptr<Statement> prep(std::string_view sql) {
    return std::make_unique<Statement>(db.get(), path, sql);
  }

  void create_schema() {
    Transaction t(db.get(), path);
    Statement v = stmt("PRAGMA user_version");
    const int version = v.start().step() ? static_cast<int>(v.int64(0)) : 0;
    v.finish();
    if (version == kSchemaVersion) return;  // rolled back: nothing was written
    if (version == 1) {                     // version 2 added runs.recording
      exec(db.get(), path, "ALTER TABLE runs ADD COLUMN recording TEXT");
      exec(db.get(), path, ("PRAGMA user_version = " + std::to_string(kSchemaVersion)).c_str());
      t.commit();
      return;
    }
    if (version != 0) {
      throw StatsError(path + ": schema version " + std::to_string(version) +
                       " (this llsfsim reads version " + std::to_string(kSchemaVersion) + ")");
    }
    Statement tables = stmt("SELECT count(*) FROM sqlite_schema");
    const std::int64_t n = tables.start().step() ? tables.int64(0) : 0;
    tables.finish();
    if (n != 0) throw StatsError(path + ": not an llsfsim statistics store (it has other tables)");
    exec(db.get(), path, kSchema);
    exec(db.get(), path, ("PRAGMA user_version = " + std::to_string(kSchemaVersion)).c_str());
    t.commit();
  }

  void prepare() {
    find_batch = prep(
        "SELECT id FROM batches WHERE kind = ? AND scenario_hash = ? AND runs_per_variant = ?");
    insert_batch = prep(
        "INSERT INTO batches (kind, scenario_file, scenario_name, scenario_hash, "
        "runs_per_variant, variants, seeds, llsfsim_version) VALUES (?, ?, ?, ?, ?, ?, ?, ?)");
    finish_batch = prep(
        "UPDATE batches SET finished = strftime('%Y-%m-%dT%H:%M:%SZ', 'now') "
        "WHERE id = ? AND finished IS NULL");
    get_batch = prep(
        "SELECT id, kind, created, coalesce(finished, ''), scenario_file, scenario_name, "
        "scenario_hash, runs_per_variant, variants, seeds FROM batches WHERE id = ?");
    list_batches = prep("SELECT id FROM batches ORDER BY id");
    delete_run = prep("DELETE FROM runs WHERE batch_id = ? AND variant = ? AND seed = ?");
    insert_run = prep(
        "INSERT INTO runs (batch_id, scenario, variant, seed, llsfsim_version, result_hash, "
        "passed, points, game_time_s, cpu_s, real_time_factor, recording) "
        "VALUES (?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?)");
    insert_stat = prep("INSERT INTO statistics (run_id, name, value) VALUES (?, ?, ?)");
    insert_order = prep(
        "INSERT INTO orders (run_id, order_id, product, requested, delivered, window_begin_s, "
        "window_end_s) VALUES (?, ?, ?, ?, ?, ?, ?)");
    insert_test = prep(
        "INSERT INTO tests (run_id, idx, name, passed, detail, at_s) VALUES (?, ?, ?, ?, ?, ?)");
    insert_award = prep(
        "INSERT INTO awards (run_id, idx, time_s, game_time_s, phase, points, reason, device, "
        "order_id, puck) VALUES (?, ?, ?, ?, ?, ?, ?, ?, ?, ?)");
    insert_event = prep(
        "INSERT INTO events (run_id, idx, time_s, kind, name, value, detail) "
        "VALUES (?, ?, ?, ?, ?, ?, ?)");
    static constexpr const char* kRunColumns =
        "SELECT id, batch_id, scenario, variant, seed, llsfsim_version, result_hash, passed, "
        "points, game_time_s, cpu_s, real_time_factor, recording FROM runs ";
    select_runs = prep(std::string(kRunColumns) + "WHERE batch_id = ? ORDER BY id");
    select_run = prep(std::string(kRunColumns) + "WHERE id = ?");
    select_stats = prep("SELECT name, value FROM statistics WHERE run_id = ? ORDER BY name");
    select_awards = prep(
        "SELECT time_s, game_time_s, phase, points, reason, coalesce(device, ''), "
        "coalesce(order_id, -1), coalesce(puck, -1) FROM awards WHERE run_id = ? ORDER BY idx");
  }
};

namespace {
// The store's directory is created if missing (a failure shows when SQLite opens the file).
const std::string& with_parent_dir(const std::string& path) {
  const std::filesystem::path dir = std::filesystem::path(path).parent_path();
  std::error_code ec;
  if (!dir.empty()) std::filesystem::create_directories(dir, ec);
  return path;
}
}  // namespace

StatsStore::StatsStore(const std::string& path)
    : impl_(std::make_unique<Impl>(with_parent_dir(path))) {}
StatsStore::~StatsStore() = default;
StatsStore::StatsStore(StatsStore&&) noexcept = default;
StatsStore& StatsStore::operator=(StatsStore&&) noexcept = default;

const std::string& StatsStore::path() const { return impl_->path; }

void StatsStore::require_writable() const {
  const Impl& m = *impl_;
  if (sqlite3_db_readonly(m.db.get(), "main") == 1) {
    throw StatsError(m.path + ": the statistics store is read-only: no run can be written to it");
  }
  std::error_code ec;
  std::filesystem::path dir = std::filesystem::absolute(m.path, ec).parent_path();
  if (ec || dir.empty()) dir = ".";
  if (::access(dir.c_str(), W_OK | X_OK) != 0) {
    throw StatsError(m.path + ": the statistics store's directory " + dir.string() +
                     " is not writable (SQLite writes its journal there): " +
                     std::error_code(errno, std::generic_category()).message());
  }
}

std::int64_t StatsStore::open_batch(const BatchKey& key) {
  Impl& m = *impl_;
  const std::string_view kind = key.kind == BatchKey::Kind::kBatch ? "batch" : "run";
  Transaction t(m.db.get(), m.path);
  Statement& f = *m.find_batch;
  f.start().bind(kind).bind(std::string_view(key.scenario_hash)).bind(key.runs_per_variant);
  if (f.step()) {
    const std::int64_t id = f.int64(0);
    f.finish();
    return id;  // the transaction rolls back: nothing was written
  }
  m.insert_batch->start()
      .bind(kind)
      .bind(std::string_view(key.scenario_file))
      .bind(std::string_view(key.scenario_name))
      .bind(std::string_view(key.scenario_hash))
      .bind(key.runs_per_variant)
      .bind(std::max(1, key.variants))
      .bind(std::string_view(join_seeds(key.seeds)))
      .bind(llsfsim_version())
      .run();
  const std::int64_t id = sqlite3_last_insert_rowid(m.db.get());
  t.commit();
  return id;
}

void StatsStore::finish_batch(std::int64_t batch_id) {
  impl_->finish_batch->start().bind(batch_id).run();
}

std::optional<StoredBatch> StatsStore::batch(std::int64_t batch_id) const {
  Statement& q = *impl_->get_batch;
  q.start().bind(batch_id);
  if (!q.step()) return std::nullopt;
  StoredBatch b;
  b.id = q.int64(0);
  b.kind = q.text(1);
  b.created = q.text(2);
  b.finished = q.text(3);
  b.scenario_file = q.text(4);
  b.scenario_name = q.text(5);
  b.scenario_hash = q.text(6);
  b.runs_per_variant = static_cast<int>(q.int64(7));
  b.variants = static_cast<int>(q.int64(8));
  b.seeds = q.text(9);
  q.finish();
  return b;
}

std::vector<StoredBatch> StatsStore::batches() const {
  std::vector<std::int64_t> ids;
  Statement& q = *impl_->list_batches;
  q.start();
  while (q.step()) ids.push_back(q.int64(0));
  q.finish();
  std::vector<StoredBatch> out;
  for (const std::int64_t id : ids) {
    if (auto b = batch(id)) out.push_back(std::move(*b));
  }
  return out;
}

std::int64_t StatsStore::add_run(std::int64_t batch_id, const RunResult& r, bool replace) {
  Impl& m = *impl_;
  const auto seed = static_cast<std::int64_t>(r.seed);  // bit-preserving for seeds >= 2^63
  Transaction t(m.db.get(), m.path);
  if (replace)
    m.delete_run->start().bind(batch_id).bind(std::string_view(r.variant)).bind(seed).run();

  // The run, then its children; any failure unwinds through the transaction's rollback.
  m.insert_run->start()
      .bind(batch_id)
      .bind(std::string_view(r.scenario))
      .bind(std::string_view(r.variant))
      .bind(seed)
      .bind(llsfsim_version())
      .bind(std::string_view(hex16(r.result_hash)))
      .bind(r.passed() ? 1 : 0)
      .bind(r.points)
      .bind(r.game_time_s)
      .bind(r.cpu_s)
      .bind(r.real_time_factor);
  if (r.recording.empty())
    m.insert_run->bind_null();
  else
    m.insert_run->bind(std::string_view(stored_recording_path(m.path, r.recording)));
  m.insert_run->run();
  const std::int64_t run_id = sqlite3_last_insert_rowid(m.db.get());

  for (const auto& [name, value] : numeric_statistics(r)) {
    m.insert_stat->start().bind(run_id).bind(std::string_view(name)).bind(value).run();
  }
  for (const OrderResult& o : r.orders) {
    m.insert_order->start()
        .bind(run_id)
        .bind(o.id)
        .bind(std::string_view(o.product))
        .bind(o.requested)
        .bind(o.delivered)
        .bind(o.window_begin_s)
        .bind(o.window_end_s)
        .run();
  }
  for (std::size_t i = 0; i < r.tests.size(); ++i) {
    const TestVerdict& v = r.tests[i];
    m.insert_test->start()
        .bind(static_cast<std::int64_t>(run_id))
        .bind(static_cast<std::int64_t>(i))
        .bind(std::string_view(v.name))
        .bind(v.passed ? 1 : 0)
        .bind(std::string_view(v.detail))
        .bind(v.at_s)
        .run();
  }
  for (std::size_t i = 0; i < r.awards.size(); ++i) {
    const RunAward& a = r.awards[i];
    Statement& s = *m.insert_award;
    s.start()
        .bind(run_id)
        .bind(static_cast<std::int64_t>(i))
        .bind(a.time_s)
        .bind(a.game_time_s)
        .bind(std::string_view(a.phase))
        .bind(a.points)
        .bind(std::string_view(a.reason));
    if (a.device.empty())
      s.bind_null();
    else
      s.bind(std::string_view(a.device));
    if (a.order < 0)
      s.bind_null();
    else
      s.bind(a.order);
    if (a.puck < 0)
      s.bind_null();
    else
      s.bind(a.puck);
    s.run();
  }

  // Events: the awards and the test verdicts, in game-time order (awards first on ties).
  struct Event {
    double time_s;
    std::string_view kind;
    std::string_view name;
    double value;
    std::string detail;
  };
  std::vector<Event> events;
  events.reserve(r.awards.size() + r.tests.size());
  for (const RunAward& a : r.awards) {
    std::string detail = a.phase;
    if (!a.device.empty()) detail += " " + a.device;
    if (a.order >= 0) detail += " order " + std::to_string(a.order);
    if (a.puck >= 0) detail += " puck " + std::to_string(a.puck);
    events.push_back({a.time_s, "award", a.reason, static_cast<double>(a.points), detail});
  }
  for (const TestVerdict& v : r.tests) {
    events.push_back(
        {v.at_s, v.passed ? "test_passed" : "test_failed", v.name, v.passed ? 1.0 : 0.0, v.detail});
  }
  std::stable_sort(events.begin(), events.end(),
                   [](const Event& a, const Event& b) { return a.time_s < b.time_s; });
  for (std::size_t i = 0; i < events.size(); ++i) {
    const Event& e = events[i];
    m.insert_event->start()
        .bind(run_id)
        .bind(static_cast<std::int64_t>(i))
        .bind(e.time_s)
        .bind(e.kind)
        .bind(e.name)
        .bind(e.value)
        .bind(std::string_view(e.detail))
        .run();
  }
  t.commit();
  return run_id;
}

namespace {
// One row of Impl::select_runs / select_run.
StoredRun read_run(const Statement& q, const std::string& db_path) {
  StoredRun s;
  s.id = q.int64(0);
  s.batch_id = q.int64(1);
  s.scenario = q.text(2);
  s.variant = q.text(3);
  s.seed = static_cast<std::uint64_t>(q.int64(4));
  s.llsfsim_version = q.text(5);
  s.result_hash = parse_hex16(q.text(6));
  s.passed = q.int64(7) != 0;
  s.points = static_cast<int>(q.int64(8));
  s.game_time_s = q.real(9);
  s.cpu_s = q.real(10);
  s.real_time_factor = q.real(11);
  s.recording = q.null(12) ? std::string() : resolved_recording_path(db_path, q.text(12));
  return s;
}
}  // namespace

std::vector<StoredRun> StatsStore::runs(std::int64_t batch_id) const {
  Statement& q = *impl_->select_runs;
  q.start().bind(batch_id);
  std::vector<StoredRun> out;
  while (q.step()) out.push_back(read_run(q, impl_->path));
  return out;
}

std::optional<StoredRun> StatsStore::run(std::int64_t run_id) const {
  Statement& q = *impl_->select_run;
  q.start().bind(run_id);
  std::optional<StoredRun> out;
  if (q.step()) out = read_run(q, impl_->path);
  q.finish();
  return out;
}

std::vector<std::pair<std::string, std::uint64_t>> StatsStore::run_keys(
    std::int64_t batch_id) const {
  std::vector<std::pair<std::string, std::uint64_t>> out;
  for (const StoredRun& r : runs(batch_id)) out.emplace_back(r.variant, r.seed);
  return out;
}

std::vector<std::pair<std::string, double>> StatsStore::statistics(std::int64_t run_id) const {
  Statement& q = *impl_->select_stats;
  q.start().bind(run_id);
  std::vector<std::pair<std::string, double>> out;
  while (q.step()) out.emplace_back(q.text(0), q.real(1));
  return out;
}

std::vector<RunAward> StatsStore::awards(std::int64_t run_id) const {
  Statement& q = *impl_->select_awards;
  q.start().bind(run_id);
  std::vector<RunAward> out;
  while (q.step()) {
    RunAward& a = out.emplace_back();
    a.time_s = q.real(0);
    a.game_time_s = q.real(1);
    a.phase = q.text(2);
    a.points = static_cast<int>(q.int64(3));
    a.reason = q.text(4);
    a.device = q.text(5);
    a.order = static_cast<int>(q.int64(6));
    a.puck = static_cast<int>(q.int64(7));
  }
  return out;
}

std::int64_t StatsStore::count_rows(std::string_view table) const {
  if (std::find(kTables.begin(), kTables.end(), table) == kTables.end()) {
    throw StatsError(impl_->path + ": no table '" + std::string(table) + "'");
  }
  Statement q = impl_->stmt("SELECT count(*) FROM " + std::string(table));
  const std::int64_t n = q.start().step() ? q.int64(0) : 0;
  q.finish();
  return n;
}

// ---- Free functions --------------------------------------------------------------------------

namespace {
// An input file's bytes for a hash, read as the loaders read it (regular files only, within the
// size limit: a named pipe among the agent files must not block the batch).
std::string hashed_file_bytes(const std::string& path) {
  std::string error;
  std::optional<std::string> bytes =
      core::try_read_input_file(path, core::kMaxSourceBytes, "input file", error);
  if (!bytes) throw StatsError(error);
  return std::move(*bytes);
}
}  // namespace

std::string file_content_hash(const std::string& path) {
  return hex16(core::fnv1a(std::string_view(hashed_file_bytes(path))));
}

std::string batch_identity_hash(const std::string& scenario_path, const ScenarioFile& file) {
  namespace fs = std::filesystem;
  std::set<std::string> files;  // sorted, each once
  for (const Scenario& s : file.variants) {
    for (const RobotSpec& r : s.robots) {
      for (const std::string& f : sim::agent_files(r.agent)) files.insert(f);
    }
    const std::vector<std::string> dirs = s.skills.skill_dirs.empty()
                                              ? sim::skill_library_dirs(s.game.levels.skill)
                                              : s.skills.skill_dirs;
    for (const std::string& d : dirs) {
      std::error_code ec;
      if (!fs::is_directory(d, ec)) continue;  // (the skill engine reports a missing directory)
      for (const auto& e : fs::recursive_directory_iterator(d, ec)) {
        if (e.is_regular_file() && e.path().extension() == ".lua") files.insert(e.path().string());
      }
    }
  }
  std::uint64_t h = core::fnv1a(std::string_view(hashed_file_bytes(scenario_path)));
  for (const std::string& f : files) {
    // The name relative to the data directory when inside it (a moved checkout keeps its ids).
    const std::string data = core::data_dir() + "/";
    const std::string name = f.starts_with(data) ? f.substr(data.size()) : f;
    h = core::fnv1a(std::string_view(name), h);
    h = core::fnv1a(std::string_view(hashed_file_bytes(f)), h);
  }
  return hex16(h);
}

std::string stored_recording_path(const std::string& db_path, const std::string& recording) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::path base = fs::absolute(fs::path(db_path).parent_path(), ec);
  const fs::path file = fs::absolute(recording, ec);
  if (ec) return recording;
  const fs::path rel = file.lexically_normal().lexically_relative(base.lexically_normal());
  // Inside the database's directory: relative (the pair can move together); else absolute.
  if (rel.empty() || *rel.begin() == "..") return file.lexically_normal().string();
  return rel.string();
}

std::string resolved_recording_path(const std::string& db_path, const std::string& stored) {
  namespace fs = std::filesystem;
  const fs::path p(stored);
  if (p.is_absolute()) return stored;
  return (fs::path(db_path).parent_path() / p).lexically_normal().string();
}

std::vector<std::pair<std::string, double>> numeric_statistics(const RunResult& r) {
  int requested = 0;
  int delivered = 0;
  for (const OrderResult& o : r.orders) {
    requested += o.requested;
    delivered += o.delivered;
  }
  int tests_failed = 0;
  for (const TestVerdict& t : r.tests) tests_failed += t.passed ? 0 : 1;
  auto d = [](auto v) { return static_cast<double>(v); };
  return {
      {"game_time_s", r.game_time_s},
      {"points", d(r.points)},
      {"exploration_points", d(r.exploration_points)},
      {"production_points", d(r.production_points)},
      {"exploration_reports", d(r.exploration_reports)},
      {"exploration_correct", d(r.exploration_correct)},
      {"deliveries", d(r.deliveries)},
      {"products_p1", d(r.products_p1)},
      {"products_p2", d(r.products_p2)},
      {"products_p3", d(r.products_p3)},
      {"recycled", d(r.recycled)},
      {"recycle_points", d(r.recycle_points)},
      {"collisions", d(r.collisions)},
      {"skill_failures", d(r.skill_failures)},
      {"agent_runtime_errors", d(r.agent_runtime_errors)},
      {"lock_grants", d(r.lock_grants)},
      {"lock_refusals", d(r.lock_refusals)},
      {"lock_waits", d(r.lock_waits)},
      {"lock_wait_s", r.lock_wait_s},
      {"lock_wait_max_s", r.lock_wait_max_s},
      {"lock_hold_max_s", r.lock_hold_max_s},
      {"first_complex_s", r.first_complex_s},
      {"role_changes", d(r.role_changes)},
      {"first_role_change_s", r.first_role_change_s},
      {"storage_min", d(r.storage_min)},
      {"storage_empty_s", r.storage_empty_s},
      {"jams", d(r.jams)},
      {"jammed_at_end", d(r.jammed_at_end)},
      {"skill_failure_streak_max", d(r.skill_failure_streak_max)},
      {"messages_sent", d(r.messages_sent)},
      {"messages_dropped", d(r.messages_dropped)},
      {"cpu_s", r.cpu_s},
      {"real_time_factor", r.real_time_factor},
      {"orders", d(r.orders.size())},
      {"order_units_requested", d(requested)},
      {"order_units_delivered", d(delivered)},
      {"awards", d(r.awards.size())},
      {"tests", d(r.tests.size())},
      {"tests_failed", d(tests_failed)},
      {"passed", r.passed() ? 1.0 : 0.0},
  };
}

}  // namespace llsf::study
