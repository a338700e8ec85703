// SPDX-License-Identifier: MIT
#include "llsf/sim/driver.h"

#include <utility>

namespace llsf::sim {

GameDriver::GameDriver(GameConfig config)
    : game_(std::make_unique<Game>(std::move(config))),
      brains_(static_cast<std::size_t>(game_->robot_count())) {}

GameDriver::~GameDriver() {
  for (int i = 0; i < game_->robot_count(); ++i) game_->set_brain(i, nullptr);
  brains_.clear();
  game_.reset();
}

GameDriver::Owned& GameDriver::slot(int index) {
  return brains_.at(static_cast<std::size_t>(index));
}

AgentBrain& GameDriver::plug_agent(int index, AgentBrainConfig config, clips::LogSink log,
                                   clips::LockListener locks, AgentReports reports) {
  Owned& s = slot(index);
  auto brain = std::make_unique<AgentBrain>(*game_, index, std::move(config), std::move(log),
                                            std::move(locks), std::move(reports));
  game_->set_brain(index, brain.get());
  s.skills.reset();
  s.agent = std::move(brain);
  return *s.agent;
}

SkillBrain& GameDriver::plug_skills(int index, lua::SkillEngineConfig config) {
  Owned& s = slot(index);
  auto brain = std::make_unique<SkillBrain>(*game_, index, std::move(config));
  game_->set_brain(index, brain.get());
  s.agent.reset();
  s.skills = std::move(brain);
  return *s.skills;
}

void GameDriver::plug(int index, RobotBrain* brain) {
  static_cast<void>(slot(index));  // (checks the index)
  game_->set_brain(index, brain);
}

AgentBrain* GameDriver::agent(int index) { return slot(index).agent.get(); }
SkillBrain* GameDriver::skills(int index) { return slot(index).skills.get(); }

void GameDriver::start(std::optional<refbox::GamePhase> phase) {
  if (phase) game_->start(*phase);
}

bool GameDriver::run_until(SimTime until, const TickHook& after_tick) {
  while (game_->time() < until) {
    game_->step();
    if (after_tick && after_tick(*game_)) return true;
  }
  return false;
}

}  // namespace llsf::sim
