// SPDX-License-Identifier: MIT
// The one worker pool of games: `batch` (run_batch) and `exercise --seeds` play their games on
// it. Games are independent and single-threaded (a game shares nothing with another but
// process-wide tables, docs/architecture.md), so a game's result is the same whatever the
// number of threads.
#pragma once

#include <algorithm>
#include <atomic>
#include <condition_variable>
#include <cstddef>
#include <deque>
#include <exception>
#include <functional>
#include <mutex>
#include <thread>
#include <utility>
#include <vector>

namespace llsf::study {

/// Worker threads for `jobs` games at most: `asked` (> 0) or else one per core, never more than
/// the games.
inline int pool_threads(int asked, std::size_t jobs) {
  const int hardware = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  return static_cast<int>(std::min<std::size_t>(asked > 0 ? asked : hardware, jobs));
}

/// Plays jobs 0 .. `jobs`-1 on pool_threads(`threads`, `jobs`) worker threads, which take them
/// in order: `play(j)` runs on a worker and returns job j's result; `done(j, result)` runs on
/// the calling thread as results arrive (in the order they end), so that nothing it prints or
/// stores interleaves. Before taking a job a worker asks `stop` (may be empty; called on the
/// workers): true, and no new job starts -- the running ones finish and are handed to `done`.
/// An exception of `play` stops the pool the same way and is rethrown (the first) after every
/// worker has ended; one of `done` stops the workers, joins them and propagates.
template <class Result>
void play_on_pool(std::size_t jobs, int threads, const std::function<Result(std::size_t)>& play,
                  const std::function<void(std::size_t, Result&)>& done,
                  const std::function<bool()>& stop = {}) {
  std::mutex mutex;
  std::condition_variable ready;
  std::deque<std::pair<std::size_t, Result>> queue;
  std::exception_ptr error;
  std::atomic<bool> stop_workers{false};
  std::atomic<std::size_t> next{0};
  const int n = pool_threads(threads, jobs);
  int running = n;
  // Joins the workers on every way out, after asking them to stop.
  struct Joiner {
    std::atomic<bool>& stop;
    std::vector<std::thread> threads;
    ~Joiner() {
      stop = true;
      for (std::thread& t : threads) {
        if (t.joinable()) t.join();
      }
    }
  } pool{stop_workers, {}};
  for (int w = 0; w < n; ++w) {
    pool.threads.emplace_back([&] {
      for (;;) {
        if (stop_workers || (stop && stop())) break;
        const std::size_t j = next++;
        if (j >= jobs) break;
        try {
          Result r = play(j);
          const std::lock_guard lock(mutex);
          queue.emplace_back(j, std::move(r));
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
  for (;;) {
    std::unique_lock lock(mutex);
    ready.wait(lock, [&] { return !queue.empty() || running == 0; });
    if (queue.empty()) break;
    std::pair<std::size_t, Result> d = std::move(queue.front());
    queue.pop_front();
    lock.unlock();
    done(d.first, d.second);  // throws: the Joiner stops and joins the workers
  }
  for (std::thread& t : pool.threads) t.join();
  if (error) std::rethrow_exception(error);
}

}  // namespace llsf::study
