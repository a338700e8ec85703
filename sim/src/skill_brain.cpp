// SPDX-License-Identifier: MIT
#include "llsf/sim/skill_brain.h"

#include <cctype>
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
  if (state_listener_) report_state();
  return r;
}

void SkillBrain::on_skill_cycle(lua::RobotApi& robot) {
  static_cast<void>(robot);
  engine_.cycle();
  report();
  if (state_listener_) report_state();
}

void SkillBrain::report_state() {
  // The first skill of the string: the identifier it starts with.
  const std::string& str = engine_.skill_string();
  std::size_t b = 0;
  while (b < str.size() && std::isspace(static_cast<unsigned char>(str[b])) != 0) ++b;
  std::size_t e = b;
  while (e < str.size() && (std::isalnum(static_cast<unsigned char>(str[e])) != 0 || str[e] == '_'))
    ++e;
  const std::string_view skill(str.data() + b, e - b);
  std::string st = skill.empty() ? std::string() : engine_.skill_state(skill);
  // A string that ended resets its skills: its end is the state then.
  const lua::SkillStatus status = engine_.status();
  if (st.empty() && (status == lua::SkillStatus::kFinal || status == lua::SkillStatus::kFailed))
    st = lua::to_string(status);
  auto emit = [&](std::string from, std::string to, std::string via = {}) {
    SkillStateChange c;
    c.time = game_.time();
    c.robot = std::string(game_.robot(index_).name());
    c.skill = std::string(skill);
    c.from = std::move(from);
    c.to = std::move(to);
    c.via = std::move(via);
    state_listener_(c);
  };
  // Every state a step went through, also within one cycle (GO -> NEXT -> GO is not "nothing").
  if (!skill.empty() && skill == state_skill_) {
    lua::SkillEngine::StatePath p = engine_.skill_state_path(skill, state_via_);
    if (p.step != state_step_ && p.states.size() >= 2) {
      if (p.states.front() != state_) emit(state_, p.states.front());  // e.g. the start state
      for (std::size_t i = 1; i < p.states.size(); ++i) {
        emit(p.states[i - 1], p.states[i], i - 1 < p.via.size() ? std::move(p.via[i - 1]) : "");
      }
      state_ = p.states.back();
    }
    state_step_ = p.step;
  }
  if (st == state_ && (skill == state_skill_ || st.empty())) {
    if (skill != state_skill_) state_skill_ = std::string(skill);  // a new string, no state yet
    return;
  }
  emit(skill == state_skill_ ? state_ : std::string(), st);
  state_skill_ = std::string(skill);
  state_ = std::move(st);
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
  if (s == lua::SkillStatus::kFailed) {
    c.error = engine_.error();
    c.reason = engine_.fail_reason();
  }
  c.result = engine_.result();
  listener_(c);
}

}  // namespace llsf::sim
