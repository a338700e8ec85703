// SPDX-License-Identifier: MIT
// The LLSF skill library (lua/skills) in the game loop, at the physical and symbolic levels:
// S0 -> S1 at a T1, the P3 chain and its delivery, recycling, exploration, failures.
#include <doctest/doctest.h>

#include <cstdio>
#include <optional>
#include <string>

#include "fixture.h"
#include "llsf/sim/game.h"
#include "llsf/sim/skill_brain.h"

using namespace llsf;
using namespace llsf::sim;

namespace {

struct Outcome {
  lua::SkillStatus status = lua::SkillStatus::kRunning;
  std::string error;
  std::string result;
  double seconds = 0.0;
};

/// Runs `skill_string` on `brain` until it ends or `max_s` pass.
Outcome run_skill(Game& g, SkillBrain& brain, const std::string& skill_string, double max_s) {
  const SimTime start = g.time();
  REQUIRE(brain.exec(skill_string).ok);
  const SimTime end = start + SimTime::from_seconds(max_s);
  while (g.time() < end && brain.engine().status() == lua::SkillStatus::kRunning) g.step();
  Outcome o;
  o.status = brain.engine().status();
  o.error = brain.engine().error();
  o.result = brain.engine().result();
  o.seconds = (g.time() - start).seconds();
  return o;
}

/// Index of a production machine of `type` without a down time starting before `after_s`.
std::optional<int> machine_of_type(const refbox::Refbox& rb, refbox::MachineType type,
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

std::string machine_name(int index) {
  return std::string(kinematic::device_name(core::DeviceId(index)));
}

/// The refbox state of the puck in robot `r`'s holder.
std::optional<refbox::PuckState> held_state(const Game& g, int r) {
  const auto p = g.puck_in_pocket(r);
  if (!p) return std::nullopt;
  return g.refbox().puck_state(*p);
}

}  // namespace

TEST_CASE("the skill library loads at both levels") {
  for (const SkillLevel level : {SkillLevel::kPhysical, SkillLevel::kSymbolic}) {
    GameConfig config = test::small_game(1);
    config.levels.skill = level;
    Game g(config);
    SkillBrain brain(g, 0);
    CHECK(brain.engine().load_errors().empty());
    for (const auto& e : brain.engine().load_errors()) MESSAGE(e);
    CHECK(brain.engine().skills().size() >= 11);
  }
}

TEST_CASE("get_s0 then finish_puck_at a T1: the refbox makes it an S1") {
  for (const SkillLevel level : {SkillLevel::kPhysical, SkillLevel::kSymbolic}) {
    CAPTURE(to_string(level));
    GameConfig config = test::small_game(1, 7);
    config.levels.skill = level;
    Game g(config);
    test::start_phase(g, refbox::GamePhase::kProduction);
    g.step();
    const auto t1 = machine_of_type(g.refbox(), refbox::MachineType::kT1, 200);
    REQUIRE(t1);
    SkillBrain brain(g, 0);
    Outcome o = run_skill(g, brain, "get_s0{}", 120);
    INFO(o.error);
    REQUIRE(o.status == lua::SkillStatus::kFinal);
    REQUIRE(held_state(g, 0) == refbox::PuckState::kS0);
    MESSAGE(std::string(to_string(level)), " get_s0 took ", o.seconds, " s");
    o = run_skill(g, brain, "finish_puck_at{place=\"" + machine_name(*t1) + "\"}", 120);
    INFO(o.error);
    REQUIRE(o.status == lua::SkillStatus::kFinal);
    CHECK(o.result == "DONE");
    CHECK(held_state(g, 0) == refbox::PuckState::kS1);
    MESSAGE(std::string(to_string(level)), " finish_puck_at took ", o.seconds, " s");
  }
}
