// SPDX-License-Identifier: MIT
// The steady-state step does not allocate: heap allocations inside Refbox::step during a
// PRODUCTION phase of random play happen only in steps that announce something (attention
// messages carry strings) or learn a new puck.
#include <doctest/doctest.h>

#include <cstdlib>
#include <new>

#include "llsf/refbox/random_play.h"
#include "llsf/refbox/refbox.h"

namespace {
bool g_counting = false;
long g_allocations = 0;
}  // namespace

// Counting replacements of the global allocation functions (for this test binary). GCC sees
// free() paired with operator new and warns; here that pairing is the replacement itself.
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"
void* operator new(std::size_t n) {
  if (g_counting) ++g_allocations;
  if (void* p = std::malloc(n == 0 ? 1 : n)) return p;
  throw std::bad_alloc();
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }

using namespace llsf;
using namespace llsf::refbox;

TEST_CASE("Refbox::step allocates only in steps that announce something") {
  RefboxConfig cfg;
  cfg.team = "Carologistics";
  const core::Rng rng(11);
  Refbox rb(cfg, rng);
  RandomPlay play(rng.stream("alloc/play"));
  std::vector<Command> cmds;
  cmds.emplace_back(std::in_place_type<command::SetGamePhase>,
                    command::SetGamePhase{GamePhase::kProduction});
  cmds.emplace_back(std::in_place_type<command::SetGameState>,
                    command::SetGameState{GameState::kRunning});
  std::vector<RfidEvent> rfid;
  std::vector<MachineReport> reports;
  rfid.reserve(16);
  StepInput in;
  in.commands = cmds;
  SimTime now;
  const StepOutput* out = &rb.step(now, in);
  int steps = 0, quiet_steps_allocating = 0, busy_steps = 0, events = 0;
  long busy_allocations = 0;
  while (rb.phase() == GamePhase::kProduction) {
    now += SimTime::from_ms(10);
    play.act(rb, *out, now, rfid, reports);
    events += static_cast<int>(rfid.size());
    in = StepInput{};
    in.rfid = rfid;
    in.insertion_slot_occupied = play.insertion_slot_occupied();
    const std::size_t pucks_before = rb.pucks().size();
    g_allocations = 0;
    g_counting = true;
    out = &rb.step(now, in);
    g_counting = false;
    ++steps;
    const bool busy = !out->attention.empty() || rb.pucks().size() != pucks_before;
    busy_steps += busy;
    if (!busy && g_allocations > 0) ++quiet_steps_allocating;
    if (busy) busy_allocations += g_allocations;
  }
  CHECK(steps >= 90000);
  CHECK(events > 500);
  CHECK(busy_steps < 20);
  CHECK(quiet_steps_allocating == 0);
  CHECK(busy_allocations > 0);  // the counter works
}

TEST_CASE("Refbox::step does not allocate during a whack-a-mole challenge") {
  RefboxConfig cfg;
  cfg.team = "Carologistics";
  Refbox rb(cfg, core::Rng(12));
  std::vector<Command> cmds;
  cmds.emplace_back(std::in_place_type<command::SetGamePhase>,
                    command::SetGamePhase{GamePhase::kWhackAMoleChallenge});
  cmds.emplace_back(std::in_place_type<command::SetGameState>,
                    command::SetGameState{GameState::kRunning});
  StepInput in;
  in.commands = cmds;
  SimTime now;
  rb.step(now, in);
  std::vector<RobotPose> poses(2);
  int steps = 0, quiet_steps_allocating = 0;
  while (rb.phase() == GamePhase::kWhackAMoleChallenge) {
    now += SimTime::from_ms(10);
    // Robot 1 reaches the mole every 2 s; robot 2 stands somewhere else.
    poses[0] = {1, {0.1, 0.1, 0.0}};
    if (steps % 200 == 199 && rb.mole()) poses[0].pose = cfg.device_poses[rb.mole()->value()];
    poses[1] = {2, {0.8, 0.8, 0.0}};
    in = StepInput{};
    in.robot_poses = poses;
    g_allocations = 0;
    g_counting = true;
    const StepOutput& out = rb.step(now, in);
    g_counting = false;
    ++steps;
    if (out.attention.empty() && g_allocations > 0) ++quiet_steps_allocating;
  }
  CHECK(steps == 30000);
  CHECK(rb.points() == 149);  // every 200th step; the 150th falls on the step that ends it
  CHECK(quiet_steps_allocating == 0);
}
