// SPDX-License-Identifier: MIT
// Batch: every matrix variant of a scenario file x N seeds, played on worker threads (games are
// independent and single-threaded) and stored run by run in a StatsStore. Resumable: the runs a
// store already holds for the batch are not played again.
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <optional>
#include <set>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "llsf/study/runner.h"
#include "llsf/study/scenario.h"
#include "llsf/study/stats_store.h"

namespace llsf::study {

/// Which seeds every variant of a batch plays: `--runs N`, `--seeds LIST` or the scenario's own.
struct SeedChoice {
  /// Runs per variant: the first N seeds of the scenario's list; beyond the list, the seeds
  /// after the list's largest, counting up (a single seed s: s, s+1, ..., s+N-1). Unset: the
  /// scenario's seed list.
  std::optional<int> runs;
  /// If not empty: exactly these seeds for every variant, in this order (`--seeds`,
  /// parse_seed_list()); `runs` must then be unset.
  std::vector<std::uint64_t> seeds;
};

/// A (variant, seed) pair of a batch: the index of the variant in ScenarioFile::variants.
struct BatchPair {
  int variant = 0;
  std::uint64_t seed = 0;
};

/// How a batch is played.
struct BatchOptions {
  /// The seeds (SeedChoice); `runs` is kept as a shorthand for `choice.runs`.
  std::optional<int> runs;
  SeedChoice choice;
  /// Worker threads (>= 1); 0: std::thread::hardware_concurrency().
  int jobs = 0;
  /// If set, every game is recorded to <recordings_dir>/batch<ID>/recording_file_name(...)
  /// (the directory is created) and the store keeps the path with the run.
  std::string recordings_dir;
  /// The ID of the recordings' subdirectory batch<ID>; 0: the batch's id in the store. A Slurm
  /// task writing a shard names the main store's id, so that recordings are named as in a local
  /// batch.
  std::int64_t recordings_batch_id = 0;
  /// Recordings also keep the agents' facts and rule firings (RunHooks::record_agents).
  bool record_agents = false;
  /// Only the pairs [slice_begin, slice_end) of batch_pairs() (a Slurm array task's slice);
  /// slice_end < 0: to the end. A sliced batch is never marked finished in the store.
  std::int64_t slice_begin = 0;
  std::int64_t slice_end = -1;
  /// (variant, seed) pairs stored elsewhere (the main store, for a task writing a shard): not
  /// played, counted as skipped.
  std::set<std::pair<std::string, std::uint64_t>> stored_elsewhere;
  /// `--fail-fast`: after the first stored run with an agent error (RunResult::agent_error) no
  /// new game starts; the running ones finish and are stored (as on Ctrl-C).
  bool fail_fast = false;
};

/// The seed list of `--seeds`: comma-separated seeds and inclusive ranges A-B ("1,5,9-12"),
/// each seed in [0, 2^63-1], no seed twice, at most ScenarioLimits::kMaxSeeds seeds. Throws
/// core::ConfigError naming the bad item.
std::vector<std::uint64_t> parse_seed_list(std::string_view text);

/// The seeds a batch plays for `s`. Throws core::ConfigError if `runs` < 1 or is more than
/// ScenarioLimits::kMaxSeeds, or if both runs and seeds are given.
std::vector<std::uint64_t> batch_seeds(const Scenario& s, const SeedChoice& choice);
/// batch_seeds() with `runs` only.
std::vector<std::uint64_t> batch_seeds(const Scenario& s, std::optional<int> runs);

/// The games a batch of `file` plays (every variant's batch_seeds). Throws core::ConfigError as
/// batch_seeds() does, and if they are more than ScenarioLimits::kMaxGames (docs/security.md,
/// "Scenario budgets").
std::int64_t batch_games(const ScenarioFile& file, const SeedChoice& choice);
/// batch_games() with `runs` only.
std::int64_t batch_games(const ScenarioFile& file, std::optional<int> runs);

/// Every (variant, seed) pair of the batch in the order it is played: seed-major (the first seed
/// of every variant, then the second, ...), so that an interrupted batch has every variant on
/// its first seeds. Slices of this list are a Slurm array's tasks (docs/cluster.md).
std::vector<BatchPair> batch_pairs(const ScenarioFile& file, const SeedChoice& choice);

/// The batch's identity in the store: scenario_hash (batch_identity_hash()) and the number of
/// seeds per variant. With `--seeds` that are not the default seeds of their count (the first N
/// of batch_seeds()), the seed list joins the identity: scenario_hash becomes
/// "<hash>+seeds-<FNV-1a 64 of the seeds>", so that two different seed lists of one length are
/// two batches. The same (variant, seed) plays the same game in every batch.
BatchKey batch_key(const ScenarioFile& file, const std::string& scenario_hash,
                   const SeedChoice& choice);

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
  int total = 0;             ///< variants x seeds
  int skipped = 0;           ///< already stored before this call
  int played = 0;            ///< played and stored by this call
  bool interrupted = false;  ///< stopped before every run was stored
  /// With BatchOptions::fail_fast: the first stored run with an agent error ("variant seed N").
  std::optional<std::string> agent_error;
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
