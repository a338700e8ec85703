// SPDX-License-Identifier: MIT
#include "llsf/study/cluster.h"

#include <sqlite3.h>

#include <algorithm>
#include <charconv>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <set>
#include <sstream>

#include "llsf/core/error.h"
#include "llsf/study/stats_store.h"

namespace llsf::study {

namespace fs = std::filesystem;

namespace {

// "<dir>/<stem>" of a store path: study.db -> study; a name without extension stays.
fs::path store_stem(const std::string& db) {
  const fs::path p(db);
  return p.parent_path() / p.stem();
}

std::optional<int> to_int(std::string_view s) {
  int v = 0;
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  if (ec != std::errc() || end != s.data() + s.size()) return std::nullopt;
  return v;
}

std::vector<std::string> split(std::string_view s, char sep) {
  std::vector<std::string> out;
  std::size_t pos = 0;
  for (;;) {
    const std::size_t at = s.find(sep, pos);
    out.emplace_back(
        s.substr(pos, at == std::string_view::npos ? std::string_view::npos : at - pos));
    if (at == std::string_view::npos) return out;
    pos = at + 1;
  }
}

}  // namespace

std::string shard_path(const std::string& db, int task) {
  char num[16];
  std::snprintf(num, sizeof num, "%05d", task);
  return store_stem(db).string() + ".shard-" + num + ".db";
}

std::vector<std::string> existing_shards(const std::string& db) {
  const fs::path stem = store_stem(db);
  const fs::path dir = stem.parent_path().empty() ? fs::path(".") : stem.parent_path();
  const std::string prefix = stem.filename().string() + ".shard-";
  std::vector<std::string> out;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(dir, ec)) {
    const std::string name = e.path().filename().string();
    if (!name.starts_with(prefix) || !name.ends_with(".db")) continue;
    const std::string_view num(name.data() + prefix.size(), name.size() - prefix.size() - 3);
    if (!to_int(num)) continue;
    out.push_back((stem.parent_path() / name).string());
  }
  std::sort(out.begin(), out.end());
  return out;
}

namespace {

// A database URL as a file name: host, port and database, no user or password.
std::string url_file_name(std::string_view url) {
  std::string_view rest = url.substr(url.find("://") + 3);
  if (const std::size_t at = rest.rfind('@'); at != std::string_view::npos)
    rest = rest.substr(at + 1);
  rest = rest.substr(0, rest.find('?'));
  std::string out;
  for (const char c : rest) {
    const bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
                    c == '-' || c == '.' || c == '_';
    out += ok ? c : '_';
  }
  return out.empty() ? "database" : out;
}

}  // namespace

std::string job_file_path(const std::string& db) {
  if (is_database_url(db)) return slurm_dir(db) + "/" + url_file_name(db) + ".slurm-jobs";
  return db + ".slurm-jobs";
}

std::string slurm_dir(const std::string& db) {
  if (is_database_url(db)) return (fs::current_path() / "llsfsim-slurm").string();
  return store_stem(db).string() + "-slurm";
}

// ---- the job file -----------------------------------------------------------------------------

void append_job(const std::string& db, const SlurmJob& job) {
  const std::string path = job_file_path(db);
  std::ofstream f(path, std::ios::app);
  f << job.job_id << '\t' << job.submitted << '\t' << job.games_per_task << '\t' << job.array
    << '\t' << job.stored_at_submit << '\t' << job.total;
  if (!job.batch.empty()) f << "\tbatch=" << job.batch;
  if (!job.script.empty()) f << "\tscript=" << job.script;
  for (const std::string& s : job.scenarios) f << '\t' << s;
  f << '\n';
  f.flush();
  if (!f) throw core::ConfigError("cannot write the job file " + path);
}

