// SPDX-License-Identifier: MIT
// Game states, phases, phase-relative game time and the lights of each phase (spec §2.6, §4).
#include <doctest/doctest.h>

#include "fixture.h"
#include "llsf/core/assert.h"

using namespace llsf;
using namespace llsf::refbox;
using namespace llsf::refbox::test;

namespace {

/// Index of the one dark machine among M1..M10, or -1 if none / more than one.
int dark_machine(const Refbox& rb) {
  int dark = -1;
  for (int i = 0; i < kProductionMachineCount; ++i) {
    const Lights l = rb.machine(DeviceId(i)).lights;
    if (l == kAllOff) {
      if (dark >= 0) return -1;
      dark = i;
    } else if (!(l == kAllOn)) {
      return -1;
    }
  }
  return dark;
}

/// Steps until setup game time `s`.
void setup_to(Game& g, double s) {
  while (g.rb.game_time() < SimTime::from_seconds(s)) g.step();
}

}  // namespace

TEST_CASE(
    "INIT -> WAIT_START -> SETUP 300 s -> EXPLORATION 180 s -> PRODUCTION 900 s -> POST_GAME") {
  RefboxConfig cfg = test_config();
  cfg.params.reset();  // drawn from the seed
  Game g(std::move(cfg), 42);
  CHECK(g.rb.state() == GameState::kWaitStart);
  CHECK(g.rb.phase() == GamePhase::kPreGame);
  CHECK_FALSE(g.rb.params().has_value());
  // Nothing runs before the start, whatever the simulated time.
  g.run_s(100);
  CHECK(g.rb.game_time() == SimTime());
  for (int i = 0; i < kDeviceCount; ++i) CHECK(g.rb.machine(DeviceId(i)).lights == kAllOn);

  g.command(command::SetGameState{GameState::kRunning});
  const StepOutput& out = g.step();
  CHECK(out.phase_changed);
  CHECK(out.state_changed);
  CHECK(g.rb.phase() == GamePhase::kSetup);
  REQUIRE(g.rb.params().has_value());
  // The plan is the seed's: the same as drawing from rng.stream("refbox") directly.
  core::RandomStream s = core::Rng(42).stream("refbox");
  CHECK(*g.rb.params() == draw_game_params(s, g.rb.rules()));

  g.run_s(150);
  CHECK(g.rb.game_time() == SimTime::from_sec(150));
  // PAUSED freezes game time.
  g.command(command::SetGameState{GameState::kPaused});
  g.step();
  g.run_s(60);
  CHECK(g.rb.game_time() == SimTime::from_sec(150) + kStep);
  g.command(command::SetGameState{GameState::kRunning});
  g.step();
  g.run_s(149.99);
  CHECK(g.rb.phase() == GamePhase::kExploration);
  CHECK(g.rb.game_time() < SimTime::from_sec(1));
  g.run_s(180);
  CHECK(g.rb.phase() == GamePhase::kProduction);
  CHECK(g.activated.size() == 9);
  g.run_s(899);
  CHECK(g.rb.phase() == GamePhase::kProduction);
  g.run_s(1.5);
  CHECK(g.rb.phase() == GamePhase::kPostGame);
  CHECK(g.rb.state() == GameState::kPaused);
  CHECK(g.attention_contains("Game over"));
  for (int i = 0; i < kDeviceCount; ++i) {
    CHECK(g.rb.machine(DeviceId(i)).lights == L(kBlink, kOff, kOff));
  }
}

TEST_CASE("a training game (no team) and skip_setup go straight to EXPLORATION") {
  RefboxConfig training = test_config();
  training.team.clear();
  Game a(std::move(training));
  a.command(command::SetGameState{GameState::kRunning});
  a.step();
  CHECK(a.rb.phase() == GamePhase::kExploration);

  RefboxConfig skip = test_config();
  skip.skip_setup = true;
  Game b(std::move(skip));
  b.command(command::SetGameState{GameState::kRunning});
  b.step();
  CHECK(b.rb.phase() == GamePhase::kExploration);

  // A team name set by the controller before the start selects SETUP again.
  RefboxConfig none = test_config();
  none.team.clear();
  Game c(std::move(none));
  c.command(command::SetTeamName{"Carologistics"});
  c.command(command::SetGameState{GameState::kRunning});
  c.step();
  CHECK(c.rb.phase() == GamePhase::kSetup);
  CHECK(c.rb.team() == "Carologistics");
}

TEST_CASE("shortened phases and a large step carry the remaining time into the next phase") {
  RefboxConfig cfg = test_config();
  cfg.setup_duration = SimTime::from_sec(10);
  cfg.exploration_duration = SimTime::from_sec(20);
  cfg.production_duration = SimTime::from_sec(30);
  Game g(std::move(cfg));
  g.command(command::SetGameState{GameState::kRunning});
  g.step();
  g.step(SimTime::from_sec(12));
  CHECK(g.rb.phase() == GamePhase::kExploration);
  CHECK(g.rb.game_time() == SimTime::from_sec(2));
  g.step(SimTime::from_sec(18));
  CHECK(g.rb.phase() == GamePhase::kProduction);
  CHECK(g.rb.game_time() == SimTime());
  g.run_s(30);
  CHECK(g.rb.phase() == GamePhase::kPostGame);
  CHECK(g.rb.game_time() == SimTime::from_sec(30));
}

