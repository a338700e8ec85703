// SPDX-License-Identifier: MIT
// `llsfsim batch`: every matrix variant of scenarios x N seeds on worker threads, stored in the
// statistics store run by run; resumable; a progress bar and a per-variant summary.
#include <fmt/format.h>

#include <memory>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "batch_cluster.h"
#include "batch_progress.h"
#include "cli_checks.h"
#include "commands.h"
#include "llsf/app/cli.h"
#include "llsf/clips/agent.h"
#include "llsf/core/error.h"
#include "llsf/core/rng.h"
#include "llsf/study/batch.h"
#include "llsf/study/compare.h"
#include "llsf/study/report.h"
#include "llsf/study/scenario.h"
#include "llsf/study/stats_store.h"

namespace llsf::app {

namespace {

void print_summary(const LoadedBatch& l, const study::BatchResult& b, const std::string& db,
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

/// The two variants of `--until A>B`, checked against the file's variants.
std::pair<std::string, std::string> until_variants(const std::string& spec,
                                                   const study::ScenarioFile& file) {
  const std::size_t gt = spec.find('>');
  if (gt == std::string::npos || spec.find('>', gt + 1) != std::string::npos) {
    throw core::ConfigError("--until: expected VARIANT_A>VARIANT_B (is A better than B?), got '" +
                            spec + "'");
  }
  std::vector<std::string> names;
  for (const study::Scenario& s : file.variants) names.push_back(s.variant);
  auto check = [&](const std::string& v) {
    if (std::find(names.begin(), names.end(), v) != names.end()) return v;
    std::string list;
    for (const std::string& n : names) list += (list.empty() ? "" : ", ") + n;
    throw core::ConfigError("--until: the scenario has no variant '" + v +
                            "' (variants: " + (list.empty() ? "none, no matrix" : list) + ")");
  };
  const std::string a = check(spec.substr(0, gt));
  const std::string b = check(spec.substr(gt + 1));
  if (a == b) throw core::ConfigError("--until: compare two different variants");
  return {a, b};
}

/// `llsfsim batch FILE --until A>B --max-runs N`: plays the file's variants in rounds of seeds
/// and after each round looks at A - B (study::SequentialPlan), until it is separated, shown
/// equivalent within --margin, or N seeds are played.
int batch_until(const BatchCommandOptions& o, std::ostream& out, std::ostream& err) {
  const char* who = "llsfsim batch";
  study::SequentialPlan plan;
  std::vector<LoadedBatch> loaded;
  std::pair<std::string, std::string> ab;
  try {
    if (o.scenarios.size() != 1) {
      throw core::ConfigError("--until compares two variants of one scenario file");
    }
    if (!o.max_runs)
      throw core::ConfigError("--until needs --max-runs N (seeds a variant at most)");
    plan.max_runs = *o.max_runs;
    plan.looks = o.looks;
    plan.margin = o.margin;
    if (const std::string p = plan.problem(); !p.empty()) throw core::ConfigError(p);
    const auto& infos = study::statistic_infos();
    if (std::none_of(infos.begin(), infos.end(),
                     [&](const study::StatisticInfo& s) { return s.name == o.statistic; })) {
      throw core::ConfigError("--statistic: unknown statistic '" + o.statistic +
                              "' (docs/statistics.md)");
    }
    study::SeedChoice choice;
    choice.runs = plan.max_runs;
    loaded = load_batches(o.scenarios, choice);
    ab = until_variants(o.until, loaded.front().file);
  } catch (const core::UserError& e) {
    err << who << ": " << e.what() << "\n";
    return kExitBadInput;
  }
  std::optional<study::StatsStore> store;
  try {
    store.emplace(o.db);
    store->require_writable();
  } catch (const study::StatsError& e) {
    err << who << ": " << e.what() << "\n";
    return kExitBadInput;
  }
  const LoadedBatch& l = loaded.front();
  const std::vector<int> sizes = plan.look_sizes();
  std::string looks_at;
  for (const int n : sizes) looks_at += (looks_at.empty() ? "" : ", ") + std::to_string(n);
  if (!o.quiet) {
    out << fmt::format(
        "until      {} > {} on {}: at most {} seeds, looks after {} seeds, each at {:.3g} % "
        "(5 % in all: Bonferroni){}\n",
        ab.first, ab.second, o.statistic, plan.max_runs, looks_at, 100.0 * plan.look_alpha(),
        plan.margin ? fmt::format("; equivalent if inside +-{:g}", *plan.margin) : "");
  }
  const SigintGuard sigint;
  BatchProgressPrinter progress(who, err, o.quiet);
  const auto variants = static_cast<std::int64_t>(l.file.variants.size());
  const std::vector<std::uint64_t> seeds = study::batch_seeds(l.file.variants.front(), l.choice);
  study::BatchResult b;
  study::SequentialLook last;
  std::string recordings_dir;
  for (int look = 1; look <= plan.looks; ++look) {
    const int n = sizes[static_cast<std::size_t>(look - 1)];
    // The first n seeds of every variant: the batch's pairs are seed-major.
    study::BatchOptions options;
    options.choice = l.choice;
    options.jobs = o.jobs.value_or(0);
    options.record_agents = o.record_agents;
    options.slice_end = n * variants;
    if (!o.no_record)
      options.recordings_dir = o.recordings.empty() ? default_recordings_dir(o.db) : o.recordings;
    recordings_dir = options.recordings_dir;
    try {
      b = study::run_batch(l.file, l.hash, *store, options, progress.hooks());
    } catch (const clips::AgentLoadError& e) {
      err << who << ": agent error:\n" << e.what() << "\n";
      return kExitBadInput;
    } catch (const core::ConfigError& e) {
      err << who << ": " << e.what() << "\n";
      return kExitBadInput;
    }
    if (progress.bar() && b.interrupted) err << "\n";
    if (b.interrupted) {
      if (!o.quiet) print_summary(l, b, store->path(), recordings_dir, out);
      return kExitInterrupted;
    }
    // The two variants' values on the first n seeds, keyed by seed.
    const std::set<std::uint64_t> first(seeds.begin(), seeds.begin() + n);
    std::vector<study::KeyedValue> va, vb;
    for (const study::RunValues& r : study::run_values(*store, b.batch_id)) {
      if (first.count(r.seed) == 0 || (r.variant != ab.first && r.variant != ab.second)) continue;
      for (const auto& [name, value] : r.statistics) {
        if (name != o.statistic) continue;
        (r.variant == ab.first ? va : vb).push_back({"seed=" + std::to_string(r.seed), value});
      }
    }
    if (va.empty() || vb.empty()) {
      if (!o.quiet) {
        out << fmt::format("look {}/{}   {} seeds: no values of {} yet\n", look, plan.looks, n,
                           o.statistic);
      }
      last = {};
      last.look = look;
      last.seeds = n;
      last.outcome = look == plan.looks ? study::SequentialOutcome::kUndecided
                                        : study::SequentialOutcome::kContinue;
      if (look == plan.looks) break;
      continue;
    }
    // Seeded by the comparison and the look: the same store gives the same decisions.
    core::RandomStream rng =
        core::Rng(1).stream("until/" + o.until + "/" + o.statistic + "/" + std::to_string(look));
    last = study::sequential_look(plan, look, va, vb, rng);
    const study::Comparison& c = last.comparison;
    if (!o.quiet) {
      out << fmt::format("look {}/{}   {} seeds: {:+.2f} [{:+.2f}, {:+.2f}] ({:.3g} % interval, {}",
                         look, plan.looks, n, c.diff, c.ci.low, c.ci.high, 100.0 * (1.0 - c.alpha),
                         study::to_string(c.pairing));
      if (plan.margin) {
        out << fmt::format("; equivalence [{:+.2f}, {:+.2f}]", c.ci_tost.low, c.ci_tost.high);
      }
      out << fmt::format("): {}\n", study::to_string(last.outcome));
    }
    if (last.outcome != study::SequentialOutcome::kContinue) break;
  }
  if (!o.quiet) {
    print_summary(l, b, store->path(), recordings_dir, out);
    std::string answer;
    const study::Comparison& c = last.comparison;
    switch (last.outcome) {
      case study::SequentialOutcome::kSeparated:
        answer = fmt::format("{} {} {} on {}: {:+.2f} after {} seeds", ab.first,
                             c.diff > 0 ? "beats" : "is beaten by", ab.second, o.statistic, c.diff,
                             last.seeds);
        break;
      case study::SequentialOutcome::kEquivalent:
        answer = fmt::format("{} and {} are equivalent within +-{:g} {} after {} seeds", ab.first,
                             ab.second, *plan.margin, o.statistic, last.seeds);
        break;
      default:
        answer = fmt::format("undecided after {} seeds (neither separated{})", last.seeds,
                             plan.margin ? " nor equivalent within the margin" : "");
    }
    out << "answer     " << answer << "\n";
  }
  return b.all_passed() ? kExitOk : kExitFailed;
}

int batch(const BatchCommandOptions& o, std::ostream& out, std::ostream& err) {
  if (o.scenarios.empty()) {
    err << "llsfsim batch: give one or more scenario files (or: batch status, batch merge)\n";
    return kExitBadInput;
  }
  // --task is the job script's (hidden from --help, so not a CLI11 `excludes`: its help line
  // would read "--slurm Excludes:" with the hidden name left out).
  if (o.slurm && o.task) {
    err << "llsfsim batch: --task is what a Slurm array task runs; it cannot be given with "
           "--slurm\n";
    return kExitBadInput;
  }
  if (o.slurm) return batch_submit(o, out, err);
  if (o.task) return batch_task(o, out, err);
  if (!o.until.empty()) return batch_until(o, out, err);
  // Load and check everything before the first game: bad input costs no time.
  std::vector<LoadedBatch> loaded;
  try {
    loaded = load_batches(o.scenarios, seed_choice(o));
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
  for (const LoadedBatch& l : loaded) {
    study::BatchOptions options;
    options.choice = l.choice;
    options.jobs = o.jobs.value_or(0);
    options.record_agents = o.record_agents;
    options.fail_fast = o.fail_fast;
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
    if (!o.quiet)
      print_summary(l, b, store->path(), options.recordings_dir, out);  // (password masked)
    if (b.agent_error) {
      err << "llsfsim batch: --fail-fast: stopped at the first run with an agent error ("
          << *b.agent_error << " of " << l.path
          << "); the games already running were stored; run it again with `llsfsim run` to "
             "see its issues, or again without --fail-fast to play the rest\n";
      return kExitFailed;
    }
    if (b.interrupted) return kExitInterrupted;
    all_passed = all_passed && b.all_passed();
  }
  return all_passed ? kExitOk : kExitFailed;
}

}  // namespace

study::SeedChoice seed_choice(const BatchCommandOptions& o) {
  study::SeedChoice c;
  c.runs = o.runs;
  if (!o.seeds.empty()) c.seeds = study::parse_seed_list(o.seeds);
  if (c.runs && !c.seeds.empty())
    throw core::ConfigError("give either --runs or --seeds, not both");
  return c;
}

std::vector<LoadedBatch> load_batches(const std::vector<std::string>& paths,
                                      const study::SeedChoice& choice) {
  std::vector<LoadedBatch> out;
  for (const std::string& path : paths) {
    LoadedBatch l{path, study::load_scenario(path), "", choice, {}, {}};
    l.hash = study::batch_identity_hash(path, l.file);
    l.pairs = study::batch_pairs(l.file, choice);  // each variant's seeds, within the budget
    l.key = study::batch_key(l.file, l.hash, choice);
    out.push_back(std::move(l));
  }
  return out;
}

Action add_batch_command(CLI::App& app) {
  auto o = std::make_shared<BatchCommandOptions>();
  CLI::App* status = app.add_subcommand(
      "status", "Progress of a batch from the store (and squeue): done, running, missing, ETA");
  const Action status_action = add_batch_status_command(*status);
  CLI::App* merge = app.add_subcommand(
      "merge", "Fold the SQLite shards of Slurm array tasks into one store (idempotent)");
  const Action merge_action = add_batch_merge_command(*merge);

  app.add_option("scenarios", o->scenarios, "Scenario files (docs/scenarios.md)");
  auto* runs =
      app.add_option("--runs", o->runs,
                     "Seeds per variant: the first N of the scenario's list; beyond the list, the "
                     "seeds after its largest, counting up (a single seed s: s..s+N-1). Default: "
                     "the scenario's seeds; at most 100000, and at most 100000 games in all "
                     "(variants x seeds)")
          ->check(kPositive);
  auto* seeds =
      app.add_option("--seeds", o->seeds,
                     "Exactly these seeds for every variant instead of the scenario's: a list of "
                     "seeds and ranges, e.g. 1-100 or 1,5,9-12 (at most 100000)")
          ->excludes(runs);
  app.add_option("--jobs,-j", o->jobs,
                 "Games played at once (default: the number of cores; with --slurm: 1 per array "
                 "task, its --cpus-per-task)")
      ->check(kPositive);
  app.add_option("--db", o->db,
                 "Statistics store: a SQLite file or a postgresql://USER@HOST:PORT/DB URL "
                 "(docs/statistics.md); with --slurm a file on shared storage or the URL")
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
  auto* fail_fast = app.add_flag(
      "--fail-fast", o->fail_fast,
      "Stop at the first run with an agent error (a runtime error or a halted agent): no new "
      "game starts, the running ones are stored; exit code 1");

  // Playing until the answer is known.
  const std::string until_group = "Play until the answer is known (docs/llsfsim.md)";
  auto* until =
      app.add_option("--until", o->until,
                     "A>B: play the file's variants in rounds of seeds until variant A minus "
                     "variant B is separated (or equivalent within --margin), or --max-runs "
                     "seeds are played; a fixed number of looks, each at 5 % / --looks")
          ->excludes(runs)
          ->excludes(seeds)
          ->group(until_group);
  app.add_option("--max-runs", o->max_runs, "--until: seeds a variant at most (at least 10)")
      ->needs(until)
      ->group(until_group);
  app.add_option("--looks", o->looks, "--until: looks at the comparison, after equal rounds")
      ->needs(until)
      ->capture_default_str()
      ->group(until_group);
  app.add_option("--statistic", o->statistic, "--until: the statistic compared")
      ->needs(until)
      ->capture_default_str()
      ->group(until_group);
  app.add_option("--margin", o->margin,
                 "--until: also stop when A and B are equivalent within +-M (in the statistic's "
                 "unit)")
      ->needs(until)
      ->group(until_group);

  // Slurm (docs/cluster.md).
  const std::string slurm = "Slurm (docs/cluster.md)";
  auto* on_slurm = app.add_flag("--slurm", o->slurm,
                                "Submit the batch as a Slurm job array (sbatch) instead of "
                                "playing it here; only the missing runs are submitted")
                       ->group(slurm)
                       ->excludes(fail_fast);
  on_slurm->excludes(until);
  app.add_option("--partition", o->partition, "sbatch --partition")->needs(on_slurm)->group(slurm);
  app.add_option("--time-limit", o->time_limit, "sbatch --time per array task, e.g. 30 or 1:00:00")
      ->needs(on_slurm)
      ->group(slurm);
  app.add_option("--array-throttle", o->array_throttle,
                 "At most K array tasks at once (sbatch --array=...%K)")
      ->check(kPositive)
      ->needs(on_slurm)
      ->group(slurm);
  auto* gpt = app.add_option("--games-per-task", o->games_per_task,
                             "Games per array task (a slice of the batch's (variant, seed) "
                             "pairs); keep it when resubmitting")
                  ->check(CLI::Range(1, 100000))
                  ->capture_default_str()
                  ->group(slurm);
  app.add_option("--sbatch-arg", o->sbatch_args,
                 "An extra sbatch argument, as an #SBATCH line (repeatable), e.g. "
                 "--sbatch-arg=--mem=2G")
      ->needs(on_slurm)
      ->group(slurm);
  app.add_flag("--dry-run", o->dry_run, "Print the job script; submit nothing, write nothing")
      ->needs(on_slurm)
      ->group(slurm);
  // What an array task runs (written into the job script, not for users).
  app.add_option("--task", o->task, "")->check(kNonNegative)->group("");
  (void)gpt;
  app.footer(
      "Plays every matrix variant x N seeds of each scenario on worker threads and stores every "
      "run in the statistics store, with a recording of every game (docs/recording.md). "
      "Resumable: runs the store already holds for the same "
      "scenario file content and seeds are not played again; Ctrl-C stores the running games "
      "and stops. With --slurm the batch becomes a Slurm job array whose tasks write SQLite "
      "shards beside --db (`batch merge` folds them in) and `batch status` follows it "
      "(docs/cluster.md). With --until A>B --max-runs N the variants are played in rounds of "
      "seeds and A - B is looked at after each round, until it is separated or equivalent "
      "within --margin (each look at 5 % / --looks, so the error rate stays at 5 % despite the "
      "repeated looks; docs/statistics.md).\n"
      "Exit code: 0 every run passed its test cases (--slurm: submitted), 1 one failed, 2 bad "
      "input, 3 internal error (a bug: please report it), 130 interrupted.");
  return [o, status, status_action, merge, merge_action](std::ostream& out, std::ostream& err) {
    if (status->parsed()) return status_action(out, err);
    if (merge->parsed()) return merge_action(out, err);
    return batch(*o, out, err);
  };
}

}  // namespace llsf::app