std::vector<SlurmJob> read_jobs(const std::string& db) {
  const std::string path = job_file_path(db);
  std::ifstream f(path);
  std::vector<SlurmJob> out;
  if (!f) return out;
  std::string line;
  int n = 0;
  while (std::getline(f, line)) {
    ++n;
    if (line.empty()) continue;
    const std::vector<std::string> w = split(line, '\t');
    auto bad = [&] {
      return core::ConfigError(path + ":" + std::to_string(n) +
                               ": not a job line (job id, submitted, games per task, array, "
                               "stored, total, batch=, script=, scenarios...; written by llsfsim "
                               "batch --slurm)");
    };
    if (w.size() < 7) throw bad();
    SlurmJob j;
    j.job_id = w[0];
    j.submitted = w[1];
    const auto g = to_int(w[2]);
    if (!g || *g < 1) throw bad();
    j.games_per_task = *g;
    j.array = w[3];
    try {
      j.stored_at_submit = std::stoll(w[4]);
      j.total = std::stoll(w[5]);
    } catch (const std::exception&) {
      throw bad();
    }
    auto field = w.begin() + 6;
    for (; field != w.end(); ++field) {
      if (field->starts_with("batch=")) {
        j.batch = field->substr(6);
      } else if (field->starts_with("script=")) {
        j.script = field->substr(7);
      } else {
        break;
      }
    }
    j.scenarios.assign(field, w.end());
    if (j.scenarios.empty()) throw bad();
    out.push_back(std::move(j));
  }
  return out;
}

// ---- the job script ---------------------------------------------------------------------------

std::string shell_quote(std::string_view s) {
  const bool safe = !s.empty() && std::all_of(s.begin(), s.end(), [](char c) {
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
           std::string_view("-_./=:,+@%").find(c) != std::string_view::npos;
  });
  if (safe) return std::string(s);
  std::string out = "'";
  for (const char c : s) {
    if (c == '\'') {
      out += "'\\''";
    } else {
      out += c;
    }
  }
  return out + "'";
}

std::string array_spec(const std::vector<int>& tasks, int throttle) {
  std::vector<int> t = tasks;
  std::sort(t.begin(), t.end());
  t.erase(std::unique(t.begin(), t.end()), t.end());
  std::string out;
  for (std::size_t i = 0; i < t.size();) {
    std::size_t j = i;
    while (j + 1 < t.size() && t[j + 1] == t[j] + 1) ++j;
    if (!out.empty()) out += ',';
    out += std::to_string(t[i]);
    if (j > i) out += "-" + std::to_string(t[j]);
    i = j + 1;
  }
  if (throttle > 0) out += "%" + std::to_string(throttle);
  return out;
}

std::string slurm_script(const SlurmScript& s) {
  if (s.tasks.empty()) throw core::ConfigError("a Slurm job array needs at least one task");
  auto one_line = [](const std::string& v, const std::string& what) {
    if (v.find_first_of("\n\r") != std::string::npos) {
      throw core::ConfigError(what + " '" + v + "' holds a line break");
    }
    return v;
  };
  std::ostringstream o;
  o << "#!/bin/bash\n"
    << "# Written by llsfsim batch --slurm (docs/cluster.md): one array task plays its slice of\n"
    << "# the batch's (variant, seed) pairs and skips the runs already stored.\n"
    << "#SBATCH --job-name=" << one_line(s.job_name, "the job name") << "\n"
    << "#SBATCH --array=" << array_spec(s.tasks, s.array_throttle) << "\n"
    << "#SBATCH --ntasks=1\n"
    << "#SBATCH --cpus-per-task=" << s.cpus_per_task << "\n"
    << "#SBATCH --requeue\n";
  if (!s.partition.empty())
    o << "#SBATCH --partition=" << one_line(s.partition, "--partition") << "\n";
  if (!s.time_limit.empty())
    o << "#SBATCH --time=" << one_line(s.time_limit, "--time-limit") << "\n";
  if (!s.workdir.empty()) o << "#SBATCH --chdir=" << one_line(s.workdir, "the directory") << "\n";
  if (!s.log_dir.empty()) {
    o << "#SBATCH --output=" << one_line(s.log_dir, "the log directory") << "/slurm-%A_%a.out\n";
  }
  for (const std::string& a : s.sbatch_args) o << "#SBATCH " << one_line(a, "--sbatch-arg") << "\n";
  o << "set -eu\n"
    << "exec";
  for (const std::string& w : s.command) o << ' ' << shell_quote(one_line(w, "an argument"));
  o << " --task \"$SLURM_ARRAY_TASK_ID\"\n";
  return o.str();
}

