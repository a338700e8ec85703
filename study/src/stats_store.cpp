// SPDX-License-Identifier: MIT
// StatsStore: the backend chosen by the --db value, and what both backends share.
#include "llsf/study/stats_store.h"

#include <algorithm>
#include <cctype>
#include <cinttypes>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <set>

#include "llsf/core/data_dir.h"
#include "llsf/core/input_file.h"
#include "llsf/core/rng.h"
#include "llsf/core/version.h"
#include "llsf/sim/agent_brain.h"
#include "llsf/sim/skill_brain.h"
#include "llsf/study/metrics.h"
#include "stats_backend.h"

namespace llsf::study {

namespace {

/// `text` with every `$NAME` of the dialect replaced.
std::string in_dialect(std::string text, const SqlDialect& d) {
  const std::pair<std::string_view, std::string_view> words[] = {{"$ID", d.id},
                                                                 {"$BIGINT", d.bigint},
                                                                 {"$REAL", d.real},
                                                                 {"$NOW", d.now},
                                                                 {"$KEYED", d.keyed}};
  for (const auto& [from, to] : words) {
    for (std::size_t at = text.find(from); at != std::string::npos;
         at = text.find(from, at + to.size())) {
      text.replace(at, from.size(), to);
    }
  }
  return text;
}

// Version 1: the tables. `$NAME`s are the dialect's words (SqlDialect).
constexpr const char* kTablesSql = R"sql(
CREATE TABLE batches (
  id               $ID,
  kind             TEXT    NOT NULL CHECK (kind IN ('batch', 'run')),
  created          TEXT    NOT NULL DEFAULT $NOW,
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
  id               $ID,
  batch_id         $BIGINT NOT NULL REFERENCES batches (id) ON DELETE CASCADE,
  scenario         TEXT    NOT NULL,
  variant          TEXT    NOT NULL,
  seed             $BIGINT NOT NULL,
  llsfsim_version  TEXT    NOT NULL,
  result_hash      TEXT    NOT NULL,
  passed           INTEGER NOT NULL CHECK (passed IN (0, 1)),
  points           INTEGER NOT NULL,
  game_time_s      $REAL NOT NULL,
  cpu_s            $REAL NOT NULL,
  real_time_factor $REAL NOT NULL,
  created          TEXT    NOT NULL DEFAULT $NOW,
  UNIQUE (batch_id, variant, seed)
);
CREATE TABLE statistics (
  run_id $BIGINT NOT NULL REFERENCES runs (id) ON DELETE CASCADE,
  name   TEXT    NOT NULL,
  value  $REAL NOT NULL,
  PRIMARY KEY (run_id, name)
)$KEYED;
CREATE INDEX statistics_by_name ON statistics (name);
CREATE TABLE orders (
  run_id         $BIGINT NOT NULL REFERENCES runs (id) ON DELETE CASCADE,
  order_id       INTEGER NOT NULL,
  product        TEXT    NOT NULL,
  requested      INTEGER NOT NULL,
  delivered      INTEGER NOT NULL,
  window_begin_s INTEGER NOT NULL,
  window_end_s   INTEGER NOT NULL,
  PRIMARY KEY (run_id, order_id)
)$KEYED;
CREATE TABLE tests (
  run_id $BIGINT NOT NULL REFERENCES runs (id) ON DELETE CASCADE,
  idx    INTEGER NOT NULL,
  name   TEXT    NOT NULL,
  passed INTEGER NOT NULL CHECK (passed IN (0, 1)),
  detail TEXT    NOT NULL,
  at_s   $REAL NOT NULL,
  PRIMARY KEY (run_id, idx)
)$KEYED;
CREATE TABLE awards (
  run_id      $BIGINT NOT NULL REFERENCES runs (id) ON DELETE CASCADE,
  idx         INTEGER NOT NULL,
  time_s      $REAL NOT NULL,
  game_time_s $REAL NOT NULL,
  phase       TEXT    NOT NULL,
  points      INTEGER NOT NULL,
  reason      TEXT    NOT NULL,
  device      TEXT,
  order_id    INTEGER,
  puck        INTEGER,
  PRIMARY KEY (run_id, idx)
)$KEYED;
CREATE TABLE events (
  run_id $BIGINT NOT NULL REFERENCES runs (id) ON DELETE CASCADE,
  idx    INTEGER NOT NULL,
  time_s $REAL NOT NULL,
  kind   TEXT    NOT NULL,
  name   TEXT    NOT NULL,
  value  $REAL,
  detail TEXT    NOT NULL,
  PRIMARY KEY (run_id, idx)
)$KEYED;
CREATE INDEX runs_by_variant ON runs (batch_id, variant);
)sql";

}  // namespace

std::array<std::string, kSchemaVersion> schema_sql(const SqlDialect& dialect) {
  return {
      in_dialect(kTablesSql, dialect),
      "ALTER TABLE runs ADD COLUMN recording TEXT;",
      R"sql(
CREATE TABLE schema_migrations (
  version     INTEGER PRIMARY KEY,
  description TEXT    NOT NULL,
  applied     TEXT
);
)sql",
      kMissingIsMissingSql,
  };
}