TEST_CASE("SetGamePhase re-initialises the phase; time never goes backwards") {
  Game g(test_config());
  g.start_production();
  g.run_s(5);
  g.enter(M(1), 1);
  g.step();
  CHECK(g.m(M(1)).state == MachineState::kProcessing);
  g.command(command::SetGamePhase{GamePhase::kProduction});
  g.step();
  CHECK(g.rb.game_time() < SimTime::from_ms(20));
  CHECK(g.m(M(1)).puck_under_rfid == puck(1));  // the reader still senses it: processed again
  CHECK_THROWS_AS(g.rb.step(g.now - SimTime::from_sec(1), StepInput{}), core::AssertionError);
}

TEST_CASE("setup lights: a dark spot runs over M1..M10, faster near the end; 90 % warning") {
  Game g(test_config());
  g.command(command::SetGameState{GameState::kRunning});
  g.step();
  REQUIRE(g.rb.phase() == GamePhase::kSetup);
  for (int i = kProductionMachineCount; i < kDeviceCount; ++i) {
    CHECK(g.rb.machine(DeviceId(i)).lights == kAllOn);
  }
  setup_to(g, 0.5);
  CHECK(dark_machine(g.rb) == 0);
  setup_to(g, 1.5);
  CHECK(dark_machine(g.rb) == 1);
  setup_to(g, 12.5);
  CHECK(dark_machine(g.rb) == 2);
  // 1 s ticks up to 240 s (240 ticks), then 0.5 s ticks up to 270 s (60), then 0.25 s.
  setup_to(g, 239.9);
  CHECK(dark_machine(g.rb) == 9);
  setup_to(g, 240.1);
  CHECK(dark_machine(g.rb) == 0);
  setup_to(g, 240.6);
  CHECK(dark_machine(g.rb) == 1);
  CHECK_FALSE(g.attention_contains("Setup phase about to end"));
  setup_to(g, 269.9);
  CHECK(dark_machine(g.rb) == 9);
  setup_to(g, 270.1);
  CHECK(dark_machine(g.rb) == 0);
  CHECK(g.attention_contains("Setup phase about to end"));
  setup_to(g, 270.3);
  CHECK(dark_machine(g.rb) == 1);
  setup_to(g, 270.55);
  CHECK(dark_machine(g.rb) == 2);
}

TEST_CASE("exploration lights: type codes on M1..M10, other devices dark, all off while paused") {
  Game g(test_config());
  g.command(command::SetGamePhase{GamePhase::kExploration});
  g.command(command::SetGameState{GameState::kRunning});
  const StepOutput& out = g.step();
  CHECK(out.lights_changed_mask != 0);
  const GameParams p = test_params();
  for (int i = 0; i < kProductionMachineCount; ++i) {
    CHECK(g.rb.machine(DeviceId(i)).lights == p.light_codes[type_index(p.machine_types[i])]);
  }
  CHECK(g.m(M(3)).lights == L(kOn, kOff, kOff));  // T3 = R in the test plan
  for (int i = kProductionMachineCount; i < kDeviceCount; ++i) {
    CHECK(g.rb.machine(DeviceId(i)).lights == kAllOff);
  }
  CHECK(g.rb.shown_type(M(3)) == "?");
  CHECK(g.rb.shown_type(dev(kD1)) == "DELIVER");
  CHECK(g.rb.exploration_signals().size() == 5);
  g.command(command::SetGameState{GameState::kPaused});
  g.step();
  for (int i = 0; i < kDeviceCount; ++i) CHECK(g.rb.machine(DeviceId(i)).lights == kAllOff);
  g.command(command::SetGameState{GameState::kRunning});
  const StepOutput& back = g.step();
  CHECK(g.m(M(3)).lights == L(kOn, kOff, kOff));
  CHECK((back.lights_changed_mask & 1u << 2) != 0);
  // Production: every device green except inactive gates (red); real types are shown.
  g.command(command::SetGamePhase{GamePhase::kProduction});
  g.step();
  for (int i = 0; i < kDeviceCount; ++i) {
    const bool inactive_gate = i == kD2 || i == kD3;
    CHECK(g.rb.machine(DeviceId(i)).lights ==
          (inactive_gate ? L(kOn, kOff, kOff) : L(kOff, kOff, kOn)));
  }
  CHECK(g.rb.shown_type(M(3)) == "T3");
}

TEST_CASE("blinking is 2 Hz in simulated time") {
  CHECK(blink_phase_on(SimTime()));
  CHECK(blink_phase_on(SimTime::from_ms(249)));
  CHECK_FALSE(blink_phase_on(SimTime::from_ms(250)));
  CHECK_FALSE(blink_phase_on(SimTime::from_ms(499)));
  CHECK(blink_phase_on(SimTime::from_ms(500)));
}
