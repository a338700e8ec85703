// SPDX-License-Identifier: MIT
// Testing agents without the world: a scripted SkillRunner and a fixture that owns an AgentHost,
// collects its log and broadcasts, and steps simulated time. See docs/clips.md ("Testing rules").
#pragma once

#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "llsf/clips/agent.h"

namespace llsf::clips {

/// A SkillRunner whose status the test sets. Records every exec() and stop().
class FakeSkillRunner final : public SkillRunner {
 public:
  void exec(std::string_view skill_string) override;
  void stop() override;
  SkillStatus status() const override { return status_; }
  std::string error() const override { return error_; }
  std::string skill_string() const override { return current_; }
  std::string result() const override { return result_; }

  /// Sets what status() and error() report from now on.
  void set_status(SkillStatus status, std::string error = {});
  /// Sets what result() reports from now on (e.g. "DONE").
  void set_result(std::string result) { result_ = std::move(result); }
  /// Every skill string passed to exec(), in order.
  const std::vector<std::string>& calls() const { return calls_; }
  int stops() const { return stops_; }

 private:
  SkillStatus status_ = SkillStatus::kIdle;
  std::string error_, current_, result_;
  std::vector<std::string> calls_;
  int stops_ = 0;
};

/// A log line kept by the fixture.
struct LoggedLine {
  core::SimTime time;
  LogLevel level = LogLevel::kInfo;
  std::string text;
};

/// An agent with a FakeSkillRunner, collected log and broadcasts, and a clock. Time starts at 0;
/// step() advances it by one agent period (100 ms) and runs one cycle.
class AgentFixture {
 public:
  /// `messages` (optional, borrowed) enables pb-create and the protobuf-msg type ids.
  /// `blackboard` (optional, borrowed) is the robot's blackboard (AgentIo::blackboard).
  explicit AgentFixture(AgentConfig config = {}, const comm::MessageRegistry* messages = nullptr,
                        Blackboard* blackboard = nullptr);
  ~AgentFixture();
  AgentFixture(const AgentFixture&) = delete;
  AgentFixture& operator=(const AgentFixture&) = delete;

  AgentHost& agent() { return *agent_; }
  FakeSkillRunner& skills() { return skills_; }

  /// Loads code; throws AgentLoadError like AgentHost::load_string().
  void load(std::string_view code, std::string_view source_name = "test.clp");
  void load_file(const std::string& path) { agent_->load_file(path); }
  /// Asserts a fact from text, e.g. "(machine (name M1) (mtype T1))".
  void assert_fact(std::string_view fact) { agent_->assert_fact(fact); }
  /// Advances time by `dt` and runs one cycle.
  CycleResult step(core::SimTime dt = core::SimTime::from_ms(100));
  /// Runs `n` cycles.
  void steps(int n);
  core::SimTime now() const { return now_; }

  /// Facts of a template, optionally filtered by slot values.
  std::vector<Fact> facts(std::string_view template_name) const {
    return agent_->facts(template_name);
  }
  std::vector<Fact> find(std::string_view template_name,
                         std::initializer_list<std::pair<std::string_view, Value>> where) const {
    return agent_->find_facts(template_name, where);
  }
  /// True if an ordered fact with exactly these fields exists, e.g. has("(state IDLE)").
  bool has(std::string_view ordered_fact);

  /// Everything the agent logged.
  const std::vector<LoggedLine>& log() const { return log_; }
  /// True if some log line contains `text`.
  bool logged(std::string_view text) const;
  /// Messages the agent broadcast (copies).
  std::vector<std::unique_ptr<google::protobuf::Message>>& sent() { return sent_; }

 private:
  FakeSkillRunner skills_;
  std::vector<LoggedLine> log_;
  std::vector<std::unique_ptr<google::protobuf::Message>> sent_;
  core::SimTime now_;
  std::unique_ptr<AgentHost> agent_;
};

}  // namespace llsf::clips
