// SPDX-License-Identifier: MIT
#include "llsf/study/batch.h"

#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <deque>
#include <exception>
#include <filesystem>
#include <map>
#include <mutex>
#include <set>
#include <thread>
#include <utility>

#include "llsf/core/error.h"
#include "llsf/study/recording.h"

namespace llsf::study {

namespace {

struct Job {
  const Scenario* scenario;
  std::uint64_t seed;
};

// Joins the workers on every way out of run_batch, after asking them to stop.
class WorkerPool {
 public:
  explicit WorkerPool(std::atomic<bool>& stop) : stop_(stop) {}
  ~WorkerPool() {
    stop_ = true;
    join();
  }
  WorkerPool(const WorkerPool&) = delete;
  WorkerPool& operator=(const WorkerPool&) = delete;
  template <class F>
  void spawn(F&& f) {
    threads_.emplace_back(std::forward<F>(f));
  }
  void join() {
    for (std::thread& t : threads_) {
      if (t.joinable()) t.join();
    }
  }

 private:
  std::atomic<bool>& stop_;
  std::vector<std::thread> threads_;
};

}  // namespace

std::vector<std::uint64_t> batch_seeds(const Scenario& s, std::optional<int> runs) {
  if (!runs) return s.seeds;
  const int n = *runs;
  if (n < 1) throw core::ConfigError("--runs must be at least 1");
  if (n > ScenarioLimits::kMaxSeeds) {
    throw core::ConfigError("--runs " + std::to_string(n) + ": at most " +
                            std::to_string(ScenarioLimits::kMaxSeeds) +
                            " seeds per variant (docs/security.md, \"Scenario budgets\")");
  }
  if (s.seeds.size() == 1) {
    std::vector<std::uint64_t> out;
    for (int i = 0; i < n; ++i) out.push_back(s.seeds.front() + static_cast<std::uint64_t>(i));
    return out;
  }
  if (static_cast<std::size_t>(n) > s.seeds.size()) {
    throw core::ConfigError(s.file + ": --runs " + std::to_string(n) + " but the scenario lists " +
                            std::to_string(s.seeds.size()) + " seeds");
  }
  return {s.seeds.begin(), s.seeds.begin() + n};
}

std::int64_t batch_games(const ScenarioFile& file, std::optional<int> runs) {
  std::int64_t games = 0;
  for (const Scenario& s : file.variants) {
    games += static_cast<std::int64_t>(batch_seeds(s, runs).size());
  }
  if (games > ScenarioLimits::kMaxGames) {
    throw core::ConfigError(
        file.file + ": " + std::to_string(file.variants.size()) + " variants x --runs " +
        std::to_string(runs.value_or(0)) + " = " + std::to_string(games) + " games: at most " +
        std::to_string(ScenarioLimits::kMaxGames) + " (docs/security.md, \"Scenario budgets\")");
  }
  return games;
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
  (void)batch_games(file, options.runs);  // within the budget

  // Every (variant, seed), seed-major: an interrupted batch has every variant on its first seeds.
  std::vector<std::vector<std::uint64_t>> seeds;
  std::size_t most = 0;
  for (const Scenario& s : file.variants) {
    seeds.push_back(batch_seeds(s, options.runs));
    most = std::max(most, seeds.back().size());
  }
  BatchKey key;
  key.kind = BatchKey::Kind::kBatch;
  key.scenario_file = file.file;
  key.scenario_name = file.variants.front().name;
  key.scenario_hash = scenario_hash;
  key.runs_per_variant = static_cast<int>(seeds.front().size());
  key.variants = static_cast<int>(file.variants.size());
  key.seeds = seeds.front();

  BatchResult result;
  result.batch_id = store.open_batch(key);
  std::set<std::pair<std::string, std::uint64_t>> stored;
  for (auto& k : store.run_keys(result.batch_id)) stored.insert(std::move(k));
  std::vector<Job> jobs;
  for (std::size_t i = 0; i < most; ++i) {
    for (std::size_t v = 0; v < file.variants.size(); ++v) {
      if (i >= seeds[v].size()) continue;
      ++result.total;
      const Scenario& s = file.variants[v];
      if (stored.contains({s.variant, seeds[v][i]})) {
        ++result.skipped;
      } else {
        jobs.push_back({&s, seeds[v][i]});
      }
    }
  }

  std::string record_dir;
  if (!options.recordings_dir.empty() && !jobs.empty()) {
    const std::filesystem::path d =
        std::filesystem::path(options.recordings_dir) / ("batch" + std::to_string(result.batch_id));
    std::error_code ec;
    std::filesystem::create_directories(d, ec);
    if (ec) {
      throw core::ConfigError("cannot create the recordings directory " + d.string() + ": " +
                              ec.message());
    }
    record_dir = d.string();
  }

  // Workers take jobs in order and queue their results; this thread stores them.
  struct Done {
    RunResult result;
  };
  std::mutex mutex;
  std::condition_variable ready;
  std::deque<Done> queue;
  std::exception_ptr error;
  std::atomic<bool> stop_workers{false};
  std::atomic<std::size_t> next{0};
  int running = 0;
  auto stopping = [&] { return stop_workers.load() || (hooks.stop && hooks.stop->load()); };

  const int hardware = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  const int threads =
      std::min(options.jobs > 0 ? options.jobs : hardware, static_cast<int>(jobs.size()));
  const auto t0 = std::chrono::steady_clock::now();  // progress only, never a game input
  BatchProgress progress;
  progress.to_play = static_cast<int>(jobs.size());
  {
    WorkerPool pool(stop_workers);
    running = threads;
    for (int w = 0; w < threads; ++w) {
      pool.spawn([&] {
        for (;;) {
          if (stopping()) break;
          const std::size_t j = next++;
          if (j >= jobs.size()) break;
          try {
            RunHooks run_hooks;
            run_hooks.record_agents = options.record_agents;
            if (!record_dir.empty()) {
              run_hooks.record_path = (std::filesystem::path(record_dir) /
                                       recording_file_name(jobs[j].scenario->name,
                                                           jobs[j].scenario->variant, jobs[j].seed))
                                          .string();
            }
            RunResult r = run_game(*jobs[j].scenario, jobs[j].seed, run_hooks);
            const std::lock_guard lock(mutex);
            queue.push_back({std::move(r)});
          } catch (...) {
            const std::lock_guard lock(mutex);
            if (!error) error = std::current_exception();
            stop_workers = true;
          }
          ready.notify_one();
        }
        {
          const std::lock_guard lock(mutex);
          --running;
        }
        ready.notify_one();
      });
    }

    // Store each result as it arrives: one transaction per run.
    for (;;) {
      std::unique_lock lock(mutex);
      ready.wait(lock, [&] { return !queue.empty() || running == 0; });
      if (queue.empty()) break;
      Done d = std::move(queue.front());
      queue.pop_front();
      lock.unlock();
      store.add_run(result.batch_id, d.result);  // throws: the pool stops and joins
      ++result.played;
      ++progress.done;
      progress.failed += d.result.passed() ? 0 : 1;
      progress.elapsed_s =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      if (hooks.stored) hooks.stored(d.result, progress);
    }
    pool.join();
  }
  if (error) std::rethrow_exception(error);

  result.interrupted = !result.complete();
  if (result.complete()) store.finish_batch(result.batch_id);
  std::vector<std::string> order;
  for (const Scenario& s : file.variants) order.push_back(s.variant);
  result.variants = summarize(store.runs(result.batch_id), order);
  return result;
}

}  // namespace llsf::study
