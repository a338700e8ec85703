// SPDX-License-Identifier: MIT
// Production machines, recycling units and the test station (spec §2.1–§2.5, §8 down times).
#include <doctest/doctest.h>

#include "fixture.h"

using namespace llsf;
using namespace llsf::refbox;
using namespace llsf::refbox::test;

namespace {

/// Puts puck `p` under machine `d`'s reader, waits `s` seconds, and takes it away again.
void process(Game& g, DeviceId d, int p, double s) {
  g.enter(d, p);
  g.step();
  g.run_s(s);
  g.leave(d, p);
  g.step();
}

int award_count(const Game& g, AwardReason r) {
  int n = 0;
  for (const auto& a : g.awards) n += a.reason == r;
  return n;
}

}  // namespace

TEST_CASE("a full T3 production from S0/S1/S2 consumes the right pucks and scores 4 + 12") {
  Game g(test_config());
  g.start_production();
  REQUIRE(g.rb.phase() == GamePhase::kProduction);
  REQUIRE(g.m(M(1)).type == MachineType::kT1);

  // T1 (4 s): S0 -> S1, for pucks 1 and 2; T1 gives no points but the completion is recorded.
  g.enter(M(1), 1);
  g.step();
  CHECK(g.m(M(1)).state == MachineState::kProcessing);
  CHECK(g.m(M(1)).lights == L(kOff, kOn, kOn));
  g.run_s(3.9);
  CHECK(g.state_of(1) == PuckState::kS0);
  g.run_s(0.2);
  CHECK(g.state_of(1) == PuckState::kS1);
  CHECK(g.m(M(1)).state == MachineState::kIdle);
  CHECK(g.m(M(1)).lights == L(kOff, kOff, kOn));
  g.leave(M(1), 1);
  g.step();
  process(g, M(1), 2, 4.1);
  CHECK(g.state_of(2) == PuckState::kS1);
  CHECK(award_count(g, AwardReason::kMachineCompleted) == 2);
  CHECK(g.award_sum() == 0);

  // T2 (S0 + S1, 20 s): S0 first takes the 2 s intermediate time, then WAITING.
  g.enter(M(2), 3);
  g.step();
  CHECK(g.m(M(2)).state == MachineState::kProcessing);
  g.run_s(2.05);
  CHECK(g.m(M(2)).state == MachineState::kWaiting);
  CHECK(g.m(M(2)).lights == L(kOff, kOn, kOff));
  REQUIRE(g.m(M(2)).loaded_count == 1);
  CHECK(g.m(M(2)).loaded[0] == puck(3));
  g.leave(M(2), 3);
  g.step();
  CHECK(g.m(M(2)).state == MachineState::kWaiting);
  g.enter(M(2), 2);
  g.step();
  CHECK(g.m(M(2)).state == MachineState::kProcessing);
  g.run_s(19.9);
  CHECK(g.state_of(2) == PuckState::kS1);
  g.run_s(0.2);
  CHECK(g.state_of(2) == PuckState::kS2);
  CHECK(g.state_of(3) == PuckState::kConsumed);
  CHECK(g.m(M(2)).loaded_count == 0);
  CHECK(g.m(M(2)).state == MachineState::kIdle);
  CHECK(g.award_sum() == 4);
  g.leave(M(2), 2);
  g.step();

  // T3 (S0 + S1 + S2, 50 s) with pucks 4 (S0), 1 (S1), 2 (S2).
  process(g, M(3), 4, 2.05);
  CHECK(g.m(M(3)).state == MachineState::kWaiting);
  process(g, M(3), 1, 2.05);
  CHECK(g.m(M(3)).loaded_count == 2);
  g.enter(M(3), 2);
  g.step();
  g.run_s(49.9);
  CHECK(g.m(M(3)).state == MachineState::kProcessing);
  g.run_s(0.2);
  CHECK(g.state_of(2) == PuckState::kP1);
  CHECK(g.state_of(4) == PuckState::kConsumed);
  CHECK(g.state_of(1) == PuckState::kConsumed);
  CHECK(g.m(M(3)).state == MachineState::kIdle);
  CHECK(g.m(M(3)).loaded_count == 0);
  CHECK(g.award_sum() == 16);
  const PointsAward& last = g.awards.back();
  CHECK(last.points == 12);
  CHECK(last.reason == AwardReason::kMachineCompleted);
  CHECK(last.device == M(3));
  CHECK(last.puck == puck(2));
  CHECK(last.phase == GamePhase::kProduction);
  // Untouched pucks stay S0.
  CHECK(g.state_of(5) == PuckState::kS0);
  CHECK(g.rb.points() == 16);
}

