// SPDX-License-Identifier: MIT
// StatsStore: the statistics of played games -- batches, runs, every numeric result, orders, test
// verdicts, points awards and events -- in one SQLite file (default `llsfsim.db`) or in a
// PostgreSQL database (`postgresql://USER@HOST:PORT/DB`). Both backends keep the same schema with
// the same semantics: each run is written in one transaction (an interrupted batch never leaves
// half a run), a run is identified by (batch, variant, seed), writing a run again is harmless.
// docs/statistics.md documents the schema.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "llsf/core/error.h"
#include "llsf/study/runner.h"

namespace llsf::study {

/// The store could not be opened, read or written (the message names the file or the URL, its
/// password masked, and the database's reason).
class StatsError : public core::UserError {
 public:
  using core::UserError::UserError;
};

/// The version of llsfsim recorded with every run (core::kVersion).
std::string_view llsfsim_version();

/// What identifies a batch and what is recorded with it.
struct BatchKey {
  enum class Kind : std::uint8_t {
    kBatch,  ///< `llsfsim batch`: every variant x runs_per_variant seeds
    kRun,    ///< `llsfsim run`: single games of one scenario file, one batch per file content
  };
  Kind kind = Kind::kBatch;
  std::string scenario_file;  ///< the path as given (metadata)
  std::string scenario_name;
  std::string scenario_hash;  ///< batch_identity_hash(): scenario, agent and skill files (identity)
  int runs_per_variant = 0;   ///< identity; 0 for kRun
  int variants = 1;
  std::vector<std::uint64_t> seeds;  ///< the first variant's seeds (metadata)
};

/// A stored batch.
struct StoredBatch {
  std::int64_t id = 0;
  std::string kind;      ///< "batch" or "run"
  std::string created;   ///< UTC, ISO 8601 (wall clock; metadata only)
  std::string finished;  ///< when its last missing run was stored; "" while incomplete
  std::string scenario_file;
  std::string scenario_name;
  std::string scenario_hash;
  int runs_per_variant = 0;
  int variants = 0;
  std::string seeds;  ///< "1,2,3"
};

/// A stored run (one row of `runs`).
struct StoredRun {
  std::int64_t id = 0;
  std::int64_t batch_id = 0;
  std::string scenario;
  std::string variant;
  std::uint64_t seed = 0;
  std::string llsfsim_version;
  std::uint64_t result_hash = 0;
  bool passed = false;
  int points = 0;
  double game_time_s = 0.0;
  double cpu_s = 0.0;
  double real_time_factor = 0.0;
  /// The run's recording ("" if none): a path relative to the working directory (or absolute),
  /// resolved from what the store keeps -- relative to the database's directory when inside it;
  /// a database server's store keeps absolute paths.
  std::string recording;
};

class StatsBackend;

/// True if `db` names a database server (`postgresql://...` or `postgres://...`), not a file.
bool is_database_url(std::string_view db);
/// `db` with the password of a URL (`scheme://user:PASSWORD@`, `password=PASSWORD`) replaced by
/// `***`; a file path unchanged. For every message that shows a --db value.
std::string masked_database_url(std::string_view db);

/// The statistics database. Not thread-safe: one thread writes (a batch queues its results to
/// the thread that owns the store). Many processes may write one store at once: SQLite locks the
/// file (a writer waits up to 10 s); PostgreSQL takes each run in its own transaction, and a
/// store that loses its connection reconnects and retries (docs/statistics.md).
class StatsStore {
 public:
  /// The default file, in the current directory.
  static constexpr std::string_view kDefaultPath = "llsfsim.db";

  /// Opens the store `path` names: a PostgreSQL database for a `postgresql://` or `postgres://`
  /// URL (what it leaves out comes from the PG* environment variables, as for psql), else a
  /// SQLite file (created if missing; its folder must exist). Creates the schema in a new store and
  /// migrates an older one. Throws StatsError if the store cannot be opened or reached, or holds a
  /// newer schema version or other tables.
  explicit StatsStore(const std::string& path);
  ~StatsStore();
  StatsStore(const StatsStore&) = delete;
  StatsStore& operator=(const StatsStore&) = delete;
  StatsStore(StatsStore&&) noexcept;
  StatsStore& operator=(StatsStore&&) noexcept;

  /// The file's path; for a database server its URL with the password masked.
  const std::string& path() const;

