// SPDX-License-Identifier: MIT
// Batch: every matrix variant of a scenario file x N seeds, played on worker threads (games are
// independent and single-threaded) and stored run by run in a StatsStore. Resumable: the runs a
// store already holds for the batch are not played again.
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "llsf/study/runner.h"
#include "llsf/study/scenario.h"
#include "llsf/study/stats_store.h"

namespace llsf::study {

/// How a batch is played.
struct BatchOptions {
  /// Runs per variant: the first N seeds of the scenario's list; for a single seed s the seeds
  /// s, s+1, ..., s+N-1. Unset: the scenario's seed list.
  std::optional<int> runs;
  /// Worker threads (>= 1); 0: std::thread::hardware_concurrency().
  int jobs = 0;
  /// If set, every game is recorded to <recordings_dir>/batch<ID>/recording_file_name(...)
  /// (the directory is created) and the store keeps the path with the run.
  std::string recordings_dir;
  /// Recordings also keep the agents' facts and rule firings (RunHooks::record_agents).
  bool record_agents = false;
};

/// The seeds a batch plays for `s`. Throws core::ConfigError if `runs` < 1 or exceeds a seed
/// list of more than one seed.
std::vector<std::uint64_t> batch_seeds(const Scenario& s, std::optional<int> runs);

/// The games a batch of `file` plays with `runs` (every variant's batch_seeds). Throws
/// core::ConfigError as batch_seeds() does, and if they are more than ScenarioLimits::kMaxGames
/// (docs/security.md, "Scenario budgets").
std::int64_t batch_games(const ScenarioFile& file, std::optional<int> runs);

/// Progress after a stored run.
struct BatchProgress {
  int done = 0;            ///< runs stored by this call
  int to_play = 0;         ///< runs this call had to play
  int failed = 0;          ///< of `done`, runs with a failed test case
  double elapsed_s = 0.0;  ///< wall-clock seconds since the first game started (progress only)
};

/// Callbacks of run_batch, all called on the thread that called run_batch.
struct BatchHooks {
  /// After each run is stored.
  std::function<void(const RunResult&, const BatchProgress&)> stored;
  /// Set (e.g. by a SIGINT handler) to stop: no new game starts, the running ones finish and are
  /// stored. May be null.
  const std::atomic<bool>* stop = nullptr;
};

/// Mean, median and pass rate of one variant's stored runs.
struct VariantSummary {
  std::string variant;
  int runs = 0;
  int passed = 0;
  double mean_points = 0.0;
  double median_points = 0.0;
  int min_points = 0;
  int max_points = 0;
};

/// What a batch did and what the store holds for it afterwards.
struct BatchResult {
  std::int64_t batch_id = 0;
  int total = 0;                         ///< variants x seeds
  int skipped = 0;                       ///< already stored before this call
  int played = 0;                        ///< played and stored by this call
  bool interrupted = false;              ///< stopped before every run was stored
  std::vector<VariantSummary> variants;  ///< over all stored runs, in matrix order
  bool all_passed() const;
  bool complete() const { return skipped + played == total; }
};

/// Plays the runs of `file` (its text hashed as `scenario_hash`) that `store` lacks, on
/// `options.jobs` threads, storing each as it finishes (one transaction per run, written on the
/// calling thread). Throws core::ConfigError for bad options, clips::AgentLoadError /
/// core::ConfigError if a game cannot start (after the running games finished), StatsError if
/// the store fails.
BatchResult run_batch(const ScenarioFile& file, const std::string& scenario_hash, StatsStore& store,
                      const BatchOptions& options, const BatchHooks& hooks = {});

/// Per-variant summaries of stored runs, variants in the order of `variant_order` (others after,
/// by name).
std::vector<VariantSummary> summarize(const std::vector<StoredRun>& runs,
                                      const std::vector<std::string>& variant_order);

}  // namespace llsf::study
