// SPDX-License-Identifier: MIT
// Player: the one way to set up and play a game above sim. A scenario's robot entry becomes an
// agent configuration in one place (agent_config, the sandbox included); a Player builds the
// game of a scenario and a seed (sim::GameDriver), plugs the robots' brains, starts the refbox
// as the scenario says and plays with observers on the driver's one tick hook. run_game (`run`,
// `batch`), `check`, `skill`, `exercise` and the allocation test all set up and play through it.
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <vector>

#include "llsf/clips/agent.h"
#include "llsf/core/sim_time.h"
#include "llsf/lua/skill_engine.h"
#include "llsf/refbox/types.h"
#include "llsf/sim/agent_brain.h"
#include "llsf/sim/driver.h"
#include "llsf/sim/game.h"
#include "llsf/sim/skill_brain.h"
#include "llsf/study/scenario.h"

namespace llsf::study {

/// The agent configuration of `scenario`'s robot entry `spec` (docs/scenarios.md, `robots`): its
/// agent files, confvals, locks, sandbox, Fawkes layout and start time, and the scenario's skill
/// engine. The one mapping from a robot entry to an agent: every game and check uses it.
sim::AgentBrainConfig agent_config(const Scenario& scenario, const RobotSpec& spec);

/// The refbox phase a scenario's `start` starts the game in (GameDriver::start); nullopt: no
/// command (StartMode::kNone, the refbox stays in PRE_GAME).
std::optional<refbox::GamePhase> start_phase(StartMode start);

/// One game of a scenario with one seed: the driver (its game and the brains it owns), set up
/// and played as every command plays it.
class Player {
 public:
  /// Called after every tick with the game; return true to stop the game after this tick.
  using Observer = std::function<bool(const sim::Game&)>;

  /// Builds `scenario.game` with `seed` (no brains yet; the robots stand still). `scenario`
  /// must outlive the player. Throws core::ConfigError.
  Player(const Scenario& scenario, std::uint64_t seed);
  Player(const Player&) = delete;
  Player& operator=(const Player&) = delete;

  const Scenario& scenario() const { return scenario_; }
  sim::GameDriver& driver() { return driver_; }
  sim::Game& game() { return driver_.game(); }
  const sim::Game& game() const { return driver_.game(); }

  /// Plugs robot `index`'s agent as its robot entry says (agent_config), with the host's sinks;
  /// nullptr (nothing plugged) if the entry names no agent. Throws clips::AgentLoadError for
  /// bad agent code, core::ConfigError for a bad skill-engine config.
  sim::AgentBrain* plug_agent(int index, clips::LogSink log = {}, clips::LockListener locks = {},
                              sim::AgentReports reports = {});
  /// plug_agent() for every robot, without sinks.
  void plug_agents();
  /// Plugs a skill engine configured by `config` as robot `index`'s brain (no agent: the caller
  /// exec()s skill strings). Throws core::ConfigError.
  sim::SkillBrain& plug_skills(int index, lua::SkillEngineConfig config);

  /// Starts the refbox as the scenario's `start` says (start_phase()).
  void start();
  /// Starts the refbox in `phase` (nullopt: no command), whatever the scenario says.
  void start(std::optional<refbox::GamePhase> phase);

  /// Adds an observer: after every tick the observers are called in the order they were added,
  /// until one returns true, which stops the game after that tick.
  void observe(Observer observer);
  /// Plays until the game time reaches `until` or an observer stops it; true if one did. May be
  /// called again to play on.
  bool play_until(core::SimTime until);

 private:
  const Scenario& scenario_;
  sim::GameDriver driver_;
  std::vector<Observer> observers_;
};

}  // namespace llsf::study
