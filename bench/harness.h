// SPDX-License-Identifier: MIT
// A small benchmark harness: named benchmarks that print one JSON object per result line,
// {"bench": "...", "metric": "...", "value": N, "unit": "..."}. Times are CPU time of the process.
#pragma once

#include <functional>
#include <string>
#include <vector>

namespace llsf::bench {

/// Prints one result line.
void report(const std::string& bench, const std::string& metric, double value,
            const std::string& unit);

/// CPU seconds used by this process so far (CLOCK_PROCESS_CPUTIME_ID).
double cpu_seconds();

/// The tree whose agents and scenarios the game benchmarks play: $LLSF_BENCH_TREE if set (e.g. a
/// `git worktree` of an older commit, to measure the agents' code before and after a change with
/// the same binary, in one run), else the source tree this was built from.
std::string tree();

/// Runs `body` `repeats` times and returns the median of the values it returns.
double median_of(int repeats, const std::function<double()>& body);

struct Registration {
  Registration(const char* name, const char* description, std::function<void()> fn);
};

}  // namespace llsf::bench

/// Registers a benchmark function `void fn()` under `name` (static initialisation).
#define LLSF_BENCH(name, description)                                           \
  static void llsf_bench_##name();                                              \
  static ::llsf::bench::Registration llsf_bench_reg_##name(#name, description,  \
                                                           &llsf_bench_##name); \
  static void llsf_bench_##name()
