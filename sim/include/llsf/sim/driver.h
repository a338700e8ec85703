// SPDX-License-Identifier: MIT
// GameDriver: the one way to play a game. It builds the Game from a GameConfig, owns the robots'
// brains (agents, skill engines) and plugs them in, starts the refbox as a controller would, and
// steps the game with a hook after every tick. `llsfsim run` and `batch` (study::run_game),
// `check`, `skill`, `exercise`, the benchmarks and the tests all play through it (above sim
// through study::Player, which sets a scenario's game up and puts its observers on the hook).
#pragma once

#include <functional>
#include <memory>
#include <optional>
#include <vector>

#include "llsf/clips/agent.h"
#include "llsf/lua/skill_engine.h"
#include "llsf/refbox/types.h"
#include "llsf/sim/agent_brain.h"
#include "llsf/sim/game.h"
#include "llsf/sim/skill_brain.h"

namespace llsf::sim {

class GameDriver {
 public:
  /// Builds the game (Game(config): prepare_game_config, then every component). No brains yet:
  /// the robots stand still until plug_*() gives them one. Throws core::ConfigError.
  explicit GameDriver(GameConfig config);
  /// Unplugs the brains, destroys them, then the game.
  ~GameDriver();
  GameDriver(const GameDriver&) = delete;
  GameDriver& operator=(const GameDriver&) = delete;

  Game& game() { return *game_; }
  const Game& game() const { return *game_; }

  /// Builds robot `index`'s CLIPS agent (with the skill engine it drives), owned by the driver,
  /// and plugs it in in place of an earlier brain of that robot. Throws clips::AgentLoadError
  /// for bad agent code, core::ConfigError for a bad skill-engine config.
  AgentBrain& plug_agent(int index, AgentBrainConfig config, clips::LogSink log = {},
                         clips::LockListener locks = {}, AgentReports reports = {});
  /// Builds a skill engine as robot `index`'s brain (no agent: the caller exec()s skill
  /// strings), owned by the driver, and plugs it in. Throws core::ConfigError.
  SkillBrain& plug_skills(int index, lua::SkillEngineConfig config = {});
  /// Plugs a brain of the caller's own (borrowed: it must outlive the driver or be unplugged
  /// with nullptr first). Brains the driver built stay its own (a wrapper may drive them).
  void plug(int index, RobotBrain* brain);
  /// The agent / skill engine the driver built for robot `index`, or nullptr.
  AgentBrain* agent(int index);
  SkillBrain* skills(int index);

  /// Starts the game as a controller would: SetGamePhase(`phase`) + SetGameState(RUNNING)
  /// (Game::start; kPreGame: the refbox runs its phases from PRE_GAME on). nullopt: no command,
  /// the refbox stays in PRE_GAME (the hackathon's default).
  void start(std::optional<refbox::GamePhase> phase);

  /// Called after every tick; return true to stop.
  using TickHook = std::function<bool(const Game&)>;
  /// Steps the game until its time reaches `until` or `after_tick` asks to stop. Returns true if
  /// the hook stopped it.
  bool run_until(SimTime until, const TickHook& after_tick = {});

 private:
  struct Owned {
    std::unique_ptr<AgentBrain> agent;
    std::unique_ptr<SkillBrain> skills;
  };
  Owned& slot(int index);

  std::unique_ptr<Game> game_;
  std::vector<Owned> brains_;  // by robot index
};

}  // namespace llsf::sim