std::string_view llsfsim_version() { return core::kVersion; }

// ---- Shared by the backends --------------------------------------------------------------------

std::string hex16(std::uint64_t v) {
  char buf[17];
  std::snprintf(buf, sizeof buf, "%016" PRIx64, v);
  return buf;
}

std::uint64_t parse_hex16(const std::string& s) {
  return s.empty() ? 0 : std::stoull(s, nullptr, 16);
}

std::string join_seeds(const std::vector<std::uint64_t>& seeds) {
  std::string out;
  for (std::size_t i = 0; i < seeds.size(); ++i) {
    if (i > 0) out += ',';
    out += std::to_string(seeds[i]);
  }
  return out;
}

RunRows make_run_rows(const RunResult& r) {
  RunRows rows;
  rows.result_hash = hex16(r.result_hash);
  rows.seed = static_cast<std::int64_t>(r.seed);  // bit-preserving for seeds >= 2^63
  rows.statistics = numeric_statistics(r);
  // Events: the awards and the test verdicts, in game-time order (awards first on ties).
  rows.events.reserve(r.awards.size() + r.tests.size());
  for (const RunAward& a : r.awards) {
    std::string detail = a.phase;
    if (!a.device.empty()) detail += " " + a.device;
    if (a.order >= 0) detail += " order " + std::to_string(a.order);
    if (a.puck >= 0) detail += " puck " + std::to_string(a.puck);
    rows.events.push_back({a.time_s, "award", a.reason, static_cast<double>(a.points), detail});
  }
  for (const TestVerdict& v : r.tests) {
    rows.events.push_back(
        {v.at_s, v.passed ? "test_passed" : "test_failed", v.name, v.passed ? 1.0 : 0.0, v.detail});
  }
  std::stable_sort(rows.events.begin(), rows.events.end(),
                   [](const RunEvent& a, const RunEvent& b) { return a.time_s < b.time_s; });
  return rows;
}

std::string conflicting_run_message(const std::string& store, std::int64_t batch_id,
                                    const RunResult& r, const std::string& stored_hash) {
  return store + ": batch " + std::to_string(batch_id) + " already holds variant '" + r.variant +
         "' seed " + std::to_string(r.seed) + " with result hash " + stored_hash + ", not " +
         hex16(r.result_hash) +
         " (the same game gave another result: was llsfsim or an input changed?)";
}

// ---- The URL of a database server --------------------------------------------------------------

bool is_database_url(std::string_view db) {
  return db.starts_with("postgresql://") || db.starts_with("postgres://");
}

namespace {
// "scheme://..." (RFC 3986 scheme: a letter, then letters, digits, '+', '-', '.').
bool has_url_scheme(std::string_view s) {
  const std::size_t colon = s.find("://");
  if (colon == std::string_view::npos || colon == 0 ||
      std::isalpha(static_cast<unsigned char>(s[0])) == 0) {
    return false;
  }
  return std::all_of(s.begin(), s.begin() + static_cast<std::ptrdiff_t>(colon), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) != 0 || c == '+' || c == '-' || c == '.';
  });
}
}  // namespace

std::string masked_database_url(std::string_view db) {
  std::string out(db);
  if (!has_url_scheme(db)) return out;
  // user:password@ in the authority.
  const std::size_t scheme = out.find("://") + 3;
  const std::size_t end = std::min(out.find_first_of("/?", scheme), out.size());
  const std::size_t at = out.rfind('@', end);
  if (at != std::string::npos && at >= scheme) {
    const std::size_t colon = out.find(':', scheme);
    if (colon != std::string::npos && colon < at) out.replace(colon + 1, at - colon - 1, "***");
  }
  // password=... among the parameters.
  for (std::size_t p = out.find('?'); p != std::string::npos && p < out.size();) {
    const std::size_t start = p + 1;
    std::size_t next = out.find('&', start);
    if (out.compare(start, 9, "password=") == 0) {
      const std::size_t value = start + 9;
      out.replace(value, (next == std::string::npos ? out.size() : next) - value, "***");
      next = out.find('&', value);
    }
    p = next;
  }
  return out;
}

// ---- StatsStore --------------------------------------------------------------------------------

namespace {
// The backend `path` names. Another URL scheme (`mysql://`, `POSTGRESQL://`, `sqlite://`) is an
// error, not a file whose name starts with "scheme:".
std::unique_ptr<StatsBackend> open_backend(const std::string& path) {
  if (is_database_url(path)) return make_postgres_backend(path);
  if (has_url_scheme(path)) {
    throw StatsError(masked_database_url(path) +
                     ": not a statistics store: a file path, or a database URL "
                     "postgresql://USER@HOST:PORT/DB (postgres://...)");
  }
  return make_sqlite_backend(path);
}
}  // namespace

