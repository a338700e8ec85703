// SPDX-License-Identifier: MIT
#include "llsf/sim/agent_brain.h"

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <utility>

namespace llsf::sim {

std::vector<std::string> agent_files(const std::vector<std::string>& entries) {
  std::vector<std::string> out;
  for (const std::string& e : entries) {
    std::error_code ec;
    if (!std::filesystem::is_directory(e, ec)) {
      out.push_back(e);
      continue;
    }
    std::vector<std::string> dir;
    for (const auto& f : std::filesystem::directory_iterator(e, ec)) {
      if (f.is_regular_file() && f.path().extension() == ".clp") dir.push_back(f.path().string());
    }
    std::sort(dir.begin(), dir.end());
    out.insert(out.end(), dir.begin(), dir.end());
  }
  return out;
}

AgentBrain::AgentBrain(Game& game, int index, AgentBrainConfig config, clips::LogSink log,
                       clips::LockListener locks) {
  skills_ = std::make_unique<SkillBrain>(game, index, std::move(config.skills));
  const RobotStack& stack = game.robot(index);
  clips::AgentConfig ac;
  ac.robot_name = std::string(stack.name());
  ac.robot_number = game.config().world.robots.at(static_cast<std::size_t>(index)).jersey_or(index);
  ac.team_name = !config.team.empty()          ? config.team
                 : !game.config().team.empty() ? game.config().team
                                               : game.config().refbox.team;
  core::RandomStream seed = game.rng().stream("clips/" + ac.robot_name);
  ac.seed = seed.next_u64();
  ac.max_rules_per_cycle = config.max_rules_per_cycle;
  ac.config = std::move(config.config);
  if (config.locks) {
    ac.locks = true;
    ac.lock_config.team_size =
        config.lock_team_size > 0 ? config.lock_team_size : game.robot_count();
    std::erase_if(ac.config,
                  [](const clips::ConfigEntry& e) { return e.path == "/clips-agent/use-locks"; });
    ac.config.push_back(clips::ConfigEntry::of("/clips-agent/use-locks", true));
  }
  clips::AgentIo io;
  io.skills = this;
  io.messages = &game.registry();
  RobotRadio* radio = &game.robot(index).radio();
  io.broadcast = [radio](const google::protobuf::Message& m) { radio->broadcast(m); };
  io.log = std::move(log);
  io.lock_events = std::move(locks);
  agent_ = std::make_unique<clips::AgentHost>(std::move(ac), std::move(io));
  for (const std::string& f : agent_files(config.agent_files)) {
    try {
      agent_->load_file(f);
    } catch (const clips::AgentLoadError& e) {
      // The lock template exists only with the lock protocol on: name the switch.
      const std::string what = e.what();
      std::ifstream in(f, std::ios::binary);
      const std::string text{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
      if (!config.locks && (what.find("deftemplate lock") != std::string::npos ||
                            text.find("(lock (") != std::string::npos)) {
        throw clips::AgentLoadError(
            what +
            "\nhint: the agent uses the host's lock facts, which exist only with the lock "
            "protocol on: set `robots.locks: true` in the scenario (docs/locks.md)");
      }
      throw;
    }
  }
}

AgentBrain::~AgentBrain() = default;

void AgentBrain::on_skill_cycle(lua::RobotApi& robot) { skills_->on_skill_cycle(robot); }

void AgentBrain::on_agent_cycle(lua::RobotApi& robot, RobotRadio& radio) {
  const lua::PoseEstimate pose = robot.pose();
  if (pose.valid) agent_->set_pose(pose.pose);
  for (Received& r : radio.inbox()) {
    if (r.message) agent_->receive(std::move(r.message), r.from, r.from_id, r.at);
  }
  agent_->cycle(robot.now());
}

void AgentBrain::exec(std::string_view skill_string) { skills_->exec(skill_string); }
void AgentBrain::stop() { skills_->engine().stop(); }

clips::SkillStatus AgentBrain::status() const {
  switch (skills_->engine().status()) {
    case lua::SkillStatus::kInactive:
      return clips::SkillStatus::kIdle;
    case lua::SkillStatus::kRunning:
      return clips::SkillStatus::kRunning;
    case lua::SkillStatus::kFinal:
      return clips::SkillStatus::kFinal;
    case lua::SkillStatus::kFailed:
      return clips::SkillStatus::kFailed;
  }
  return clips::SkillStatus::kIdle;
}
std::string AgentBrain::error() const { return skills_->engine().error(); }
std::string AgentBrain::skill_string() const { return skills_->engine().skill_string(); }
std::string AgentBrain::result() const { return skills_->engine().result(); }

}  // namespace llsf::sim
