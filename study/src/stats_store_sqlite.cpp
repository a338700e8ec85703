// SPDX-License-Identifier: MIT
// The statistics store in one SQLite file (the default backend; docs/statistics.md).
#include <sqlite3.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <filesystem>
#include <memory>
#include <string>

#include "sqlite_util.h"
#include "stats_backend.h"

namespace llsf::study {

namespace {

// The migrations in SQLite's dialect (schema_sql, stats_store.cpp). Version 2 and earlier kept
// the version in `PRAGMA user_version` only; it is still written, so that an older llsfsim
// refuses a newer file rather than misreading it.
const std::array<std::string, kSchemaVersion>& sqlite_migrations() {
  static const std::array<std::string, kSchemaVersion> sql = schema_sql(kSqliteDialect);
  return sql;
}

// ---- RAII wrappers of the SQLite C API -------------------------------------------------------

using sqlite::DbCloser;
using sqlite::StmtFinalizer;
using DbHandle = std::unique_ptr<sqlite3, DbCloser>;

using sqlite::exec;
using sqlite::Statement;
using sqlite::Transaction;

// The store's folder must exist: a typo in `--db` (or a path meant for another machine) is the
// user's error, not a folder to create (docs/llsfsim.md; a folder made at `/` by a run as root).
const std::string& in_existing_dir(const std::string& path) {
  const std::filesystem::path dir = std::filesystem::path(path).parent_path();
  std::error_code ec;
  if (!dir.empty() && !std::filesystem::is_directory(dir, ec)) {
    throw StatsError(path + ": cannot open the statistics store: the folder " + dir.string() +
                     " does not exist");
  }
  return path;
}

// ---- The backend -----------------------------------------------------------------------------

class SqliteBackend final : public StatsBackend {
 public:
  explicit SqliteBackend(const std::string& p) : path_(in_existing_dir(p)) {
    sqlite3* raw = nullptr;
    const int rc =
        sqlite3_open_v2(path_.c_str(), &raw, SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE, nullptr);
    db_.reset(raw);  // closed even if opening failed
    if (rc != SQLITE_OK) {
      throw StatsError(path_ + ": cannot open the statistics store: " +
                       (raw ? sqlite3_errmsg(raw) : "out of memory"));
    }
    sqlite3_extended_result_codes(db_.get(), 1);
    sqlite3_busy_timeout(db_.get(), 10000);
    exec(db_.get(), path_, "PRAGMA foreign_keys = ON");
    migrate();
    prepare();
  }

  const std::string& path() const override { return path_; }

  void require_writable() const override {
    if (sqlite3_db_readonly(db_.get(), "main") == 1) {
      throw StatsError(path_ + ": the statistics store is read-only: no run can be written to it");
    }
    std::error_code ec;
    std::filesystem::path dir = std::filesystem::absolute(path_, ec).parent_path();
    if (ec || dir.empty()) dir = ".";
    if (::access(dir.c_str(), W_OK | X_OK) != 0) {
      throw StatsError(path_ + ": the statistics store's directory " + dir.string() +
                       " is not writable (SQLite writes its journal there): " +
                       std::error_code(errno, std::generic_category()).message());
    }
  }

  std::int64_t open_batch(const BatchKey& key) override {
    const std::string_view kind = key.kind == BatchKey::Kind::kBatch ? "batch" : "run";
    Transaction t(db_.get(), path_);
    Statement& f = *find_batch_;
    f.start().bind(kind).bind(std::string_view(key.scenario_hash)).bind(key.runs_per_variant);
    if (f.step()) {
      const std::int64_t id = f.int64(0);
      f.finish();
      return id;  // the transaction rolls back: nothing was written
    }
    insert_batch_->start()
        .bind(kind)
        .bind(std::string_view(key.scenario_file))
        .bind(std::string_view(key.scenario_name))
        .bind(std::string_view(key.scenario_hash))
        .bind(key.runs_per_variant)
        .bind(std::max(1, key.variants))
        .bind(std::string_view(join_seeds(key.seeds)))
        .bind(llsfsim_version())
        .run();
    const std::int64_t id = sqlite3_last_insert_rowid(db_.get());
    t.commit();
    return id;
  }

  void finish_batch(std::int64_t batch_id) override { finish_batch_->start().bind(batch_id).run(); }

  void remove_empty_batch(std::int64_t batch_id) override {
    remove_empty_batch_->start().bind(batch_id).bind(batch_id).run();
  }