// ---- squeue and sacct -------------------------------------------------------------------------

std::vector<SlurmTask> parse_slurm_tasks(std::string_view text) {
  std::vector<SlurmTask> out;
  for (const std::string& raw : split(text, '\n')) {
    std::string line = raw;
    while (!line.empty() && (line.back() == '\r' || line.back() == ' ')) line.pop_back();
    const std::vector<std::string> w = split(line, '|');
    if (w.size() < 2) continue;
    const std::size_t us = w[0].find('_');
    if (us == std::string::npos) continue;  // not an array task (or a step: "123_4.batch")
    if (w[0].find('.') != std::string::npos) continue;
    SlurmTask t;
    t.job_id = w[0].substr(0, us);
    if (!to_int(t.job_id)) continue;
    std::string index = w[0].substr(us + 1);
    t.state = w[1].substr(0, w[1].find(' '));  // "CANCELLED by 0" -> CANCELLED
    t.detail = w.size() > 2 ? w[2] : "";
    if (index.starts_with("[")) {
      // A pending rest: "[4-9%2]" or "[4,6-7]".
      index = index.substr(
          1, index.find(']') == std::string::npos ? std::string::npos : index.find(']') - 1);
      index = index.substr(0, index.find('%'));
      for (const std::string& part : split(index, ',')) {
        const std::size_t dash = part.find('-');
        const auto a = to_int(part.substr(0, dash));
        const auto b = dash == std::string::npos ? a : to_int(part.substr(dash + 1));
        if (!a || !b || *b < *a || *b - *a > 1'000'000) continue;
        for (int i = *a; i <= *b; ++i) t.pending.push_back(i);
      }
      if (t.pending.empty()) continue;
    } else {
      const auto i = to_int(index);
      if (!i) continue;
      t.task = *i;
    }
    out.push_back(std::move(t));
  }
  return out;
}

// ---- merge ------------------------------------------------------------------------------------

