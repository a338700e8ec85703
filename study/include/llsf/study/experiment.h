// SPDX-License-Identifier: MIT
// Experiments: a study that plays several scenario files as batches into one statistics store,
// then checks calibration targets, findings and sensitivity sweeps against the stored runs (per
// group, e.g. per robot profile) with bootstrap confidence intervals, and renders the verdicts
// as text and markdown. docs/experiments.md documents the file format and the semantics.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "llsf/study/compare.h"
#include "llsf/study/scenario.h"
#include "llsf/study/stats_store.h"

namespace llsf::study {

/// One scenario file of an experiment, played as one batch.
struct ExperimentBatch {
  std::string name;           ///< the key under `batches`
  std::string file;           ///< the scenario file, resolved against the experiment's directory
  std::string file_as_given;  ///< as written in the experiment file
  std::string where;          ///< "file:line:column" of its entry (for errors)
  ScenarioFile scenario;      ///< loaded and expanded
  std::string hash;  ///< batch_identity_hash(file, scenario): the batch's identity in a store
  /// The values of each matrix axis (ScenarioFile::axes' order), in file order.
  std::vector<std::vector<std::string>> axis_values;
  /// Per variant (ScenarioFile::variants' order): its value of each axis.
  std::vector<std::vector<std::string>> variant_axes;

  /// The index of `axis` in ScenarioFile::axes, -1 if it has no such axis.
  int axis_index(const std::string& axis) const;
};

/// Axis values that select variants: every listed axis must have its value.
using AxisFilter = std::vector<std::pair<std::string, std::string>>;

/// Which runs and which statistic a target, check or sweep looks at.
struct Selection {
  int batch = 0;  ///< index into Experiment::batches
  std::string statistic;
  /// Runs whose value is below this are left out (e.g. -1 for "never happened").
  std::optional<double> ignore_below;
  /// Shares: a run counts if its value is greater than this.
  double above = 0.0;
};

/// One condition on the stored runs.
struct Check {
  enum class Kind : std::uint8_t {
    kGreater,       ///< mean(a) - mean(b): the 95 % interval lies above 0
    kNotGreater,    ///< mean(a) - mean(b): the 90 % interval lies below +margin
    kNotLess,       ///< mean(a) - mean(b): the 90 % interval lies above -margin
    kEquivalent,    ///< mean(a) - mean(b): the 90 % interval lies inside +-margin
    kDifferenceIn,  ///< mean(a) - mean(b) lies in [low, high]
    kMeanIn,        ///< mean(a) lies in [low, high]
    kMedianIn,      ///< median(a) lies in [low, high]
    kShareAtMost,   ///< the share of runs of `a` with a value > above is at most `high`
    kShareAtLeast,  ///< ... at least `low`
  };
  Kind kind = Kind::kGreater;
  Selection sel;
  AxisFilter a;  ///< the runs (comparisons: the first side)
  AxisFilter b;  ///< comparisons only: the second side
  double low = 0.0, high = 0.0;
  /// not_greater, not_less, equivalent: the margin in the statistic's unit (> 0), and why.
  double margin = 0.0;
  std::string margin_reason;
  std::string where;  ///< "file:line:column: path" of the check (for errors)
};

/// "greater", "mean_in", ... as in the experiment file.
std::string to_string(Check::Kind k);

/// A calibration target: one check, evaluated per group.
struct CalibrationTarget {
  std::string name;
  std::string source;
  Check check;
  std::vector<std::string> groups;  ///< only these group values ("": all)
};

/// A finding of the study: every check must hold for it to be reproduced.
struct Finding {
  std::string id;
  std::string claim;
  std::string source;
  std::vector<Check> checks;
  std::vector<std::string> groups;  ///< only these group values ("": all)
};

/// A sensitivity sweep: per value of `axis`, the values of `compare` ranked by their mean.
struct Sweep {
  std::string name;
  std::string source;
  Selection sel;
  std::string axis;
  std::string compare;
  std::string baseline;  ///< a value of `axis`: the row the others are compared with
  AxisFilter fixed;      ///< `where`: the batch's other axes
  std::vector<std::string> groups;
  std::string where;
};

/// A table of means: one row per value of `rows` (an axis), one column per statistic -- the
/// mechanisms behind a verdict (lock waits, collisions, failures) beside the outcome.
struct Table {
  std::string name;
  std::string source;
  Selection sel;                        ///< batch and ignore_below (statistic: per column)
  std::string rows;                     ///< an axis of the batch
  std::vector<std::string> values;      ///< its values shown, in this order
  std::vector<std::string> statistics;  ///< the columns
  AxisFilter fixed;                     ///< `where`: the batch's other axes
  std::vector<std::string> groups;
  std::string where;
};

/// A loaded and validated experiment file.
struct Experiment {
  std::string file;  ///< the experiment file, as given
  std::string name;
  std::string description;
  std::vector<ExperimentBatch> batches;  ///< in file order
  std::string group_by;                  ///< a matrix axis, "" for none
  /// The group_by axis's values over every batch that has it, in first-seen order.
  std::vector<std::string> groups;
  std::vector<CalibrationTarget> calibration;
  std::vector<Finding> findings;
  std::vector<Sweep> sweeps;
  std::vector<Table> tables;

