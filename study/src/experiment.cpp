// SPDX-License-Identifier: MIT
#include "llsf/study/experiment.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <numeric>
#include <set>
#include <stdexcept>
#include <tuple>

#include "llsf/core/assert.h"
#include "llsf/core/config.h"
#include "llsf/core/error.h"
#include "llsf/core/rng.h"
#include "llsf/study/batch.h"
#include "llsf/study/report.h"

namespace llsf::study {

namespace {

// ---------------------------------------------------------------------------------------------
// Loading

/// "file:line:column: path" of a node, the prefix of errors found after loading.
std::string where_of(const core::ConfigNode& n) {
  return n.location() + ": " + (n.path().empty() ? std::string("(top level)") : n.path());
}

std::string join(const std::vector<std::string>& v, const std::string& sep) {
  std::string out;
  for (const std::string& s : v) out += (out.empty() ? "" : sep) + s;
  return out;
}

bool contains(const std::vector<std::string>& v, const std::string& x) {
  return std::find(v.begin(), v.end(), x) != v.end();
}

/// The names a stored run may have (StatsStore writes numeric_statistics()).
const std::vector<std::string>& known_statistics() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> out;
    for (const StatisticInfo& s : statistic_infos()) out.push_back(s.name);
    return out;
  }();
  return names;
}

/// Whether a game may lack `name` (then no run having it is no sign of an old store).
bool may_be_absent(const std::string& name) {
  for (const StatisticInfo& s : statistic_infos()) {
    if (s.name == name) return s.may_be_absent;
  }
  return false;
}

/// A statistic no stored run of a batch has: an error unless games may lack it (a store written
/// before the statistic existed, or a typo the loader could not see).
void require_stored(const std::set<std::string>& stored, const std::string& statistic,
                    const std::string& where, const std::string& batch) {
  if (stored.empty() || stored.count(statistic) > 0 || may_be_absent(statistic)) return;
  throw core::ConfigError(where + ": no stored run of batch '" + batch + "' has the statistic '" +
                          statistic + "'");
}

/// The non-empty string under `key`; "missing key 'key'" at `map` if absent. `node`, if given,
/// becomes the value's node (for later errors about the value).
std::string required_string(const core::ConfigNode& map, std::string_view key,
                            core::ConfigNode* node = nullptr) {
  const core::ConfigNode n = map[key];
  if (!n.defined()) map.fail("missing key '" + std::string(key) + "'");
  const std::string s = n.as_string();
  if (s.empty()) n.fail("must not be empty");
  if (node != nullptr) *node = n;
  return s;
}

std::string optional_string(const core::ConfigNode& map, std::string_view key) {
  std::string s;
  map.read(key, s);
  return s;
}

/// A variant name's value of each axis ("config=P3-P3,loss=20" with axes config, loss).
std::vector<std::string> split_variant(const std::string& variant,
                                       const std::vector<std::string>& axes) {
  std::vector<std::string> out;
  std::size_t pos = 0;
  for (std::size_t a = 0; a < axes.size(); ++a) {
    pos += axes[a].size() + 1;  // "axis="
    std::size_t end = variant.size();
    if (a + 1 < axes.size()) {
      end = variant.find("," + axes[a + 1] + "=", pos);
      LLSF_DEMAND(end != std::string::npos);
    }
    out.push_back(variant.substr(pos, end - pos));
    pos = end + 1;
  }
  return out;
}

const ExperimentBatch& batch_of(const Experiment& e, const core::ConfigNode& node, int* index) {
  core::ConfigNode at;
  const std::string name = required_string(node, "batch", &at);
  for (std::size_t i = 0; i < e.batches.size(); ++i) {
    if (e.batches[i].name == name) {
      *index = static_cast<int>(i);
      return e.batches[i];
    }
  }
  std::vector<std::string> names;
  for (const ExperimentBatch& b : e.batches) names.push_back(b.name);
  at.fail("unknown batch '" + name + "' (batches: " + join(names, ", ") + ")");
}

/// Checks that `axis` is one of the batch's axes.
void require_axis(const ExperimentBatch& b, const std::string& axis, const core::ConfigNode& at) {
  if (b.axis_index(axis) >= 0) return;
  at.fail("batch '" + b.name + "' has no axis '" + axis + "' (" +
          (b.scenario.axes.empty() ? std::string("its scenario has no matrix")
                                   : "axes: " + join(b.scenario.axes, ", ")) +
          ")");
}

void require_value(const ExperimentBatch& b, const std::string& axis, const std::string& value,
                   const core::ConfigNode& at) {
  const auto& values = b.axis_values[static_cast<std::size_t>(b.axis_index(axis))];
  if (contains(values, value)) return;
  at.fail("axis '" + axis + "' of batch '" + b.name + "' has no value '" + value +
          "' (values: " + join(values, ", ") + ")");
}

/// `{axis: value, ...}`: every axis of the batch, every value of its axis, not the group axis.
AxisFilter read_filter(const Experiment& e, const ExperimentBatch& b, const core::ConfigNode& n) {
  AxisFilter out;
  if (!n.defined() || n.is_null()) return out;
  n.require_map();
  for (const std::string& axis : n.keys()) {
    const core::ConfigNode v = n[axis];
    if (!v.is_scalar()) v.fail("expected an axis value");
    require_axis(b, axis, v);
    if (axis == e.group_by) {
      v.fail("'" + axis +
             "' is the group_by axis: every check is evaluated per group; choose "
             "groups with `groups: [...]`");
    }
    require_value(b, axis, v.as_string(), v);
    out.emplace_back(axis, v.as_string());
  }
  return out;
}

std::string read_statistic(const core::ConfigNode& map) {
  core::ConfigNode at;
  const std::string s = required_string(map, "statistic", &at);
  if (!contains(known_statistics(), s)) {
    at.fail("unknown statistic '" + s +
            "' (docs/statistics.md; e.g. points, production_points, deliveries, "
            "first_complex_production_s, storage_empty_game_s, storage_ran_empty, role_changes, "
            "jams)");
  }
  return s;
}

std::pair<double, double> read_range(const core::ConfigNode& n) {
  if (!n.is_sequence() || n.size() != 2) n.fail("expected a range [low, high]");
  const double lo = n.at(0).as_double();
  const double hi = n.at(1).as_double();
  if (!(lo <= hi)) n.fail("the range's low end is above its high end");
  return {lo, hi};
}

/// The `groups` of an entry (`n`, possibly undefined); with `batch` (a calibration target, sweep or
/// table), that batch must have the group_by axis.
std::vector<std::string> read_groups(const Experiment& e, const core::ConfigNode& n,
                                     const ExperimentBatch* batch) {
  std::vector<std::string> out;
  if (!n.defined()) return out;
  if (e.group_by.empty()) n.fail("groups need `group_by` at the top level");
  if (!n.is_sequence() || n.size() == 0) n.fail("expected a list of group values");
  for (const core::ConfigNode& g : n.elements()) {
    const std::string v = g.as_string();
    if (!contains(e.groups, v)) {
      g.fail("unknown group '" + v + "' (values of '" + e.group_by + "': " + join(e.groups, ", ") +
             ")");
    }
    if (!contains(out, v)) out.push_back(v);
  }
  if (batch != nullptr && batch->axis_index(e.group_by) < 0) {
    n.fail("batch '" + batch->name + "' has no axis '" + e.group_by + "'");
  }
  return out;
}

/// The end of a sweep or table: every axis of its batch other than `free` (the swept and
/// compared axes, or the rows) and the group_by axis must be fixed by `fixed` -- a statistic
/// over pooled variants would mean nothing (`free_are` names the free axes in the message) --
/// and its `groups`.
std::vector<std::string> read_fixed_rest_and_groups(const Experiment& e, const ExperimentBatch& b,
                                                    const core::ConfigNode& n,
                                                    const AxisFilter& fixed,
                                                    const std::vector<std::string>& free,
                                                    std::string_view free_are) {
  for (const std::string& axis : b.scenario.axes) {
    if (contains(free, axis) || axis == e.group_by) continue;
    const bool is_fixed =
        std::any_of(fixed.begin(), fixed.end(), [&](const auto& f) { return f.first == axis; });
    if (!is_fixed) {
      n.fail("axis '" + axis + "' of batch '" + b.name + "' is neither " + std::string(free_are) +
             " nor fixed: give it in `where: {" + axis + ": ...}`");
    }
  }
  return read_groups(e, n["groups"], &b);
}

/// ignore_below and above of a selection; `above` only where a share is taken.
void read_selection_options(const core::ConfigNode& map, bool share, Selection& sel) {
  if (const core::ConfigNode n = map["ignore_below"]; n.defined()) sel.ignore_below = n.as_double();
  if (const core::ConfigNode n = map["above"]; n.defined()) {
    if (!share) n.fail("only share_at_most and share_at_least take `above`");
    sel.above = n.as_double();
  }
}

