// SPDX-License-Identifier: MIT
// SkillBrain: a robot's skill layer in the game loop -- a lua::SkillEngine over the robot's
// RobotStack, cycled at the game's skill rate, with the LLSF skill library (lua/skills/) at the
// robot's skill level. Agents (or tools such as `llsfsim skill`) send it skill strings.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

#include "llsf/lua/skill_engine.h"
#include "llsf/sim/game.h"

namespace llsf::sim {

/// The skill directories of the LLSF skill library for `level`: `lua/skills` of the source tree
/// (or `library_dir` if not empty), plus its `symbolic/` subdirectory at the symbolic level
/// (whose primitives replace the physical ones of the same name).
std::vector<std::string> skill_library_dirs(SkillLevel level, std::string_view library_dir = {});

/// A change of a skill string's status, for listeners.
struct SkillStatusChange {
  SimTime time;
  std::string robot;
  std::string skill_string;
  lua::SkillStatus status = lua::SkillStatus::kInactive;
  std::string error;  ///< set when FAILED
  /// Why it failed, as data (lua::FailReason; kNone unless FAILED): read this, not `error`.
  lua::FailReason reason = lua::FailReason::kNone;
  std::string result;  ///< what the skills reported when the string ended
};

/// A change of the state of a skill string's first skill (its state machine), for listeners.
struct SkillStateChange {
  SimTime time;
  std::string robot;
  std::string skill;  ///< the skill string's first skill ("rescue" in "rescue{}")
  std::string from;   ///< the state before ("" when the skill was not running)
  std::string to;     ///< the state now ("" when the skill is not running or has no FSM)
  /// With set_state_listener(..., true): what took it from `from` to `to` within the step
  /// (`{"START", "DRIVE", cond=true} at skill.lua:19`, `its sub-skills ended FINAL (final_to)`);
  /// "" otherwise and for changes seen only between steps (a new string, its end).
  std::string via;
};

/// Runs a skill engine as robot `index`'s brain (on_skill_cycle). Its owner plugs it into the
/// game (GameDriver::plug_skills, or Game::set_brain) and unplugs it before destroying it; the
/// game must outlive it.
class SkillBrain final : public RobotBrain {
 public:
  /// `config.skill_dirs` empty: the skill library of the game's skill level. The engine's rate
  /// is the game's skill rate; its `math.random` seed comes from the stream "lua/<robot>".
  /// Throws core::ConfigError for a bad config or a missing skill directory.
  SkillBrain(Game& game, int index, lua::SkillEngineConfig config = {});
  ~SkillBrain() override;
  SkillBrain(const SkillBrain&) = delete;
  SkillBrain& operator=(const SkillBrain&) = delete;

  lua::SkillEngine& engine() { return engine_; }
  const lua::SkillEngine& engine() const { return engine_; }
  /// exec() on the engine, reporting the new status to the listener.
  lua::ExecResult exec(std::string_view skill_string);
  /// Called after every status change of the skill string (RUNNING, FINAL, FAILED, INACTIVE).
  void set_listener(std::function<void(const SkillStatusChange&)> listener) {
    listener_ = std::move(listener);
  }

  /// Called when the state of the skill string's first skill changes (checked after exec() and
  /// every cycle; one query of the engine per cycle, only while a listener is set), once for
  /// every state a step went through. `with_via`: the changes say what took them (`via`).
  void set_state_listener(std::function<void(const SkillStateChange&)> listener,
                          bool with_via = false) {
    state_listener_ = std::move(listener);
    state_via_ = with_via;
  }

  void on_skill_cycle(lua::RobotApi& robot) override;

 private:
  void report();
  void report_state();

  Game& game_;
  int index_;
  lua::SkillEngine engine_;
  std::function<void(const SkillStatusChange&)> listener_;
  lua::SkillStatus last_ = lua::SkillStatus::kInactive;
  std::string last_string_;
  std::function<void(const SkillStateChange&)> state_listener_;
  std::string state_skill_;       ///< the skill whose state was last reported
  std::string state_;             ///< its state as last reported
  std::int64_t state_step_ = -1;  ///< the skill's step whose states were last reported
  bool state_via_ = false;        ///< the listener wants SkillStateChange::via
};

}  // namespace llsf::sim
