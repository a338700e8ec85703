// SPDX-License-Identifier: MIT
#include "llsf/sim/skill_brain.h"

#include <string>
#include <utility>

#include "llsf/core/data_dir.h"

namespace llsf::sim {

namespace {

lua::SkillEngineConfig with_defaults(lua::SkillEngineConfig c, const Game& game, int index) {
  if (c.skill_dirs.empty()) c.skill_dirs = skill_library_dirs(game.config().levels.skill);
  c.rate_hz = game.config().skill_rate_hz;
  core::RandomStream seed = game.rng().stream("lua/" + std::string(game.robot(index).name()));
  c.random_seed = seed.next_u64();
  return c;
}

}  // namespace

std::vector<std::string> skill_library_dirs(SkillLevel level, std::string_view library_dir) {
  const std::string base =
      library_dir.empty() ? core::data_dir() + "/lua/skills" : std::string(library_dir);
  std::vector<std::string> dirs{base};
  if (level == SkillLevel::kSymbolic) dirs.push_back(base + "/symbolic");
  return dirs;
}

SkillBrain::SkillBrain(Game& game, int index, lua::SkillEngineConfig config)
    : game_(game),
      index_(index),
      engine_(with_defaults(std::move(config), game, index), game.robot(index)) {}

SkillBrain::~SkillBrain() = default;

lua::ExecResult SkillBrain::exec(std::string_view skill_string) {
  lua::ExecResult r = engine_.exec(skill_string);
  last_string_.clear();  // always report the new string
  report();
  return r;
}

void SkillBrain::on_skill_cycle(lua::RobotApi& robot) {
  static_cast<void>(robot);
  engine_.cycle();
  report();
}

void SkillBrain::report() {
  const lua::SkillStatus s = engine_.status();
  if (s == last_ && last_string_ == engine_.skill_string()) return;
  last_ = s;
  last_string_ = engine_.skill_string();
  if (!listener_) return;
  SkillStatusChange c;
  c.time = game_.time();
  c.robot = std::string(game_.robot(index_).name());
  c.skill_string = engine_.skill_string();
  c.status = s;
  if (s == lua::SkillStatus::kFailed) c.error = engine_.error();
  c.result = engine_.result();
  listener_(c);
}

}  // namespace llsf::sim
