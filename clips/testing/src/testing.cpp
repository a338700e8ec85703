// SPDX-License-Identifier: MIT
// FakeSkillRunner and AgentFixture (llsf/clips/testing.h).
#include "llsf/clips/testing.h"

#include <google/protobuf/message.h>

namespace llsf::clips {

void FakeSkillRunner::exec(std::string_view skill_string) {
  current_ = std::string(skill_string);
  calls_.push_back(current_);
  status_ = SkillStatus::kRunning;
  error_.clear();
  result_.clear();
}

void FakeSkillRunner::stop() {
  ++stops_;
  status_ = SkillStatus::kIdle;
}

void FakeSkillRunner::set_status(SkillStatus status, std::string error) {
  status_ = status;
  error_ = std::move(error);
}

AgentFixture::AgentFixture(AgentConfig config, const comm::MessageRegistry* messages,
                           Blackboard* blackboard) {
  AgentIo io;
  io.blackboard = blackboard;
  io.skills = &skills_;
  io.messages = messages;
  io.broadcast = [this](const google::protobuf::Message& m) {
    std::unique_ptr<google::protobuf::Message> copy(m.New());
    copy->CopyFrom(m);
    sent_.push_back(std::move(copy));
  };
  io.log = [this](const LogRecord& r) { log_.push_back({r.time, r.level, std::string(r.text)}); };
  agent_ = std::make_unique<AgentHost>(std::move(config), std::move(io));
}

AgentFixture::~AgentFixture() = default;

void AgentFixture::load(std::string_view code, std::string_view source_name) {
  agent_->load_string(code, source_name);
}

CycleResult AgentFixture::step(core::SimTime dt) {
  now_ += dt;
  return agent_->cycle(now_);
}

void AgentFixture::steps(int n) {
  for (int i = 0; i < n; ++i) step();
}

bool AgentFixture::has(std::string_view ordered_fact) {
  // Let CLIPS parse the fields: (any-factp ((?f NAME)) (eq ?f:implied (create$ FIELDS))).
  std::string_view body = ordered_fact;
  while (!body.empty() && (body.front() == ' ' || body.front() == '(')) body.remove_prefix(1);
  while (!body.empty() && (body.back() == ' ' || body.back() == ')')) body.remove_suffix(1);
  const auto space = body.find(' ');
  const std::string name(body.substr(0, space));
  const std::string fields(space == std::string_view::npos ? "" : body.substr(space + 1));
  const Value v =
      agent_->eval("(any-factp ((?f " + name + ")) (eq ?f:implied (create$ " + fields + ")))");
  return v.is_symbol("TRUE");
}

bool AgentFixture::logged(std::string_view text) const {
  for (const auto& l : log_)
    if (l.text.find(text) != std::string::npos) return true;
  return false;
}

}  // namespace llsf::clips
