// SPDX-License-Identifier: MIT
// Game extensions: a variant of the game (the hackathon world, a future rule set) as an object
// that the one game loop calls at fixed points of its tick, in the manner of ARGoS' loop
// functions. An extension owns its own state, draws from its own named random streams and may
// give the robots' skill API what the variant adds; the tick itself is written once, in
// Game::step() (docs/architecture.md, "One tick" and "Adding a variant").
#pragma once

#include <memory>
#include <span>
#include <string_view>
#include <vector>

#include "llsf/core/rng.h"
#include "llsf/core/sim_time.h"
#include "llsf/lua/robot_api.h"
#include "llsf/sim/game_config.h"

namespace llsf::sim {

class Game;

/// What a game extension gives one robot's skill API: the variant interfaces of lua::RobotApi
/// (the Lua interfaces `puck_detector` and `rescue`), which RobotStack forwards to it. Owned by
/// the extension; lives as long as the game.
class RobotAddOn {
 public:
  virtual ~RobotAddOn() = default;
  /// Coloured pucks seen (lua::RobotApi::colour_pucks), valid until the next sensor update.
  virtual std::span<const lua::ColourPuckSighting> colour_pucks() const { return {}; }
  /// The rescue task (lua::RobotApi::rescue), or nullptr.
  virtual const lua::RescueInfo* rescue() const { return nullptr; }
};

/// A variant of the game, called by the Game at fixed points (GameExtension hooks below, in the
/// order of docs/architecture.md "One tick"). One object per game: not shared between games, not
/// copied; called on the game's thread only. Every hook has an empty default.
class GameExtension {
 public:
  virtual ~GameExtension() = default;

  /// A short name for messages ("hackathon").
  virtual std::string_view name() const = 0;

  /// Before anything is built: may change the configuration the game plays (add obstacles,
  /// replace pucks, add planner places) and keep what it drew. Draws only from its own named
  /// streams of `rng` (the scenario seed's Rng). Throws core::ConfigError.
  virtual void setup(GameConfig& config, const core::Rng& rng) {
    (void)config;
    (void)rng;
  }
  /// Once the game is built (world, refbox, radio, planner, robot stacks), before the first tick.
  virtual void on_built(Game& game) { (void)game; }
  /// Tick step 1: at the start of every tick, before the actuators and the world step; `now` is
  /// the time the tick steps to (Game::time() is still the last tick's).
  virtual void pre_step(Game& game, SimTime now) {
    (void)game;
    (void)now;
  }
  /// Tick step 6, after every robot stack has perceived the world: the variant's own sensors
  /// (what it adds to the robots' percepts), before the skills read them in step 7.
  virtual void sense(Game& game, SimTime now) {
    (void)game;
    (void)now;
  }
  /// Tick step 9, after the agents' cycle and before the tick hook (so that a recorder on the
  /// hook sees the extension's state of this tick).
  virtual void post_step(Game& game, SimTime now) {
    (void)game;
    (void)now;
  }
  /// What this extension gives robot `robot`'s skill API, or nullptr (asked once, after
  /// on_built(); at most one extension of a game may answer for a robot).
  virtual const RobotAddOn* robot_add_on(int robot) const {
    (void)robot;
    return nullptr;
  }
};

/// A variant's entry in GameConfig::extensions: its configuration, validated with the game's,
/// and the factory of each game's extension object. Immutable and shared between the copies of a
/// GameConfig (every game makes its own extension from it).
class GameExtensionFactory {
 public:
  virtual ~GameExtensionFactory() = default;
  /// Throws core::ConfigError "game.<field>: reason" for a configuration that does not fit
  /// `config` (called by GameConfig::validate()).
  virtual void validate(const GameConfig& config) const { (void)config; }
  /// A new extension for one game.
  virtual std::unique_ptr<GameExtension> make() const = 0;
};

/// A configuration as a game plays it, with the game's extensions set up: what the Game
/// constructor builds from (prepare_game).
struct PreparedGame {
  GameConfig config;
  std::vector<std::unique_ptr<GameExtension>> extensions;
};

/// Validates `config`, makes its extensions (one per GameConfig::extensions entry, in order) and
/// calls their setup() in that order with the Rng of `config.seed`. Throws core::ConfigError.
PreparedGame prepare_game(GameConfig config);

}  // namespace llsf::sim