bool is_share(Check::Kind k) {
  return k == Check::Kind::kShareAtMost || k == Check::Kind::kShareAtLeast;
}

bool has_margin(Check::Kind k) {
  return k == Check::Kind::kNotGreater || k == Check::Kind::kNotLess ||
         k == Check::Kind::kEquivalent;
}

bool is_comparison(Check::Kind k) {
  return k == Check::Kind::kGreater || has_margin(k) || k == Check::Kind::kDifferenceIn;
}

std::optional<Check::Kind> kind_of(const std::string& s) {
  for (const Check::Kind k :
       {Check::Kind::kGreater, Check::Kind::kNotGreater, Check::Kind::kNotLess,
        Check::Kind::kEquivalent, Check::Kind::kDifferenceIn, Check::Kind::kMeanIn,
        Check::Kind::kMedianIn, Check::Kind::kShareAtMost, Check::Kind::kShareAtLeast}) {
    if (to_string(k) == s) return k;
  }
  return std::nullopt;
}

/// Sets a check's bound from the node of its range or share value.
void read_bound(Check& c, const core::ConfigNode& n) {
  if (is_share(c.kind)) {
    const double v = n.as_double(core::probability());
    c.low = c.kind == Check::Kind::kShareAtLeast ? v : 0.0;
    c.high = c.kind == Check::Kind::kShareAtMost ? v : 1.0;
  } else {
    std::tie(c.low, c.high) = read_range(n);
  }
}

/// The head of a named entry (a calibration target, a sweep, a table): a map with a `name` that
/// no other entry of its kind (`names`, `what`: "target") has, and an optional `source`.
template <class Entry>
void read_name(const core::ConfigNode& n, std::set<std::string>& names, const char* what,
               Entry& entry) {
  n.require_map();
  core::ConfigNode name;
  entry.name = required_string(n, "name", &name);
  if (!names.insert(entry.name).second) {
    name.fail(std::string("a second ") + what + " of this name");
  }
  entry.source = optional_string(n, "source");
}

/// The head of every entry that reads runs (a check, target, sweep or table): where it is (for
/// reports) and the batch it reads (into sel.batch).
const ExperimentBatch& read_batch_head(const Experiment& e, const core::ConfigNode& n,
                                       std::string& where, Selection& sel) {
  where = where_of(n);
  return batch_of(e, n, &sel.batch);
}

CalibrationTarget read_target(const Experiment& e, const core::ConfigNode& n,
                              std::set<std::string>& names) {
  CalibrationTarget t;
  read_name(n, names, "target", t);
  Check& c = t.check;
  const ExperimentBatch& b = read_batch_head(e, n, c.where, c.sel);
  c.a = read_filter(e, b, n["where"]);
  c.sel.statistic = read_statistic(n);
  int kinds = 0;
  for (const char* key : {"mean_in", "median_in", "share_at_most", "share_at_least"}) {
    const core::ConfigNode bound = n[key];
    if (!bound.defined()) continue;
    ++kinds;
    c.kind = *kind_of(key);
    read_bound(c, bound);
  }
  if (kinds != 1) {
    n.fail("give exactly one of mean_in, median_in, share_at_most, share_at_least");
  }
  read_selection_options(n, is_share(c.kind), c.sel);
  t.groups = read_groups(e, n["groups"], &b);
  n.no_other_keys();
  return t;
}

Check read_check(const Experiment& e, const core::ConfigNode& entry) {
  entry.require_map();
  if (entry.size() != 1) {
    entry.fail(
        "a check is one of greater, not_greater, not_less, equivalent, difference_in, mean_in, "
        "median_in, share_at_most, share_at_least: {batch: ..., ...}");
  }
  const std::string key = entry.keys().front();
  const std::optional<Check::Kind> kind = kind_of(key);
  const core::ConfigNode n = entry[key];
  if (!kind) {
    n.fail("unknown check '" + key +
           "' (checks: greater, not_greater, not_less, equivalent, difference_in, mean_in, "
           "median_in, share_at_most, share_at_least)");
  }
  n.require_map();
  if (n.is_null()) n.fail("expected {batch: ..., statistic: ..., ...}");
  Check c;
  c.kind = *kind;
  const ExperimentBatch& b = read_batch_head(e, n, c.where, c.sel);
  c.sel.statistic = read_statistic(n);
  read_selection_options(n, is_share(c.kind), c.sel);
  // Each kind asks for its own keys -- a comparison `a` and `b` (and a difference `range`), the
  // others `where` and `range` or a share's `value` -- before no_other_keys().
  if (is_comparison(c.kind)) {
    const core::ConfigNode a = n["a"];
    const core::ConfigNode bn = n["b"];
    const core::ConfigNode range =
        c.kind == Check::Kind::kDifferenceIn ? n["range"] : core::ConfigNode();
    const core::ConfigNode margin = has_margin(c.kind) ? n["margin"] : core::ConfigNode();
    const core::ConfigNode reason = has_margin(c.kind) ? n["margin_reason"] : core::ConfigNode();
    n.no_other_keys();
    if (!a.defined()) n.fail("missing key 'a' (the axis values of the first side)");
    if (!bn.defined()) n.fail("missing key 'b' (the axis values of the second side)");
    c.a = read_filter(e, b, a);
    c.b = read_filter(e, b, bn);
    if (c.a == c.b) n.fail("'a' and 'b' select the same runs");
    if (c.kind == Check::Kind::kDifferenceIn) {
      if (!range.defined()) n.fail("missing key 'range' ([low, high])");
      read_bound(c, range);
    }
    // "No better", "no worse" and "same" need a margin: without one a check would hold by
    // absence of evidence (fewer or noisier games would make it easier to pass).
    if (has_margin(c.kind)) {
      if (!margin.defined()) {
        n.fail(
            "missing key 'margin' (the difference, in the statistic's unit, that still counts "
            "as no difference, e.g. 10 points: docs/experiments.md)");
      }
      c.margin = margin.as_double();
      if (!(c.margin > 0.0) || !std::isfinite(c.margin)) margin.fail("must be a number above 0");
      if (!reason.defined()) {
        n.fail("missing key 'margin_reason' (why this margin: cite the source or say why)");
      }
      c.margin_reason = reason.as_string();
      if (c.margin_reason.empty()) reason.fail("must not be empty");
    }
  } else {
    const core::ConfigNode where = n["where"];
    const char* bound_key = is_share(c.kind) ? "value" : "range";
    const core::ConfigNode bound = n[bound_key];
    n.no_other_keys();
    c.a = read_filter(e, b, where);
    if (!bound.defined()) {
      n.fail(std::string("missing key '") + bound_key + "'" +
             (is_share(c.kind) ? " (the share, 0..1)" : " ([low, high])"));
    }
    read_bound(c, bound);
  }
  return c;
}

Finding read_finding(const Experiment& e, const core::ConfigNode& n, std::set<std::string>& ids) {
  n.require_map();
  Finding f;
  core::ConfigNode id;
  f.id = required_string(n, "id", &id);
  if (!ids.insert(f.id).second) id.fail("a second finding of this id");
  f.claim = required_string(n, "claim");
  f.source = optional_string(n, "source");
  const core::ConfigNode groups = n["groups"];
  f.groups = read_groups(e, groups, nullptr);
  const core::ConfigNode checks = n["checks"];
  n.no_other_keys();
  if (!checks.defined()) n.fail("missing key 'checks'");
  if (!checks.is_sequence() || checks.size() == 0) checks.fail("expected a list of checks");
  for (const core::ConfigNode& c : checks.elements()) f.checks.push_back(read_check(e, c));
  const bool grouped = std::any_of(f.checks.begin(), f.checks.end(), [&](const Check& c) {
    return e.batches[static_cast<std::size_t>(c.sel.batch)].axis_index(e.group_by) >= 0;
  });
  if (!f.groups.empty() && !grouped) {
    groups.fail("none of the checks' batches has an axis '" + e.group_by + "'");
  }
  return f;
}