  std::optional<StoredBatch> batch(std::int64_t batch_id) const override {
    Statement& q = *get_batch_;
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

  std::vector<StoredBatch> batches() const override {
    std::vector<std::int64_t> ids;
    Statement& q = *list_batches_;
    q.start();
    while (q.step()) ids.push_back(q.int64(0));
    q.finish();
    std::vector<StoredBatch> out;
    for (const std::int64_t id : ids) {
      if (auto b = batch(id)) out.push_back(std::move(*b));
    }
    return out;
  }

  std::int64_t add_run(std::int64_t batch_id, const RunResult& r, bool replace) override {
    const RunRows rows = make_run_rows(r);
    Transaction t(db_.get(), path_);  // BEGIN IMMEDIATE: no other writer until COMMIT
    // The run stored before: the same result is this run (a retry: nothing to write); another
    // result replaces it or is an error.
    Statement& f = *find_run_;
    f.start().bind(batch_id).bind(std::string_view(r.variant)).bind(rows.seed);
    if (f.step()) {
      const std::int64_t id = f.int64(0);
      const std::string hash = f.text(1);
      f.finish();
      if (!replace) {
        if (hash == rows.result_hash) return id;  // rolled back: nothing was written
        throw StatsError(conflicting_run_message(path_, batch_id, r, hash));
      }
      delete_run_->start().bind(id).run();
    }

    // The run, then its children; any failure unwinds through the transaction's rollback.
    insert_run_->start()
        .bind(batch_id)
        .bind(std::string_view(r.scenario))
        .bind(std::string_view(r.variant))
        .bind(rows.seed)
        .bind(llsfsim_version())
        .bind(std::string_view(rows.result_hash))
        .bind(r.passed() ? 1 : 0)
        .bind(r.points)
        .bind(r.game_time_s)
        .bind(r.cpu_s)
        .bind(r.real_time_factor);
    if (r.recording.empty())
      insert_run_->bind_null();
    else
      insert_run_->bind(std::string_view(stored_recording_path(path_, r.recording)));
    insert_run_->run();
    const std::int64_t run_id = sqlite3_last_insert_rowid(db_.get());

    for (const auto& [name, value] : rows.statistics) {
      insert_stat_->start().bind(run_id).bind(std::string_view(name)).bind(value).run();
    }
    for (const OrderResult& o : r.orders) {
      insert_order_->start()
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
      insert_test_->start()
          .bind(run_id)
          .bind(static_cast<std::int64_t>(i))
          .bind(std::string_view(v.name))
          .bind(v.passed ? 1 : 0)
          .bind(std::string_view(v.detail))
          .bind(v.at_s)
          .run();
    }
    for (std::size_t i = 0; i < r.awards.size(); ++i) {
      const RunAward& a = r.awards[i];
      Statement& s = *insert_award_;
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
    for (std::size_t i = 0; i < rows.events.size(); ++i) {
      const RunEvent& e = rows.events[i];
      insert_event_->start()
          .bind(run_id)
          .bind(static_cast<std::int64_t>(i))
          .bind(e.time_s)
          .bind(std::string_view(e.kind))
          .bind(std::string_view(e.name))
          .bind(e.value)
          .bind(std::string_view(e.detail))
          .run();
    }
    t.commit();
    return run_id;
  }

  std::vector<StoredRun> runs(std::int64_t batch_id) const override {
    Statement& q = *select_runs_;
    q.start().bind(batch_id);
    std::vector<StoredRun> out;
    while (q.step()) out.push_back(read_run(q));
    return out;
  }

  std::optional<StoredRun> run(std::int64_t run_id) const override {
    Statement& q = *select_run_;
    q.start().bind(run_id);
    std::optional<StoredRun> out;
    if (q.step()) out = read_run(q);
    q.finish();
    return out;
  }

  std::vector<std::pair<std::string, double>> statistics(std::int64_t run_id) const override {
    Statement& q = *select_stats_;
    q.start().bind(run_id);
    std::vector<std::pair<std::string, double>> out;
    while (q.step()) out.emplace_back(q.text(0), q.real(1));
    return out;
  }

  std::vector<RunAward> awards(std::int64_t run_id) const override {
    Statement& q = *select_awards_;
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

  std::int64_t count_rows(std::string_view table) const override {
    Statement q(db_.get(), path_, "SELECT count(*) FROM " + std::string(table));
    const std::int64_t n = q.start().step() ? q.int64(0) : 0;
    q.finish();
    return n;
  }

 private:
  std::unique_ptr<Statement> prep(std::string_view sql) {
    return std::make_unique<Statement>(db_.get(), path_, sql);
  }
  std::int64_t single_int(const char* sql) {
    Statement q(db_.get(), path_, sql);
    const std::int64_t v = q.start().step() ? q.int64(0) : 0;
    q.finish();
    return v;
  }

  // Brings the file to kSchemaVersion, one migration after the other, in one transaction. The
  // version: the highest of schema_migrations, or `PRAGMA user_version` for files of llsfsim
  // before the table (versions 1 and 2).
  void migrate() {
    Transaction t(db_.get(), path_);
    const bool has_migrations = single_int(
                                    "SELECT count(*) FROM sqlite_schema WHERE type = 'table' AND "
                                    "name = 'schema_migrations'") != 0;
    const int version =
        static_cast<int>(has_migrations ? single_int("SELECT max(version) FROM schema_migrations")
                                        : single_int("PRAGMA user_version"));
    if (version == kSchemaVersion) return;  // rolled back: nothing was written
    if (version > kSchemaVersion || version < 0) {
      throw StatsError(path_ + ": schema version " + std::to_string(version) +
                       " (this llsfsim reads versions up to " + std::to_string(kSchemaVersion) +
                       "; a newer llsfsim wrote it)");
    }
    if (version == 0 && single_int("SELECT count(*) FROM sqlite_schema") != 0) {
      throw StatsError(path_ + ": not an llsfsim statistics store (it has other tables)");
    }
    for (int v = version + 1; v <= kSchemaVersion; ++v) {
      exec(db_.get(), path_, sqlite_migrations()[static_cast<std::size_t>(v - 1)].c_str());
    }
    // Every version in the table: the ones applied now with the time, older ones without.
    Statement rec(db_.get(), path_,
                  "INSERT OR IGNORE INTO schema_migrations (version, description, applied) VALUES "
                  "(?, ?, CASE WHEN ? THEN strftime('%Y-%m-%dT%H:%M:%SZ', 'now') END)");
    for (const Migration& m : kMigrations) {
      rec.start()
          .bind(m.version)
          .bind(std::string_view(m.description))
          .bind(m.version > version ? 1 : 0)
          .run();
    }
    exec(db_.get(), path_, ("PRAGMA user_version = " + std::to_string(kSchemaVersion)).c_str());
    t.commit();
  }

  void prepare() {
    find_batch_ = prep(
        "SELECT id FROM batches WHERE kind = ? AND scenario_hash = ? AND runs_per_variant = ?");
    insert_batch_ = prep(
        "INSERT INTO batches (kind, scenario_file, scenario_name, scenario_hash, "
        "runs_per_variant, variants, seeds, llsfsim_version) VALUES (?, ?, ?, ?, ?, ?, ?, ?)");
    finish_batch_ = prep(
        "UPDATE batches SET finished = strftime('%Y-%m-%dT%H:%M:%SZ', 'now') "
        "WHERE id = ? AND finished IS NULL");
    remove_empty_batch_ = prep(
        "DELETE FROM batches WHERE id = ? AND NOT EXISTS (SELECT 1 FROM runs WHERE batch_id = ?)");
    get_batch_ = prep(
        "SELECT id, kind, created, coalesce(finished, ''), scenario_file, scenario_name, "
        "scenario_hash, runs_per_variant, variants, seeds FROM batches WHERE id = ?");
    list_batches_ = prep("SELECT id FROM batches ORDER BY id");
    find_run_ =
        prep("SELECT id, result_hash FROM runs WHERE batch_id = ? AND variant = ? AND seed = ?");
    delete_run_ = prep("DELETE FROM runs WHERE id = ?");
    insert_run_ = prep(
        "INSERT INTO runs (batch_id, scenario, variant, seed, llsfsim_version, result_hash, "
        "passed, points, game_time_s, cpu_s, real_time_factor, recording) "
        "VALUES (?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?)");
    insert_stat_ = prep("INSERT INTO statistics (run_id, name, value) VALUES (?, ?, ?)");
    insert_order_ = prep(
        "INSERT INTO orders (run_id, order_id, product, requested, delivered, window_begin_s, "
        "window_end_s) VALUES (?, ?, ?, ?, ?, ?, ?)");
    insert_test_ = prep(
        "INSERT INTO tests (run_id, idx, name, passed, detail, at_s) VALUES (?, ?, ?, ?, ?, ?)");
    insert_award_ = prep(
        "INSERT INTO awards (run_id, idx, time_s, game_time_s, phase, points, reason, device, "
        "order_id, puck) VALUES (?, ?, ?, ?, ?, ?, ?, ?, ?, ?)");
    insert_event_ = prep(
        "INSERT INTO events (run_id, idx, time_s, kind, name, value, detail) "
        "VALUES (?, ?, ?, ?, ?, ?, ?)");
    static constexpr const char* kRunColumns =
        "SELECT id, batch_id, scenario, variant, seed, llsfsim_version, result_hash, passed, "
        "points, game_time_s, cpu_s, real_time_factor, recording FROM runs ";
    select_runs_ = prep(std::string(kRunColumns) + "WHERE batch_id = ? ORDER BY id");
    select_run_ = prep(std::string(kRunColumns) + "WHERE id = ?");
    select_stats_ = prep("SELECT name, value FROM statistics WHERE run_id = ? ORDER BY name");
    select_awards_ = prep(
        "SELECT time_s, game_time_s, phase, points, reason, coalesce(device, ''), "
        "coalesce(order_id, -1), coalesce(puck, -1) FROM awards WHERE run_id = ? ORDER BY idx");
  }

  // One row of select_runs_ / select_run_.
  StoredRun read_run(const Statement& q) const {
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
    s.recording = q.null(12) ? std::string() : resolved_recording_path(path_, q.text(12));
    return s;
  }

  std::string path_;
  DbHandle db_;
  // Prepared once, used for every run.
  std::unique_ptr<Statement> find_batch_, insert_batch_, finish_batch_, remove_empty_batch_,
      get_batch_, list_batches_, find_run_, delete_run_, insert_run_, insert_stat_, insert_order_,
      insert_test_, insert_award_, insert_event_, select_runs_, select_run_, select_stats_,
      select_awards_;
};

}  // namespace

std::unique_ptr<StatsBackend> make_sqlite_backend(const std::string& path) {
  return std::make_unique<SqliteBackend>(path);
}

}  // namespace llsf::study
