// SPDX-License-Identifier: MIT
// llsfsim's installed C++ interface (docs/install.md): load a scenario file, play a game, read
// its result. This header is all a program on the installed package includes: it names no other
// llsfsim header and no dependency's, so the simulator's internals (the world, the game loop,
// the agent host) can change without breaking a program built against it. Within one minor
// version (0.1.z) this interface stays source- and link-compatible.
#pragma once

#include <cstdint>
#include <map>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

namespace llsfsim {

/// The package's version, "0.1.0" (the same as `llsfsim --version` and the CMake package's).
std::string version();

/// Bad input: a scenario, agent or skill file that cannot be used. what() names the file, line
/// and field ("scenario.yaml:12:3: robots.count: must be in [1, 6]"), as the command line does.
class Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct PlayOptions;
struct Result;
class Scenario;
Result play(const Scenario& scenario, std::uint64_t seed, const PlayOptions& options);

/// One variant of a scenario file (docs/scenarios.md), ready to play. Cheap to copy.
class Scenario {
 public:
  /// Loads `file` and expands its matrix: one Scenario per variant, in the file's order. Relative
  /// paths inside it (agents, skills) resolve against the file's folder; the skill library
  /// comes from the data directory (docs/install.md). Throws Error.
  static std::vector<Scenario> load(const std::string& file);

  std::string name() const;
  /// "axis=value,axis=value", or "" for a file without a matrix.
  std::string variant() const;
  /// The seeds the file lists (`seed:` / `seeds:`).
  std::vector<std::uint64_t> seeds() const;
  /// Game time to play, seconds.
  double duration_s() const;
  /// Plays less (or more) game time; throws Error outside the scenario limits.
  void set_duration_s(double seconds);

  struct Impl;  ///< (the library's; opaque)
  explicit Scenario(std::shared_ptr<const Impl> impl);

 private:
  friend Result play(const Scenario& scenario, std::uint64_t seed, const PlayOptions& options);
  std::shared_ptr<const Impl> impl_;
};

/// How to play.
struct PlayOptions {
  /// If set, the game is recorded to this file (docs/recording.md).
  std::string record_path;
};

/// A test case of the scenario (`tests:`) and its verdict.
struct TestResult {
  std::string name;  ///< "points_at_least"
  bool passed = false;
  std::string detail;  ///< "42 points (need >= 30 by 720 s)"
};

/// What a game gave.
struct Result {
  int points = 0;            ///< the refbox's total
  double game_time_s = 0.0;  ///< simulated seconds played
  std::uint64_t hash = 0;    ///< the same seed and scenario give the same hash
  bool passed = false;       ///< every test case held (and, under `strict`, no agent mistake)
  /// Every statistic of docs/statistics.md by its name ("deliveries", "lock_wait_s", ...); one a
  /// game lacks (a first complex product that never came) is left out, not given a value.
  std::map<std::string, double> statistics;
  std::vector<TestResult> tests;
  /// The whole summary as `llsfsim run --json` prints it (docs/llsfsim.md).
  std::string json;
};

/// Plays `scenario` with `seed` (the same pair, the same game). Throws Error for bad agent or
/// skill files, before anything is played.
Result play(const Scenario& scenario, std::uint64_t seed, const PlayOptions& options);
/// The same with the default options.
Result play(const Scenario& scenario, std::uint64_t seed);

}  // namespace llsfsim
