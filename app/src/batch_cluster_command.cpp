// SPDX-License-Identifier: MIT
// `llsfsim batch` on a Slurm cluster (docs/cluster.md): `--slurm` (submit a job array of the
// missing slices), `--task I` (one array task: its slice into its SQLite shard or the database
// server), `batch status` (done / running / missing per variant, games per minute, ETA, failed
// tasks with their job ids; --wait follows it) and `batch merge` (shards into one store).
#include <fmt/format.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <memory>
#include <optional>
#include <ostream>
#include <set>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "batch_cluster.h"
#include "batch_progress.h"
#include "cli_checks.h"
#include "llsf/app/cli.h"
#include "llsf/clips/agent.h"
#include "llsf/core/error.h"
#include "llsf/study/cluster.h"

namespace llsf::app {

namespace {

namespace fs = std::filesystem;
using Pair = std::pair<std::string, std::uint64_t>;  // variant, seed

struct ProcessOutput {
  int code = -1;       ///< exit code; -1 if it could not run or died of a signal
  std::string output;  ///< stdout and stderr
};

// Runs `argv` through the shell (each word quoted) and collects its output.
ProcessOutput run_process(const std::vector<std::string>& argv) {
  std::string cmd;
  for (const std::string& w : argv) cmd += study::shell_quote(w) + " ";
  cmd += "2>&1";
  ProcessOutput r;
  FILE* p = popen(cmd.c_str(), "r");
  if (p == nullptr) return r;
  std::array<char, 4096> buf{};
  std::size_t n = 0;
  while ((n = std::fread(buf.data(), 1, buf.size(), p)) > 0) r.output.append(buf.data(), n);
  const int status = pclose(p);
  if (status != -1 && WIFEXITED(status)) r.code = WEXITSTATUS(status);
  return r;
}

std::string utc_now() {
  const std::time_t t = std::time(nullptr);
  std::tm tm{};
  gmtime_r(&t, &tm);
  std::array<char, 32> buf{};
  std::strftime(buf.data(), buf.size(), "%Y-%m-%dT%H:%M:%SZ", &tm);
  return buf.data();
}

// Seconds since an ISO 8601 UTC time written by utc_now(); nullopt if unreadable.
std::optional<double> seconds_since(const std::string& iso) {
  std::tm tm{};
  if (strptime(iso.c_str(), "%Y-%m-%dT%H:%M:%SZ", &tm) == nullptr) return std::nullopt;
  return std::difftime(std::time(nullptr), timegm(&tm));
}

std::string absolute(const std::string& p) { return fs::absolute(p).lexically_normal().string(); }

// The batch of `key`'s identity in `store`, if stored (never created).
std::optional<std::int64_t> find_batch(const study::StatsStore& store, const study::BatchKey& key) {
  for (const study::StoredBatch& b : store.batches()) {
    if (b.kind == "batch" && b.scenario_hash == key.scenario_hash &&
        b.runs_per_variant == key.runs_per_variant) {
      return b.id;
    }
  }
  return std::nullopt;
}

// The (variant, seed) pairs of each loaded batch stored in the SQLite store `db` and its
// shards (or in the database server); `db` is not created.
std::vector<std::set<Pair>> stored_pairs(const std::string& db,
                                         const std::vector<LoadedBatch>& loaded) {
  std::vector<std::set<Pair>> out(loaded.size());
  std::vector<std::string> stores;
  std::error_code ec;
  if (study::is_database_url(db) || fs::exists(db, ec)) stores.push_back(db);
  if (!study::is_database_url(db)) {
    for (const std::string& s : study::existing_shards(db)) stores.push_back(s);
  }
  for (const std::string& path : stores) {
    const study::StatsStore store(path);
    for (std::size_t i = 0; i < loaded.size(); ++i) {
      if (const auto id = find_batch(store, loaded[i].key)) {
        for (auto& k : store.run_keys(*id)) out[i].insert(std::move(k));
      }
    }
  }
  return out;
}

// The batches' identities as kept in the job file: tells two batches' submissions into one store
// (one job file) apart.
std::string batch_identity(const std::vector<LoadedBatch>& loaded) {
  std::string id;
  for (const LoadedBatch& l : loaded) {
    id += (id.empty() ? "" : ",") + l.key.scenario_hash + ":" +
          std::to_string(l.key.runs_per_variant);
  }
  return id;
}

// The submissions of this batch recorded for `db` (lines of older llsfsim, without the
// identity, count for every batch).
std::vector<study::SlurmJob> batch_jobs(const std::string& db,
                                        const std::vector<LoadedBatch>& loaded) {
  const std::string id = batch_identity(loaded);
  std::vector<study::SlurmJob> jobs = study::read_jobs(db);
  std::erase_if(jobs, [&](const study::SlurmJob& j) { return !j.batch.empty() && j.batch != id; });
  return jobs;
}

// The store as printed: a URL with its password masked; a SQLite file "and its shards".
std::string store_text(const std::string& db) {
  return study::is_database_url(db) ? study::masked_database_url(db) : db + " and its shards";
}

std::int64_t total_pairs(const std::vector<LoadedBatch>& loaded) {
  std::int64_t n = 0;
  for (const LoadedBatch& l : loaded) n += static_cast<std::int64_t>(l.pairs.size());
  return n;
}

const std::string& variant_name(const LoadedBatch& l, const study::BatchPair& p) {
  return l.file.variants[static_cast<std::size_t>(p.variant)].variant;
}

}  // namespace

// ---- batch --slurm ----------------------------------------------------------------------------

int batch_submit(const BatchCommandOptions& o, std::ostream& out, std::ostream& err) {
  const std::string who = "llsfsim batch --slurm";
  std::vector<LoadedBatch> loaded;
  std::vector<std::set<Pair>> stored;
  const std::string db = study::is_database_url(o.db) ? o.db : absolute(o.db);
  try {
    loaded = load_batches(o.scenarios, seed_choice(o));
    stored = stored_pairs(db, loaded);
  } catch (const core::UserError& e) {
    err << who << ": " << e.what() << "\n";
    return kExitBadInput;
  }

  // The array's tasks: the slices of the pairs (all files in turn) that hold a missing run.
  std::set<int> tasks;
  std::int64_t offset = 0;
  std::int64_t done = 0;
  for (std::size_t i = 0; i < loaded.size(); ++i) {
    for (std::size_t k = 0; k < loaded[i].pairs.size(); ++k) {
      const study::BatchPair& p = loaded[i].pairs[k];
      if (stored[i].contains({variant_name(loaded[i], p), p.seed})) {
        ++done;
      } else {
        tasks.insert(static_cast<int>((offset + static_cast<std::int64_t>(k)) / o.games_per_task));
      }
    }
    offset += static_cast<std::int64_t>(loaded[i].pairs.size());
  }
  const std::int64_t total = total_pairs(loaded);
  if (tasks.empty()) {
    out << fmt::format("all {} runs are stored in {}; nothing to submit\n", total, store_text(db));
    return kExitOk;
  }

  const std::string recordings =
      o.no_record ? "" : absolute(o.recordings.empty() ? default_recordings_dir(db) : o.recordings);
  study::SlurmScript script;
  script.job_name = "llsfsim-" + loaded.front().file.variants.front().name;
  script.partition = o.partition;
  script.time_limit = o.time_limit;
  script.array_throttle = o.array_throttle;
  script.cpus_per_task = o.jobs.value_or(1);
  script.tasks.assign(tasks.begin(), tasks.end());
  script.sbatch_args = o.sbatch_args;
  script.log_dir = study::slurm_dir(db);
  // The tasks start in this directory: scenario paths as given name the same files (and the
  // same batch identity, which names the agent files as the scenario reaches them).
  script.workdir = fs::current_path().string();
  std::error_code ec;
  std::string self = fs::read_symlink("/proc/self/exe", ec).string();
  if (ec) self = "llsfsim";
  script.command = {self, "batch"};
  for (const LoadedBatch& l : loaded) script.command.push_back(l.path);
  script.command.insert(script.command.end(),
                        {"--db", db, "--games-per-task", std::to_string(o.games_per_task), "--jobs",
                         std::to_string(script.cpus_per_task)});
  if (o.runs) script.command.insert(script.command.end(), {"--runs", std::to_string(*o.runs)});
  if (!o.seeds.empty()) script.command.insert(script.command.end(), {"--seeds", o.seeds});
  if (o.no_record) {
    script.command.emplace_back("--no-record");
  } else {
    script.command.insert(script.command.end(), {"--recordings", recordings});
    if (o.record_agents) script.command.emplace_back("--record-agents");
  }
  std::string text;
  try {
    text = study::slurm_script(script);
  } catch (const core::UserError& e) {
    err << who << ": " << e.what() << "\n";
    return kExitBadInput;
  }
  if (o.dry_run) {
    out << text;
    return kExitOk;
  }

  // The batches exist in the main store before a task starts: tasks name their recordings'
  // directory by the main store's batch id, as a local batch does.
  std::vector<std::int64_t> opened_now;  // batches this submission created (undone if it fails)
  try {
    study::StatsStore store(db);
    store.require_writable();
    for (const LoadedBatch& l : loaded) {
      const bool existed = find_batch(store, l.key).has_value();
      const std::int64_t id = store.open_batch(l.key);
      if (!existed) opened_now.push_back(id);
    }
  } catch (const study::StatsError& e) {
    err << who << ": " << e.what() << "\n";
    return kExitBadInput;
  }
  // A submission that fails leaves nothing behind: no empty batch, no job script.
  auto undo = [&db, &opened_now, &script](const std::string& script_file) {
    std::error_code ignored;
    if (!script_file.empty()) fs::remove(script_file, ignored);
    fs::remove(script.log_dir, ignored);  // only if it is empty
    try {
      study::StatsStore store(db);
      for (const std::int64_t id : opened_now) store.remove_empty_batch(id);
    } catch (const study::StatsError&) {
      // The store was just written; if it cannot be reached now the error above says enough.
    }
  };
  fs::create_directories(script.log_dir, ec);
  if (ec) {
    err << who << ": cannot create " << script.log_dir << ": " << ec.message() << "\n";
    undo("");
    return kExitBadInput;
  }
  const std::string stamp = utc_now();
  // job-N.sh with the first free N, created exclusively: two submissions at once into one
  // directory (two batches of one database server) never share a script.
  std::string script_path;
  for (int n = 1;; ++n) {
    script_path = script.log_dir + "/job-" + std::to_string(n) + ".sh";
    std::FILE* f = std::fopen(script_path.c_str(), "wx");
    if (f == nullptr) {
      if (errno == EEXIST) continue;
      err << who << ": cannot write " << script_path << ": " << std::strerror(errno) << "\n";
      undo("");
      return kExitBadInput;
    }
    const bool written = std::fwrite(text.data(), 1, text.size(), f) == text.size();
    if (std::fclose(f) != 0 || !written) {
      err << who << ": cannot write " << script_path << "\n";
      undo(script_path);
      return kExitBadInput;
    }
    break;
  }
  const ProcessOutput sb = run_process({"sbatch", "--parsable", script_path});
  std::string job_id = sb.output.substr(0, sb.output.find_first_of(";\n"));
  if (sb.code != 0 || job_id.empty() ||
      !std::all_of(job_id.begin(), job_id.end(), [](char c) { return c >= '0' && c <= '9'; })) {
    err << who << ": sbatch " << script_path << " failed"
        << (sb.code == 127 ? " (sbatch not found: is slurm-client installed?)" : "") << ":\n"
        << sb.output
        << "(nothing was submitted: the job script and the new batch rows are removed)\n";
    undo(script_path);
    return kExitBadInput;
  }
  study::SlurmJob job;
  job.job_id = job_id;
  job.submitted = stamp;
  job.games_per_task = o.games_per_task;
  job.array = study::array_spec(script.tasks, o.array_throttle);
  job.stored_at_submit = done;
  job.total = total;
  job.batch = batch_identity(loaded);
  job.script = script_path;
  for (const LoadedBatch& l : loaded) job.scenarios.push_back(l.path);
  study::append_job(db, job);
  if (!o.quiet) {
    out << fmt::format(
        "submitted  job {} (array {}): {} of {} runs missing, {} games per task\n"
        "script     {}\nlogs       {}/slurm-{}_<task>.out\n",
        job_id, job.array, total - done, total, o.games_per_task, script_path, script.log_dir,
        job_id);
    std::string follow;
    for (const LoadedBatch& l : loaded) follow += " " + study::shell_quote(l.path);
    if (o.runs) follow += " --runs " + std::to_string(*o.runs);
    if (!o.seeds.empty()) follow += " --seeds " + study::shell_quote(o.seeds);
    out << fmt::format(
        "follow     llsfsim batch status{} --db {} --wait\n", follow,
        study::shell_quote(study::is_database_url(db) ? study::masked_database_url(db) : db));
    if (!study::is_database_url(db)) {
      out << fmt::format("then       llsfsim batch merge --db {}\n", study::shell_quote(db));
    }
  }
  return kExitOk;
}

// ---- batch --task I ---------------------------------------------------------------------------

int batch_task(const BatchCommandOptions& o, std::ostream& out, std::ostream& err) {
  const int task = *o.task;
  const std::string who = "llsfsim batch --task " + std::to_string(task);
  std::vector<LoadedBatch> loaded;
  try {
    loaded = load_batches(o.scenarios, seed_choice(o));
  } catch (const core::UserError& e) {
    err << who << ": " << e.what() << "\n";
    return kExitBadInput;
  }
  const bool server = study::is_database_url(o.db);
  const std::string target = server ? o.db : study::shard_path(o.db, task);
  // Runs and batch ids of the main store (a SQLite file: read, never written by a task).
  std::vector<std::set<Pair>> in_main(loaded.size());
  std::vector<std::int64_t> main_ids(loaded.size(), 0);
  std::optional<study::StatsStore> store;
  try {
    std::error_code ec;
    if (!server && fs::exists(o.db, ec)) {
      const study::StatsStore main(o.db);
      for (std::size_t i = 0; i < loaded.size(); ++i) {
        if (const auto id = find_batch(main, loaded[i].key)) {
          main_ids[i] = *id;
          for (auto& k : main.run_keys(*id)) in_main[i].insert(std::move(k));
        }
      }
    }
    store.emplace(target);
    store->require_writable();
  } catch (const study::StatsError& e) {
    err << who << ": " << e.what() << "\n";
    return kExitBadInput;
  }

  const std::int64_t begin = static_cast<std::int64_t>(task) * o.games_per_task;
  const std::int64_t end = begin + o.games_per_task;
  if (begin >= total_pairs(loaded)) {
    err << who << ": the batch has " << total_pairs(loaded) << " runs; task " << task
        << " of --games-per-task " << o.games_per_task << " has none\n";
    return kExitBadInput;
  }
  const SigintGuard sigint;
  BatchProgressPrinter progress(who, err, o.quiet);
  std::int64_t offset = 0;
  for (std::size_t i = 0; i < loaded.size(); ++i) {
    const LoadedBatch& l = loaded[i];
    const auto n = static_cast<std::int64_t>(l.pairs.size());
    const std::int64_t b = std::max<std::int64_t>(begin - offset, 0);
    const std::int64_t e = std::min<std::int64_t>(end - offset, n);
    offset += n;
    if (b >= e) continue;
    study::BatchOptions options;
    options.choice = l.choice;
    options.jobs = o.jobs.value_or(1);
    options.record_agents = o.record_agents;
    if (!o.no_record) {
      options.recordings_dir = o.recordings.empty() ? default_recordings_dir(o.db) : o.recordings;
    }
    options.recordings_batch_id = main_ids[i];
    options.slice_begin = b;
    options.slice_end = e;
    options.stored_elsewhere = std::move(in_main[i]);
    study::BatchResult r;
    try {
      r = study::run_batch(l.file, l.hash, *store, options, progress.hooks());
    } catch (const clips::AgentLoadError& ex) {
      err << who << ": agent error:\n" << ex.what() << "\n";
      return kExitBadInput;
    } catch (const core::ConfigError& ex) {
      err << who << ": " << ex.what() << "\n";
      return kExitBadInput;
    }
    if (!o.quiet) {
      out << fmt::format("task {}: {} pairs {}..{} of {}: {} played, {} stored before, into {}\n",
                         task, l.path, b, e - 1, n, r.played, r.skipped,
                         study::masked_database_url(target));
    }
    if (r.interrupted) return kExitInterrupted;
  }
  // Test verdicts are stored; the task itself succeeded (a failed test is not a failed task).
  return kExitOk;
}

// ---- batch status -----------------------------------------------------------------------------

namespace {

struct StatusOptions {
  std::vector<std::string> scenarios;
  std::optional<int> runs;
  std::string seeds;
  std::string db{study::StatsStore::kDefaultPath};
  bool wait = false;
  double interval_s = 5.0;
  int resubmit = 0;  ///< --wait: resubmissions of the missing tasks at most
};

struct VariantCount {
  std::string variant;
  int total = 0;
  int done = 0;
  int running = 0;
  int queued = 0;
};

struct Status {
  std::vector<VariantCount> variants;
  int total = 0;
  int done = 0;
  int running = 0;
  int queued = 0;
  std::optional<double> per_minute;
  std::vector<std::string> failed;  ///< "task 3 (job 123_3): CANCELLED ..." with missing runs
  std::string note;                 ///< e.g. sacct unavailable
  /// The tasks (of the last submission's games per task) holding a run that is neither stored
  /// nor in a live task.
  std::set<int> missing_tasks;
};

bool live_state(const std::string& s) {
  return s == "RUNNING" || s == "COMPLETING" || s == "CONFIGURING" || s == "REQUEUED" ||
         s == "RESIZING" || s == "SIGNALING" || s == "STAGE_OUT" || s == "REQUEUE_HOLD" ||
         s == "REQUEUE_FED" || s == "SUSPENDED";
}
bool failed_state(const std::string& s) {
  return s == "FAILED" || s == "CANCELLED" || s == "TIMEOUT" || s == "NODE_FAIL" ||
         s == "OUT_OF_MEMORY" || s == "PREEMPTED" || s == "BOOT_FAIL" || s == "DEADLINE";
}

Status collect(const std::vector<LoadedBatch>& loaded, const std::string& db) {
  Status st;
  const std::vector<std::set<Pair>> stored = stored_pairs(db, loaded);
  const std::vector<study::SlurmJob> jobs = batch_jobs(db, loaded);

  // What Slurm says about the recorded arrays: the live tasks (squeue) and the ended ones (sacct).
  std::map<std::string, int> games_per_task;
  std::string ids;
  for (const study::SlurmJob& j : jobs) {
    games_per_task[j.job_id] = j.games_per_task;
    ids += (ids.empty() ? "" : ",") + j.job_id;
  }
  // squeue -t all: the live tasks and those that ended within slurmctld's MinJobAge (all jobs,
  // filtered here: a job id slurmctld has forgotten would fail `squeue -j`); sacct (with Slurm
  // accounting) for older ones.
  std::vector<study::SlurmTask> live;
  std::vector<study::SlurmTask> ended;
  if (!ids.empty()) {
    const ProcessOutput q = run_process({"squeue", "-h", "-t", "all", "-o", "%i|%T|%r"});
    if (q.code == 0) {
      for (study::SlurmTask& t : study::parse_slurm_tasks(q.output)) {
        if (!games_per_task.contains(t.job_id)) continue;
        (failed_state(t.state) ? ended : live).push_back(std::move(t));
      }
    } else {
      st.note = "squeue failed: " + q.output.substr(0, q.output.find('\n'));
    }
    const ProcessOutput a =
        run_process({"sacct", "-n", "-P", "-X", "-j", ids, "-o", "JobID,State,ExitCode"});
    if (a.code == 0) {
      for (study::SlurmTask& t : study::parse_slurm_tasks(a.output)) ended.push_back(std::move(t));
    }
  }
  // Global pair index -> running (1) / queued (2).
  std::map<std::int64_t, int> active;
  std::set<std::pair<std::string, int>> live_tasks;
  auto mark = [&](const std::string& job, int task, int how) {
    const auto g = games_per_task.find(job);
    if (g == games_per_task.end()) return;
    live_tasks.insert({job, task});
    for (std::int64_t k = static_cast<std::int64_t>(task) * g->second;
         k < static_cast<std::int64_t>(task + 1) * g->second; ++k) {
      int& a = active[k];
      if (a == 0 || how < a) a = how;
    }
  };
  for (const study::SlurmTask& t : live) {
    if (!live_state(t.state) && t.state != "PENDING") continue;  // COMPLETED and the like
    if (t.task >= 0) {
      mark(t.job_id, t.task, live_state(t.state) ? 1 : 2);
    } else {
      for (const int p : t.pending) mark(t.job_id, p, 2);
    }
  }
  // A failed task's pairs [first, first + games per task) and what happened to it.
  std::map<std::int64_t, std::pair<std::int64_t, std::string>> why_failed;
  for (const study::SlurmTask& t : ended) {
    if (t.task < 0 || !failed_state(t.state) || live_tasks.contains({t.job_id, t.task})) continue;
    const auto g = games_per_task.find(t.job_id);
    if (g == games_per_task.end()) continue;
    why_failed[static_cast<std::int64_t>(t.task) * g->second] = {
        g->second,
        fmt::format("task {} (job {}_{}): {}{}", t.task, t.job_id, t.task, t.state,
                    t.detail.empty() || t.detail == "None" ? "" : " (" + t.detail + ")")};
  }

  std::int64_t offset = 0;
  std::set<std::string> told;
  for (std::size_t i = 0; i < loaded.size(); ++i) {
    const LoadedBatch& l = loaded[i];
    std::map<std::string, VariantCount> by;
    for (std::size_t k = 0; k < l.pairs.size(); ++k) {
      const std::string& v = variant_name(l, l.pairs[k]);
      VariantCount& c = by[v];
      c.variant = v;
      ++c.total;
      const std::int64_t g = offset + static_cast<std::int64_t>(k);
      if (stored[i].contains({v, l.pairs[k].seed})) {
        ++c.done;
        continue;
      }
      const auto a = active.find(g);
      if (a != active.end()) {
        (a->second == 1 ? c.running : c.queued) += 1;
        continue;
      }
      // Missing: its task in the last submission's cut, and a failed task that held it.
      if (!jobs.empty()) st.missing_tasks.insert(static_cast<int>(g / jobs.back().games_per_task));
      for (const auto& [first, what] : why_failed) {
        if (g >= first && g < first + what.first && told.insert(what.second).second) {
          st.failed.push_back(what.second);
        }
      }
    }
    for (const study::Scenario& s : l.file.variants) {
      if (by.contains(s.variant)) {
        st.variants.push_back(by[s.variant]);
        by.erase(s.variant);
      }
    }
    offset += static_cast<std::int64_t>(l.pairs.size());
  }
  for (const VariantCount& c : st.variants) {
    st.total += c.total;
    st.done += c.done;
    st.running += c.running;
    st.queued += c.queued;
  }
  if (!jobs.empty()) {
    const study::SlurmJob& last = jobs.back();
    const auto since = seconds_since(last.submitted);
    if (since && *since > 0 && st.done > last.stored_at_submit) {
      st.per_minute = static_cast<double>(st.done - last.stored_at_submit) / (*since / 60.0);
    }
  }
  return st;
}

void print_status(const Status& st, const std::string& db, std::ostream& out) {
  out << fmt::format("{:<32} {:>6} {:>6} {:>7} {:>6} {:>7}\n", "variant", "runs", "done", "running",
                     "queued", "missing");
  for (const VariantCount& c : st.variants) {
    out << fmt::format("{:<32} {:>6} {:>6} {:>7} {:>6} {:>7}\n",
                       c.variant.empty() ? "-" : c.variant, c.total, c.done, c.running, c.queued,
                       c.total - c.done - c.running - c.queued);
  }
  const int missing = st.total - st.done - st.running - st.queued;
  std::string rate = "games/min   -";
  if (st.per_minute) {
    const double eta = (st.total - st.done) / *st.per_minute * 60.0;
    rate = fmt::format("games/min   {:.1f}, ETA {}", *st.per_minute, duration_text(eta));
  }
  out << fmt::format(
      "total       {} of {} runs stored in {}; {} running, {} queued, {} missing\n{}\n", st.done,
      st.total, store_text(db), st.running, st.queued, missing, rate);
  for (const std::string& f : st.failed) out << "failed      " << f << "\n";
  if (!st.note.empty()) out << "note        " << st.note << "\n";
  if (missing > 0 && st.running + st.queued == 0) {
    out << "missing     resubmit with the same `llsfsim batch ... --slurm` to play them\n";
  }
}

// Submits the tasks of `st.missing_tasks` again with the last submission's job script (sbatch's
// --array overrides the script's); records the job. Returns false (and says why) if it cannot.
bool resubmit(const Status& st, const std::string& db, const std::vector<LoadedBatch>& loaded,
              std::ostream& err) {
  const std::vector<study::SlurmJob> jobs = batch_jobs(db, loaded);
  if (jobs.empty() || st.missing_tasks.empty()) return false;
  // The last job script of this batch (job files of older llsfsim: study-slurm/job-N.sh with the
  // largest N).
  std::string script = jobs.back().script;
  int largest = 0;
  std::error_code ec;
  if (script.empty()) {
    for (const auto& e : fs::directory_iterator(study::slurm_dir(db), ec)) {
      const std::string name = e.path().filename().string();
      if (!name.starts_with("job-") || !name.ends_with(".sh")) continue;
      const int n = std::atoi(name.c_str() + 4);
      if (n > largest) {
        largest = n;
        script = e.path().string();
      }
    }
  }
  if (script.empty()) {
    err << "llsfsim batch status: no job script in " << study::slurm_dir(db) << " to resubmit\n";
    return false;
  }
  const std::vector<int> tasks(st.missing_tasks.begin(), st.missing_tasks.end());
  const std::string array = study::array_spec(tasks, 0);
  const ProcessOutput sb = run_process({"sbatch", "--parsable", "--array=" + array, script});
  const std::string job_id = sb.output.substr(0, sb.output.find_first_of(";\n"));
  if (sb.code != 0 || job_id.empty()) {
    err << "llsfsim batch status: sbatch " << script << " failed:\n" << sb.output;
    return false;
  }
  study::SlurmJob job = jobs.back();
  job.job_id = job_id;
  job.submitted = utc_now();
  job.array = array;
  job.script = script;
  job.stored_at_submit = st.done;
  study::append_job(db, job);
  err << fmt::format(
      "llsfsim batch status: resubmitted the tasks holding the {} missing runs: job {} "
      "(array {})\n",
      st.total - st.done - st.running - st.queued, job_id, array);
  return true;
}

int batch_status(const StatusOptions& o, std::ostream& out, std::ostream& err) {
  const std::string who = "llsfsim batch status";
  BatchCommandOptions bo;
  bo.scenarios = o.scenarios;
  bo.runs = o.runs;
  bo.seeds = o.seeds;
  const std::string db = study::is_database_url(o.db) ? o.db : absolute(o.db);
  std::vector<LoadedBatch> loaded;
  Status st;
  try {
    loaded = load_batches(bo.scenarios, seed_choice(bo));
    st = collect(loaded, db);
  } catch (const core::UserError& e) {
    err << who << ": " << e.what() << "\n";
    return kExitBadInput;
  }
  if (!o.wait) {
    print_status(st, db, out);
    return kExitOk;
  }
  // --wait: a bar on a terminal (or a line per change) until every run is stored.
  const SigintGuard sigint;
  const bool bar = &err == &std::cerr && isatty(STDERR_FILENO) != 0;
  int last_done = -1;
  int resubmits_left = o.resubmit;
  for (;;) {
    if (st.done != last_done || bar) {
      const std::string eta =
          st.per_minute ? duration_text((st.total - st.done) / *st.per_minute * 60.0) : "-";
      err << fmt::format("{}{} {}/{} runs, {} running, {} queued, {:.1f} games/min, ETA {}{}",
                         bar ? "\r" : "", progress_bar(st.done, st.total), st.done, st.total,
                         st.running, st.queued, st.per_minute.value_or(0.0), eta,
                         bar ? "   " : "\n");
      err.flush();
      last_done = st.done;
    }
    if (st.done == st.total || SigintGuard::interrupted()) break;
    if (st.running + st.queued == 0) {  // nothing left that could store the rest
      if (resubmits_left == 0) break;
      if (bar) err << "\n";
      for (const std::string& f : st.failed) err << "failed      " << f << "\n";
      if (!resubmit(st, db, loaded, err)) break;
      --resubmits_left;
      last_done = -1;
    }
    std::this_thread::sleep_for(std::chrono::duration<double>(o.interval_s));
    try {
      st = collect(loaded, db);
    } catch (const core::UserError& e) {
      err << (bar ? "\n" : "") << who << ": " << e.what() << "\n";
      return kExitBadInput;
    }
  }
  if (bar) err << "\n";
  print_status(st, db, out);
  if (SigintGuard::interrupted()) return kExitInterrupted;
  return st.done == st.total ? kExitOk : kExitFailed;
}

}  // namespace

Action add_batch_status_command(CLI::App& sub) {
  auto o = std::make_shared<StatusOptions>();
  sub.add_option("scenarios", o->scenarios, "The batch's scenario files")->required();
  auto* runs = sub.add_option("--runs", o->runs, "As given to `batch`")->check(kPositive);
  sub.add_option("--seeds", o->seeds, "As given to `batch`")->excludes(runs);
  sub.add_option("--db", o->db, "The statistics store given to `batch`")->capture_default_str();
  auto* wait =
      sub.add_flag("--wait", o->wait,
                   "Follow the batch with a progress bar until every run is stored (exit 0), or "
                   "until no task is left running or queued with runs missing (exit 1)");
  sub.add_option("--resubmit", o->resubmit,
                 "With --wait: when runs are missing and no task is left (a task failed, was "
                 "cancelled or timed out), submit the tasks holding them again with the last job "
                 "script, at most N times")
      ->check(CLI::Range(0, 1000))
      ->needs(wait);
  sub.add_option("--interval", o->interval_s, "Seconds between two looks with --wait")
      ->check(CLI::Range(0.1, 3600.0))
      ->capture_default_str();
  sub.footer(
      "Per variant: runs stored (in --db and, for a SQLite store, its shards), running and "
      "queued in the Slurm array tasks that `batch --slurm` recorded in <db>.slurm-jobs "
      "(squeue), missing; games per minute since the last submission and the ETA; tasks that "
      "failed, were cancelled or timed out (sacct) with their job ids.\n"
      "Exit code: 0 ok (with --wait: complete), 1 --wait ended with runs missing, 2 bad input, "
      "130 interrupted.");
  return [o](std::ostream& out, std::ostream& err) { return batch_status(*o, out, err); };
}

// ---- batch merge ------------------------------------------------------------------------------

namespace {

struct MergeOptions {
  std::vector<std::string> shards;
  std::string db{study::StatsStore::kDefaultPath};
  bool quiet = false;
};

int batch_merge(const MergeOptions& o, std::ostream& out, std::ostream& err) {
  const std::string who = "llsfsim batch merge";
  if (study::is_database_url(o.db)) {
    err << who << ": --db " << o.db
        << ": shards merge into a SQLite file; Slurm tasks write to a database server directly\n";
    return kExitBadInput;
  }
  const std::vector<std::string> shards =
      o.shards.empty() ? study::existing_shards(o.db) : o.shards;
  if (shards.empty()) {
    err << who << ": no shards given and none beside " << o.db << " (<name>.shard-NNNNN.db)\n";
    return kExitBadInput;
  }
  study::MergeCounts sum;
  for (const std::string& s : shards) {
    try {
      const study::MergeCounts c = study::merge_shard(s, o.db);
      sum.batches_added += c.batches_added;
      sum.runs_added += c.runs_added;
      sum.runs_present += c.runs_present;
      sum.batches_finished += c.batches_finished;
      sum.runs_differing += c.runs_differing;
      if (!o.quiet) {
        out << fmt::format("{}: {} runs added, {} already in {}\n", s, c.runs_added, c.runs_present,
                           o.db);
      }
    } catch (const study::StatsError& e) {
      err << who << ": " << e.what() << "\n";
      return kExitBadInput;
    }
  }
  if (sum.runs_differing > 0) {
    err << who << ": " << sum.runs_differing
        << " runs of the shards have another result hash than the same (variant, seed) in " << o.db
        << " (kept: the store's); were they played by different llsfsim versions?\n";
  }
  if (!o.quiet) {
    out << fmt::format(
        "merged     {} shards into {}: {} runs added, {} already there, {} new "
        "batches, {} batches complete\n",
        shards.size(), o.db, sum.runs_added, sum.runs_present, sum.batches_added,
        sum.batches_finished);
  }
  return kExitOk;
}

}  // namespace

Action add_batch_merge_command(CLI::App& sub) {
  auto o = std::make_shared<MergeOptions>();
  sub.add_option("shards", o->shards,
                 "Shard files (default: every <db name>.shard-NNNNN.db beside --db)");
  sub.add_option("--db", o->db, "The SQLite store to merge into (created if missing)")
      ->capture_default_str();
  sub.add_flag("-q,--quiet", o->quiet, "Only the exit code");
  sub.footer(
      "Copies every run of the shards that --db lacks, whole (statistics, orders, tests, awards, "
      "events), into the batch of the same identity; one transaction per shard. Merging again "
      "changes nothing. The shards are left as they are.\n"
      "Exit code: 0 ok, 2 bad input (a file that cannot be read, another schema version).");
  return [o](std::ostream& out, std::ostream& err) { return batch_merge(*o, out, err); };
}

}  // namespace llsf::app
