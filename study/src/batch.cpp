// SPDX-License-Identifier: MIT
#include "llsf/study/batch.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <filesystem>
#include <map>
#include <set>
#include <string_view>
#include <utility>

#include "llsf/core/error.h"
#include "llsf/study/pool.h"
#include "llsf/study/recording.h"

namespace llsf::study {

namespace {

struct Job {
  const Scenario* scenario;
  std::uint64_t seed;
};

std::string seeds_budget() {
  return std::to_string(ScenarioLimits::kMaxSeeds) +
         " seeds per variant (docs/security.md, \"Scenario budgets\")";
}

// One seed of --seeds: decimal digits only, at most 2^63-1.
std::uint64_t parse_seed(std::string_view item, std::string_view whole) {
  constexpr std::uint64_t kMax = 0x7fff'ffff'ffff'ffffULL;
  auto bad = [&](const std::string& why) {
    return core::ConfigError("--seeds " + std::string(whole) + ": '" + std::string(item) + "' " +
                             why);
  };
  if (item.empty()) throw bad("is empty (expected a seed or a range A-B)");
  std::uint64_t v = 0;
  for (const char c : item) {
    if (c < '0' || c > '9') throw bad("is not a seed (digits, or A-B)");
    const auto d = static_cast<std::uint64_t>(c - '0');
    if (v > (kMax - d) / 10) throw bad("is too large (at most 9223372036854775807)");
    v = v * 10 + d;
  }
  return v;
}

std::string hex16(std::uint64_t v) {
  static constexpr char kDigits[] = "0123456789abcdef";
  std::string out(16, '0');
  for (int i = 15; i >= 0; --i, v >>= 4) out[static_cast<std::size_t>(i)] = kDigits[v & 0xf];
  return out;
}

}  // namespace

std::vector<std::uint64_t> parse_seed_list(std::string_view text) {
  std::vector<std::uint64_t> out;
  std::set<std::uint64_t> seen;
  std::size_t pos = 0;
  for (;;) {
    const std::size_t comma = text.find(',', pos);
    const std::string_view item =
        text.substr(pos, comma == std::string_view::npos ? std::string_view::npos : comma - pos);
    const std::size_t dash = item.find('-');
    if (dash == 0) {  // not a range with its first seed missing: a negative seed
      throw core::ConfigError("--seeds " + std::string(text) + ": '" + std::string(item) +
                              "' is negative: a seed is a whole number from 0 (a range is A-B)");
    }
    std::uint64_t first = 0;
    std::uint64_t last = 0;
    if (dash == std::string_view::npos) {
      first = last = parse_seed(item, text);
    } else {
      first = parse_seed(item.substr(0, dash), text);
      last = parse_seed(item.substr(dash + 1), text);
      if (last < first) {
        throw core::ConfigError("--seeds " + std::string(text) + ": '" + std::string(item) +
                                "' is an empty range (A-B needs A <= B)");
      }
    }
    if (last - first >= static_cast<std::uint64_t>(ScenarioLimits::kMaxSeeds) ||
        out.size() + (last - first + 1) > static_cast<std::size_t>(ScenarioLimits::kMaxSeeds)) {
      throw core::ConfigError("--seeds " + std::string(text) + ": more than " + seeds_budget());
    }
    for (std::uint64_t v = first;; ++v) {
      if (!seen.insert(v).second) {
        throw core::ConfigError("--seeds " + std::string(text) + ": seed " + std::to_string(v) +
                                " is given twice");
      }
      out.push_back(v);
      if (v == last) break;
    }
    if (comma == std::string_view::npos) break;
    pos = comma + 1;
  }
  return out;
}

std::vector<std::uint64_t> batch_seeds(const Scenario& s, const SeedChoice& choice) {
  if (!choice.seeds.empty()) {
    if (choice.runs) throw core::ConfigError("give either --runs or --seeds, not both");
    if (choice.seeds.size() > static_cast<std::size_t>(ScenarioLimits::kMaxSeeds)) {
      throw core::ConfigError("--seeds: more than " + seeds_budget());
    }
    return choice.seeds;
  }
  if (!choice.runs) return s.seeds;
  const int n = *choice.runs;
  if (n < 1) throw core::ConfigError("--runs must be at least 1");
  if (n > ScenarioLimits::kMaxSeeds) {
    throw core::ConfigError("--runs " + std::to_string(n) + ": at most " + seeds_budget());
  }
  if (static_cast<std::size_t>(n) <= s.seeds.size()) return {s.seeds.begin(), s.seeds.begin() + n};
  // Beyond the scenario's list: the seeds after its largest, counting up. Deterministic (a
  // function of the list alone) and never one of the list's seeds.
  std::vector<std::uint64_t> out = s.seeds;
  std::uint64_t next = *std::max_element(s.seeds.begin(), s.seeds.end()) + 1;
  while (out.size() < static_cast<std::size_t>(n)) out.push_back(next++);
  return out;
}

std::vector<std::uint64_t> batch_seeds(const Scenario& s, std::optional<int> runs) {
  return batch_seeds(s, SeedChoice{runs, {}});
}

std::int64_t batch_games(const ScenarioFile& file, const SeedChoice& choice) {
  std::int64_t games = 0;
  for (const Scenario& s : file.variants) {
    games += static_cast<std::int64_t>(batch_seeds(s, choice).size());
  }
  if (games > ScenarioLimits::kMaxGames) {
    const std::string per = !choice.seeds.empty()
                                ? " x --seeds (" + std::to_string(choice.seeds.size()) + " seeds)"
                            : choice.runs ? " x --runs " + std::to_string(*choice.runs)
                                          : " x their seeds";
    throw core::ConfigError(file.file + ": " + std::to_string(file.variants.size()) + " variants" +
                            per + " = " + std::to_string(games) + " games: at most " +
                            std::to_string(ScenarioLimits::kMaxGames) +
                            " (docs/security.md, \"Scenario budgets\")");
  }
  return games;
}

std::int64_t batch_games(const ScenarioFile& file, std::optional<int> runs) {
  return batch_games(file, SeedChoice{runs, {}});
}

std::vector<BatchPair> batch_pairs(const ScenarioFile& file, const SeedChoice& choice) {
  (void)batch_games(file, choice);  // within the budget
  std::vector<std::vector<std::uint64_t>> seeds;
  std::size_t most = 0;
  for (const Scenario& s : file.variants) {
    seeds.push_back(batch_seeds(s, choice));
    most = std::max(most, seeds.back().size());
  }
  std::vector<BatchPair> out;
  for (std::size_t i = 0; i < most; ++i) {
    for (std::size_t v = 0; v < file.variants.size(); ++v) {
      if (i < seeds[v].size()) out.push_back({static_cast<int>(v), seeds[v][i]});
    }
  }
  return out;
}

BatchKey batch_key(const ScenarioFile& file, const std::string& scenario_hash,
                   const SeedChoice& choice) {
  if (file.variants.empty()) throw core::ConfigError(file.file + ": no variants");
  BatchKey key;
  key.kind = BatchKey::Kind::kBatch;
  key.scenario_file = file.file;
  key.scenario_name = file.variants.front().name;
  key.scenario_hash = scenario_hash;
  key.seeds = batch_seeds(file.variants.front(), choice);
  key.runs_per_variant = static_cast<int>(key.seeds.size());
  key.variants = static_cast<int>(file.variants.size());
  if (!choice.seeds.empty()) {
    // --seeds that equal `--runs N`'s seeds for every variant are that batch.
    const SeedChoice as_runs{static_cast<int>(choice.seeds.size()), {}};
    const bool default_seeds =
        std::all_of(file.variants.begin(), file.variants.end(),
                    [&](const Scenario& s) { return batch_seeds(s, as_runs) == choice.seeds; });
    if (!default_seeds) {
      std::uint64_t h = 0xcbf29ce484222325ULL;  // FNV-1a 64 over the seeds' 8 bytes each (LE)
      for (std::uint64_t seed : choice.seeds) {
        for (int b = 0; b < 8; ++b, seed >>= 8) {
          h ^= seed & 0xff;
          h *= 0x100000001b3ULL;
        }
      }
      key.scenario_hash += "+seeds-" + hex16(h);
    }
  }
  return key;
}

bool BatchResult::all_passed() const {
  return std::all_of(variants.begin(), variants.end(),
                     [](const VariantSummary& v) { return v.passed == v.runs; });
}

std::vector<VariantSummary> summarize(const std::vector<StoredRun>& runs,
                                      const std::vector<std::string>& variant_order) {
  std::map<std::string, std::vector<const StoredRun*>> by_variant;
  for (const StoredRun& r : runs) by_variant[r.variant].push_back(&r);
  std::vector<std::string> order;
  for (const std::string& v : variant_order) {
    if (by_variant.contains(v)) order.push_back(v);
  }
  for (const auto& [v, list] : by_variant) {
    if (std::find(order.begin(), order.end(), v) == order.end()) order.push_back(v);
  }
  std::vector<VariantSummary> out;
  for (const std::string& v : order) {
    const auto& list = by_variant[v];
    VariantSummary s;
    s.variant = v;
    s.runs = static_cast<int>(list.size());
    std::vector<int> points;
    double sum = 0.0;
    for (const StoredRun* r : list) {
      points.push_back(r->points);
      sum += r->points;
      s.passed += r->passed ? 1 : 0;
    }
    std::sort(points.begin(), points.end());
    const std::size_t n = points.size();
    s.mean_points = sum / static_cast<double>(n);
    s.median_points = n % 2 == 1 ? points[n / 2] : 0.5 * (points[n / 2 - 1] + points[n / 2]);
    s.min_points = points.front();
    s.max_points = points.back();
    out.push_back(s);
  }
  return out;
}

BatchResult run_batch(const ScenarioFile& file, const std::string& scenario_hash, StatsStore& store,
                      const BatchOptions& options, const BatchHooks& hooks) {
  if (file.variants.empty()) throw core::ConfigError(file.file + ": no variants");
  if (options.jobs < 0) throw core::ConfigError("--jobs must be at least 1");
  SeedChoice choice = options.choice;
  if (options.runs) {
    if (choice.runs && *choice.runs != *options.runs) {
      throw core::ConfigError("BatchOptions: runs and choice.runs differ");
    }
    choice.runs = options.runs;
  }
  const std::vector<BatchPair> pairs = batch_pairs(file, choice);  // within the budget
  const BatchKey key = batch_key(file, scenario_hash, choice);
  const auto n_pairs = static_cast<std::int64_t>(pairs.size());
  const std::int64_t begin = std::clamp<std::int64_t>(options.slice_begin, 0, n_pairs);
  const std::int64_t end =
      options.slice_end < 0 ? n_pairs : std::clamp<std::int64_t>(options.slice_end, begin, n_pairs);
  const bool sliced = begin > 0 || end < n_pairs;

  BatchResult result;
  result.batch_id = store.open_batch(key);
  std::set<std::pair<std::string, std::uint64_t>> stored;
  for (auto& k : store.run_keys(result.batch_id)) stored.insert(std::move(k));
  std::vector<Job> jobs;
  for (std::int64_t k = begin; k < end; ++k) {
    const BatchPair& p = pairs[static_cast<std::size_t>(k)];
    ++result.total;
    const Scenario& s = file.variants[static_cast<std::size_t>(p.variant)];
    if (stored.contains({s.variant, p.seed}) ||
        options.stored_elsewhere.contains({s.variant, p.seed})) {
      ++result.skipped;
    } else {
      jobs.push_back({&s, p.seed});
    }
  }

  std::string record_dir;
  if (!options.recordings_dir.empty() && !jobs.empty()) {
    const std::filesystem::path d =
        std::filesystem::path(options.recordings_dir) /
        ("batch" + std::to_string(options.recordings_batch_id > 0 ? options.recordings_batch_id
                                                                  : result.batch_id));
    std::error_code ec;
    std::filesystem::create_directories(d, ec);
    if (ec) {
      throw core::ConfigError("cannot create the recordings directory " + d.string() + ": " +
                              ec.message());
    }
    record_dir = d.string();
  }

  // The pool's workers play the jobs in order; this thread stores each result as it arrives
  // (one transaction per run).
  std::atomic<bool> stop_workers{false};
  const auto t0 = std::chrono::steady_clock::now();  // progress only, never a game input
  BatchProgress progress;
  progress.to_play = static_cast<int>(jobs.size());
  play_on_pool<RunResult>(
      jobs.size(), options.jobs,
      [&](std::size_t j) {
        RunHooks run_hooks;
        run_hooks.record_agents = options.record_agents;
        if (!record_dir.empty()) {
          run_hooks.record_path =
              (std::filesystem::path(record_dir) /
               recording_file_name(jobs[j].scenario->name, jobs[j].scenario->variant, jobs[j].seed))
                  .string();
        }
        RunResult r = run_game(*jobs[j].scenario, jobs[j].seed, run_hooks);
        // Stop here, not only when the result is stored: the storing thread may lag behind a
        // worker that plays short games, which would then play them all.
        if (options.fail_fast && r.agent_error()) stop_workers = true;
        return r;
      },
      [&](std::size_t, RunResult& r) {
        store.add_run(result.batch_id, r);  // throws: the pool stops and joins
        ++result.played;
        ++progress.done;
        progress.failed += r.passed() ? 0 : 1;
        if (options.fail_fast && !result.agent_error && r.agent_error()) {
          result.agent_error =
              (r.variant.empty() ? "" : r.variant + " ") + "seed " + std::to_string(r.seed);
          stop_workers = true;  // no new game; the running ones finish and are stored
        }
        progress.elapsed_s =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        if (hooks.stored) hooks.stored(r, progress);
      },
      [&] { return stop_workers.load() || (hooks.stop && hooks.stop->load()); });

  result.interrupted = !result.complete();
  if (result.complete() && !sliced && options.stored_elsewhere.empty()) {
    store.finish_batch(result.batch_id);
  }
  std::vector<std::string> order;
  for (const Scenario& s : file.variants) order.push_back(s.variant);
  result.variants = summarize(store.runs(result.batch_id), order);
  return result;
}

}  // namespace llsf::study
