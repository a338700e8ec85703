// SPDX-License-Identifier: MIT
// `llsfsim batch` on a Slurm cluster (docs/cluster.md): `--slurm` submits a job array, the
// hidden `--task I` is what one array task runs, `batch status` and `batch merge`.
#pragma once

#include <CLI/CLI.hpp>

#include <iosfwd>
#include <optional>
#include <string>
#include <vector>

#include "commands.h"
#include "llsf/study/batch.h"
#include "llsf/study/scenario.h"
#include "llsf/study/stats_store.h"

namespace llsf::app {

/// The options of `llsfsim batch`.
struct BatchCommandOptions {
  std::vector<std::string> scenarios;
  std::optional<int> runs;
  std::string seeds;  ///< --seeds "1,5,9-12" ("" = none)
  std::optional<int> jobs;
  std::string db{study::StatsStore::kDefaultPath};
  std::string recordings;  ///< "" = default_recordings_dir(db)
  bool no_record = false;
  bool record_agents = false;
  bool quiet = false;
  bool fail_fast = false;  ///< stop at the first run with an agent error (not with --slurm)
  // Playing until the answer is known (docs/llsfsim.md, "--until").
  std::string until;  ///< "VARIANT_A>VARIANT_B" ("" = a plain batch)
  std::string statistic = "points";
  std::optional<double> margin;
  std::optional<int> max_runs;
  int looks = 5;
  // Slurm
  bool slurm = false;
  std::string partition;
  std::string time_limit;
  int array_throttle = 0;
  int games_per_task = 10;
  std::vector<std::string> sbatch_args;
  bool dry_run = false;
  std::optional<int> task;  ///< hidden: play array task I's slice
};

/// A scenario file of a batch, loaded and checked, with its pairs and identity.
struct LoadedBatch {
  std::string path;
  study::ScenarioFile file;
  std::string hash;
  study::SeedChoice choice;
  std::vector<study::BatchPair> pairs;
  study::BatchKey key;
};

/// Loads `paths` with `choice`: files, identities, pairs. Throws core::UserError.
std::vector<LoadedBatch> load_batches(const std::vector<std::string>& paths,
                                      const study::SeedChoice& choice);
/// The seed choice of the options (--runs, --seeds). Throws core::ConfigError.
study::SeedChoice seed_choice(const BatchCommandOptions& o);

/// `batch --slurm`: writes the job script and submits it (or prints it with --dry-run).
int batch_submit(const BatchCommandOptions& o, std::ostream& out, std::ostream& err);
/// `batch --task I`: plays array task I's slice into its shard (or the database server).
int batch_task(const BatchCommandOptions& o, std::ostream& out, std::ostream& err);
/// Registers `batch status` on `sub`.
Action add_batch_status_command(CLI::App& sub);
/// Registers `batch merge` on `sub`.
Action add_batch_merge_command(CLI::App& sub);

}  // namespace llsf::app
