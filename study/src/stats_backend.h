// SPDX-License-Identifier: MIT
// The statistics store's backends behind one contract: StatsStore (stats_store.h) forwards every
// call to a StatsBackend, SQLite (stats_store_sqlite.cpp) or PostgreSQL
// (stats_store_postgres.cpp). What a run writes is computed once, here, for both.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "llsf/study/stats_store.h"

namespace llsf::study {

/// The schema version both backends create and migrate to (docs/statistics.md, "Schema").
/// 1: the tables; 2: runs.recording; 3: the schema_migrations table; 4: absent values instead of
/// -1 placeholders, the time statistics named by their base, the "never happened" shares.
inline constexpr int kSchemaVersion = 4;

/// The schema's tables (count_rows() accepts these names only).
inline constexpr std::array<std::string_view, 8> kStoreTables = {
    "batches", "runs", "statistics", "orders", "tests", "awards", "events", "schema_migrations"};

/// One migration step: applied in order, each recorded in schema_migrations.
struct Migration {
  int version;
  const char* description;
};
/// The descriptions of versions 1..kSchemaVersion (the SQL is each backend's dialect).
inline constexpr std::array<Migration, 4> kMigrations = {{
    {1, "batches, runs, statistics, orders, tests, awards, events"},
    {2, "runs.recording"},
    {3, "schema_migrations"},
    {4,
     "absent values instead of -1; first_complex_production_s, first_role_change_game_s, "
     "storage_empty_game_s; complex_made, storage_ran_empty"},
}};

/// Migration 4, the same SQL in both dialects: the "never happened" shares from the old -1
/// placeholders, then the placeholders deleted (absent is no row) and the time statistics
/// renamed to name their base (production time, game time).
inline constexpr const char* kMissingIsMissingSql = R"sql(
INSERT INTO statistics (run_id, name, value)
  SELECT run_id, 'complex_made', CASE WHEN value >= 0 THEN 1.0 ELSE 0.0 END
  FROM statistics WHERE name = 'first_complex_s';
INSERT INTO statistics (run_id, name, value)
  SELECT run_id, 'storage_ran_empty', CASE WHEN value >= 0 THEN 1.0 ELSE 0.0 END
  FROM statistics WHERE name = 'storage_empty_s';
DELETE FROM statistics
  WHERE name IN ('first_complex_s', 'first_role_change_s', 'storage_empty_s') AND value < 0;
UPDATE statistics SET name = 'first_complex_production_s' WHERE name = 'first_complex_s';
UPDATE statistics SET name = 'first_role_change_game_s' WHERE name = 'first_role_change_s';
UPDATE statistics SET name = 'storage_empty_game_s' WHERE name = 'storage_empty_s';
)sql";

/// One row of `events`.
struct RunEvent {
  double time_s = 0.0;
  std::string kind;
  std::string name;
  double value = 0.0;
  std::string detail;
};

/// Everything add_run writes besides the run's row: computed from a RunResult once, the same
/// for both backends.
struct RunRows {
  std::string result_hash;  ///< 16 hex digits
  std::int64_t seed = 0;    ///< the uint64 seed bit for bit
  std::vector<std::pair<std::string, double>> statistics;
  std::vector<RunEvent> events;  ///< awards and verdicts in game-time order (awards first on ties)
};
RunRows make_run_rows(const RunResult& r);

/// 16 lower-case hex digits; the inverse ("" reads as 0).
std::string hex16(std::uint64_t v);
std::uint64_t parse_hex16(const std::string& s);
/// "1,2,3".
std::string join_seeds(const std::vector<std::uint64_t>& seeds);

/// The store behind StatsStore. One object is used by one thread at a time.
class StatsBackend {
 public:
  StatsBackend() = default;
  virtual ~StatsBackend() = default;
  StatsBackend(const StatsBackend&) = delete;
  StatsBackend& operator=(const StatsBackend&) = delete;

  /// The file path, or the URL without its password.
  virtual const std::string& path() const = 0;
  virtual void require_writable() const = 0;
  virtual std::int64_t open_batch(const BatchKey& key) = 0;
  virtual void finish_batch(std::int64_t batch_id) = 0;
  virtual void remove_empty_batch(std::int64_t batch_id) = 0;
  virtual std::vector<StoredBatch> batches() const = 0;
  virtual std::optional<StoredBatch> batch(std::int64_t batch_id) const = 0;
  virtual std::int64_t add_run(std::int64_t batch_id, const RunResult& r, bool replace) = 0;
  virtual std::vector<StoredRun> runs(std::int64_t batch_id) const = 0;
  virtual std::optional<StoredRun> run(std::int64_t run_id) const = 0;
  virtual std::vector<std::pair<std::string, double>> statistics(std::int64_t run_id) const = 0;
  virtual std::vector<RunAward> awards(std::int64_t run_id) const = 0;
  virtual std::int64_t count_rows(std::string_view table) const = 0;
};

/// The SQLite file `path` (created if missing).
std::unique_ptr<StatsBackend> make_sqlite_backend(const std::string& path);
/// The PostgreSQL database `url` (postgresql://... or postgres://...).
std::unique_ptr<StatsBackend> make_postgres_backend(const std::string& url);

/// The message for a run stored before with another result (same key, other result hash).
std::string conflicting_run_message(const std::string& store, std::int64_t batch_id,
                                    const RunResult& r, const std::string& stored_hash);

}  // namespace llsf::study