  /// The batch named `name`, or null.
  const ExperimentBatch* batch(const std::string& name) const;
};

/// Loads and validates an experiment file and every scenario file it names (relative to its
/// directory). Throws core::ConfigError naming file:line:column and the key for unknown keys,
/// wrong types, unknown batches, axes, axis values, statistics or groups, and for scenario
/// files that do not load.
Experiment load_experiment(const std::string& path);

/// How the store's batches of an experiment are found and evaluated.
struct EvaluateOptions {
  /// Runs per variant the batches were played with (`--runs`; unset: each scenario's seeds).
  std::optional<int> runs;
  /// The bootstrap's seed: every check draws from its own named stream of it, so the same store
  /// gives the same report, and adding a check changes no other check's interval.
  std::uint64_t seed = 1;
  /// Fewest games a side (pairs, if paired) for a verdict; fewer give "too few games".
  int min_games = kMinGamesForVerdict;
  /// If set, only the first N seeds of each variant's list are evaluated (a look of `llsfsim
  /// experiment --until`, and its report); the counts still compare with a complete batch.
  std::optional<int> first_seeds;
};

/// What the store holds of one batch.
struct BatchState {
  std::string name;
  std::string file_as_given;
  std::string scenario_name;
  std::int64_t batch_id = 0;  ///< 0: not in the store
  int runs_per_variant = 0;
  int variants = 0;
  int expected = 0;  ///< runs of a complete batch
  int stored = 0;
  /// Not in the store: the runs per variant of other stored batches of the same file content.
  std::vector<int> other_runs_per_variant;
};

/// The runs one side of a check used.
struct SampleCounts {
  int used = 0;      ///< runs whose value entered the statistic
  int stored = 0;    ///< runs of the selection in the store (used + ignored)
  int expected = 0;  ///< runs of the selection in a complete batch
};

/// A check's numbers and whether it holds.
struct CheckResult {
  /// kTooFew: fewer than kMinGamesForVerdict games (pairs) on a side: numbers, no verdict.
  enum class Outcome : std::uint8_t { kHolds, kFails, kNoData, kTooFew };
  Outcome outcome = Outcome::kNoData;
  std::string description;  ///< "points: config=P3-P3 > config=P1P2-P3"
  /// The measured value: the difference, mean, median or share.
  double value = 0.0;
  /// Its 95 % interval: bootstrap (differences, means, medians) or Wilson (shares).
  double ci_low = 0.0, ci_high = 0.0;
  SampleCounts a, b;  ///< b: comparisons only
  /// Comparisons: the method (paired by seed or unpaired), the 90 % interval, p, the smallest
  /// detectable difference and the games a difference of this size would need.
  std::optional<Comparison> comparison;
  std::string measured;  ///< the numbers as one readable line
  bool holds() const { return outcome == Outcome::kHolds; }
};

/// A target's or finding's verdict in one group.
enum class Verdict : std::uint8_t {
  kHolds,   ///< "met" / "reproduced"
  kFails,   ///< "not met" / "not reproduced"
  kNoData,  ///< a check had no runs at all
  kTooFew,  ///< no check failed, but one had too few games for a verdict
};

struct TargetResult {
  const CalibrationTarget* target = nullptr;
  std::string group;  ///< "" without group_by (or if the target's batch lacks the axis)
  CheckResult check;
  Verdict verdict = Verdict::kNoData;
};

struct FindingGroupResult {
  std::string group;
  std::vector<CheckResult> checks;
  Verdict verdict = Verdict::kNoData;
  std::vector<int> failed;  ///< 1-based numbers of the checks that failed
};

struct FindingResult {
  const Finding* finding = nullptr;
  std::vector<FindingGroupResult> groups;
};

/// One row of a sweep: one value of the swept axis.
struct SweepRow {
  std::string value;
  std::vector<double> means;       ///< per compare value (Sweep::compare's values, file order)
  std::vector<SampleCounts> n;     ///< likewise
  std::string ranking;             ///< "P3-P3 > P1P2-P3 > P1P2-P3-R" (only values with runs)
  std::vector<std::string> order;  ///< compare values with runs, best first
  bool comparable = false;         ///< this row and the baseline row both have a ranking
  bool differs = false;            ///< comparable, and the ranking differs from the baseline row's
  /// The top two differ at 5 % after Holm's correction over the sweep's rows, with enough games.
  bool separated = false;
  double top_diff = 0.0, top_low = 0.0, top_high = 0.0;  ///< mean(first) - mean(second), 95 %
  bool has_top_two = false;
  std::optional<Comparison> top;  ///< the comparison of the top two (paired by seed if shared)
};

struct SweepResult {
  const Sweep* sweep = nullptr;
  std::string group;
  std::vector<std::string> compare_values;
  std::vector<SweepRow> rows;
  int comparisons = 0;  ///< rows with a top two: the family Holm's correction controls
};

/// One row of a table: one value of its axis.
struct TableRow {
  std::string value;
  int runs = 0;               ///< stored runs of the row
  std::vector<double> means;  ///< per statistic (Table::statistics' order)
  std::vector<int> n;         ///< runs whose value entered each mean
};

struct TableResult {
  const Table* table = nullptr;
  std::string group;
  std::vector<TableRow> rows;
};

/// Everything an evaluation found; rendered by to_text() and to_markdown().
struct ExperimentResult {
  const Experiment* experiment = nullptr;
  std::string command;                  ///< the command that reproduces it
  int min_games = kMinGamesForVerdict;  ///< EvaluateOptions::min_games
  std::vector<BatchState> batches;
  std::vector<TargetResult> calibration;
  std::vector<FindingResult> findings;
  std::vector<SweepResult> sweeps;
  std::vector<TableResult> tables;
};

/// Evaluates `e` against the runs `store` holds (it keeps a pointer to `e`: `e` must outlive
/// the result). Missing batches or runs are not an error: what is stored is evaluated and the
/// counts say what is missing. Throws core::ConfigError naming the experiment file's line for a
/// statistic no stored run of its batch has, StatsError if the store cannot be read.
ExperimentResult evaluate(const Experiment& e, const StatsStore& store,
                          const EvaluateOptions& options = {});

/// Whether `experiment --until` looks at a check of this kind after every round: the comparisons
/// with a test (greater, not_greater, not_less, equivalent). The others (difference_in, mean_in,
/// median_in, share_*) are evaluated once, on what was played.
bool is_sequential(Check::Kind k);

/// One comparison check of a finding in one group at one look of `experiment --until`.
struct CheckLook {
  /// kOpen: neither way yet. kHolds / kFails: the look's test decided the check (greater:
  /// the interval lies above / below 0; a margin check: inside / beyond the margin).
  enum class Decision : std::uint8_t { kOpen, kHolds, kFails };
  int finding = 0;  ///< index into Experiment::findings
  int check = 0;    ///< 1-based, in the finding's list
  std::string group;
  std::string description;  ///< as the report's
  /// At the look's level (compare_means with alpha = plan.look_alpha()); unset: a side without
  /// values.
  std::optional<Comparison> comparison;
  Decision decision = Decision::kOpen;
};

/// "open", "holds", "fails".
std::string to_string(CheckLook::Decision d);

/// Look number `look` (1-based) of `plan` at every sequential check (is_sequential) of the
/// findings `findings` (indices into e.findings), in every group, on the first
/// plan.look_sizes()[look - 1] seeds of each variant (options.first_seeds is replaced by it).
/// Each check and group draws its bootstrap from its own stream named by the finding, check,
/// group and look: the same store gives the same decisions. Throws as evaluate().
std::vector<CheckLook> look_at_findings(const Experiment& e, const StatsStore& store,
                                        const EvaluateOptions& options,
                                        const std::vector<int>& findings,
                                        const SequentialPlan& plan, int look);

/// The report as readable text (the terminal's).
std::string to_text(const ExperimentResult& r);
/// The report as GitHub markdown: the heading, the command, the batches, the calibration table,
/// a table per finding and per sweep. The same result gives the same bytes.
std::string to_markdown(const ExperimentResult& r);

/// `text` with the lines between `<!-- experiment NAME begin -->` and `<!-- experiment NAME
/// end -->` replaced by `replacement`; everything else is kept byte for byte. Throws
/// std::invalid_argument if a marker is missing, repeated or out of order.
std::string replace_between_markers(const std::string& text, const std::string& name,
                                    const std::string& replacement);

}  // namespace llsf::study