StatsStore::StatsStore(const std::string& path) : backend_(open_backend(path)) {}
StatsStore::~StatsStore() = default;
StatsStore::StatsStore(StatsStore&&) noexcept = default;
StatsStore& StatsStore::operator=(StatsStore&&) noexcept = default;

const std::string& StatsStore::path() const { return backend_->path(); }
void StatsStore::require_writable() const { backend_->require_writable(); }
std::int64_t StatsStore::open_batch(const BatchKey& key) { return backend_->open_batch(key); }
void StatsStore::finish_batch(std::int64_t batch_id) { backend_->finish_batch(batch_id); }
void StatsStore::remove_empty_batch(std::int64_t batch_id) {
  backend_->remove_empty_batch(batch_id);
}
std::vector<StoredBatch> StatsStore::batches() const { return backend_->batches(); }
std::optional<StoredBatch> StatsStore::batch(std::int64_t batch_id) const {
  return backend_->batch(batch_id);
}
std::int64_t StatsStore::add_run(std::int64_t batch_id, const RunResult& r, bool replace) {
  return backend_->add_run(batch_id, r, replace);
}
std::vector<StoredRun> StatsStore::runs(std::int64_t batch_id) const {
  return backend_->runs(batch_id);
}
std::optional<StoredRun> StatsStore::run(std::int64_t run_id) const {
  return backend_->run(run_id);
}
std::vector<std::pair<std::string, std::uint64_t>> StatsStore::run_keys(
    std::int64_t batch_id) const {
  std::vector<std::pair<std::string, std::uint64_t>> out;
  for (const StoredRun& r : runs(batch_id)) out.emplace_back(r.variant, r.seed);
  return out;
}
std::vector<std::pair<std::string, double>> StatsStore::statistics(std::int64_t run_id) const {
  return backend_->statistics(run_id);
}
std::vector<RunAward> StatsStore::awards(std::int64_t run_id) const {
  return backend_->awards(run_id);
}
std::int64_t StatsStore::count_rows(std::string_view table) const {
  if (std::find(kStoreTables.begin(), kStoreTables.end(), table) == kStoreTables.end()) {
    throw StatsError(path() + ": no table '" + std::string(table) + "'");
  }
  return backend_->count_rows(table);
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
      // A Fawkes-style agent path-loads any file of its directory, and has its .proto files.
      std::error_code ec;
      if (r.fawkes && fs::is_directory(r.agent_dir, ec)) {
        for (const auto& e : fs::recursive_directory_iterator(r.agent_dir, ec)) {
          const fs::path ext = e.path().extension();
          if (e.is_regular_file() && (ext == ".clp" || ext == ".proto"))
            files.insert(e.path().string());
        }
      }
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
    // Skills written for Fawkes: their helper modules and navgraph files.
    for (const std::string& d : s.skills.module_dirs) {
      std::error_code ec;
      for (const auto& e : fs::recursive_directory_iterator(d, ec)) {
        if (e.is_regular_file() && e.path().extension() == ".lua") files.insert(e.path().string());
      }
    }
    for (const std::string& d : s.skills.cfg_dirs) {
      std::error_code ec;
      for (const auto& e : fs::recursive_directory_iterator(d, ec)) {
        const fs::path ext = e.path().extension();
        if (e.is_regular_file() && (ext == ".yaml" || ext == ".yml")) {
          files.insert(e.path().string());
        }
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
  const fs::path file = fs::absolute(recording, ec);
  if (ec) return recording;
  // A database server: absolute (the store has no directory; the nodes of a cluster see shared
  // storage at the same path).
  if (is_database_url(db_path)) return file.lexically_normal().string();
  const fs::path base = fs::absolute(fs::path(db_path).parent_path(), ec);
  if (ec) return recording;
  const fs::path rel = file.lexically_normal().lexically_relative(base.lexically_normal());
  // Inside the database's directory: relative (the pair can move together); else absolute.
  if (rel.empty() || *rel.begin() == "..") return file.lexically_normal().string();
  return rel.string();
}

std::string resolved_recording_path(const std::string& db_path, const std::string& stored) {
  namespace fs = std::filesystem;
  const fs::path p(stored);
  // Absolute, or (a database server's store) relative to the working directory.
  if (p.is_absolute() || is_database_url(db_path)) return stored;
  return (fs::path(db_path).parent_path() / p).lexically_normal().string();
}

std::vector<std::pair<std::string, double>> numeric_statistics(const RunResult& r) {
  // The metric table (metrics.h) in its order; an absent metric has no row.
  std::vector<std::pair<std::string, double>> out;
  for (const Metric& m : metrics()) {
    if (const std::optional<double> v = m.value(r)) out.emplace_back(std::string(m.name), *v);
  }
  return out;
}

const std::vector<StatisticInfo>& statistic_infos() {
  static const std::vector<StatisticInfo> infos = [] {
    std::vector<StatisticInfo> out;
    for (const Metric& m : metrics()) out.push_back({std::string(m.name), m.may_be_absent});
    return out;
  }();
  return infos;
}

}  // namespace llsf::study
