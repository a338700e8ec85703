// SPDX-License-Identifier: MIT
#include "llsf/study/report.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <numeric>
#include <sstream>
#include <tuple>

#include "llsf/core/assert.h"
#include "llsf/core/data_dir.h"
#include "llsf/core/rng.h"
#include "llsf/core/text.h"

namespace llsf::study {

namespace {

std::string fmt(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.4g", v);
  return buf;
}

StatSummary summarize(const std::string& name, std::vector<double> v) {
  StatSummary s;
  s.name = name;
  s.n = static_cast<int>(v.size());
  if (v.empty()) return s;
  std::sort(v.begin(), v.end());
  s.mean = std::accumulate(v.begin(), v.end(), 0.0) / static_cast<double>(v.size());
  s.median = quantile(v, 0.5);
  s.q1 = quantile(v, 0.25);
  s.q3 = quantile(v, 0.75);
  s.min = v.front();
  s.max = v.back();
  return s;
}

}  // namespace

const StatSummary* VariantReport::find(const std::string& name) const {
  for (const StatSummary& s : stats) {
    if (s.name == name) return &s;
  }
  return nullptr;
}

BatchReport make_report(const StatsStore& store, std::int64_t batch_id, std::uint64_t seed) {
  BatchReport r;
  const auto batch = store.batch(batch_id);
  if (!batch) throw StatsError(store.path() + ": no batch " + std::to_string(batch_id));
  r.batch = *batch;
  // Values per variant and statistic (keyed by seed, for pairing), variants in first-stored
  // order.
  std::vector<std::string> order;
  std::map<std::string, std::map<std::string, std::vector<KeyedValue>>> values;
  std::map<std::string, std::pair<int, int>> pass;  // runs, passed
  // Runs by (variant, seed), not in stored order: the order in which workers, array tasks or a
  // merge stored them must not change the bootstrap's resamples (the same report from a local
  // batch and from the same batch played on a cluster).
  std::vector<StoredRun> runs = store.runs(batch_id);
  std::sort(runs.begin(), runs.end(), [](const StoredRun& a, const StoredRun& b) {
    return std::tie(a.variant, a.seed) < std::tie(b.variant, b.seed);
  });
  for (const StoredRun& run : runs) {
    if (values.find(run.variant) == values.end()) order.push_back(run.variant);
    auto& per = values[run.variant];
    const std::string key = "seed=" + std::to_string(run.seed);
    for (const auto& [name, v] : store.statistics(run.id)) per[name].push_back({key, v});
    auto& p = pass[run.variant];
    ++p.first;
    if (run.passed) ++p.second;
  }
  // Name order: the store's order depends on which worker finished first.
  std::sort(order.begin(), order.end());
  for (const std::string& variant : order) {
    VariantReport vr;
    vr.variant = variant;
    vr.runs = pass[variant].first;
    vr.passed = pass[variant].second;
    for (const auto& [name, kv] : values[variant]) {
      std::vector<double> v;
      for (const KeyedValue& x : kv) v.push_back(x.value);
      vr.stats.push_back(summarize(name, v));
    }
    r.variants.push_back(std::move(vr));
  }
  // Differences against the first variant, paired by seed where the seeds are shared.
  if (order.size() < 2) return r;
  // Each difference draws from its own named stream: a statistic added to the store (or a
  // variant) changes no other difference's interval.
  const core::Rng streams(seed);
  const auto& base = values[order.front()];
  for (std::size_t i = 1; i < order.size(); ++i) {
    const auto& other = values[order[i]];
    for (const auto& [name, b] : base) {
      const auto it = other.find(name);
      if (it == other.end() || b.empty() || it->second.empty()) continue;
      Difference d;
      d.variant = order[i];
      d.baseline = order.front();
      d.statistic = name;
      core::RandomStream rng = streams.stream("report/" + order[i] + "/" + name);
      d.comparison = compare_means(it->second, b, rng);
      d.diff = d.comparison.diff;
      d.ci_low = d.comparison.ci.low;
      d.ci_high = d.comparison.ci.high;
      r.differences.push_back(std::move(d));
    }
  }
  // Holm per statistic: its comparisons (each variant against the first) are one family.
  std::map<std::string, std::vector<std::size_t>> family;
  for (std::size_t k = 0; k < r.differences.size(); ++k) {
    family[r.differences[k].statistic].push_back(k);
  }
  for (const auto& [name, members] : family) {
    std::vector<double> p;
    for (const std::size_t k : members) p.push_back(r.differences[k].comparison.p_value);
    const std::vector<bool> rejected = holm(p);
    for (std::size_t j = 0; j < members.size(); ++j) {
      Difference& d = r.differences[members[j]];
      d.comparisons = static_cast<int>(members.size());
      d.separated = rejected[j] && d.comparison.enough;
    }
  }
  return r;
}

namespace {
/// A CSV field in double quotes, quotes inside doubled (RFC 4180).
std::string csv_quoted(const std::string& field) {
  std::string out = "\"";
  for (const char c : field) {
    if (c == '"') out += '"';
    out += c;
  }
  return out + "\"";
}
}  // namespace

std::string to_csv(const BatchReport& r) {
  std::string out = "variant,statistic,n,mean,median,q1,q3,min,max,pass_rate,runs\n";
  for (const VariantReport& v : r.variants) {
    const double rate = v.runs > 0 ? static_cast<double>(v.passed) / v.runs : 0.0;
    for (const StatSummary& s : v.stats) {
      out += csv_quoted(v.variant) + "," + s.name + "," + std::to_string(s.n) + "," + fmt(s.mean) +
             "," + fmt(s.median) + "," + fmt(s.q1) + "," + fmt(s.q3) + "," + fmt(s.min) + "," +
             fmt(s.max) + "," + fmt(rate) + "," + std::to_string(v.runs) + "\n";
    }
  }
  return out;
}

namespace {
/// `v` with `digits` decimals as the HTML report shows it (JavaScript's toFixed, Math.round): the
/// nearest, and an exact tie away from zero -- printf would round it to even (2.25 -> "2.2"
/// beside the page's "2.3", 62.5 % -> 62 beside 63).
std::string fixed(double v, int digits) {
  if (std::isfinite(v)) {
    // An exact tie (|v| * 10^digits ends in .5 exactly) is a dyadic |v| = m / 2^(digits+1), m odd.
    const double t = std::ldexp(std::fabs(v), digits + 1);
    if (t < 9007199254740992.0 && t == std::floor(t) && std::fmod(t, 2.0) == 1.0) {
      v = std::nextafter(v, v > 0.0 ? HUGE_VAL : -HUGE_VAL);
    }
  }
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", digits, v);
  return buf;
}

/// The games a difference rests on: "30 pairs", "30 vs 28 games", and the runs left out.
std::string games_text(const Comparison& c) {
  std::string s =
      c.pairing == Pairing::kPaired
          ? "paired by seed: " + std::to_string(c.pairs) + (c.pairs == 1 ? " pair" : " pairs")
          : "unpaired: " + std::to_string(c.n_a) + " vs " + std::to_string(c.n_b) + " games";
  if (c.unmatched > 0) s += ", " + std::to_string(c.unmatched) + " without a partner left out";
  return s;
}

/// "about 40 games per variant would separate a difference of this size" or why not known.
std::string games_needed_text(const Comparison& c) {
  const char* unit = c.pairing == Pairing::kPaired ? " seeds" : " games per variant";
  if (c.games_needed) {
    return "about " + std::to_string(*c.games_needed) + unit +
           " would separate a difference of this size";
  }
  if (!c.se) return std::string("the spread is unknown with one game");
  return std::string("no difference to separate");
}

/// One line of the differences: value, interval, star, and what the runs allow.
std::string difference_line(const Difference& d) {
  const Comparison& c = d.comparison;
  // Rounded as the HTML page rounds (fixed()), no "-0.0".
  auto sign = [](double x) {
    if (x == 0.0) x = 0.0;
    return (x >= 0.0 ? "+" : "") + fixed(x, 1);
  };
  char numbers[96];
  std::snprintf(numbers, sizeof numbers, " %8s  [%s, %s]%s  (", sign(d.diff).c_str(),
                sign(d.ci_low).c_str(), sign(d.ci_high).c_str(), d.separated ? "  *" : "");
  std::string out = d.variant;
  if (out.size() < 28) out.resize(28, ' ');
  out += numbers + games_text(c);
  if (!c.enough) {
    out += "; too few for a verdict, which needs " + std::to_string(kMinGamesForVerdict) + "; " +
           games_needed_text(c);
  } else if (!d.separated && c.games_needed) {
    out += "; " + games_needed_text(c);
  }
  return out + ")\n";
}

}  // namespace

std::string to_text(const BatchReport& r) {
  std::string out = "batch " + std::to_string(r.batch.id) + "  " + r.batch.scenario_name + " (" +
                    r.batch.scenario_file + ")\n\n";
  char line[256];
  std::snprintf(line, sizeof line, "%-28s %5s %6s  %7s %7s %7s %7s %7s %7s\n", "variant", "runs",
                "passed", "mean", "median", "q1", "q3", "min", "max");
  out += line;
  for (const VariantReport& v : r.variants) {
    const StatSummary* p = v.find("points");
    StatSummary none;
    if (p == nullptr) p = &none;
    // The pass rate as the page computes it: pass_rate (passed / runs) times 100.
    const double rate = v.runs > 0 ? static_cast<double>(v.passed) / v.runs * 100.0 : 0.0;
    std::snprintf(line, sizeof line, "%-28s %5d %5s%%  %7s %7s %7s %7s %7s %7s\n",
                  v.variant.empty() ? "(no matrix)" : v.variant.c_str(), v.runs,
                  fixed(rate, 0).c_str(), fixed(p->mean, 1).c_str(), fixed(p->median, 1).c_str(),
                  fixed(p->q1, 1).c_str(), fixed(p->q3, 1).c_str(), fixed(p->min, 0).c_str(),
                  fixed(p->max, 0).c_str());
    out += line;
  }
  bool header = false;
  for (const Difference& d : r.differences) {
    if (d.statistic != "points") continue;
    if (!header) {
      out += "\npoints: difference of means against " + d.baseline +
             " (bootstrap 95 % interval; * separated at 5 % " +
             (d.comparisons > 1
                  ? "after Holm's correction for " + std::to_string(d.comparisons) + " comparisons"
                  : std::string("(one comparison)")) +
             ")\n";
      header = true;
    }
    out += difference_line(d);
  }
  return out;
}

std::vector<RunValues> run_values(const StatsStore& store, std::int64_t batch_id) {
  std::vector<RunValues> out;
  for (const StoredRun& run : store.runs(batch_id)) {
    RunValues v;
    v.variant = run.variant;
    v.seed = run.seed;
    v.passed = run.passed;
    v.result_hash = run.result_hash;
    v.statistics = store.statistics(run.id);
    out.push_back(std::move(v));
  }
  std::sort(out.begin(), out.end(), [](const RunValues& a, const RunValues& b) {
    return a.variant != b.variant ? a.variant < b.variant : a.seed < b.seed;
  });
  return out;
}

namespace {

using Json = nlohmann::ordered_json;  // keys in the order written: a stable, readable file

/// A number, or null if it is not finite (JSON has no NaN or infinity).
Json number(double v) { return std::isfinite(v) ? Json(v) : Json(nullptr); }

std::string hex16(std::uint64_t v) {
  char buf[17];
  std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(v));
  return buf;
}

/// `</script` (any case) would end the inline script early; `<\/script` means the same to
/// JavaScript inside strings and regular expressions, the only places a bundle can hold it.
std::string escape_script_end(const std::string& js) {
  std::string out;
  out.reserve(js.size());
  for (std::size_t i = 0; i < js.size(); ++i) {
    out += js[i];
    if (js[i] != '<' || i + 7 >= js.size() || js[i + 1] != '/') continue;
    std::string word = js.substr(i + 2, 6);
    for (char& c : word) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    if (word == "script") out += '\\';
  }
  return out;
}

constexpr const char* kPageHead = R"(<!DOCTYPE html>
<html lang="en">
<head>
<meta charset="utf-8">
<meta name="viewport" content="width=device-width, initial-scale=1">
<meta name="generator" content="llsfsim report --html">
<title>)";