TEST_CASE("wrong inputs make a machine INVALID until the puck is removed") {
  Game g(test_config());
  g.start_production();
  // S0 into... T1 gets an S1? First make an S1 at M1, then put it into M6 (T1).
  process(g, M(1), 1, 4.1);
  REQUIRE(g.state_of(1) == PuckState::kS1);
  g.enter(M(6), 1);
  g.step();
  CHECK(g.m(M(6)).state == MachineState::kInvalid);
  CHECK(g.m(M(6)).lights == L(kOff, kBlink, kOff));
  g.run_s(10);
  CHECK(g.state_of(1) == PuckState::kS1);  // an invalid input is not transformed
  g.leave(M(6), 1);
  g.step();
  CHECK(g.m(M(6)).state == MachineState::kIdle);

  // A duplicate input state: T2 loaded with an S0 rejects a second S0.
  process(g, M(2), 2, 2.05);
  REQUIRE(g.m(M(2)).state == MachineState::kWaiting);
  g.enter(M(2), 3);
  g.step();
  CHECK(g.m(M(2)).state == MachineState::kInvalid);
  g.leave(M(2), 3);
  g.step();
  CHECK(g.m(M(2)).state == MachineState::kWaiting);  // the loaded S0 is still there
  CHECK(g.state_of(3) == PuckState::kS0);
  CHECK(g.award_sum() == 0);
}

TEST_CASE("junk rule: a puck still registered at another machine is consumed") {
  Game g(test_config());
  g.start_production();
  // Puck 1 becomes an intermediate input of M2 (T2) and is then carried to M7 (also T2).
  process(g, M(2), 1, 2.05);
  REQUIRE(g.m(M(2)).loaded_count == 1);
  g.enter(M(7), 1);
  g.step();
  CHECK(g.m(M(7)).state == MachineState::kInvalid);
  CHECK(g.m(M(7)).lights == L(kOff, kBlink, kOff));
  CHECK(g.state_of(1) == PuckState::kConsumed);
  CHECK(g.m(M(2)).loaded_count == 0);
  CHECK(g.m(M(2)).state == MachineState::kIdle);
  g.leave(M(7), 1);
  g.step();
  CHECK(g.m(M(7)).state == MachineState::kIdle);
  // The consumed carrier can be recycled: R1, 2 s, +3 points (0.6.1).
  g.enter(dev(kR1), 1);
  g.step();
  CHECK(g.m(dev(kR1)).state == MachineState::kProcessing);
  g.run_s(2.05);
  CHECK(g.state_of(1) == PuckState::kS0);
  CHECK(g.m(dev(kR1)).state == MachineState::kIdle);
  REQUIRE(!g.awards.empty());
  CHECK(g.awards.back().reason == AwardReason::kRecycled);
  CHECK(g.awards.back().points == 3);
  // A non-CONSUMED puck at a recycler is invalid.
  g.leave(dev(kR1), 1);
  g.enter(dev(kR2), 2);
  g.step();
  CHECK(g.m(dev(kR2)).state == MachineState::kInvalid);
  CHECK(g.m(dev(kR2)).lights == L(kOff, kBlink, kOff));
}

TEST_CASE("removing the puck during processing aborts the step without points") {
  Game g(test_config());
  g.start_production();
  g.enter(M(5), 1);  // T5: S0 -> P3 in 30 s
  g.step();
  g.run_s(20);
  g.leave(M(5), 1);
  g.step();
  CHECK(g.m(M(5)).state == MachineState::kIdle);
  g.run_s(20);
  CHECK(g.state_of(1) == PuckState::kS0);
  // An intermediate removed before its 2 s is not loaded.
  g.enter(M(4), 2);
  g.step();
  g.run_s(1);
  g.leave(M(4), 2);
  g.step();
  g.run_s(2);
  CHECK(g.m(M(4)).loaded_count == 0);
  CHECK(g.m(M(4)).state == MachineState::kIdle);
}