Sweep read_sweep(const Experiment& e, const core::ConfigNode& n, std::set<std::string>& names) {
  Sweep s;
  read_name(n, names, "sweep", s);
  const ExperimentBatch& b = read_batch_head(e, n, s.where, s.sel);
  s.sel.statistic = read_statistic(n);
  read_selection_options(n, false, s.sel);
  core::ConfigNode axis_node;
  s.axis = required_string(n, "axis", &axis_node);
  require_axis(b, s.axis, axis_node);
  core::ConfigNode compare_node;
  s.compare = required_string(n, "compare", &compare_node);
  require_axis(b, s.compare, compare_node);
  if (s.compare == s.axis) compare_node.fail("must be another axis than `axis`");
  for (const core::ConfigNode& a : {axis_node, compare_node}) {
    if (a.as_string() == e.group_by) {
      a.fail("'" + e.group_by + "' is the group_by axis (sweeps are evaluated per group)");
    }
  }
  const auto& rows = b.axis_values[static_cast<std::size_t>(b.axis_index(s.axis))];
  s.baseline = rows.front();
  if (const core::ConfigNode baseline = n["baseline"]; baseline.defined()) {
    s.baseline = baseline.as_string();
    require_value(b, s.axis, s.baseline, baseline);
  }
  const core::ConfigNode where = n["where"];
  s.fixed = read_filter(e, b, where);
  for (const auto& [axis, value] : s.fixed) {
    if (axis == s.axis || axis == s.compare) {
      where[axis].fail("'" + axis + "' is swept or compared; it cannot be fixed");
    }
  }
  s.groups = read_fixed_rest_and_groups(e, b, n, s.fixed, {s.axis, s.compare}, "swept, compared");
  n.no_other_keys();
  return s;
}

Table read_table(const Experiment& e, const core::ConfigNode& n, std::set<std::string>& names) {
  Table t;
  read_name(n, names, "table", t);
  const ExperimentBatch& b = read_batch_head(e, n, t.where, t.sel);
  read_selection_options(n, false, t.sel);
  core::ConfigNode rows;
  t.rows = required_string(n, "rows", &rows);
  require_axis(b, t.rows, rows);
  if (t.rows == e.group_by) {
    rows.fail("'" + e.group_by + "' is the group_by axis (tables are made per group)");
  }
  const auto& all = b.axis_values[static_cast<std::size_t>(b.axis_index(t.rows))];
  if (const core::ConfigNode v = n["values"]; v.defined()) {
    if (!v.is_sequence() || v.size() == 0) v.fail("expected a list of values of '" + t.rows + "'");
    for (const core::ConfigNode& x : v.elements()) {
      require_value(b, t.rows, x.as_string(), x);
      if (contains(t.values, x.as_string())) x.fail("a second row of this value");
      t.values.push_back(x.as_string());
    }
  } else {
    t.values = all;
  }
  const core::ConfigNode stats = n["statistics"];
  if (!stats.defined()) n.fail("missing key 'statistics' (the columns: a list of statistics)");
  if (!stats.is_sequence() || stats.size() == 0) stats.fail("expected a list of statistics");
  for (const core::ConfigNode& x : stats.elements()) {
    const std::string st = x.as_string();
    if (!contains(known_statistics(), st)) {
      x.fail("unknown statistic '" + st + "' (docs/statistics.md)");
    }
    t.statistics.push_back(st);
  }
  const core::ConfigNode where = n["where"];
  t.fixed = read_filter(e, b, where);
  for (const auto& [axis, value] : t.fixed) {
    if (axis == t.rows) where[axis].fail("'" + axis + "' makes the rows; it cannot be fixed");
  }
  t.groups = read_fixed_rest_and_groups(e, b, n, t.fixed, {t.rows}, "the rows");
  n.no_other_keys();
  return t;
}

ExperimentBatch read_batch(const std::string& name, const core::ConfigNode& n,
                           const std::filesystem::path& dir) {
  ExperimentBatch b;
  b.name = name;
  b.where = n.location();
  if (!n.is_scalar()) n.fail("expected a scenario file");
  b.file_as_given = n.as_string();
  if (b.file_as_given.empty()) n.fail("expected a scenario file");
  const std::filesystem::path p(b.file_as_given);
  b.file = p.is_absolute() ? p.string() : (dir / p).lexically_normal().string();
  try {
    b.scenario = load_scenario(b.file);
    b.hash = batch_identity_hash(b.file, b.scenario);
  } catch (const core::UserError& err) {
    n.fail(err.what());
  }
  b.axis_values.resize(b.scenario.axes.size());
  for (const Scenario& s : b.scenario.variants) {
    b.variant_axes.push_back(split_variant(s.variant, b.scenario.axes));
    for (std::size_t a = 0; a < b.scenario.axes.size(); ++a) {
      if (!contains(b.axis_values[a], b.variant_axes.back()[a]))
        b.axis_values[a].push_back(b.variant_axes.back()[a]);
    }
  }
  return b;
}

}  // namespace

int ExperimentBatch::axis_index(const std::string& axis) const {
  for (std::size_t i = 0; i < scenario.axes.size(); ++i) {
    if (scenario.axes[i] == axis) return static_cast<int>(i);
  }
  return -1;
}

const ExperimentBatch* Experiment::batch(const std::string& n) const {
  for (const ExperimentBatch& b : batches) {
    if (b.name == n) return &b;
  }
  return nullptr;
}

std::string to_string(Check::Kind k) {
  switch (k) {
    case Check::Kind::kGreater:
      return "greater";
    case Check::Kind::kNotGreater:
      return "not_greater";
    case Check::Kind::kNotLess:
      return "not_less";
    case Check::Kind::kEquivalent:
      return "equivalent";
    case Check::Kind::kDifferenceIn:
      return "difference_in";
    case Check::Kind::kMeanIn:
      return "mean_in";
    case Check::Kind::kMedianIn:
      return "median_in";
    case Check::Kind::kShareAtMost:
      return "share_at_most";
    case Check::Kind::kShareAtLeast:
      return "share_at_least";
  }
  return "?";
}

Experiment load_experiment(const std::string& path) {
  const core::ConfigNode root = core::ConfigNode::load_file(path);
  if (!root.is_map()) root.fail("an experiment file is a map (name, batches, findings, ...)");
  Experiment e;
  e.file = path;
  core::ConfigNode name;
  e.name = required_string(root, "name", &name);
  for (const char c : e.name) {
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '-' || c == '_' || c == '.')) {
      name.fail("use letters, digits, '-', '_' and '.' (it names the report's markers)");
    }
  }
  e.description = optional_string(root, "description");
  const core::ConfigNode batches = root["batches"];
  const core::ConfigNode group_by = root["group_by"];
  auto list = [&](std::string_view key) {
    const core::ConfigNode n = root[key];
    if (!n.defined() || n.is_null()) return std::vector<core::ConfigNode>{};
    if (!n.is_sequence()) n.fail("expected a list");
    return n.elements();
  };
  const std::vector<core::ConfigNode> calibration = list("calibration");
  const std::vector<core::ConfigNode> findings = list("findings");
  const std::vector<core::ConfigNode> sweeps = list("sweeps");
  const std::vector<core::ConfigNode> tables = list("tables");
  root.no_other_keys();  // before the batches are loaded, which takes a while

  // The batches: every scenario file loaded now, so that a bad one costs no playing time.
  if (!batches.defined()) root.fail("missing key 'batches' (name: scenario file)");
  if (!batches.is_map() || batches.size() == 0) {
    batches.fail("expected a map of batch names to scenario files");
  }
  const std::filesystem::path dir = std::filesystem::path(path).parent_path();
  for (const std::string& batch : batches.keys()) {
    e.batches.push_back(read_batch(batch, batches[batch], dir));
  }

  // The groups: the values of the group_by axis over every batch that has it.
  if (group_by.defined()) {
    e.group_by = group_by.as_string();
    for (const ExperimentBatch& b : e.batches) {
      const int a = b.axis_index(e.group_by);
      if (a < 0) continue;
      for (const std::string& v : b.axis_values[static_cast<std::size_t>(a)]) {
        if (!contains(e.groups, v)) e.groups.push_back(v);
      }
    }
    if (e.groups.empty()) group_by.fail("no batch has an axis '" + e.group_by + "'");
  }

  std::set<std::string> names;
  for (const core::ConfigNode& n : calibration) e.calibration.push_back(read_target(e, n, names));
  names.clear();
  for (const core::ConfigNode& n : findings) e.findings.push_back(read_finding(e, n, names));
  names.clear();
  for (const core::ConfigNode& n : sweeps) e.sweeps.push_back(read_sweep(e, n, names));
  names.clear();
  for (const core::ConfigNode& n : tables) e.tables.push_back(read_table(e, n, names));
  if (e.calibration.empty() && e.findings.empty() && e.sweeps.empty() && e.tables.empty()) {
    root.fail("nothing to evaluate: give calibration targets, findings, sweeps or tables");
  }
  return e;
}