constexpr const char* kPageStyle = R"(</title>
<style>
body { font: 14px/1.4 system-ui, sans-serif; color: #222; margin: 1.5rem auto; max-width: 1000px;
       padding: 0 1rem; }
h1 { font-size: 1.4rem; margin-bottom: 0.2rem; }
h2 { font-size: 1.1rem; margin-top: 2rem; }
.meta { color: #555; margin-top: 0; }
table { border-collapse: collapse; margin: 0.5rem 0; font-variant-numeric: tabular-nums; }
th, td { padding: 0.2rem 0.6rem; border-bottom: 1px solid #ddd; text-align: right; }
th:first-child, td:first-child { text-align: left; }
thead th { border-bottom: 2px solid #999; }
.significant { font-weight: bold; }
.note { color: #555; font-size: 0.9rem; }
.error { color: #b00; }
</style>
</head>
<body>
<main id="llsf-report"><noscript><pre>)";

}  // namespace

std::string to_json(const BatchReport& r, const std::vector<RunValues>& runs) {
  Json j;
  j["format"] = "llsfsim-report";
  j["format_version"] = 2;
  j["llsfsim_version"] = std::string(llsfsim_version());
  // The batch's identity and metadata; its created/finished times (wall clock) stay out.
  Json batch;
  batch["id"] = r.batch.id;
  batch["kind"] = r.batch.kind;
  batch["scenario_name"] = r.batch.scenario_name;
  batch["scenario_file"] = r.batch.scenario_file;
  batch["scenario_hash"] = r.batch.scenario_hash;
  batch["runs_per_variant"] = r.batch.runs_per_variant;
  batch["variants"] = r.batch.variants;
  batch["seeds"] = r.batch.seeds;
  j["batch"] = std::move(batch);

  Json variants = Json::array();
  for (const VariantReport& v : r.variants) {
    Json jv;
    jv["variant"] = v.variant;
    jv["runs"] = v.runs;
    jv["passed"] = v.passed;
    jv["pass_rate"] = number(v.runs > 0 ? static_cast<double>(v.passed) / v.runs : 0.0);
    Json stats = Json::object();
    for (const StatSummary& s : v.stats) {
      stats[s.name] = Json{{"n", s.n},
                           {"mean", number(s.mean)},
                           {"median", number(s.median)},
                           {"q1", number(s.q1)},
                           {"q3", number(s.q3)},
                           {"min", number(s.min)},
                           {"max", number(s.max)}};
    }
    jv["statistics"] = std::move(stats);
    variants.push_back(std::move(jv));
  }
  j["variants"] = std::move(variants);

  Json differences = Json::array();
  for (const Difference& d : r.differences) {
    const Comparison& c = d.comparison;
    auto optional_number = [](const auto& v) { return v ? number(*v) : Json(nullptr); };
    differences.push_back(Json{{"variant", d.variant},
                               {"baseline", d.baseline},
                               {"statistic", d.statistic},
                               {"diff", number(d.diff)},
                               {"ci_low", number(d.ci_low)},
                               {"ci_high", number(d.ci_high)},
                               {"method", to_string(c.pairing)},
                               {"pairs", c.pairs},
                               {"n_variant", c.n_a},
                               {"n_baseline", c.n_b},
                               {"unmatched", c.unmatched},
                               {"p_value", number(c.p_value)},
                               {"comparisons", d.comparisons},
                               {"enough_games", c.enough},
                               {"separated", d.separated},
                               {"detectable", optional_number(c.detectable)},
                               {"games_needed", c.games_needed ? Json(*c.games_needed) : Json()}});
  }
  j["differences"] = std::move(differences);

  Json jruns = Json::array();
  for (const RunValues& run : runs) {
    Json stats = Json::object();
    for (const auto& [name, value] : run.statistics) stats[name] = number(value);
    jruns.push_back(Json{{"variant", run.variant},
                         {"seed", run.seed},
                         {"passed", run.passed},
                         {"result_hash", hex16(run.result_hash)},
                         {"statistics", std::move(stats)}});
  }
  j["runs"] = std::move(jruns);
  return j.dump(1, ' ', false, Json::error_handler_t::replace) + "\n";
}

std::string viewer_dir() {
  const char* env = std::getenv("LLSF_VIEWER_DIR");
  if (env != nullptr && *env != '\0') return env;
  return core::data_dir() + "/viewer/dist";
}

std::string to_html(const BatchReport& r, const std::string& json, const std::string& dir) {
  const std::string bundle_path = dir + "/report.js";
  std::ifstream in(bundle_path, std::ios::binary);
  std::ostringstream bundle;
  bundle << in.rdbuf();
  if (!in || bundle.str().empty()) {
    throw ViewerBundleMissing("the viewer bundle is missing (run `make viewer`): " + bundle_path +
                              " cannot be read");
  }
  // '<' occurs in JSON only inside strings, where \u003c means the same: no `</script>` and no
  // `<!--` can end or confuse the data block.
  std::string data;
  data.reserve(json.size());
  for (const char c : json) {
    if (c == '<') {
      data += "\\u003c";
    } else {
      data += c;
    }
  }
  std::string page = kPageHead;
  page += core::xml_escape("llsfsim report: " + r.batch.scenario_name + " (batch " +
                           std::to_string(r.batch.id) + ")");
  page += kPageStyle;
  page += core::xml_escape(to_text(r));
  page += "</pre></noscript></main>\n<script id=\"llsf-report-data\" type=\"application/json\">\n";
  page += data;
  page += "</script>\n<script>\n";
  page += escape_script_end(bundle.str());
  page += "\n</script>\n</body>\n</html>\n";
  return page;
}

}  // namespace llsf::study