  /// Throws StatsError unless runs can be written: the file opened read-only (its permissions,
  /// a read-only file system) or its directory not writable (SQLite's journal goes there); for
  /// PostgreSQL a read-only server (a standby) or a role without INSERT on the tables. For
  /// `run` and `batch` before the first game, so that a store that cannot take the result
  /// costs no game.
  void require_writable() const;

  /// The id of the batch with `key`'s identity (kind, scenario_hash, runs_per_variant), created
  /// if there is none (two writers opening the same new batch at once get the same id).
  std::int64_t open_batch(const BatchKey& key);
  /// Marks a batch complete (sets `finished` to now, once).
  void finish_batch(std::int64_t batch_id);
  /// Removes the batch `batch_id` if it holds no run (a submission that failed after opening
  /// it); does nothing otherwise.
  void remove_empty_batch(std::int64_t batch_id);
  /// Every batch (and stored single run's batch), by id.
  std::vector<StoredBatch> batches() const;
  /// The batch `batch_id`, if it exists.
  std::optional<StoredBatch> batch(std::int64_t batch_id) const;

  /// Writes `r` with its statistics, orders, test verdicts, awards and events in one
  /// transaction; returns the run's id. A run is identified by (batch, variant, seed); if the
  /// batch holds one already: with the same result hash, nothing is written and its id returned
  /// (a retried task, a merged shard: never a second copy); with another result, `replace`
  /// deletes it in the same transaction and writes `r` (the latest game counts: `llsfsim run`),
  /// else that is an error. With `replace` the run is always written anew (measurements,
  /// recording; its id may change). On any error nothing of the run is written (StatsError).
  std::int64_t add_run(std::int64_t batch_id, const RunResult& r, bool replace = false);

  /// The runs of a batch, by id.
  std::vector<StoredRun> runs(std::int64_t batch_id) const;
  /// One run by its id, if stored.
  std::optional<StoredRun> run(std::int64_t run_id) const;
  /// The (variant, seed) pairs of a batch's stored runs.
  std::vector<std::pair<std::string, std::uint64_t>> run_keys(std::int64_t batch_id) const;
  /// A run's statistics (name, value), by name.
  std::vector<std::pair<std::string, double>> statistics(std::int64_t run_id) const;
  /// A run's points awards, in order.
  std::vector<RunAward> awards(std::int64_t run_id) const;
  /// Rows in `table` (one of the schema's tables; tests and reports).
  std::int64_t count_rows(std::string_view table) const;

 private:
  std::unique_ptr<StatsBackend> backend_;  ///< SQLite or PostgreSQL (study/src/stats_backend.h)
};

/// FNV-1a 64 of the file's bytes as 16 hex digits. Throws StatsError if the file cannot be read.
std::string file_content_hash(const std::string& path);

/// A batch's identity (BatchKey::scenario_hash): FNV-1a 64 over the scenario file's bytes and
/// the names and bytes of every file its games load -- each variant's agent files (directories
/// expanded to their *.clp files) and skill files (every *.lua under the skill directories; the
/// skill library of the variant's skill level when the scenario names none) -- as 16 hex digits.
/// Editing an agent or a skill makes a new batch, so a rerun plays instead of reusing old
/// results. Throws StatsError if a file cannot be read.
std::string batch_identity_hash(const std::string& scenario_path, const ScenarioFile& file);

/// The statistics of `r` by name, in the order of docs/statistics.md: every numeric field of
/// RunResult (points, exploration_points, ..., cpu_s, real_time_factor) that has a value. A
/// statistic that may be absent (the time of something that did not happen) is left out when
/// absent: the store keeps no row for it, never a placeholder.
std::vector<std::pair<std::string, double>> numeric_statistics(const RunResult& r);

/// One statistic of the store: its name and whether a game may lack it (statistic_infos()).
struct StatisticInfo {
  std::string name;
  bool may_be_absent = false;  ///< a time of something that may not happen in a game
};

/// Every statistic numeric_statistics() can give, in its order: the one definition the store,
/// the experiment file's checks and the reports read.
const std::vector<StatisticInfo>& statistic_infos();

/// How the store keeps a recording path: relative to the database file's directory when the
/// file lies inside it (database and recordings can move together), else absolute; always
/// absolute for a database server (`db_path` a URL).
std::string stored_recording_path(const std::string& db_path, const std::string& recording);
/// The inverse: a kept path as a path usable from the working directory (for a database server a
/// relative kept path is taken as relative to the working directory).
std::string resolved_recording_path(const std::string& db_path, const std::string& stored);

}  // namespace llsf::study