namespace {

// ---------------------------------------------------------------------------------------------
// Evaluation

/// One batch's stored runs, grouped by variant, each variant's runs in seed order.
struct BatchData {
  const ExperimentBatch* batch = nullptr;
  std::vector<int> expected;  ///< per variant: runs of a complete batch
  /// Per variant, its runs in seed order: the seed and every statistic of the run.
  std::vector<std::vector<std::pair<std::uint64_t, std::map<std::string, double>>>> runs;
  std::set<std::string> statistics;  ///< every name a run has
};

BatchData load_batch_data(const ExperimentBatch& b, const StatsStore& store,
                          const EvaluateOptions& o, BatchState& state) {
  BatchData d;
  d.batch = &b;
  d.runs.resize(b.scenario.variants.size());
  std::map<std::string, std::size_t> index;
  // Per variant, the seeds evaluated: all, or the first N (a look of `experiment --until`).
  std::vector<std::set<std::uint64_t>> first(b.scenario.variants.size());
  for (std::size_t v = 0; v < b.scenario.variants.size(); ++v) {
    const Scenario& s = b.scenario.variants[v];
    index[s.variant] = v;
    const std::vector<std::uint64_t> seeds = batch_seeds(s, o.runs);
    d.expected.push_back(static_cast<int>(seeds.size()));
    if (o.first_seeds) {
      const auto n = static_cast<std::size_t>(std::clamp(*o.first_seeds, 0, d.expected.back()));
      first[v].insert(seeds.begin(), seeds.begin() + static_cast<std::ptrdiff_t>(n));
    }
  }
  state.name = b.name;
  state.file_as_given = b.file_as_given;
  state.scenario_name = b.scenario.variants.front().name;
  state.variants = static_cast<int>(b.scenario.variants.size());
  state.runs_per_variant = d.expected.front();
  state.expected = std::accumulate(d.expected.begin(), d.expected.end(), 0);
  for (const StoredBatch& sb : store.batches()) {
    if (sb.kind != "batch" || sb.scenario_hash != b.hash) continue;
    if (sb.runs_per_variant == state.runs_per_variant) {
      state.batch_id = sb.id;
    } else {
      state.other_runs_per_variant.push_back(sb.runs_per_variant);
    }
  }
  if (state.batch_id == 0) return d;
  // Seed order within a variant: the bootstrap's draws must not depend on the storing order.
  std::vector<StoredRun> runs = store.runs(state.batch_id);
  std::sort(runs.begin(), runs.end(), [](const StoredRun& x, const StoredRun& y) {
    return x.variant != y.variant ? x.variant < y.variant : x.seed < y.seed;
  });
  for (const StoredRun& run : runs) {
    const auto it = index.find(run.variant);
    if (it == index.end()) continue;
    if (o.first_seeds && first[it->second].count(run.seed) == 0) continue;
    std::map<std::string, double> values;
    for (const auto& [name, value] : store.statistics(run.id)) {
      values[name] = value;
      d.statistics.insert(name);
    }
    d.runs[it->second].emplace_back(run.seed, std::move(values));
    ++state.stored;
  }
  return d;
}

bool matches(const ExperimentBatch& b, std::size_t variant, const AxisFilter& filter) {
  for (const auto& [axis, value] : filter) {
    const int a = b.axis_index(axis);
    if (a < 0 || b.variant_axes[variant][static_cast<std::size_t>(a)] != value) return false;
  }
  return true;
}

/// The values of `sel`'s statistic over the runs of the variants `filter` selects, each keyed by
/// its seed and its variant's values of `key_axes` (the axes pooled on both sides of a
/// comparison): the key pairs a run with the other side's run of the same seed.
std::vector<KeyedValue> collect_keyed(const BatchData& d, const Selection& sel,
                                      const AxisFilter& filter,
                                      const std::vector<std::size_t>& key_axes, SampleCounts& n) {
  std::vector<KeyedValue> out;
  const ExperimentBatch& b = *d.batch;
  for (std::size_t v = 0; v < d.runs.size(); ++v) {
    if (!matches(b, v, filter)) continue;
    n.expected += d.expected[v];
    std::string pooled;
    for (const std::size_t a : key_axes) {
      pooled += "," + b.scenario.axes[a] + "=" + b.variant_axes[v][a];
    }
    for (const auto& [seed, run] : d.runs[v]) {
      ++n.stored;
      const auto it = run.find(sel.statistic);
      if (it == run.end()) continue;
      if (sel.ignore_below && it->second < *sel.ignore_below) continue;
      out.push_back({"seed=" + std::to_string(seed) + pooled, it->second});
    }
  }
  n.used = static_cast<int>(out.size());
  return out;
}

std::vector<double> values_of(const std::vector<KeyedValue>& kv) {
  std::vector<double> out;
  out.reserve(kv.size());
  for (const KeyedValue& x : kv) out.push_back(x.value);
  return out;
}

/// The values of `sel`'s statistic over the runs of the variants `filter` selects.
std::vector<double> collect(const BatchData& d, const Selection& sel, const AxisFilter& filter,
                            SampleCounts& n) {
  return values_of(collect_keyed(d, sel, filter, {}, n));
}

/// The axes of `b` that neither filter names: pooled on both sides, part of the pairing key.
std::vector<std::size_t> pooled_axes(const ExperimentBatch& b, const AxisFilter& x,
                                     const AxisFilter& y) {
  std::vector<std::size_t> out;
  for (std::size_t a = 0; a < b.scenario.axes.size(); ++a) {
    auto named = [&](const AxisFilter& f) {
      return std::any_of(f.begin(), f.end(),
                         [&](const auto& p) { return p.first == b.scenario.axes[a]; });
    };
    if (!named(x) && !named(y)) out.push_back(a);
  }
  return out;
}

/// `filter` plus the group's axis value, if the batch has the group axis.
AxisFilter with_group(const Experiment& e, const ExperimentBatch& b, AxisFilter filter,
                      const std::string& group) {
  if (!group.empty() && b.axis_index(e.group_by) >= 0) filter.emplace_back(e.group_by, group);
  return filter;
}

double mean_of(const std::vector<double>& v) {
  return std::accumulate(v.begin(), v.end(), 0.0) / static_cast<double>(v.size());
}

/// Wilson score 95 % interval of k successes in n trials.
Interval wilson(int k, int n) {
  const double z = 1.959963984540054;
  const double nn = n;
  const double p = k / nn;
  const double denom = 1.0 + z * z / nn;
  const double centre = (p + z * z / (2.0 * nn)) / denom;
  const double half = z / denom * std::sqrt(p * (1.0 - p) / nn + z * z / (4.0 * nn * nn));
  return {std::max(0.0, centre - half), std::min(1.0, centre + half)};
}

// Numbers as the reports print them: fewer decimals for larger values.
std::string num(double v) {
  if (v == 0.0) return "0";
  char buf[48];
  const double a = std::fabs(v);
  std::snprintf(buf, sizeof buf, a >= 10.0 ? "%.1f" : a >= 1.0 ? "%.2f" : "%.3f", v);
  std::string s = buf;
  if (s == "-0.0" || s == "-0.00" || s == "-0.000") s.erase(0, 1);
  return s;
}

std::string signed_num(double v) {
  const std::string s = num(v);
  return s.front() == '-' || s == "0" ? s : "+" + s;
}

/// A number as written in the experiment file ("540", "0.02", "-0.5").
std::string bound(double v) {
  char buf[48];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

std::string filter_text(const AxisFilter& f) {
  if (f.empty()) return "all runs";
  std::string out;
  for (const auto& [axis, value] : f) out += (out.empty() ? "" : ",") + axis + "=" + value;
  return out;
}

std::string counts_text(const SampleCounts& c) {
  std::string s = "n " + std::to_string(c.used);
  if (c.used != c.stored) s += " of " + std::to_string(c.stored);
  if (c.stored != c.expected) {
    s += " (" + std::to_string(c.stored) + " of " + std::to_string(c.expected) + " runs)";
  }
  return s;
}

/// A side without values: nothing stored, or every value left out.
std::string missing_text(const SampleCounts& c) {
  if (c.stored == 0) return "0 of " + std::to_string(c.expected) + " runs stored";
  return counts_text(c);
}

std::string describe(const Check& c) {
  const std::string& stat = c.sel.statistic;
  std::string s;
  switch (c.kind) {
    case Check::Kind::kGreater:
      s = stat + ": " + filter_text(c.a) + " > " + filter_text(c.b);
      break;
    case Check::Kind::kNotGreater:
      s = stat + ": " + filter_text(c.a) + " not > " + filter_text(c.b) + " by " + bound(c.margin) +
          " or more";
      break;
    case Check::Kind::kNotLess:
      s = stat + ": " + filter_text(c.a) + " not < " + filter_text(c.b) + " by " + bound(c.margin) +
          " or more";
      break;
    case Check::Kind::kEquivalent:
      s = stat + ": " + filter_text(c.a) + " = " + filter_text(c.b) + " within ±" + bound(c.margin);
      break;
    case Check::Kind::kDifferenceIn:
      s = stat + ": " + filter_text(c.a) + " - " + filter_text(c.b) + " in [" + bound(c.low) +
          ", " + bound(c.high) + "]";
      break;
    case Check::Kind::kMeanIn:
    case Check::Kind::kMedianIn:
      s = stat + ": " + (c.kind == Check::Kind::kMeanIn ? "mean" : "median") +
          (c.a.empty() ? "" : " of " + filter_text(c.a)) + " in [" + bound(c.low) + ", " +
          bound(c.high) + "]";
      break;
    case Check::Kind::kShareAtMost:
    case Check::Kind::kShareAtLeast:
      s = "share of " + filter_text(c.a) + " with " + stat + " > " + bound(c.sel.above) +
          (c.kind == Check::Kind::kShareAtMost ? " at most " : " at least ") +
          bound(c.kind == Check::Kind::kShareAtMost ? c.high : c.low);
      break;
  }
  if (c.sel.ignore_below) s += " (values below " + bound(*c.sel.ignore_below) + " left out)";
  if (has_margin(c.kind)) s += " (margin: " + c.margin_reason + ")";
  return s;
}

/// "paired by seed (100 pairs)" or "unpaired", with the runs a pairing left out.
std::string method_text(const Comparison& c) {
  if (c.pairing == Pairing::kUnpaired) return "unpaired";
  std::string s =
      "paired by seed (" + std::to_string(c.pairs) + (c.pairs == 1 ? " pair" : " pairs");
  if (c.unmatched > 0) s += ", " + std::to_string(c.unmatched) + " runs without a partner left out";
  return s + ")";
}

/// What the runs could show: the smallest detectable difference, the games a difference of the
/// size seen would need.
std::string power_text(const Comparison& c, bool detectable) {
  std::string s;
  if (detectable && c.detectable) s += "; smallest detectable " + num(*c.detectable);
  if (c.games_needed) {
    s += "; about " + std::to_string(*c.games_needed) +
         (c.pairing == Pairing::kPaired ? " seeds" : " games per side") +
         " would separate a difference of this size";
  } else if (!c.se) {
    s += "; the spread is unknown with one game";
  }
  return s;
}

std::string too_few_text(int games, int min_games) {
  return "; too few games for a verdict (" + std::to_string(games) + ", needs " +
         std::to_string(min_games) + ")";
}

/// Evaluates one check in one group, drawing its bootstrap from `rng`.
CheckResult evaluate_check(const Experiment& e, const std::vector<BatchData>& data, const Check& c,
                           const std::string& group, core::RandomStream rng, int min_games) {
  const BatchData& d = data[static_cast<std::size_t>(c.sel.batch)];
  const ExperimentBatch& b = *d.batch;
  require_stored(d.statistics, c.sel.statistic, c.where, b.name);
  CheckResult r;
  r.description = describe(c);
  const AxisFilter fa = with_group(e, b, c.a, group);
  const AxisFilter fb = with_group(e, b, c.b, group);
  const std::vector<std::size_t> key_axes = pooled_axes(b, fa, fb);
  const std::vector<KeyedValue> ak = collect_keyed(d, c.sel, fa, key_axes, r.a);
  const std::vector<double> a = values_of(ak);
  if (is_comparison(c.kind)) {
    const std::vector<KeyedValue> bk = collect_keyed(d, c.sel, fb, key_axes, r.b);
    if (ak.empty() || bk.empty()) {
      r.measured = "no data: " + missing_text(r.a) + " vs " + missing_text(r.b);
      return r;
    }
    const Comparison cmp = compare_means(ak, bk, rng, min_games);
    r.comparison = cmp;
    r.value = cmp.diff;
    const bool margin = has_margin(c.kind);
    const Interval ci = margin ? cmp.ci_tost : cmp.ci;
    r.ci_low = ci.low;
    r.ci_high = ci.high;
    r.measured = "difference " + signed_num(r.value) + (margin ? ", 90 % CI [" : ", 95 % CI [") +
                 signed_num(ci.low) + ", " + signed_num(ci.high) + "], " + method_text(cmp) + "; " +
                 counts_text(r.a) + " vs " + counts_text(r.b).substr(2);
    bool holds = false;
    switch (c.kind) {
      case Check::Kind::kGreater:
        holds = cmp.ci.low > 0.0;
        break;
      case Check::Kind::kNotGreater:
        holds = within_margin(cmp, MarginTest::kNotAbove, c.margin);
        break;
      case Check::Kind::kNotLess:
        holds = within_margin(cmp, MarginTest::kNotBelow, c.margin);
        break;
      case Check::Kind::kEquivalent:
        holds = within_margin(cmp, MarginTest::kSame, c.margin);
        break;
      default:
        holds = r.value >= c.low && r.value <= c.high;
    }
    if (!cmp.enough) {
      r.measured += too_few_text(cmp.games(), min_games) + power_text(cmp, margin);
      r.outcome = CheckResult::Outcome::kTooFew;
      return r;
    }
    // A greater that failed, or a margin check: what the runs could have shown.
    if (margin || (c.kind == Check::Kind::kGreater && !holds)) {
      r.measured += power_text(cmp, margin);
    }
    r.outcome = holds ? CheckResult::Outcome::kHolds : CheckResult::Outcome::kFails;
    return r;
  }
  if (a.empty()) {
    r.measured = "no data: " + missing_text(r.a);
    return r;
  }
  if (is_share(c.kind)) {
    const auto k = static_cast<int>(
        std::count_if(a.begin(), a.end(), [&](double v) { return v > c.sel.above; }));
    const int n = static_cast<int>(a.size());
    r.value = static_cast<double>(k) / n;
    const Interval ci = wilson(k, n);
    r.ci_low = ci.low;
    r.ci_high = ci.high;
    char buf[128];
    std::snprintf(buf, sizeof buf, "share %.3f (%d of %d), Wilson 95 %% CI [%.3f, %.3f]; ", r.value,
                  k, n, ci.low, ci.high);
    r.measured = buf + counts_text(r.a);
  } else {
    const Estimator est = c.kind == Check::Kind::kMeanIn ? Estimator::kMean : Estimator::kMedian;
    std::vector<double> sorted = a;
    std::sort(sorted.begin(), sorted.end());
    r.value = est == Estimator::kMean ? mean_of(a) : quantile(sorted, 0.5);
    const Interval ci = bootstrap_interval(a, {}, est, rng);
    r.ci_low = ci.low;
    r.ci_high = ci.high;
    r.measured = std::string(est == Estimator::kMean ? "mean " : "median ") + num(r.value) +
                 ", 95 % CI [" + num(ci.low) + ", " + num(ci.high) + "]; " + counts_text(r.a);
  }
  if (static_cast<int>(a.size()) < min_games) {
    r.measured += too_few_text(static_cast<int>(a.size()), min_games);
    r.outcome = CheckResult::Outcome::kTooFew;
    return r;
  }
  r.outcome = r.value >= c.low && r.value <= c.high ? CheckResult::Outcome::kHolds
                                                    : CheckResult::Outcome::kFails;
  return r;
}

/// The groups an item is evaluated in: {""} unless one of its batches has the group axis.
std::vector<std::string> groups_of(const Experiment& e, const std::vector<int>& batches,
                                   const std::vector<std::string>& chosen) {
  const bool grouped =
      !e.group_by.empty() && std::any_of(batches.begin(), batches.end(), [&](int b) {
        return e.batches[static_cast<std::size_t>(b)].axis_index(e.group_by) >= 0;
      });
  if (!grouped) return {""};
  return chosen.empty() ? e.groups : chosen;
}

core::RandomStream stream(const EvaluateOptions& o, const std::string& name) {
  return core::Rng(o.seed).stream(name);
}

SweepResult evaluate_sweep(const Experiment& e, const std::vector<BatchData>& data, const Sweep& s,
                           const std::string& group, const EvaluateOptions& o) {
  const BatchData& d = data[static_cast<std::size_t>(s.sel.batch)];
  const ExperimentBatch& b = *d.batch;
  require_stored(d.statistics, s.sel.statistic, s.where, b.name);
  SweepResult r;
  r.sweep = &s;
  r.group = group;
  r.compare_values = b.axis_values[static_cast<std::size_t>(b.axis_index(s.compare))];
  const auto& rows = b.axis_values[static_cast<std::size_t>(b.axis_index(s.axis))];
  std::vector<std::string> baseline_order;
  for (const std::string& value : rows) {
    SweepRow row;
    row.value = value;
    std::vector<std::vector<KeyedValue>> samples;
    for (const std::string& cv : r.compare_values) {
      AxisFilter f = s.fixed;
      f.emplace_back(s.axis, value);
      f.emplace_back(s.compare, cv);
      SampleCounts n;
      // Every axis is fixed (or the group's): the seed alone pairs the compared values' runs.
      samples.push_back(collect_keyed(d, s.sel, with_group(e, b, f, group), {}, n));
      row.means.push_back(samples.back().empty() ? 0.0 : mean_of(values_of(samples.back())));
      row.n.push_back(n);
    }
    // Best mean first; equal means keep the file order.
    std::vector<std::size_t> idx;
    for (std::size_t i = 0; i < samples.size(); ++i) {
      if (!samples[i].empty()) idx.push_back(i);
    }
    std::stable_sort(idx.begin(), idx.end(),
                     [&](std::size_t x, std::size_t y) { return row.means[x] > row.means[y]; });
    for (std::size_t k = 0; k < idx.size(); ++k) {
      row.order.push_back(r.compare_values[idx[k]]);
      if (k > 0) row.ranking += row.means[idx[k]] == row.means[idx[k - 1]] ? " = " : " > ";
      row.ranking += r.compare_values[idx[k]];
    }
    if (idx.size() >= 2) {
      row.has_top_two = true;
      core::RandomStream rng = stream(o, "sweep/" + s.name + "/" + group + "/" + value);
      row.top = compare_means(samples[idx[0]], samples[idx[1]], rng, o.min_games);
      row.top_diff = row.top->diff;
      row.top_low = row.top->ci.low;
      row.top_high = row.top->ci.high;
    }
    if (value == s.baseline) baseline_order = row.order;
    r.rows.push_back(std::move(row));
  }
  // The rows' top-two comparisons are one family: Holm's correction over them.
  std::vector<double> p;
  for (const SweepRow& row : r.rows) {
    if (row.top) p.push_back(row.top->p_value);
  }
  r.comparisons = static_cast<int>(p.size());
  const std::vector<bool> rejected = holm(p);
  std::size_t k = 0;
  for (SweepRow& row : r.rows) {
    row.comparable = !row.order.empty() && !baseline_order.empty();
    row.differs = row.comparable && row.value != s.baseline && row.order != baseline_order;
    if (row.top) row.separated = rejected[k++] && row.top->enough;
  }
  return r;
}

TableResult evaluate_table(const Experiment& e, const std::vector<BatchData>& data, const Table& t,
                           const std::string& group) {
  const BatchData& d = data[static_cast<std::size_t>(t.sel.batch)];
  const ExperimentBatch& b = *d.batch;
  for (const std::string& st : t.statistics) require_stored(d.statistics, st, t.where, b.name);
  TableResult r;
  r.table = &t;
  r.group = group;
  for (const std::string& value : t.values) {
    TableRow row;
    row.value = value;
    AxisFilter f = t.fixed;
    f.emplace_back(t.rows, value);
    f = with_group(e, b, f, group);
    for (const std::string& st : t.statistics) {
      Selection sel = t.sel;
      sel.statistic = st;
      SampleCounts n;
      const std::vector<double> v = collect(d, sel, f, n);
      row.runs = n.stored;
      row.means.push_back(v.empty() ? 0.0 : mean_of(v));
      row.n.push_back(n.used);
    }
    r.rows.push_back(std::move(row));
  }
  return r;
}

}  // namespace

ExperimentResult evaluate(const Experiment& e, const StatsStore& store, const EvaluateOptions& o) {
  ExperimentResult r;
  r.experiment = &e;
  r.command = "llsfsim experiment " + e.file + (o.runs ? " --runs " + std::to_string(*o.runs) : "");
  r.min_games = o.min_games;
  std::vector<BatchData> data;
  for (const ExperimentBatch& b : e.batches) {
    r.batches.emplace_back();
    data.push_back(load_batch_data(b, store, o, r.batches.back()));
  }

  for (const CalibrationTarget& t : e.calibration) {
    for (const std::string& g : groups_of(e, {t.check.sel.batch}, t.groups)) {
      TargetResult tr;
      tr.target = &t;
      tr.group = g;
      tr.check = evaluate_check(e, data, t.check, g, stream(o, "calibration/" + t.name + "/" + g),
                                o.min_games);
      tr.verdict = tr.check.outcome == CheckResult::Outcome::kHolds    ? Verdict::kHolds
                   : tr.check.outcome == CheckResult::Outcome::kFails  ? Verdict::kFails
                   : tr.check.outcome == CheckResult::Outcome::kTooFew ? Verdict::kTooFew
                                                                       : Verdict::kNoData;
      r.calibration.push_back(std::move(tr));
    }
  }

  for (const Finding& f : e.findings) {
    FindingResult fr;
    fr.finding = &f;
    std::vector<int> batches;
    for (const Check& c : f.checks) batches.push_back(c.sel.batch);
    for (const std::string& g : groups_of(e, batches, f.groups)) {
      FindingGroupResult gr;
      gr.group = g;
      bool no_data = false, too_few = false;
      for (std::size_t i = 0; i < f.checks.size(); ++i) {
        gr.checks.push_back(evaluate_check(
            e, data, f.checks[i], g,
            stream(o, "finding/" + f.id + "/" + std::to_string(i + 1) + "/" + g), o.min_games));
        const CheckResult::Outcome out = gr.checks.back().outcome;
        if (out == CheckResult::Outcome::kFails) gr.failed.push_back(static_cast<int>(i) + 1);
        no_data = no_data || out == CheckResult::Outcome::kNoData;
        too_few = too_few || out == CheckResult::Outcome::kTooFew;
      }
      // A check that failed with enough games decides; then missing runs, then too few games.
      gr.verdict = !gr.failed.empty() ? Verdict::kFails
                   : no_data          ? Verdict::kNoData
                   : too_few          ? Verdict::kTooFew
                                      : Verdict::kHolds;
      fr.groups.push_back(std::move(gr));
    }
    r.findings.push_back(std::move(fr));
  }

  for (const Sweep& s : e.sweeps) {
    for (const std::string& g : groups_of(e, {s.sel.batch}, s.groups)) {
      r.sweeps.push_back(evaluate_sweep(e, data, s, g, o));
    }
  }

  for (const Table& t : e.tables) {
    for (const std::string& g : groups_of(e, {t.sel.batch}, t.groups)) {
      r.tables.push_back(evaluate_table(e, data, t, g));
    }
  }
  return r;
}

bool is_sequential(Check::Kind k) { return k == Check::Kind::kGreater || has_margin(k); }

std::string to_string(CheckLook::Decision d) {
  switch (d) {
    case CheckLook::Decision::kOpen:
      return "open";
    case CheckLook::Decision::kHolds:
      return "holds";
    case CheckLook::Decision::kFails:
      return "fails";
  }
  return "?";
}

std::vector<CheckLook> look_at_findings(const Experiment& e, const StatsStore& store,
                                        const EvaluateOptions& options,
                                        const std::vector<int>& findings,
                                        const SequentialPlan& plan, int look) {
  LLSF_DEMAND(plan.problem().empty());
  LLSF_DEMAND(look >= 1 && look <= plan.looks);
  EvaluateOptions o = options;
  o.first_seeds = plan.look_sizes()[static_cast<std::size_t>(look - 1)];
  // Only the batches the findings' checks use are read.
  std::vector<BatchData> data(e.batches.size());
  for (const int f : findings) {
    for (const Check& c : e.findings[static_cast<std::size_t>(f)].checks) {
      const auto i = static_cast<std::size_t>(c.sel.batch);
      if (data[i].batch != nullptr) continue;
      BatchState state;
      data[i] = load_batch_data(e.batches[i], store, o, state);
    }
  }
  std::vector<CheckLook> out;
  for (const int fi : findings) {
    const Finding& f = e.findings[static_cast<std::size_t>(fi)];
    std::vector<int> batches;
    for (const Check& c : f.checks) batches.push_back(c.sel.batch);
    for (const std::string& g : groups_of(e, batches, f.groups)) {
      for (std::size_t i = 0; i < f.checks.size(); ++i) {
        const Check& c = f.checks[i];
        if (!is_sequential(c.kind)) continue;
        CheckLook l;
        l.finding = fi;
        l.check = static_cast<int>(i) + 1;
        l.group = g;
        l.description = describe(c);
        const BatchData& d = data[static_cast<std::size_t>(c.sel.batch)];
        const ExperimentBatch& b = *d.batch;
        require_stored(d.statistics, c.sel.statistic, c.where, b.name);
        const AxisFilter fa = with_group(e, b, c.a, g);
        const AxisFilter fb = with_group(e, b, c.b, g);
        const std::vector<std::size_t> key_axes = pooled_axes(b, fa, fb);
        SampleCounts na, nb;
        const std::vector<KeyedValue> ak = collect_keyed(d, c.sel, fa, key_axes, na);
        const std::vector<KeyedValue> bk = collect_keyed(d, c.sel, fb, key_axes, nb);
        if (ak.empty() || bk.empty()) {
          out.push_back(std::move(l));
          continue;
        }
        // Each check, group and look its own stream: adding a check changes no other decision.
        core::RandomStream rng = stream(o, "until/finding/" + f.id + "/" + std::to_string(l.check) +
                                               "/" + g + "/" + std::to_string(look));
        const Comparison cmp =
            compare_means(ak, bk, rng, o.min_games, kBootstrapResamples, plan.look_alpha());
        l.comparison = cmp;
        // A check is decided when its test is conclusive either way at the look's level; the
        // margin checks on the 1 - 2 alpha interval (two one-sided tests), greater on 1 - alpha.
        using D = CheckLook::Decision;
        const Interval t = cmp.ci_tost;
        const double m = c.margin;
        D dec = D::kOpen;
        switch (c.kind) {
          case Check::Kind::kGreater:
            dec = cmp.ci.low > 0.0 ? D::kHolds : cmp.ci.high < 0.0 ? D::kFails : D::kOpen;
            break;
          case Check::Kind::kNotGreater:
            dec = t.high < m ? D::kHolds : t.low >= m ? D::kFails : D::kOpen;
            break;
          case Check::Kind::kNotLess:
            dec = t.low > -m ? D::kHolds : t.high <= -m ? D::kFails : D::kOpen;
            break;
          case Check::Kind::kEquivalent:
            dec = -m < t.low && t.high < m     ? D::kHolds
                  : t.low >= m || t.high <= -m ? D::kFails
                                               : D::kOpen;
            break;
          default:
            break;
        }
        l.decision = cmp.enough ? dec : D::kOpen;
        out.push_back(std::move(l));
      }
    }
  }
  return out;
}

namespace {

// ---------------------------------------------------------------------------------------------
// Rendering

std::string target_verdict(Verdict v) {
  return v == Verdict::kHolds    ? "met"
         : v == Verdict::kFails  ? "not met"
         : v == Verdict::kTooFew ? "too few games"
                                 : "no data";
}

std::string finding_verdict(const FindingGroupResult& g, int min_games) {
  if (g.verdict == Verdict::kHolds) return "reproduced";
  if (g.verdict == Verdict::kNoData) return "no data";
  if (g.verdict == Verdict::kTooFew) {
    return "no verdict: too few games (at least " + std::to_string(min_games) + " a side)";
  }
  std::vector<std::string> nums;
  for (const int i : g.failed) nums.push_back(std::to_string(i));
  return std::string("not reproduced (check") + (g.failed.size() > 1 ? "s " : " ") +
         join(nums, ", ") + " failed)";
}

std::string outcome_text(CheckResult::Outcome o) {
  return o == CheckResult::Outcome::kHolds    ? "holds"
         : o == CheckResult::Outcome::kFails  ? "fails"
         : o == CheckResult::Outcome::kTooFew ? "too few"
                                              : "no data";
}

std::string group_label(const std::string& g) { return g.empty() ? "all" : g; }

std::string batch_line(const BatchState& b) {
  std::string s = std::to_string(b.stored) + " of " + std::to_string(b.expected) + " runs";
  if (b.batch_id == 0) {
    s += ", not in the store";
    if (!b.other_runs_per_variant.empty()) {
      std::vector<std::string> v;
      for (const int n : b.other_runs_per_variant) v.push_back(std::to_string(n));
      s += " (stored with --runs " + join(v, ", ") + ")";
    }
  } else if (b.stored < b.expected) {
    s += ", incomplete";
  }
  return s;
}

std::string sweep_cell(const SweepRow& row, std::size_t i) {
  if (row.n[i].used == 0) return "-";
  const SampleCounts& n = row.n[i];
  return num(row.means[i]) + " (n " + std::to_string(n.used) +
         (n.used != n.stored ? " of " + std::to_string(n.stored) : "") + ")";
}

std::string top_two(const SweepRow& row) {
  if (!row.has_top_two) return "-";
  const std::string numbers = signed_num(row.top_diff) + " [" + signed_num(row.top_low) + ", " +
                              signed_num(row.top_high) + "]";
  if (!row.top->enough) {
    return "too few games (" + std::to_string(row.top->games()) + "): " + numbers;
  }
  return std::string(row.separated ? "separated" : "not separated") + ": " + numbers;
}

/// How a sweep's top two were compared: the method and the family Holm's correction controls.
std::string sweep_method(const SweepResult& s) {
  std::string method = "unpaired";
  for (const SweepRow& row : s.rows) {
    if (row.top && row.top->pairing == Pairing::kPaired) method = "paired by seed";
  }
  return method + ", Holm's correction over " + std::to_string(s.comparisons) +
         (s.comparisons == 1 ? " comparison" : " comparisons");
}

/// Findings test each check at 5 % on its own; the report says so, with the number of checks.
std::string findings_note(const ExperimentResult& r) {
  int checks = 0;
  for (const FindingResult& f : r.findings) {
    for (const FindingGroupResult& g : f.groups) checks += static_cast<int>(g.checks.size());
  }
  return "Each of the " + std::to_string(checks) +
         " checks is tested at the 5 % level on its own (no correction across checks: each "
         "finding is its own claim); differences are paired by seed where the runs share their "
         "seeds; no verdict from fewer than " +
         std::to_string(r.min_games) + " games a side.";
}

/// A table's cell: the mean, with "n of N" if some runs have no value (absent, or left out).
std::string table_cell(const TableRow& row, std::size_t i) {
  if (row.n[i] == 0) return "-";
  return num(row.means[i]) + (row.n[i] != row.runs ? " (n " + std::to_string(row.n[i]) + " of " +
                                                         std::to_string(row.runs) + ")"
                                                   : "");
}

std::string table_heading(const TableResult& t, const Experiment& e) {
  const Table& tb = *t.table;
  return "Mean per run by `" + tb.rows + "` of batch `" +
         e.batches[static_cast<std::size_t>(tb.sel.batch)].name + "`" +
         (tb.fixed.empty() ? "" : " (" + filter_text(tb.fixed) + ")") +
         (tb.sel.ignore_below ? ", values below " + bound(*tb.sel.ignore_below) + " left out"
                              : "") +
         ".";
}

std::string vs_baseline(const SweepRow& row, const Sweep& s) {
  if (row.value == s.baseline) return "baseline";
  if (!row.comparable) return "-";
  return row.differs ? "differs" : "same";
}

/// A table cell: no line breaks, `|` escaped.
std::string cell(const std::string& text) {
  std::string out;
  for (const char c : text) {
    if (c == '|') {
      out += "\\|";
    } else if (c == '\n' || c == '\r') {
      out += ' ';
    } else {
      out += c;
    }
  }
  return out.empty() ? " " : out;
}

std::string row(const std::vector<std::string>& cells) {
  std::string out = "|";
  for (const std::string& c : cells) out += " " + cell(c) + " |";
  return out + "\n";
}

std::string pad(const std::string& s, std::size_t width) {
  return s.size() >= width ? s + " " : s + std::string(width - s.size(), ' ');
}

}  // namespace

std::string to_text(const ExperimentResult& r) {
  const Experiment& e = *r.experiment;
  std::string out = "experiment " + e.name + " (" + e.file + ")\n";
  out += "command    " + r.command + "\n";
  for (const BatchState& b : r.batches) {
    out += "batch      " + pad(b.name, 16) + pad(b.file_as_given, 24) +
           (b.batch_id ? "#" + std::to_string(b.batch_id) + "  " : "") + batch_line(b) + "\n";
  }

  if (!r.calibration.empty()) out += "\ncalibration\n";
  for (const TargetResult& t : r.calibration) {
    out += "  " + pad(target_verdict(t.verdict), 9) + t.target->name +
           (t.group.empty() ? "" : " [" + t.group + "]") + "\n";
    out += "           " + t.check.description + "\n";
    out += "           " + t.check.measured + "\n";
  }

  if (!r.findings.empty()) out += "\nfindings   (" + findings_note(r) + ")\n";
  for (const FindingResult& f : r.findings) {
    out += "  " + f.finding->id + "  " + f.finding->claim + "\n";
    for (const FindingGroupResult& g : f.groups) {
      out += "    " + group_label(g.group) + ": " + finding_verdict(g, r.min_games) + "\n";
      for (std::size_t i = 0; i < g.checks.size(); ++i) {
        const CheckResult& c = g.checks[i];
        out += "      " + std::to_string(i + 1) + " " + pad(outcome_text(c.outcome), 8) +
               c.description + "\n";
        out += "                 " + c.measured + "\n";
      }
    }
  }

  if (!r.sweeps.empty()) out += "\nsweeps\n";
  for (const SweepResult& s : r.sweeps) {
    const Sweep& sw = *s.sweep;
    out += "  " + sw.name + (s.group.empty() ? "" : " [" + s.group + "]") + ": " +
           sw.sel.statistic + " by " + sw.compare + " per " + sw.axis + " (batch " +
           e.batches[static_cast<std::size_t>(sw.sel.batch)].name +
           (sw.fixed.empty() ? "" : ", " + filter_text(sw.fixed)) + "; top two " + sweep_method(s) +
           ")\n";
    std::size_t w = sw.axis.size();
    for (const SweepRow& row : s.rows) w = std::max(w, row.value.size());
    std::vector<std::size_t> cw;
    for (std::size_t i = 0; i < s.compare_values.size(); ++i) {
      std::size_t c = s.compare_values[i].size();
      for (const SweepRow& row : s.rows) c = std::max(c, sweep_cell(row, i).size());
      cw.push_back(c + 2);
    }
    out += "    " + pad(sw.axis, w + 2);
    for (std::size_t i = 0; i < s.compare_values.size(); ++i)
      out += pad(s.compare_values[i], cw[i]);
    out += "ranking\n";
    for (const SweepRow& row : s.rows) {
      out += "    " + pad(row.value, w + 2);
      for (std::size_t i = 0; i < s.compare_values.size(); ++i)
        out += pad(sweep_cell(row, i), cw[i]);
      out += (row.ranking.empty() ? "-" : row.ranking) + "  (" + vs_baseline(row, sw) +
             "; top two " + top_two(row) + ")\n";
    }
  }

  if (!r.tables.empty()) out += "\ntables\n";
  for (const TableResult& t : r.tables) {
    const Table& tb = *t.table;
    out += "  " + tb.name + (t.group.empty() ? "" : " [" + t.group + "]") + ": " +
           table_heading(t, e) + "\n";
    std::size_t w = tb.rows.size();
    for (const TableRow& row : t.rows) w = std::max(w, row.value.size());
    std::vector<std::size_t> cw;
    for (std::size_t i = 0; i < tb.statistics.size(); ++i) {
      std::size_t c = tb.statistics[i].size();
      for (const TableRow& row : t.rows) c = std::max(c, table_cell(row, i).size());
      cw.push_back(c + 2);
    }
    auto add_line = [&out](std::string line) {
      while (!line.empty() && line.back() == ' ') line.pop_back();
      out += line + "\n";
    };
    std::string head = "    " + pad(tb.rows, w + 2) + pad("runs", 6);
    for (std::size_t i = 0; i < tb.statistics.size(); ++i) head += pad(tb.statistics[i], cw[i]);
    add_line(head);
    for (const TableRow& row : t.rows) {
      std::string line = "    " + pad(row.value, w + 2) + pad(std::to_string(row.runs), 6);
      for (std::size_t i = 0; i < tb.statistics.size(); ++i) line += pad(table_cell(row, i), cw[i]);
      add_line(line);
    }
  }
  return out;
}

std::string to_markdown(const ExperimentResult& r) {
  const Experiment& e = *r.experiment;
  std::string out = "## Experiment " + e.name + "\n\n";
  if (!e.description.empty()) out += e.description + "\n\n";
  out += "Reproduce: `" + r.command + "`\n\n";
  out += "| batch | scenario file | variants | runs per variant | runs stored |\n";
  out += "|---|---|---:|---:|---|\n";
  for (const BatchState& b : r.batches) {
    out += row({b.name, "`" + b.file_as_given + "`", std::to_string(b.variants),
                std::to_string(b.runs_per_variant), batch_line(b)});
  }

  if (!r.calibration.empty()) {
    out += "\n### Calibration\n\n";
    out += "| target | source | group | condition | measured | verdict |\n";
    out += "|---|---|---|---|---|---|\n";
    for (const TargetResult& t : r.calibration) {
      out += row({t.target->name, t.target->source, group_label(t.group), t.check.description,
                  t.check.measured, "**" + target_verdict(t.verdict) + "**"});
    }
  }

  if (!r.findings.empty()) {
    out += "\n### Findings\n\n" + findings_note(r) + "\n\n";
    out += "| finding | claim | verdict |\n|---|---|---|\n";
    for (const FindingResult& f : r.findings) {
      std::vector<std::string> verdicts;
      for (const FindingGroupResult& g : f.groups) {
        verdicts.push_back((g.group.empty() ? "" : g.group + ": ") +
                           finding_verdict(g, r.min_games));
      }
      out += row({f.finding->id, f.finding->claim, join(verdicts, "; ")});
    }
    for (const FindingResult& f : r.findings) {
      out += "\n#### " + f.finding->id + ": " + f.finding->claim + "\n\n";
      if (!f.finding->source.empty()) out += "Source: " + f.finding->source + "\n\n";
      out += "| group | check | measured | holds |\n|---|---|---|---|\n";
      for (const FindingGroupResult& g : f.groups) {
        for (std::size_t i = 0; i < g.checks.size(); ++i) {
          const CheckResult& c = g.checks[i];
          out += row({group_label(g.group), std::to_string(i + 1) + ". " + c.description,
                      c.measured, outcome_text(c.outcome)});
        }
        out += row({group_label(g.group), "**verdict**", "",
                    "**" + finding_verdict(g, r.min_games) + "**"});
      }
    }
  }

  if (!r.sweeps.empty()) out += "\n### Sweeps\n";
  for (const SweepResult& s : r.sweeps) {
    const Sweep& sw = *s.sweep;
    out += "\n#### " + sw.name + (s.group.empty() ? "" : " (" + s.group + ")") + "\n\n";
    if (!sw.source.empty()) out += "Source: " + sw.source + "\n\n";
    out +=
        "Mean `" + sw.sel.statistic + "` per `" + sw.compare + "` for each `" + sw.axis +
        "` of batch `" + e.batches[static_cast<std::size_t>(sw.sel.batch)].name + "`" +
        (sw.fixed.empty() ? "" : " (" + filter_text(sw.fixed) + ")") +
        (sw.sel.ignore_below ? ", values below " + bound(*sw.sel.ignore_below) + " left out" : "") +
        "; baseline `" + sw.baseline +
        "`. Top two: the bootstrap 95 % interval of the best minus the second mean (" +
        sweep_method(s) + ").\n\n";
    std::vector<std::string> head{sw.axis};
    std::string align = "|---|";
    for (const std::string& cv : s.compare_values) {
      head.push_back(cv);
      align += "---:|";
    }
    for (const char* h : {"ranking", "vs baseline", "top two"}) {
      head.push_back(h);
      align += "---|";
    }
    out += row(head) + align + "\n";
    for (const SweepRow& rw : s.rows) {
      std::vector<std::string> cells{rw.value};
      for (std::size_t i = 0; i < s.compare_values.size(); ++i) cells.push_back(sweep_cell(rw, i));
      cells.push_back(rw.ranking.empty() ? "-" : rw.ranking);
      cells.push_back(rw.differs ? "**differs**" : vs_baseline(rw, sw));
      cells.push_back(top_two(rw));
      out += row(cells);
    }
  }

  if (!r.tables.empty()) out += "\n### Tables\n";
  for (const TableResult& t : r.tables) {
    const Table& tb = *t.table;
    out += "\n#### " + tb.name + (t.group.empty() ? "" : " (" + t.group + ")") + "\n\n";
    if (!tb.source.empty()) out += "Source: " + tb.source + "\n\n";
    out += table_heading(t, e) + "\n\n";
    std::vector<std::string> head{tb.rows, "runs"};
    std::string align = "|---|---:|";
    for (const std::string& st : tb.statistics) {
      head.push_back(st);
      align += "---:|";
    }
    out += row(head) + align + "\n";
    for (const TableRow& rw : t.rows) {
      std::vector<std::string> cells{rw.value, std::to_string(rw.runs)};
      for (std::size_t i = 0; i < tb.statistics.size(); ++i) cells.push_back(table_cell(rw, i));
      out += row(cells);
    }
  }
  return out;
}

std::string replace_between_markers(const std::string& text, const std::string& name,
                                    const std::string& replacement) {
  // A marker counts as a whole line (a trailing '\r' allowed).
  auto find_line = [&](const std::string& marker) {
    std::vector<std::size_t> at;
    std::size_t pos = 0;
    while ((pos = text.find(marker, pos)) != std::string::npos) {
      const bool starts = pos == 0 || text[pos - 1] == '\n';
      std::size_t end = pos + marker.size();
      if (end < text.size() && text[end] == '\r') ++end;
      const bool ends = end == text.size() || text[end] == '\n';
      if (starts && ends) at.push_back(pos);
      pos += marker.size();
    }
    if (at.empty()) throw std::invalid_argument("no line '" + marker + "'");
    if (at.size() > 1) throw std::invalid_argument("the line '" + marker + "' appears twice");
    return at.front();
  };
  const std::string begin = "<!-- experiment " + name + " begin -->";
  const std::string end = "<!-- experiment " + name + " end -->";
  const std::size_t b = find_line(begin);
  const std::size_t en = find_line(end);
  if (en < b) throw std::invalid_argument("'" + end + "' comes before '" + begin + "'");
  const std::size_t after = text.find('\n', b);
  if (after == std::string::npos || after + 1 > en) {
    throw std::invalid_argument("'" + end + "' comes before '" + begin + "'");
  }
  std::string out = text.substr(0, after + 1) + replacement;
  if (!replacement.empty() && replacement.back() != '\n') out += '\n';
  return out + text.substr(en);
}

}  // namespace llsf::study