TEST_CASE("a down time during processing pushes the end back by the whole down time") {
  RefboxConfig cfg = test_config();
  cfg.params->down_times = {{M(5), 10, 70}, {dev(kR1), 5, 35}};
  Game g(std::move(cfg));
  g.start_production();
  g.enter(M(5), 1);  // T5, 30 s: would end at ~30 s; down 10..70 pushes it to ~90 s
  g.step();
  g.run_to_game_time(10.005);
  CHECK(g.m(M(5)).state == MachineState::kDown);
  CHECK(g.m(M(5)).lights == L(kOn, kOff, kOff));
  CHECK(g.m(M(5)).state_before_down == MachineState::kProcessing);
  g.run_to_game_time(69.99);
  CHECK(g.m(M(5)).state == MachineState::kDown);
  g.run_to_game_time(70.005);
  CHECK(g.m(M(5)).state == MachineState::kProcessing);
  CHECK(g.m(M(5)).lights == L(kOff, kOn, kOn));
  g.run_to_game_time(89.9);
  CHECK(g.state_of(1) == PuckState::kS0);
  g.run_to_game_time(90.1);
  CHECK(g.state_of(1) == PuckState::kP3);
  CHECK(g.m(M(5)).state == MachineState::kIdle);
  // The recycler went down 5..35 and came back IDLE.
  CHECK(g.m(dev(kR1)).state == MachineState::kIdle);
  bool r1_was_down = false;
  for (const auto& h : g.rb.report().machine_history) {
    r1_was_down = r1_was_down || (h.device == dev(kR1) && h.to == MachineState::kDown);
  }
  CHECK(r1_was_down);
}

TEST_CASE("pucks placed on a DOWN machine wait; removal while down changes the saved state") {
  RefboxConfig cfg = test_config();
  cfg.params->down_times = {{M(1), 5, 20}, {M(2), 5, 20}};
  Game g(std::move(cfg));
  g.start_production();
  // M2 (T2) gets an intermediate S0 before its down time.
  process(g, M(2), 3, 2.05);
  REQUIRE(g.m(M(2)).state == MachineState::kWaiting);
  g.run_to_game_time(6);
  CHECK(g.m(M(1)).state == MachineState::kDown);
  CHECK(g.m(M(2)).state_before_down == MachineState::kWaiting);
  g.enter(M(1), 1);
  g.step();
  g.run_s(5);
  CHECK(g.m(M(1)).state == MachineState::kDown);
  CHECK_FALSE(g.m(M(1)).puck_under_rfid.valid());
  CHECK(g.state_of(1) == PuckState::kS0);
  // Up again at 20 s: the puck still lying there is processed.
  g.run_to_game_time(20.02);
  CHECK(g.m(M(1)).state == MachineState::kProcessing);
  g.run_to_game_time(24.1);
  CHECK(g.state_of(1) == PuckState::kS1);
  CHECK(g.m(M(2)).state == MachineState::kWaiting);
}

TEST_CASE("the test station shows puck states in every phase") {
  Game g(test_config());
  // PRE_GAME: no puck -> all on; with a puck -> the puck's code.
  CHECK(g.m(dev(kTst)).lights == kAllOn);
  g.enter(dev(kTst), 1);
  g.step();
  CHECK(g.m(dev(kTst)).lights == L(kOff, kOn, kOff));  // S0: yellow
  g.leave(dev(kTst), 1);
  g.step();
  CHECK(g.m(dev(kTst)).lights == kAllOn);
  g.start_production();
  CHECK(g.m(dev(kTst)).lights == L(kOff, kOff, kOn));
  process(g, M(1), 1, 4.1);   // S1
  process(g, M(5), 2, 30.1);  // P3
  g.enter(dev(kTst), 1);
  g.step();
  CHECK(g.m(dev(kTst)).lights == L(kOn, kOn, kOff));
  g.leave(dev(kTst), 1);
  g.enter(dev(kTst), 2);
  g.step();
  CHECK(g.m(dev(kTst)).lights == L(kBlink, kOff, kOff));
  g.leave(dev(kTst), 2);
  g.step();
  CHECK(g.m(dev(kTst)).lights == L(kOff, kOff, kOn));
  // The test station never changes a puck.
  CHECK(g.state_of(2) == PuckState::kP3);
}

