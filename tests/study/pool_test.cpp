// SPDX-License-Identifier: MIT
// The one worker pool of games (study/pool.h): `batch` and `exercise --seeds` play on it.
#include <doctest/doctest.h>

#include <atomic>
#include <set>
#include <stdexcept>
#include <thread>
#include <vector>

#include "llsf/study/pool.h"

using namespace llsf::study;

TEST_CASE("play_on_pool: every job once, results handed to the calling thread") {
  const std::thread::id caller = std::this_thread::get_id();
  std::atomic<int> played{0};
  std::vector<int> results(20, -1);
  std::set<std::size_t> seen;
  bool on_caller = true;
  play_on_pool<int>(
      results.size(), 3,
      [&](std::size_t j) {
        ++played;
        return static_cast<int>(j * j);
      },
      [&](std::size_t j, int& r) {
        on_caller = on_caller && std::this_thread::get_id() == caller;
        CHECK(seen.insert(j).second);
        results[j] = r;
      });
  CHECK(played == 20);
  CHECK(on_caller);
  for (std::size_t j = 0; j < results.size(); ++j) CHECK(results[j] == static_cast<int>(j * j));
  // No job: no thread, nothing called.
  play_on_pool<int>(
      0, 4, [](std::size_t) -> int { throw std::logic_error("no job to play"); },
      [](std::size_t, int&) { FAIL("no result to hand"); });
  CHECK(pool_threads(0, 0) == 0);
  CHECK(pool_threads(8, 3) == 3);
  CHECK(pool_threads(2, 100) == 2);
  CHECK(pool_threads(0, 100) >= 1);
}

TEST_CASE("play_on_pool: a stop starts no new job; the running ones are handed over") {
  std::atomic<bool> stop{false};
  int handed = 0;
  std::atomic<int> played{0};
  play_on_pool<int>(
      1000, 2,
      [&](std::size_t j) {
        ++played;
        // The jobs after the fifth wait for the stop: the workers cannot run ahead of it.
        while (j >= 5 && !stop) std::this_thread::yield();
        return 0;
      },
      [&](std::size_t, int&) {
        if (++handed == 5) stop = true;
      },
      [&] { return stop.load(); });
  CHECK(handed >= 5);
  CHECK(handed == played);  // every game played was handed over
  CHECK(played <= 7);       // the five, and at most one more per worker
}

TEST_CASE("play_on_pool: a job's exception stops the pool and is rethrown after the rest") {
  std::atomic<int> played{0};
  int handed = 0;
  CHECK_THROWS_WITH_AS(play_on_pool<int>(
                           100, 2,
                           [&](std::size_t j) {
                             ++played;
                             if (j == 3) throw std::runtime_error("seed 3 failed");
                             return 0;
                           },
                           [&](std::size_t, int&) { ++handed; }),
                       "seed 3 failed", std::runtime_error);
  CHECK(handed == played - 1);  // all but the failed one handed over
  // An exception of `done` propagates; the workers are joined.
  CHECK_THROWS_WITH_AS(play_on_pool<int>(
                           100, 2, [](std::size_t) { return 0; },
                           [](std::size_t, int&) { throw std::runtime_error("store failed"); }),
                       "store failed", std::runtime_error);
}
