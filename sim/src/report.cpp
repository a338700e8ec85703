// SPDX-License-Identifier: MIT
#include "llsf/sim/report.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <numeric>

#include "llsf/core/rng.h"

namespace llsf::sim {

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

double quantile(const std::vector<double>& sorted, double q) {
  if (sorted.empty()) return 0.0;
  const double h = (static_cast<double>(sorted.size()) - 1.0) * std::clamp(q, 0.0, 1.0);
  const auto lo = static_cast<std::size_t>(std::floor(h));
  const std::size_t hi = std::min(lo + 1, sorted.size() - 1);
  return sorted[lo] + (h - static_cast<double>(lo)) * (sorted[hi] - sorted[lo]);
}

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
  // Values per variant and statistic, variants in first-stored order.
  std::vector<std::string> order;
  std::map<std::string, std::map<std::string, std::vector<double>>> values;
  std::map<std::string, std::pair<int, int>> pass;  // runs, passed
  for (const StoredRun& run : store.runs(batch_id)) {
    if (values.find(run.variant) == values.end()) order.push_back(run.variant);
    auto& per = values[run.variant];
    for (const auto& [name, v] : store.statistics(run.id)) per[name].push_back(v);
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
    for (const auto& [name, v] : values[variant]) vr.stats.push_back(summarize(name, v));
    r.variants.push_back(std::move(vr));
  }
  // Differences of means against the first variant, percentile bootstrap.
  if (order.size() < 2) return r;
  core::RandomStream rng(seed);
  constexpr int kResamples = 2000;
  const auto& base = values[order.front()];
  for (std::size_t i = 1; i < order.size(); ++i) {
    const auto& other = values[order[i]];
    for (const auto& [name, b] : base) {
      const auto it = other.find(name);
      if (it == other.end() || b.empty() || it->second.empty()) continue;
      const std::vector<double>& a = it->second;
      auto mean = [](const std::vector<double>& x) {
        return std::accumulate(x.begin(), x.end(), 0.0) / static_cast<double>(x.size());
      };
      std::vector<double> diffs;
      diffs.reserve(kResamples);
      for (int k = 0; k < kResamples; ++k) {
        double sa = 0.0, sb = 0.0;
        for (std::size_t j = 0; j < a.size(); ++j) {
          sa += a[static_cast<std::size_t>(
              rng.uniform_int(0, static_cast<std::int64_t>(a.size()) - 1))];
        }
        for (std::size_t j = 0; j < b.size(); ++j) {
          sb += b[static_cast<std::size_t>(
              rng.uniform_int(0, static_cast<std::int64_t>(b.size()) - 1))];
        }
        diffs.push_back(sa / static_cast<double>(a.size()) - sb / static_cast<double>(b.size()));
      }
      std::sort(diffs.begin(), diffs.end());
      Difference d;
      d.variant = order[i];
      d.baseline = order.front();
      d.statistic = name;
      d.diff = mean(a) - mean(b);
      d.ci_low = quantile(diffs, 0.025);
      d.ci_high = quantile(diffs, 0.975);
      r.differences.push_back(std::move(d));
    }
  }
  return r;
}

std::string to_csv(const BatchReport& r) {
  std::string out = "variant,statistic,n,mean,median,q1,q3,min,max,pass_rate\n";
  for (const VariantReport& v : r.variants) {
    const double rate = v.runs > 0 ? static_cast<double>(v.passed) / v.runs : 0.0;
    for (const StatSummary& s : v.stats) {
      out += "\"" + v.variant + "\"," + s.name + "," + std::to_string(s.n) + "," + fmt(s.mean) +
             "," + fmt(s.median) + "," + fmt(s.q1) + "," + fmt(s.q3) + "," + fmt(s.min) + "," +
             fmt(s.max) + "," + fmt(rate) + "\n";
    }
  }
  return out;
}

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
    std::snprintf(line, sizeof line, "%-28s %5d %5.0f%%  %7.1f %7.1f %7.1f %7.1f %7.0f %7.0f\n",
                  v.variant.empty() ? "(no matrix)" : v.variant.c_str(), v.runs,
                  v.runs > 0 ? 100.0 * v.passed / v.runs : 0.0, p->mean, p->median, p->q1, p->q3,
                  p->min, p->max);
    out += line;
  }
  bool header = false;
  for (const Difference& d : r.differences) {
    if (d.statistic != "points") continue;
    if (!header) {
      out += "\npoints: difference of means against " + d.baseline + " (bootstrap 95 % interval)\n";
      header = true;
    }
    std::snprintf(line, sizeof line, "%-28s %+8.1f  [%+.1f, %+.1f]%s\n", d.variant.c_str(), d.diff,
                  d.ci_low, d.ci_high, (d.ci_low > 0.0 || d.ci_high < 0.0) ? "  *" : "");
    out += line;
  }
  return out;
}

}  // namespace llsf::sim