namespace {

struct DbCloser {
  void operator()(sqlite3* db) const { sqlite3_close_v2(db); }
};
struct StmtFinalizer {
  void operator()(sqlite3_stmt* s) const { sqlite3_finalize(s); }
};

class Db {
 public:
  explicit Db(const std::string& path) : path_(path) {
    sqlite3* raw = nullptr;
    const int rc = sqlite3_open_v2(path.c_str(), &raw, SQLITE_OPEN_READWRITE, nullptr);
    db_.reset(raw);
    if (rc != SQLITE_OK) fail("cannot open");
    sqlite3_busy_timeout(db_.get(), 30'000);
  }
  [[noreturn]] void fail(const std::string& what) const {
    throw StatsError(path_ + ": " + what + ": " + (db_ ? sqlite3_errmsg(db_.get()) : "no memory"));
  }
  void exec(const std::string& sql) {
    if (sqlite3_exec(db_.get(), sql.c_str(), nullptr, nullptr, nullptr) != SQLITE_OK) fail(sql);
  }
  std::unique_ptr<sqlite3_stmt, StmtFinalizer> prepare(const std::string& sql) {
    sqlite3_stmt* s = nullptr;
    if (sqlite3_prepare_v2(db_.get(), sql.c_str(), -1, &s, nullptr) != SQLITE_OK) fail(sql);
    return std::unique_ptr<sqlite3_stmt, StmtFinalizer>(s);
  }
  // Steps `s`; true for a row, false when done.
  bool step(sqlite3_stmt* s) {
    const int rc = sqlite3_step(s);
    if (rc == SQLITE_ROW) return true;
    if (rc == SQLITE_DONE) return false;
    fail(sqlite3_sql(s));
  }
  std::int64_t int_query(const std::string& sql) {
    auto s = prepare(sql);
    return step(s.get()) ? sqlite3_column_int64(s.get(), 0) : 0;
  }
  std::int64_t last_id() const { return sqlite3_last_insert_rowid(db_.get()); }
  // The columns of `schema`.`table`, in order.
  std::vector<std::string> columns(const std::string& schema, const std::string& table) {
    auto s = prepare("PRAGMA " + schema + ".table_info(" + table + ")");
    std::vector<std::string> out;
    while (step(s.get()))
      out.emplace_back(reinterpret_cast<const char*>(sqlite3_column_text(s.get(), 1)));
    return out;
  }

 private:
  std::string path_;
  std::unique_ptr<sqlite3, DbCloser> db_;
};

std::string text(sqlite3_stmt* s, int col) {
  const unsigned char* t = sqlite3_column_text(s, col);
  return t ? reinterpret_cast<const char*>(t) : "";
}

// "INSERT INTO main.T (a, b, ...) SELECT a, ?1, ... FROM s.T WHERE <where>": every column of the
// target copied, `replaced` bound to ?1 instead, `skipped` left to its default.
std::string copy_sql(const std::vector<std::string>& cols, const std::string& table,
                     const std::string& replaced, const std::string& skipped,
                     const std::string& where) {
  std::string names;
  std::string values;
  for (const std::string& c : cols) {
    if (c == skipped) continue;
    if (!names.empty()) {
      names += ", ";
      values += ", ";
    }
    names += c;
    values += c == replaced ? "?1" : c;
  }
  return "INSERT INTO main." + table + " (" + names + ") SELECT " + values + " FROM s." + table +
         " WHERE " + where;
}

}  // namespace

MergeCounts merge_shard(const std::string& shard, const std::string& into) {
  std::error_code ec;
  if (!fs::is_regular_file(shard, ec)) throw StatsError(shard + ": no such shard file");
  if (fs::equivalent(shard, into, ec)) throw StatsError(shard + ": is the target itself");
  {
    const StatsStore check_shard(shard);  // its schema version is ours
    const StatsStore target(into);        // created with the schema if new
    target.require_writable();
  }
  Db db(into);
  db.exec("PRAGMA foreign_keys = ON");
  {
    auto a = db.prepare("ATTACH DATABASE ?1 AS s");
    sqlite3_bind_text(a.get(), 1, shard.c_str(), -1, SQLITE_TRANSIENT);
    db.step(a.get());
  }
  if (db.int_query("PRAGMA main.user_version") != db.int_query("PRAGMA s.user_version")) {
    throw StatsError(shard + ": another schema version than " + into);
  }
  MergeCounts counts;
  db.exec("BEGIN IMMEDIATE");
  try {
    // Child tables: every table of the target with a run_id column.
    std::vector<std::pair<std::string, std::vector<std::string>>> children;
    {
      auto t = db.prepare("SELECT name FROM main.sqlite_master WHERE type = 'table' ORDER BY name");
      while (db.step(t.get())) {
        const std::string name = text(t.get(), 0);
        std::vector<std::string> cols = db.columns("main", name);
        if (name != "runs" && std::find(cols.begin(), cols.end(), "run_id") != cols.end()) {
          children.emplace_back(name, std::move(cols));
        }
      }
    }
    const std::vector<std::string> batch_cols = db.columns("main", "batches");
    const std::vector<std::string> run_cols = db.columns("main", "runs");
    auto find_batch = db.prepare(
        "SELECT id FROM main.batches WHERE kind = ?1 AND scenario_hash = ?2 AND "
        "runs_per_variant = ?3");
    auto add_batch = db.prepare(copy_sql(batch_cols, "batches", "finished", "id", "id = ?2"));
    auto find_run = db.prepare(
        "SELECT result_hash FROM main.runs WHERE batch_id = ?1 AND variant = ?2 AND seed = ?3");
    auto add_run = db.prepare(copy_sql(run_cols, "runs", "batch_id", "id", "id = ?2"));
    auto set_recording = db.prepare("UPDATE main.runs SET recording = ?1 WHERE id = ?2");
    std::vector<std::pair<std::string, std::unique_ptr<sqlite3_stmt, StmtFinalizer>>> add_child;
    for (const auto& [name, cols] : children) {
      add_child.emplace_back(name, db.prepare(copy_sql(cols, name, "run_id", "", "run_id = ?2")));
    }
    std::set<std::int64_t> touched;
    auto batches =
        db.prepare("SELECT id, kind, scenario_hash, runs_per_variant FROM s.batches ORDER BY id");
    while (db.step(batches.get())) {
      const std::int64_t from = sqlite3_column_int64(batches.get(), 0);
      sqlite3_reset(find_batch.get());
      sqlite3_bind_text(find_batch.get(), 1, text(batches.get(), 1).c_str(), -1, SQLITE_TRANSIENT);
      sqlite3_bind_text(find_batch.get(), 2, text(batches.get(), 2).c_str(), -1, SQLITE_TRANSIENT);
      sqlite3_bind_int64(find_batch.get(), 3, sqlite3_column_int64(batches.get(), 3));
      std::int64_t to = 0;
      if (db.step(find_batch.get())) {
        to = sqlite3_column_int64(find_batch.get(), 0);
      } else {
        sqlite3_reset(add_batch.get());
        sqlite3_bind_null(add_batch.get(), 1);  // finished: set below when complete
        sqlite3_bind_int64(add_batch.get(), 2, from);
        db.step(add_batch.get());
        to = db.last_id();
        ++counts.batches_added;
      }
      auto runs = db.prepare(
          "SELECT id, variant, seed, recording, result_hash FROM s.runs WHERE batch_id = ?1 ORDER "
          "BY "
          "id");
      sqlite3_bind_int64(runs.get(), 1, from);
      while (db.step(runs.get())) {
        sqlite3_reset(find_run.get());
        sqlite3_bind_int64(find_run.get(), 1, to);
        sqlite3_bind_text(find_run.get(), 2, text(runs.get(), 1).c_str(), -1, SQLITE_TRANSIENT);
        sqlite3_bind_int64(find_run.get(), 3, sqlite3_column_int64(runs.get(), 2));
        if (db.step(find_run.get())) {
          ++counts.runs_present;
          // The same (variant, seed) of one batch is the same game: a different result means
          // different programs (llsfsim versions, data directories) played the two copies.
          if (text(find_run.get(), 0) != text(runs.get(), 4)) ++counts.runs_differing;
          continue;
        }
        const std::int64_t run_from = sqlite3_column_int64(runs.get(), 0);
        sqlite3_reset(add_run.get());
        sqlite3_bind_int64(add_run.get(), 1, to);
        sqlite3_bind_int64(add_run.get(), 2, run_from);
        db.step(add_run.get());
        const std::int64_t run_to = db.last_id();
        if (sqlite3_column_type(runs.get(), 3) != SQLITE_NULL && !text(runs.get(), 3).empty()) {
          const std::string rec =
              stored_recording_path(into, resolved_recording_path(shard, text(runs.get(), 3)));
          sqlite3_reset(set_recording.get());
          sqlite3_bind_text(set_recording.get(), 1, rec.c_str(), -1, SQLITE_TRANSIENT);
          sqlite3_bind_int64(set_recording.get(), 2, run_to);
          db.step(set_recording.get());
        }
        for (auto& [name, stmt] : add_child) {
          sqlite3_reset(stmt.get());
          sqlite3_bind_int64(stmt.get(), 1, run_to);
          sqlite3_bind_int64(stmt.get(), 2, run_from);
          db.step(stmt.get());
        }
        ++counts.runs_added;
        touched.insert(to);
      }
    }
    // A batch whose every run is now stored is finished (as run_batch marks a local one).
    for (const std::int64_t id : touched) {
      const std::int64_t missing = db.int_query(
          "SELECT b.runs_per_variant * b.variants - (SELECT count(*) FROM main.runs r WHERE "
          "r.batch_id = b.id) FROM main.batches b WHERE b.id = " +
          std::to_string(id) + " AND b.kind = 'batch' AND b.finished IS NULL");
      const std::int64_t unfinished =
          db.int_query("SELECT count(*) FROM main.batches WHERE finished IS NULL AND id = " +
                       std::to_string(id));
      if (unfinished == 1 && missing <= 0) {
        db.exec(
            "UPDATE main.batches SET finished = strftime('%Y-%m-%dT%H:%M:%SZ', 'now') WHERE id = " +
            std::to_string(id));
        ++counts.batches_finished;
      }
    }
    db.exec("COMMIT");
  } catch (...) {
    try {
      db.exec("ROLLBACK");
    } catch (
        const StatsError&) {  // NOLINT(bugprone-empty-catch): the first error is the one to tell
    }
    throw;
  }
  return counts;
}

}  // namespace llsf::study
