// SPDX-License-Identifier: MIT
// Shared helpers of the sim tests: small game configs, controller commands, a scripted brain.
#pragma once

#include <doctest/doctest.h>
#include <llsf_msgs/GameState.pb.h>

#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "llsf/refbox/protocol.h"
#include "llsf/sim/game.h"

namespace llsf::test {

/// The 2013 game with `robots` robots (1..3 of the default starts), laser off (faster).
inline sim::GameConfig small_game(int robots, std::uint64_t seed = 7) {
  sim::GameConfig c;
  c.seed = seed;
  c.world.sensors.laser.enabled = false;
  c.world.robots.resize(static_cast<std::size_t>(robots));
  return c;
}

/// Index of a production machine of `type` whose down time (if any) starts after `after_s`.
inline std::optional<int> machine_of_type(const refbox::Refbox& rb, refbox::MachineType type,
                                          int after_s) {
  const auto& params = *rb.params();
  for (int i = 0; i < refbox::kProductionMachineCount; ++i) {
    if (params.machine_types[static_cast<std::size_t>(i)] != type) continue;
    bool early_down = false;
    for (const auto& d : params.down_times) {
      if (d.device.value() == i && d.start_s <= after_s) early_down = true;
    }
    if (!early_down) return i;
  }
  return std::nullopt;
}

/// Controller: switch the refbox to `phase` and start it.
inline void start_phase(sim::Game& g, refbox::GamePhase phase) { g.start(phase); }

/// A brain running a list of skill steps in order: each step is called every skill cycle until
/// it returns true.
class StepBrain : public sim::RobotBrain {
 public:
  using Step = std::function<bool(lua::RobotApi&)>;
  explicit StepBrain(std::vector<Step> steps) : steps_(std::move(steps)) {}
  void on_skill_cycle(lua::RobotApi& robot) override {
    ++skill_cycles;
    if (index < steps_.size() && steps_[index](robot)) ++index;
  }
  void on_agent_cycle(lua::RobotApi&, sim::RobotRadio& radio) override {
    ++agent_cycles;
    messages += static_cast<int>(radio.inbox().size());
  }
  bool done() const { return index == steps_.size(); }

  std::size_t index = 0;
  int skill_cycles = 0;
  int agent_cycles = 0;
  int messages = 0;

 private:
  std::vector<Step> steps_;
};

/// A step that sends the robot to `place` and waits for the navigator to end; if
/// `must_arrive`, it must arrive.
inline StepBrain::Step go(std::string place, bool forward = false, bool must_arrive = true) {
  auto started = std::make_shared<std::uint64_t>(0);
  return [place, forward, must_arrive, started](lua::RobotApi& r) {
    if (*started == 0) {
      r.goto_place(place, forward);
      *started = r.navigator().goal_id;
      return false;
    }
    const lua::NavState s = r.navigator();
    if (s.status == lua::NavStatus::kRunning) return false;
    INFO(r.name(), " to ", place, ": ", s.error);
    if (must_arrive) CHECK(s.status == lua::NavStatus::kArrived);
    return true;
  };
}

}  // namespace llsf::test