TEST_CASE("LoadPuckInMachine and RemovePuckFromMachine (controller)") {
  Game g(test_config());
  g.start_production();
  // Load an S0 into M2 (T2), then place an S1 made at M1: completes with +4.
  g.command(command::LoadPuck{M(2), puck(3)});
  g.step();
  CHECK(g.m(M(2)).state == MachineState::kWaiting);
  CHECK(g.m(M(2)).loaded_count == 1);
  // Removing it from the loaded list consumes it.
  g.command(command::RemovePuck{M(2), puck(3)});
  g.step();
  CHECK(g.m(M(2)).loaded_count == 0);
  CHECK(g.m(M(2)).state == MachineState::kIdle);
  CHECK(g.state_of(3) == PuckState::kConsumed);
  // Loading the single input of a T1 completes it at once (T1: 0 points, recorded).
  g.command(command::LoadPuck{M(1), puck(4)});
  g.step();
  CHECK(g.state_of(4) == PuckState::kS1);
  CHECK(g.awards.back().reason == AwardReason::kMachineCompleted);
  // Place = an RFID placement.
  g.command(command::PlacePuck{M(6), puck(5)});
  g.step();
  CHECK(g.m(M(6)).state == MachineState::kProcessing);
  // SetPucks replaces the list (a puck still under a reader is learned again as S0).
  g.command(command::SetPucks{{100, 101}});
  g.step();
  CHECK(g.rb.pucks().size() == 3);
  CHECK(g.state_of(5) == PuckState::kS0);
  CHECK(g.m(M(6)).state == MachineState::kProcessing);
  g.command(command::RemovePuck{M(6), puck(5)});
  g.command(command::SetPucks{{100, 101}});
  g.step();
  CHECK(g.rb.pucks().size() == 2);
  CHECK(g.state_of(100) == PuckState::kS0);
}

TEST_CASE("a puck moving between two readers within one step is never at both") {
  Game g(test_config());
  g.start_production();
  g.enter(M(2), 1);
  g.step();
  g.run_s(2.05);  // loaded in M2 (T2), still under its reader
  REQUIRE(g.m(M(2)).loaded_count == 1);
  // The world reports "entered M1" before "left M2" in the same step: the removal at M2 is seen
  // first, then M1 applies the junk rule because the puck is still in M2's loaded list.
  g.enter(M(1), 1);
  g.leave(M(2), 1);
  g.step();
  CHECK(g.m(M(2)).puck_under_rfid != puck(1));
  CHECK(g.m(M(1)).puck_under_rfid == puck(1));
  CHECK(g.m(M(1)).state == MachineState::kInvalid);
  CHECK(g.m(M(2)).loaded_count == 0);
  CHECK(g.state_of(1) == PuckState::kConsumed);
  // A plain S0 moving from the (idle) test station to M1 in one step is processed normally.
  g.leave(M(1), 1);
  g.enter(dev(kTst), 2);
  g.step();
  g.enter(M(1), 2);
  g.leave(dev(kTst), 2);
  g.step();
  CHECK(g.m(M(1)).state == MachineState::kProcessing);
}

TEST_CASE("unknown puck ids: learned as S0 (PLC) or ignored") {
  Game a(test_config());
  a.start_production();
  a.enter(M(1), 77);
  a.step();
  CHECK(a.state_of(77) == PuckState::kS0);
  CHECK(a.m(M(1)).state == MachineState::kProcessing);
  RefboxConfig cfg = test_config();
  cfg.learn_unknown_pucks = false;
  Game b(std::move(cfg));
  b.start_production();
  b.enter(M(1), 77);
  b.step();
  CHECK_FALSE(b.rb.puck_state(PuckId(77)).has_value());
  CHECK(b.m(M(1)).state == MachineState::kIdle);
  CHECK(a.rb.state_hash() != b.rb.state_hash());
}

TEST_CASE("machines do nothing outside PRODUCTION + RUNNING; a paused production freezes them") {
  Game g(test_config());
  g.enter(M(1), 1);
  g.step();
  CHECK(g.m(M(1)).state == MachineState::kIdle);
  CHECK_FALSE(g.m(M(1)).puck_under_rfid.valid());
  g.start_production();  // the puck still lies there: processed now
  CHECK(g.m(M(1)).state == MachineState::kProcessing);
  g.run_s(2);
  g.command(command::SetGameState{GameState::kPaused});
  g.step();
  g.run_s(10);
  CHECK(g.state_of(1) == PuckState::kS0);
  CHECK(g.m(M(1)).state == MachineState::kProcessing);
  g.command(command::SetGameState{GameState::kRunning});
  g.step();
  g.run_s(2.1);
  CHECK(g.state_of(1) == PuckState::kS1);
}
