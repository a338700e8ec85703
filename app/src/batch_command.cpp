// SPDX-License-Identifier: MIT
// `llsfsim batch`: every matrix variant of scenarios x N seeds on worker threads, stored in the
// statistics store run by run; resumable; a progress bar and a per-variant summary.
#include <fmt/format.h>

#include <memory>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "batch_progress.h"
#include "commands.h"
#include "llsf/app/cli.h"
#include "llsf/clips/agent.h"
#include "llsf/core/error.h"
#include "llsf/study/batch.h"
#include "llsf/study/scenario.h"
#include "llsf/study/stats_store.h"

namespace llsf::app {

namespace {

struct BatchCommandOptions {
  std::vector<std::string> scenarios;
  std::optional<int> runs;
  std::optional<int> jobs;
  std::string db{study::StatsStore::kDefaultPath};
  std::string recordings;  ///< "" = default_recordings_dir(db)
  bool no_record = false;
  bool record_agents = false;
  bool quiet = false;
};

struct Loaded {
  std::string path;
  study::ScenarioFile file;
  std::string hash;
};

void print_summary(const Loaded& l, const study::BatchResult& b, const std::string& db,
                   const std::string& recordings, std::ostream& out) {
  out << fmt::format("batch      {} ({}) #{} in {}: {} runs, {} played, {} stored before\n",
                     l.file.variants.front().name, l.path, b.batch_id, db, b.total, b.played,
                     b.skipped);
  if (!recordings.empty()) {
    out << fmt::format("recordings {}/batch{}/\n", recordings, b.batch_id);
  }
  out << fmt::format("{:<32} {:>5} {:>7} {:>7} {:>7} {:>5} {:>5}\n", "variant", "runs", "passed",
                     "mean", "median", "min", "max");
  int runs = 0;
  int failed = 0;
  for (const study::VariantSummary& v : b.variants) {
    out << fmt::format("{:<32} {:>5} {:>7} {:>7.1f} {:>7.1f} {:>5} {:>5}\n",
                       v.variant.empty() ? "-" : v.variant, v.runs,
                       fmt::format("{}/{}", v.passed, v.runs), v.mean_points, v.median_points,
                       v.min_points, v.max_points);
    runs += v.runs;
    failed += v.runs - v.passed;
  }
  if (b.interrupted) {
    out << fmt::format(
        "result     interrupted: {} of {} runs stored; the same command plays the rest\n", runs,
        b.total);
  } else if (failed == 0) {
    out << fmt::format("result     all {} runs passed their test cases\n", runs);
  } else {
    out << fmt::format("result     {} of {} runs failed a test case\n", failed, runs);
  }
}

int batch(const BatchCommandOptions& o, std::ostream& out, std::ostream& err) {
  // Load and check everything before the first game: bad input costs no time.
  std::vector<Loaded> loaded;
  try {
    for (const std::string& path : o.scenarios) {
      Loaded l{path, study::load_scenario(path), ""};
      l.hash = study::batch_identity_hash(path, l.file);
      (void)study::batch_games(l.file, o.runs);  // each variant's seeds, within the budget
      loaded.push_back(std::move(l));
    }
  } catch (const core::UserError& e) {
    err << "llsfsim batch: " << e.what() << "\n";
    return kExitBadInput;
  }
  std::optional<study::StatsStore> store;
  try {
    store.emplace(o.db);
    store->require_writable();
  } catch (const study::StatsError& e) {
    err << "llsfsim batch: " << e.what() << "\n";
    return kExitBadInput;
  }

  const SigintGuard sigint;
  // A bar on a terminal; otherwise (logs, tests) one line per stored run.
  BatchProgressPrinter progress("llsfsim batch", err, o.quiet);
  bool all_passed = true;
  for (const Loaded& l : loaded) {
    study::BatchOptions options;
    options.runs = o.runs;
    options.jobs = o.jobs.value_or(0);
    options.record_agents = o.record_agents;
    if (!o.no_record)
      options.recordings_dir = o.recordings.empty() ? default_recordings_dir(o.db) : o.recordings;
    const study::BatchHooks hooks = progress.hooks();
    study::BatchResult b;
    try {
      b = study::run_batch(l.file, l.hash, *store, options, hooks);
    } catch (const clips::AgentLoadError& e) {
      err << "llsfsim batch: agent error:\n" << e.what() << "\n";
      return kExitBadInput;
    } catch (const core::ConfigError& e) {
      err << "llsfsim batch: " << e.what() << "\n";
      return kExitBadInput;
    }
    if (progress.bar() && b.interrupted) err << "\n";
    if (!o.quiet) print_summary(l, b, o.db, options.recordings_dir, out);
    if (b.interrupted) return kExitInterrupted;
    all_passed = all_passed && b.all_passed();
  }
  return all_passed ? kExitOk : kExitFailed;
}

}  // namespace

Action add_batch_command(CLI::App& app) {
  auto o = std::make_shared<BatchCommandOptions>();
  app.add_option("scenarios", o->scenarios, "Scenario files (docs/scenarios.md)")->required();
  app.add_option("--runs", o->runs,
                 "Seeds per variant: the first N of the scenario's list, or s..s+N-1 for a "
                 "single seed s (default: the scenario's seeds); at most 100000, and at most "
                 "100000 games in all (variants x seeds)")
      ->check(CLI::PositiveNumber);
  app.add_option("--jobs,-j", o->jobs, "Games played at once (default: the number of cores)")
      ->check(CLI::PositiveNumber);
  app.add_option("--db", o->db, "Statistics store (SQLite; docs/statistics.md)")
      ->capture_default_str();
  auto* rec = app.add_option(
      "--recordings", o->recordings,
      "Directory for the games' recordings, one subdirectory per batch "
      "(default: <db name>-recordings beside the --db file, e.g. llsfsim-recordings)");
  auto* no_rec =
      app.add_flag("--no-record", o->no_record, "Do not record the games")->excludes(rec);
  app.add_flag("--record-agents", o->record_agents,
               "Recordings also keep the agents' facts and rule firings (the facts, fact and rules "
               "lines of docs/recording.md; off by default in batches: it costs time and space, "
               "docs/benchmarks.md)")
      ->excludes(no_rec);
  app.add_flag("-q,--quiet", o->quiet, "No progress and no summary, only the exit code");
  app.footer(
      "Plays every matrix variant x N seeds of each scenario on worker threads and stores every "
      "run in the statistics store, with a recording of every game (docs/recording.md). "
      "Resumable: runs the store already holds for the same "
      "scenario file content and --runs are not played again; Ctrl-C stores the running games "
      "and stops.\n"
      "Exit code: 0 every run passed its test cases, 1 one failed, 2 bad input, 3 internal "
      "error (a bug: please report it), 130 interrupted.");
  return [o](std::ostream& out, std::ostream& err) { return batch(*o, out, err); };
}

}  // namespace llsf::app
