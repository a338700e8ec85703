// SPDX-License-Identifier: MIT
// `llsfsim experiment`: plays an experiment's scenario files as batches into one statistics
// store (resumable, like `llsfsim batch`), then checks its calibration targets, findings and
// sweeps against the stored runs and writes the verdicts as text and markdown.
#include <fmt/format.h>

#include <algorithm>
#include <cstdint>
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
#include <vector>

#include "batch_progress.h"
#include "cli_checks.h"
#include "commands.h"
#include "llsf/app/cli.h"
#include "llsf/clips/agent.h"
#include "llsf/core/assert.h"
#include "llsf/core/error.h"
#include "llsf/core/input_file.h"
#include "llsf/study/batch.h"
#include "llsf/study/compare.h"
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
  // Playing until the answer is known.
  bool until = false;     ///< --until given
  std::string until_ids;  ///< its value: finding ids, comma-separated ("": every finding)
  std::optional<int> max_runs;
  int looks = 5;
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

/// Plays every batch of `e` the store lacks (with `slice_seeds`: only the first N seeds of every
/// variant). Returns an exit code, or nullopt to go on.
std::optional<int> play(const ExperimentOptions& o, const study::Experiment& e,
                        study::StatsStore& store, BatchProgressPrinter& progress, std::ostream& out,
                        std::ostream& err, std::optional<int> slice_seeds = std::nullopt) {
  for (const study::ExperimentBatch& eb : e.batches) {
    study::BatchOptions options;
    options.runs = o.until ? o.max_runs : o.runs;
    // The first N seeds of every variant: a batch's (variant, seed) pairs are seed-major.
    if (slice_seeds) {
      options.slice_end = static_cast<std::int64_t>(*slice_seeds) *
                          static_cast<std::int64_t>(eb.scenario.variants.size());
    }
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

/// The findings `--until` plays for (indices into e.findings): those named, or every finding
/// with a check to look at. Throws core::ConfigError naming the option and the value.
std::vector<int> until_findings(const ExperimentOptions& o, const study::Experiment& e) {
  auto sequential = [&](const study::Finding& f) {
    return std::any_of(f.checks.begin(), f.checks.end(),
                       [](const study::Check& c) { return study::is_sequential(c.kind); });
  };
  std::vector<int> out;
  if (o.until_ids.empty()) {
    for (std::size_t i = 0; i < e.findings.size(); ++i) {
      if (sequential(e.findings[i])) out.push_back(static_cast<int>(i));
    }
    if (out.empty()) {
      throw core::ConfigError(
          "--until: the experiment has no finding with a greater, not_greater, not_less or "
          "equivalent check to play until");
    }
    return out;
  }
  std::string ids;
  for (const study::Finding& f : e.findings) ids += (ids.empty() ? "" : ", ") + f.id;
  std::size_t pos = 0;
  while (pos <= o.until_ids.size()) {
    std::size_t end = o.until_ids.find(',', pos);
    if (end == std::string::npos) end = o.until_ids.size();
    const std::string id = o.until_ids.substr(pos, end - pos);
    pos = end + 1;
    const auto it = std::find_if(e.findings.begin(), e.findings.end(),
                                 [&](const study::Finding& f) { return f.id == id; });
    if (it == e.findings.end()) {
      throw core::ConfigError("--until: the experiment has no finding '" + id +
                              "' (findings: " + (ids.empty() ? std::string("none") : ids) + ")");
    }
    if (!sequential(*it)) {
      throw core::ConfigError("--until: finding " + id +
                              " has no greater, not_greater, not_less or equivalent check to "
                              "play until (its checks are evaluated on whatever is played)");
    }
    const int index = static_cast<int>(it - e.findings.begin());
    if (std::find(out.begin(), out.end(), index) == out.end()) out.push_back(index);
  }
  return out;
}

/// `--until`: plays every batch in rounds of seeds and after each round looks at the comparison
/// checks of `findings` (study::look_at_findings), until every finding is decided or the plan's
/// last look. Sets `seeds` to the seeds a variant played; returns an exit code, or nullopt to go
/// on to the report.
std::optional<int> play_until(const ExperimentOptions& o, const study::Experiment& e,
                              const std::vector<int>& findings, const study::SequentialPlan& plan,
                              study::StatsStore& store, BatchProgressPrinter& progress,
                              std::ostream& out, std::ostream& err, int& seeds) {
  const std::vector<int> sizes = plan.look_sizes();
  if (!o.quiet) {
    std::string ids, at;
    for (const int f : findings) {
      ids += (ids.empty() ? "" : ", ") + e.findings[static_cast<std::size_t>(f)].id;
    }
    for (const int n : sizes) at += (at.empty() ? "" : ", ") + std::to_string(n);
    out << fmt::format(
        "until      {}: at most {} seeds a variant, looks after {} seeds; each comparison check "
        "at {:.3g} % a look (5 % in all per check: Bonferroni over the {} looks; not corrected "
        "over the checks); difference_in, mean_in, median_in and share checks are evaluated "
        "once, on what is played\n",
        ids, plan.max_runs, at, 100.0 * plan.look_alpha(), plan.looks);
    out.flush();
  }
  // The decisions so far, in look_at_findings' order, and the seeds each was decided at.
  std::vector<study::CheckLook> decided;
  std::vector<int> decided_at;
  study::EvaluateOptions eo;
  eo.runs = plan.max_runs;
  for (int look = 1; look <= plan.looks; ++look) {
    const int n = sizes[static_cast<std::size_t>(look - 1)];
    if (const std::optional<int> code = play(o, e, store, progress, out, err, n)) return code;
    seeds = n;
    const std::vector<study::CheckLook> now =
        study::look_at_findings(e, store, eo, findings, plan, look);
    if (decided.empty()) {
      decided = now;
      decided_at.assign(now.size(), 0);
      for (study::CheckLook& c : decided) c.decision = study::CheckLook::Decision::kOpen;
    }
    LLSF_DEMAND(now.size() == decided.size());
    int open = 0;
    std::string lines;
    for (std::size_t i = 0; i < now.size(); ++i) {
      const study::CheckLook& c = now[i];
      const std::string name =
          fmt::format("  {} check {} ({})", e.findings[static_cast<std::size_t>(c.finding)].id,
                      c.check, c.group.empty() ? "all" : c.group);
      if (decided_at[i] > 0) {
        lines += fmt::format("{}: {} since {} seeds\n", name, study::to_string(decided[i].decision),
                             decided_at[i]);
        continue;
      }
      // A decision, once made, stands: the Bonferroni bound covers every look.
      if (c.decision != study::CheckLook::Decision::kOpen) {
        decided[i] = c;
        decided_at[i] = n;
      } else {
        ++open;
      }
      if (!c.comparison) {
        lines += fmt::format("{}: no values yet: open\n", name);
        continue;
      }
      const study::Comparison& cmp = *c.comparison;
      const study::Check& check = e.findings[static_cast<std::size_t>(c.finding)]
                                      .checks[static_cast<std::size_t>(c.check - 1)];
      const bool margin = check.kind != study::Check::Kind::kGreater;
      const study::Interval ci = margin ? cmp.ci_tost : cmp.ci;
      lines += fmt::format(
          "{}: {:+.2f} [{:+.2f}, {:+.2f}] ({:.3g} % interval{}, {}{}): {}\n", name, cmp.diff,
          ci.low, ci.high, 100.0 * (1.0 - (margin ? 2.0 : 1.0) * cmp.alpha),
          margin ? fmt::format(", margin {:g}", check.margin) : "", study::to_string(cmp.pairing),
          cmp.enough ? "" : fmt::format(", {} games: too few", cmp.games()),
          study::to_string(c.decision));
    }
    if (!o.quiet) {
      out << fmt::format("look {}/{}   {} seeds, {} comparison checks, {} open:\n{}", look,
                         plan.looks, n, now.size(), open, lines);
      out.flush();
    }
    if (open == 0) break;
  }
  if (!o.quiet) {
    // Per finding: decided when every one of its comparison checks is.
    for (const int f : findings) {
      int at = 0;
      bool all = true;
      std::string detail;
      for (std::size_t i = 0; i < decided.size(); ++i) {
        if (decided[i].finding != f) continue;
        all = all && decided_at[i] > 0;
        at = std::max(at, decided_at[i]);
        detail += fmt::format("{}check {}{} {}", detail.empty() ? "" : ", ", decided[i].check,
                              decided[i].group.empty() ? "" : " (" + decided[i].group + ")",
                              study::to_string(decided[i].decision));
      }
      const std::string& id = e.findings[static_cast<std::size_t>(f)].id;
      out << (all ? fmt::format("finding    {} decided after {} seeds ({})\n", id, at, detail)
                  : fmt::format("finding    {} undecided after {} seeds ({})\n", id, seeds,
                                detail));
    }
  }
  return std::nullopt;
}

int experiment(const ExperimentOptions& o, std::ostream& out, std::ostream& err) {
  // Load and check everything before the first game: bad input costs no time.
  study::Experiment e;
  std::optional<std::string> update_text;
  study::SequentialPlan plan;  // --until
  std::vector<int> findings;   // --until: indices into e.findings
  try {
    e = study::load_experiment(o.file);
    if (o.until) {
      if (!o.max_runs)
        throw core::ConfigError("--until needs --max-runs N (seeds a variant at most)");
      plan.max_runs = *o.max_runs;
      plan.looks = o.looks;
      if (const std::string p = plan.problem(); !p.empty()) throw core::ConfigError(p);
      findings = until_findings(o, e);
    }
    for (const study::ExperimentBatch& b : e.batches) {
      for (const study::Scenario& s : b.scenario.variants) {
        (void)study::batch_seeds(s, o.until ? o.max_runs : o.runs);
      }
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

  int played_seeds = 0;  // --until: seeds a variant played
  if (!o.report_only) {
    const SigintGuard sigint;
    BatchProgressPrinter progress("llsfsim experiment", err, o.quiet);
    try {
      const std::optional<int> code =
          o.until ? play_until(o, e, findings, plan, *store, progress, out, err, played_seeds)
                  : play(o, e, *store, progress, out, err);
      if (code) return *code;
    } catch (const core::ConfigError& ex) {
      err << "llsfsim experiment: " << ex.what() << "\n";
      return kExitBadInput;
    } catch (const study::StatsError& ex) {
      err << "llsfsim experiment: " << ex.what() << "\n";
      return kExitBadInput;
    }
  }

  // Evaluate and report (--until: on the seeds played).
  study::EvaluateOptions eo;
  eo.runs = o.until ? o.max_runs : o.runs;
  if (o.until) eo.first_seeds = played_seeds;
  study::ExperimentResult r;
  try {
    r = study::evaluate(e, *store, eo);
    if (o.until) {
      r.command = "llsfsim experiment " + e.file + " --until" +
                  (o.until_ids.empty() ? "" : " " + o.until_ids) + " --max-runs " +
                  std::to_string(plan.max_runs) + " --looks " + std::to_string(plan.looks);
    }
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
      if (b.stored >= b.expected || o.until) continue;
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
  auto* runs =
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
  auto* report_only =
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

  // Playing until the answer is known.
  const std::string until_group = "Play until the answer is known (docs/experiments.md)";
  auto* until =
      app.add_option("--until", o->until_ids,
                     "Play every batch in rounds of seeds until each finding named (default: "
                     "every finding with a greater, not_greater, not_less or equivalent check) is "
                     "decided -- each such check separated, or shown within or beyond its margin "
                     "-- or --max-runs seeds are played; a fixed number of looks, each check at "
                     "5 % / --looks a look")
          ->type_name("[ID,...]")
          ->expected(0, 1)
          ->excludes(runs)
          ->excludes(report_only)
          ->group(until_group);
  app.add_option("--max-runs", o->max_runs, "--until: seeds a variant at most (at least 10)")
      ->needs(until)
      ->group(until_group);
  app.add_option("--looks", o->looks, "--until: looks at the checks, after equal rounds")
      ->needs(until)
      ->capture_default_str()
      ->group(until_group);
  app.footer(
      "Plays every batch of the experiment (each scenario file: every matrix variant x N seeds, "
      "as llsfsim batch; resumable, Ctrl-C stores the running games and stops), then evaluates "
      "its calibration targets, findings, sweeps and tables per group against the stored runs, "
      "with bootstrap intervals from a fixed seed (the same store gives the same report; "
      "differences paired by seed where the runs share their seeds; no better / no worse / same "
      "against the check's margin; no verdict from fewer than 10 games a side; "
      "docs/statistics.md), and prints the verdicts. Verdicts are results: a finding that is not "
      "reproduced still exits 0. With --until [ID,...] --max-runs N the batches are played in "
      "rounds of seeds and the findings' comparison checks looked at after each round (each at "
      "5 % / --looks, so every check's error rate stays at 5 % despite the repeated looks), "
      "until every finding is decided or N seeds are played; the report then covers the seeds "
      "played (docs/experiments.md).\n"
      "Exit code: 0 done, 2 bad input (the experiment, a scenario, the store, a markdown file "
      "without the markers), 3 internal error (a bug: please report it), 130 interrupted.");
  return [o, until](std::ostream& out, std::ostream& err) {
    o->until = until->count() > 0;
    return experiment(*o, out, err);
  };
}

}  // namespace llsf::app
