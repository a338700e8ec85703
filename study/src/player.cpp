// SPDX-License-Identifier: MIT
#include "llsf/study/player.h"

#include <utility>

namespace llsf::study {

namespace {

sim::GameConfig seeded(const Scenario& scenario, std::uint64_t seed) {
  sim::GameConfig config = scenario.game;
  config.seed = seed;
  return config;
}

}  // namespace

sim::AgentBrainConfig agent_config(const Scenario& scenario, const RobotSpec& spec) {
  sim::AgentBrainConfig c;
  c.agent_files = spec.agent;
  c.config = spec.config;
  c.skills = scenario.skills;
  c.locks = spec.locks;
  c.sandbox = spec.sandbox;
  c.fawkes = spec.fawkes;
  c.agent_dir = spec.agent_dir;
  c.start = spec.agent_start;
  return c;
}

std::optional<refbox::GamePhase> start_phase(StartMode start) {
  switch (start) {
    case StartMode::kNone:
      return std::nullopt;
    case StartMode::kExploration:
      return refbox::GamePhase::kExploration;
    case StartMode::kProduction:
      return refbox::GamePhase::kProduction;
    case StartMode::kGame:
      break;
  }
  return refbox::GamePhase::kPreGame;
}

Player::Player(const Scenario& scenario, std::uint64_t seed)
    : scenario_(scenario), driver_(seeded(scenario, seed)) {}

sim::AgentBrain* Player::plug_agent(int index, clips::LogSink log, clips::LockListener locks,
                                    sim::AgentReports reports) {
  const RobotSpec& spec = scenario_.robots.at(static_cast<std::size_t>(index));
  if (spec.agent.empty()) return nullptr;
  return &driver_.plug_agent(index, agent_config(scenario_, spec), std::move(log), std::move(locks),
                             std::move(reports));
}

void Player::plug_agents() {
  for (int i = 0; i < game().robot_count(); ++i) plug_agent(i);
}

sim::SkillBrain& Player::plug_skills(int index, lua::SkillEngineConfig config) {
  return driver_.plug_skills(index, std::move(config));
}

void Player::start() { driver_.start(start_phase(scenario_.start)); }

void Player::start(std::optional<refbox::GamePhase> phase) { driver_.start(phase); }

void Player::observe(Observer observer) { observers_.push_back(std::move(observer)); }

bool Player::play_until(core::SimTime until) {
  return driver_.run_until(until, [this](const sim::Game& game) {
    for (const Observer& o : observers_) {
      if (o(game)) return true;
    }
    return false;
  });
}

}  // namespace llsf::study
