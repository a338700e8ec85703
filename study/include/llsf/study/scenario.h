// SPDX-License-Identifier: MIT
// Scenario: a YAML file that says which game to play -- seeds, refbox rules and phases, robots
// with their agents and skill level, radio, abstraction levels, rates, end, test cases -- and a
// matrix of variants a batch expands. docs/scenarios.md documents every key.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "llsf/clips/config_values.h"
#include "llsf/core/config.h"
#include "llsf/core/sim_time.h"
#include "llsf/lua/skill_engine.h"
#include "llsf/sim/game_config.h"
#include "llsf/study/metrics.h"

namespace llsf::study {

/// One robot's brain: its agent files and configuration (empty agent: no brain, it stands).
struct RobotSpec {
  std::vector<std::string> agent;  ///< files or directories, resolved against the scenario's dir
  clips::ConfigEntries config;     ///< confval facts (under /clips-agent)
  bool locks = false;              ///< the lock protocol (robots.locks)
  bool sandbox = true;             ///< the agents' sandbox (robots.sandbox, docs/security.md)
  /// A Fawkes-style agent (robots.agent: {fawkes: DIR, entry: FILE}, docs/fawkes.md): `agent` is
  /// its entry file, `agent_dir` the directory it may read (Fawkes' clips-dirs).
  bool fawkes = false;
  std::string agent_dir;
  std::vector<std::string> proto_dirs;  ///< its own .proto directories (also in game.agent_protos)
  /// Game time at which the robot's agent starts cycling (robots.each[i].agent_start_s): robots
  /// whose software was switched on one after the other.
  core::SimTime agent_start;
};

/// A pass/fail condition on a finished game: a metric against a limit (the metric table's test
/// cases, metrics.h: points_at_least, deliveries_at_least, collisions_at_most, ...), or no
/// agent error (no_agent_errors: no runtime error and no halted agent).
struct TestCase {
  std::string name;
  /// The metric judged, with its test_key and bound; nullptr: no_agent_errors.
  const Metric* metric = nullptr;
  double value = 0.0;          ///< the limit
  std::optional<double> by_s;  ///< game time (s since the start) at which it must hold
  bool no_agent_errors() const { return metric == nullptr; }
};

/// How the game starts: the controller's first commands at time 0.
enum class StartMode : std::uint8_t {
  kGame,         ///< SetGameState RUNNING in PRE_GAME: the refbox runs its phases
  kExploration,  ///< SetGamePhase EXPLORATION + RUNNING
  kProduction,   ///< SetGamePhase PRODUCTION + RUNNING
  kNone,         ///< no command: the refbox stays in PRE_GAME (the hackathon's default)
};

/// A fully resolved scenario variant (one matrix cell).
struct Scenario {
  std::string name;
  std::string description;
  std::string file;     ///< the YAML file
  std::string variant;  ///< "" without a matrix, else "axis=value,axis=value"
  std::vector<std::uint64_t> seeds{1};
  sim::GameConfig game;  ///< world, refbox, radio, navigation, levels, rates (seed: the first)
  StartMode start = StartMode::kGame;
  core::SimTime duration;  ///< game time to play
  std::vector<RobotSpec> robots;
  lua::SkillEngineConfig skills;  ///< skill_dirs empty: the library of the skill level
  std::vector<TestCase> tests;
  /// Scenario key `strict` (or `run --strict`): an agent mistake (RunIssue::is_mistake) fails
  /// the run through the test case "strict: no agent mistakes".
  bool strict = false;
};

/// A scenario file: every variant of its matrix (one if it has none), in matrix order.
struct ScenarioFile {
  std::string file;
  std::vector<std::string> axes;  ///< matrix axis names, in file order
  std::vector<Scenario> variants;
};

/// The budgets of a scenario (docs/security.md, "Scenario budgets"): bounds that keep a game
/// and a batch finite and their memory small, whatever a scenario file says.
struct ScenarioLimits {
  static constexpr double kMinDurationS = 1.0;     ///< duration_s: a game plays something
  static constexpr double kMaxDurationS = 3600.0;  ///< duration_s: over twice the longest game
  /// Physics steps of one game (duration / physics step): 3600 s at 1000 Hz.
  static constexpr std::int64_t kMaxPhysicsSteps = 3'600'000;
  static constexpr double kMinPhysicsHz = 10.0;        ///< rates.physics_hz (a step of 100 ms)
  static constexpr double kMaxPhysicsHz = 1000.0;      ///< rates.physics_hz (a step of 1 ms)
  static constexpr double kMinCycleHz = 0.1;           ///< rates.skill_hz and agent_hz
  static constexpr double kMinBeaconPeriodS = 0.01;    ///< rates.beacon_period_s
  static constexpr double kMaxBeaconPeriodS = 60.0;    ///< rates.beacon_period_s
  static constexpr std::int64_t kMaxSeeds = 100'000;   ///< seeds of one variant
  static constexpr std::int64_t kMaxVariants = 1'000;  ///< variants of a matrix
  /// Games of a scenario file or a batch: its variants' seeds summed (`batch --runs` included).
  static constexpr std::int64_t kMaxGames = 100'000;
};

/// Loads and validates a scenario file and expands its matrix. Throws core::ConfigError naming
/// file:line:column and the key for unknown keys, wrong types, impossible values, missing agent
/// files or directories.
ScenarioFile load_scenario(const std::string& path);

/// Reads one scenario from a map with the keys of a scenario file (no `matrix`), e.g. a
/// section of another YAML file (`llsfsim exercise`'s exercise.yaml); relative paths resolve
/// against `file`'s directory. Throws core::ConfigError like load_scenario().
Scenario read_scenario_map(const core::ConfigNode& root, const std::string& file);

/// "points_at_least 30 by 720 s", for reports.
std::string describe(const TestCase& t);

}  // namespace llsf::study
