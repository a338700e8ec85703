// SPDX-License-Identifier: MIT
// Batches on a Slurm cluster (docs/cluster.md): the slices of a batch that array tasks play, the
// SQLite shards they write without a database server and their merge, the job script, the job
// file beside the store and what squeue/sacct say about the tasks. No process is started here:
// `llsfsim batch --slurm` (app) runs sbatch, squeue and sacct and hands their output to these.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace llsf::study {

// is_database_url() (a postgresql:// URL or a SQLite file) is in stats_store.h.

/// The SQLite shard that array task `task` writes for the store `db`: "<dir>/<stem>.shard-<task,
/// 5 digits>.db" beside it (study.db -> study.shard-00003.db).
std::string shard_path(const std::string& db, int task);
/// The shards of `db` that exist, by name.
std::vector<std::string> existing_shards(const std::string& db);

/// The job file beside the store, "<db>.slurm-jobs": one line per submission (SlurmJob); for a
/// database server "llsfsim-slurm/<host and database>.slurm-jobs" in the current directory.
std::string job_file_path(const std::string& db);
/// The directory beside the store for job scripts and the tasks' logs, "<dir>/<stem>-slurm";
/// for a database server "llsfsim-slurm" in the current directory (absolute).
std::string slurm_dir(const std::string& db);

/// One submission, as kept in the job file (tab-separated, one line: job id, submitted, games
/// per task, array, stored, total, `batch=...`, `script=...`, scenarios).
struct SlurmJob {
  std::string job_id;                 ///< sbatch's job id of the array
  std::string submitted;              ///< UTC, ISO 8601 (wall clock; progress only)
  int games_per_task = 0;             ///< the slice length
  std::string array;                  ///< the --array spec, e.g. "0-3,7%2"
  std::int64_t stored_at_submit = 0;  ///< runs stored when submitted (for games per minute)
  std::int64_t total = 0;             ///< runs of the batch
  /// The batches' identities ("<scenario hash>:<runs per variant>" per file, comma-separated):
  /// tells the submissions of two batches into one store apart ("" in lines of older llsfsim).
  std::string batch;
  std::string script;                  ///< the job script submitted ("" in older lines)
  std::vector<std::string> scenarios;  ///< as given to `batch --slurm`
};
/// Appends `job` to the job file of `db`. Throws core::ConfigError if it cannot be written.
void append_job(const std::string& db, const SlurmJob& job);
/// The submissions recorded for `db` (none if there is no job file). Throws core::ConfigError
/// naming the file and line for a malformed line.
std::vector<SlurmJob> read_jobs(const std::string& db);

/// What a Slurm job script does.
struct SlurmScript {
  std::string job_name = "llsfsim";
  std::string partition;                 ///< "" = the cluster's default
  std::string time_limit;                ///< per task, sbatch --time ("" = the partition's)
  int array_throttle = 0;                ///< %K: at most K tasks at once; 0 = no limit
  int cpus_per_task = 1;                 ///< = the task's --jobs
  std::vector<int> tasks;                ///< the array's task ids
  std::vector<std::string> sbatch_args;  ///< extra `#SBATCH` lines, verbatim
  std::string log_dir;                   ///< slurm-%A_%a.out goes there
  std::string workdir;                   ///< sbatch --chdir: where the tasks start ("" = sbatch's)
  std::vector<std::string> command;      ///< the task's command; SLURM_ARRAY_TASK_ID is appended
};
/// "0-3,7,9-10" (ranges of consecutive ids) followed by "%K" when throttled.
std::string array_spec(const std::vector<int>& tasks, int throttle);
/// The bash job script for sbatch: #SBATCH lines (--requeue: a task whose node fails runs
/// again), then `exec` of the command with "--task $SLURM_ARRAY_TASK_ID". Words are quoted for
/// the shell. Throws core::ConfigError if an sbatch argument holds a newline or no task is given.
std::string slurm_script(const SlurmScript& s);
/// `s` quoted for bash (single quotes unless it is made of safe characters).
std::string shell_quote(std::string_view s);

/// One array task as squeue or sacct reports it.
struct SlurmTask {
  std::string job_id;        ///< the array's job id ("123")
  int task = -1;             ///< the array index; -1 for the pending rest of an array ("[4-9%2]")
  std::vector<int> pending;  ///< the indices of a pending rest
  std::string state;   ///< RUNNING, PENDING, COMPLETED, FAILED, CANCELLED, TIMEOUT, NODE_FAIL, ...
  std::string detail;  ///< reason (squeue) or exit code (sacct)
};
/// Parses `squeue -h -r -o '%i|%T|%r'` (e.g. "123_4|RUNNING|None") and `sacct -n -P -X -o
/// JobID,State,ExitCode` output ("123_4|CANCELLED by 0|0:15"). Lines that are not array tasks
/// are skipped; "123_[4-9%2]" yields one entry with `pending`.
std::vector<SlurmTask> parse_slurm_tasks(std::string_view text);

/// What merge_shard() did.
struct MergeCounts {
  int batches_added = 0;     ///< batches the target did not have
  int runs_added = 0;        ///< runs copied
  int runs_present = 0;      ///< runs the target held already (not copied again)
  int runs_differing = 0;    ///< of those, runs whose result hash differs from the shard's copy
  int batches_finished = 0;  ///< batches that became complete by the merge
};
/// Copies every run of the SQLite store `shard` that the SQLite store `into` lacks, with its
/// statistics, orders, test verdicts, awards and events, into the batch of the same identity
/// (kind, scenario_hash, runs_per_variant), created if missing; one transaction per shard, so
/// an interrupted merge leaves nothing half-copied. Recording paths are rewritten relative to
/// `into`. A batch whose runs are all present afterwards is marked finished. Idempotent:
/// merging again copies nothing. Throws StatsError if a file cannot be read or written or the
/// two schema versions differ.
MergeCounts merge_shard(const std::string& shard, const std::string& into);

}  // namespace llsf::study
