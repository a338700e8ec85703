// SPDX-License-Identifier: MIT
// `llsfsim experiment`: plays an experiment's scenario files as batches into one statistics
// store (resumable, like `llsfsim batch`), then checks its calibration targets, findings and
// sweeps against the stored runs and writes the verdicts as text and markdown.
#include <fmt/format.h>

#include <cstdio>
#include <exception>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <memory>
#include <optional>
#include <ostream>
#include <stdexcept>
#include <string>

#include "batch_progress.h"
#include "cli_checks.h"
#include "commands.h"
#include "llsf/app/cli.h"
#include "llsf/clips/agent.h"
#include "llsf/core/error.h"
#include "llsf/core/input_file.h"
#include "llsf/study/batch.h"
#include "llsf/study/experiment.h"
#include "llsf/study/stats_store.h"

namespace llsf::app {

namespace {

struct ExperimentOptions {
  std::string file;
  std::string db{study::StatsStore::kDefaultPath};
  std::optional<int> runs;
  std::optional<int> jobs;
  std::string recordings;  ///< "" = default_recordings_dir(db)
  bool no_record = false;
  bool report_only = false;
  std::string out;     ///< write the markdown report here
  std::string update;  ///< replace the experiment's section of this markdown file
  bool quiet = false;
};

/// Reads a whole file; nullopt if it cannot be read.
std::optional<std::string> read_file(const std::string& path) {
  std::string error;
  return core::try_read_input_file(path, core::kMaxSourceBytes, "markdown file", error);
}

/// Writes `text` next to `path` and renames it into place: a failed write leaves no half file.
bool write_file(const std::string& path, const std::string& text) {
  const std::string tmp = path + ".tmp";
  std::ofstream f(tmp, std::ios::binary);
  f << text;
  f.close();
  if (!f || std::rename(tmp.c_str(), path.c_str()) != 0) {
    std::remove(tmp.c_str());
    return false;
  }
  return true;
}

/// Plays every batch of `e` the store lacks. Returns an exit code, or nullopt to go on.
std::optional<int> play(const ExperimentOptions& o, const study::Experiment& e,
                        study::StatsStore& store, std::ostream& out, std::ostream& err) {
  const SigintGuard sigint;
  BatchProgressPrinter progress("llsfsim experiment", err, o.quiet);
  for (const study::ExperimentBatch& eb : e.batches) {
    study::BatchOptions options;
    options.runs = o.runs;
    options.jobs = o.jobs.value_or(0);
    if (!o.no_record)
      options.recordings_dir = o.recordings.empty() ? default_recordings_dir(o.db) : o.recordings;
    study::BatchResult b;
    try {
      b = study::run_batch(eb.scenario, eb.hash, store, options, progress.hooks());
    } catch (const clips::AgentLoadError& ex) {
      err << "llsfsim experiment: batch " << eb.name << ": agent error:\n" << ex.what() << "\n";
      return kExitBadInput;
    } catch (const core::ConfigError& ex) {
      err << "llsfsim experiment: batch " << eb.name << ": " << ex.what() << "\n";
      return kExitBadInput;
    }
    if (progress.bar() && b.interrupted) err << "\n";
    if (!o.quiet) {
      int runs = 0;
      int failed = 0;
      for (const study::VariantSummary& v : b.variants) {
        runs += v.runs;
        failed += v.runs - v.passed;
      }
      out << fmt::format(
          "batch      {} ({}) #{} in {}: {} runs, {} played, {} stored before{}\n", eb.name,
          eb.file, b.batch_id, store.path(), b.total, b.played, b.skipped,
          failed > 0 ? fmt::format("; {} of {} failed a test case", failed, runs) : "");
      out.flush();
    }
    if (b.interrupted) {
      if (!o.quiet) {
        out << "result     interrupted: the same command plays the missing runs and reports\n";
      }
      return kExitInterrupted;
    }
  }
  return std::nullopt;
}

int experiment(const ExperimentOptions& o, std::ostream& out, std::ostream& err) {
  // Load and check everything before the first game: bad input costs no time.
  study::Experiment e;
  std::optional<std::string> update_text;
  try {
    e = study::load_experiment(o.file);
    for (const study::ExperimentBatch& b : e.batches) {
      for (const study::Scenario& s : b.scenario.variants) (void)study::batch_seeds(s, o.runs);
    }
  } catch (const core::UserError& ex) {
    err << "llsfsim experiment: " << ex.what() << "\n";
    return kExitBadInput;
  }
  if (!o.update.empty()) {
    update_text = read_file(o.update);
    if (!update_text) {
      err << "llsfsim experiment: cannot read " << o.update << "\n";
      return kExitBadInput;
    }
    try {
      (void)study::replace_between_markers(*update_text, e.name, "");
    } catch (const std::invalid_argument& ex) {
      err << "llsfsim experiment: " << o.update << ": " << ex.what() << "\n";
      return kExitBadInput;
    }
  }
  if (o.report_only && !study::is_database_url(o.db) && !std::filesystem::exists(o.db)) {
    err << "llsfsim experiment: no statistics store " << o.db
        << " (play the experiment first: llsfsim experiment " << o.file << ")\n";
    return kExitBadInput;
  }
  std::optional<study::StatsStore> store;
  try {
    store.emplace(o.db);
  } catch (const study::StatsError& ex) {
    err << "llsfsim experiment: " << ex.what() << "\n";
    return kExitBadInput;
  }

  if (!o.report_only) {
    if (const std::optional<int> code = play(o, e, *store, out, err)) return *code;
  }

  // Evaluate and report.
  study::EvaluateOptions eo;
  eo.runs = o.runs;
  study::ExperimentResult r;
  try {
    r = study::evaluate(e, *store, eo);
  } catch (const core::ConfigError& ex) {
    err << "llsfsim experiment: " << ex.what() << "\n";
    return kExitBadInput;
  } catch (const study::StatsError& ex) {
    err << "llsfsim experiment: " << ex.what() << "\n";
    return kExitBadInput;
  }
  if (!o.quiet) {
    if (!o.report_only) out << "\n";
    out << study::to_text(r);
    for (const study::BatchState& b : r.batches) {
      if (b.stored >= b.expected) continue;
      err << "llsfsim experiment: batch " << b.name << " holds " << b.stored << " of " << b.expected
          << " runs; `" << r.command << "` plays the missing ones\n";
    }
  }
  const std::string markdown = study::to_markdown(r);
  if (!o.out.empty() && !write_file(o.out, markdown)) {
    err << "llsfsim experiment: cannot write " << o.out << "\n";
    return kExitBadInput;
  }
  if (update_text) {
    // Read again: the file may have been edited while the batches played.
    const std::optional<std::string> now = read_file(o.update);
    std::string updated;
    try {
      if (!now) throw std::invalid_argument("cannot read it");
      updated = study::replace_between_markers(*now, e.name, markdown);
    } catch (const std::invalid_argument& ex) {
      err << "llsfsim experiment: " << o.update << ": " << ex.what() << "\n";
      return kExitBadInput;
    }
    if (!write_file(o.update, updated)) {
      err << "llsfsim experiment: cannot write " << o.update << "\n";
      return kExitBadInput;
    }
  }
  return kExitOk;
}

}  // namespace

Action add_experiment_command(CLI::App& app) {
  auto o = std::make_shared<ExperimentOptions>();
  app.add_option("experiment", o->file, "Experiment file (docs/experiments.md)")
      ->required()
      ->check(CLI::ExistingFile);
  app.add_option("--db", o->db,
                 "Statistics store: a SQLite file or a postgresql://USER@HOST:PORT/DB URL "
                 "(docs/statistics.md)")
      ->capture_default_str();
  app.add_option("--runs", o->runs,
                 "Seeds per variant of every batch: the first N of each scenario's list, or "
                 "s..s+N-1 for a single seed s (default: each scenario's seeds)")
      ->check(kPositive);
  auto* jobs =
      app.add_option("--jobs,-j", o->jobs, "Games played at once (default: the number of cores)")
          ->check(kPositive);
  auto* rec = app.add_option("--recordings", o->recordings,
                             "Directory for the games' recordings, one subdirectory per batch "
                             "(default: <db name>-recordings beside the --db file)");
  auto* no_rec =
      app.add_flag("--no-record", o->no_record, "Do not record the games")->excludes(rec);
  app.add_flag("--report-only", o->report_only,
               "Play nothing: evaluate what the store holds and say what is missing")
      ->excludes(jobs)
      ->excludes(rec)
      ->excludes(no_rec);
  app.add_option("--out", o->out, "Also write the report as markdown to this file");
  app.add_option("--update", o->update,
                 "Replace the lines between `<!-- experiment NAME begin -->` and `<!-- experiment "
                 "NAME end -->` of this markdown file with the report (NAME: the experiment's "
                 "name); the rest of the file is kept byte for byte")
      ->check(CLI::ExistingFile);
  app.add_flag("-q,--quiet", o->quiet, "No progress and no report on the terminal");
  app.footer(
      "Plays every batch of the experiment (each scenario file: every matrix variant x N seeds, "
      "as llsfsim batch; resumable, Ctrl-C stores the running games and stops), then evaluates "
      "its calibration targets, findings, sweeps and tables per group against the stored runs, "
      "with bootstrap intervals from a fixed seed (the same store gives the same report; "
      "differences paired by seed where the runs share their seeds; no better / no worse / same "
      "against the check's margin; no verdict from fewer than 10 games a side; "
      "docs/statistics.md), and prints the verdicts. Verdicts are results: a finding that is not "
      "reproduced still exits 0.\n"
      "Exit code: 0 done, 2 bad input (the experiment, a scenario, the store, a markdown file "
      "without the markers), 3 internal error (a bug: please report it), 130 interrupted.");
  return [o](std::ostream& out, std::ostream& err) { return experiment(*o, out, err); };
}

}  // namespace llsf::app
