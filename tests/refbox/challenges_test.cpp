// SPDX-License-Identifier: MIT
// The technical-challenge phases (spec §4, §7): OPEN_CHALLENGE, NAVIGATION_CHALLENGE (60 s),
// WHACK_A_MOLE_CHALLENGE (300 s) with its moles, vision poses, referee pause/resume and points.
#include <doctest/doctest.h>

#include <set>

#include "fixture.h"

using namespace llsf;
using namespace llsf::refbox;
using namespace llsf::refbox::test;

namespace {

/// Enters `phase` from PRE_GAME and sets RUNNING in the same step.
void start_challenge(Game& g, GamePhase phase) {
  g.command(command::SetGamePhase{phase});
  g.command(command::SetGameState{GameState::kRunning});
  g.step();
}

/// The pose of device `d` in the default table.
core::Pose2D pose_of(const Game& g, DeviceId d) { return g.rb.config().device_poses[d.value()]; }

int count_reason(const Game& g, AwardReason r) {
  int n = 0;
  for (const PointsAward& a : g.awards) n += a.reason == r;
  return n;
}

/// Puts robot 1 onto the current mole for one step; returns the mole it reached.
DeviceId reach_mole(Game& g) {
  REQUIRE(g.rb.mole().has_value());
  const DeviceId m = *g.rb.mole();
  const core::Pose2D p = pose_of(g, m);
  g.vision(1, p.x, p.y);
  g.step();
  return m;
}

}  // namespace

TEST_CASE("challenge phases: protocol numbers and names") {
  CHECK(static_cast<int>(GamePhase::kOpenChallenge) == 1000);
  CHECK(static_cast<int>(GamePhase::kNavigationChallenge) == 1001);
  CHECK(static_cast<int>(GamePhase::kWhackAMoleChallenge) == 1002);
  CHECK(to_string(GamePhase::kOpenChallenge) == "OPEN_CHALLENGE");
  CHECK(to_string(GamePhase::kNavigationChallenge) == "NAVIGATION_CHALLENGE");
  CHECK(to_string(GamePhase::kWhackAMoleChallenge) == "WHACK_A_MOLE_CHALLENGE");
  CHECK(is_challenge(GamePhase::kWhackAMoleChallenge));
  CHECK_FALSE(is_challenge(GamePhase::kProduction));
  CHECK_FALSE(is_challenge(GamePhase::kPostGame));
}

TEST_CASE("NAVIGATION_CHALLENGE: 60 s of running game time, frozen while paused, then POST_GAME") {
  Game g(test_config());
  g.command(command::SetGamePhase{GamePhase::kNavigationChallenge});
  g.step();
  CHECK(g.rb.phase() == GamePhase::kNavigationChallenge);
  CHECK(g.rb.state() == GameState::kWaitStart);
  CHECK(g.rb.params().has_value());  // left PRE_GAME: parameterised like any game
  CHECK(g.rb.phase_duration(GamePhase::kNavigationChallenge) == SimTime::from_sec(60));
  // Not RUNNING: no game time.
  g.run_s(30);
  CHECK(g.rb.game_time() == SimTime());
  g.command(command::SetGameState{GameState::kRunning});
  g.step();
  g.run_s(20);
  CHECK(g.rb.game_time() == SimTime::from_sec(20));
  // All lamps dark during the challenge (the spec gives them no meaning).
  for (int i = 0; i < kDeviceCount; ++i) CHECK(g.rb.machine(DeviceId(i)).lights == kAllOff);
  g.command(command::SetGameState{GameState::kPaused});
  g.step();
  g.run_s(100);
  CHECK(g.rb.game_time() == SimTime::from_sec(20) + kStep);
  CHECK(g.rb.phase() == GamePhase::kNavigationChallenge);
  g.command(command::SetGameState{GameState::kRunning});
  g.step();  // commands act after the clock: this step adds no game time
  const SimTime resumed = g.now;
  while (g.rb.phase() == GamePhase::kNavigationChallenge) g.step();
  CHECK(g.rb.phase() == GamePhase::kPostGame);
  CHECK(g.rb.state() == GameState::kPaused);
  CHECK(g.rb.game_time() == SimTime::from_sec(60));
  // Exactly 60 s of running time: 20 s + one step before the pause, the rest after it.
  CHECK(g.now - resumed == SimTime::from_sec(40) - kStep);
  CHECK(g.rb.machine(M(1)).lights == L(kBlink, kOff, kOff));
  CHECK(g.awards.empty());
  CHECK(g.rb.points() == 0);
}

TEST_CASE("OPEN_CHALLENGE: untimed, game time stays 0 while RUNNING, no end, dark lamps") {
  Game g(test_config());
  start_challenge(g, GamePhase::kOpenChallenge);
  CHECK(g.rb.state() == GameState::kRunning);
  g.run_s(400);
  CHECK(g.rb.phase() == GamePhase::kOpenChallenge);
  CHECK(g.rb.game_time() == SimTime());
  for (int i = 0; i < kDeviceCount; ++i) CHECK(g.rb.machine(DeviceId(i)).lights == kAllOff);
  // The test station still shows a puck (quirk 6 holds in every phase).
  g.enter(DeviceId(kTst), 3);
  g.step();
  CHECK(g.rb.machine(DeviceId(kTst)).lights == L(kOff, kOn, kOff));
  // The referee ends it by hand.
  g.command(command::SetGamePhase{GamePhase::kPostGame});
  g.step();
  CHECK(g.rb.phase() == GamePhase::kPostGame);
}

TEST_CASE("WHACK_A_MOLE: one lit mole, +1 per machine reached by vision, 300 s, then POST_GAME") {
  Game g(test_config());
  start_challenge(g, GamePhase::kWhackAMoleChallenge);
  REQUIRE(g.rb.mole().has_value());
  const DeviceId first = *g.rb.mole();
  CHECK(is_production_machine(first));
  // The mole is lit (all three lamps), every other device is dark.
  for (int i = 0; i < kDeviceCount; ++i) {
    CHECK(g.rb.machine(DeviceId(i)).lights == (DeviceId(i) == first ? kAllOn : kAllOff));
  }
  const core::Pose2D mp = pose_of(g, first);

  // Outside the 0.65 x 0.65 m box (0.33 m off in x): nothing; a robot at another machine:
  // nothing.
  g.vision(1, mp.x + 0.33, mp.y);
  const DeviceId other = DeviceId((first.value() + 1) % kProductionMachineCount);
  g.vision(2, pose_of(g, other).x, pose_of(g, other).y);
  g.step();
  CHECK(g.awards.empty());
  CHECK(g.rb.mole() == first);

  // Inside the box (corner at 0.32, 0.32): +1, a new and different mole.
  g.vision(1, mp.x + 0.32, mp.y - 0.32);
  g.step();
  REQUIRE(g.awards.size() == 1);
  CHECK(g.awards[0].points == 1);
  CHECK(g.awards[0].reason == AwardReason::kMoleReached);
  CHECK(g.awards[0].phase == GamePhase::kWhackAMoleChallenge);
  CHECK(g.awards[0].device == first);
  REQUIRE(g.rb.mole().has_value());
  CHECK(*g.rb.mole() != first);
  CHECK(g.rb.machine(*g.rb.mole()).lights == kAllOn);
  CHECK(g.rb.machine(first).lights == kAllOff);
  CHECK(g.rb.phase_points(GamePhase::kWhackAMoleChallenge) == 1);
  CHECK(g.rb.points() == 1);

  // Standing on the old mole scores nothing more.
  g.vision(1, mp.x, mp.y);
  g.step();
  CHECK(g.awards.size() == 1);

  // Ten more moles, none repeated twice in a row.
  DeviceId prev = *g.rb.mole();
  for (int i = 0; i < 10; ++i) {
    const DeviceId reached = reach_mole(g);
    CHECK(reached == prev);
    REQUIRE(g.rb.mole().has_value());
    CHECK(*g.rb.mole() != reached);
    prev = *g.rb.mole();
  }
  CHECK(g.rb.points() == 11);
  CHECK(count_reason(g, AwardReason::kMoleReached) == 11);

  // The challenge lasts 300 s of running game time; then POST_GAME, no mole.
  while (g.rb.phase() == GamePhase::kWhackAMoleChallenge) g.step();
  CHECK(g.rb.phase() == GamePhase::kPostGame);
  CHECK(g.rb.state() == GameState::kPaused);
  CHECK(g.rb.game_time() == SimTime::from_sec(300));
  CHECK_FALSE(g.rb.mole().has_value());
  CHECK(g.now > SimTime::from_sec(300));
  CHECK(g.now <= SimTime::from_sec(300) + SimTime::from_ms(200));
  // In POST_GAME a pose on a machine scores nothing.
  g.vision(1, pose_of(g, M(1)).x, pose_of(g, M(1)).y);
  g.step();
  CHECK(g.rb.points() == 11);
  CHECK(g.rb.machine(M(1)).lights == L(kBlink, kOff, kOff));
  // The report lists the WHACK_A_MOLE phase total.
  const GameReport r = g.rb.report();
  bool listed = false;
  for (const PhaseTotal& t : r.phase_totals) {
    if (t.phase == GamePhase::kWhackAMoleChallenge) {
      listed = true;
      CHECK(t.sum == 11);
      CHECK(t.counted == 11);
    }
  }
  CHECK(listed);
  CHECK(r.total_points == 11);
  CHECK(to_json(r).find("MOLE_REACHED") != std::string::npos);
}

TEST_CASE("WHACK_A_MOLE: referee pause counts the mole, resume lights the next; time frozen") {
  Game g(test_config());
  // Entered while not running: no mole and no point until the game runs.
  g.command(command::SetGamePhase{GamePhase::kWhackAMoleChallenge});
  g.step();
  CHECK_FALSE(g.rb.mole().has_value());
  for (int i = 0; i < kDeviceCount; ++i) CHECK(g.rb.machine(DeviceId(i)).lights == kAllOff);
  g.command(command::SetGameState{GameState::kRunning});
  g.step();
  REQUIRE(g.rb.mole().has_value());
  CHECK(g.awards.empty());
  const DeviceId first = *g.rb.mole();
  g.run_s(10);

  g.command(command::SetGameState{GameState::kPaused});
  g.step();
  REQUIRE(g.awards.size() == 1);
  CHECK(g.awards[0].reason == AwardReason::kMoleReachedReferee);
  CHECK(g.awards[0].device == first);
  CHECK(g.awards[0].points == 1);
  CHECK_FALSE(g.rb.mole().has_value());
  for (int i = 0; i < kDeviceCount; ++i) CHECK(g.rb.machine(DeviceId(i)).lights == kAllOff);
  const SimTime frozen = g.rb.game_time();
  // Paused: no time, no vision points, a second pause changes nothing.
  g.vision(1, pose_of(g, first).x, pose_of(g, first).y);
  g.command(command::SetGameState{GameState::kPaused});
  g.run_s(50);
  CHECK(g.rb.game_time() == frozen);
  CHECK(g.awards.size() == 1);

  g.command(command::SetGameState{GameState::kRunning});
  g.step();
  REQUIRE(g.rb.mole().has_value());
  CHECK(*g.rb.mole() != first);
  CHECK(g.awards.size() == 1);  // resuming itself gives nothing
  CHECK(g.rb.game_time() == frozen);
  g.step();
  CHECK(g.rb.game_time() == frozen + kStep);
  CHECK(g.rb.points() == 1);
}

TEST_CASE("GameState.points sums EXPLORATION, PRODUCTION and WHACK_A_MOLE, each floored at 0") {
  Game g(test_config());
  // EXPLORATION: +4 -3 -3 = -2, counts 0 ...
  g.command(command::SetGamePhase{GamePhase::kExploration});
  g.step();
  g.report({{{"M1", "T1"}, {"M2", "T5"}, {"M3", "T5"}}});
  g.step();
  CHECK(g.rb.phase_points(GamePhase::kExploration) == -2);
  CHECK(g.rb.points() == 0);
  // ... one more correct report makes it +2.
  g.report({{{"M4", "T4"}}});
  g.step();
  CHECK(g.rb.phase_points(GamePhase::kExploration) == 2);
  CHECK(g.rb.points() == 2);

  // WHACK_A_MOLE: three moles, +3.
  start_challenge(g, GamePhase::kWhackAMoleChallenge);
  for (int i = 0; i < 3; ++i) reach_mole(g);
  CHECK(g.rb.phase_points(GamePhase::kWhackAMoleChallenge) == 3);
  CHECK(g.rb.points() == 5);
  // A minor penalty during the challenge counts in its sum: -25 % of 5 -> -1.
  g.command(command::Penalty{false});
  g.step();
  CHECK(g.awards.back().phase == GamePhase::kWhackAMoleChallenge);
  CHECK(g.rb.phase_points(GamePhase::kWhackAMoleChallenge) == 2);
  CHECK(g.rb.points() == 4);

  // PRODUCTION: a major penalty (at least -5) makes the production sum negative: counts 0.
  g.start_production();
  g.command(command::Penalty{true});
  g.step();
  CHECK(g.rb.phase_points(GamePhase::kProduction) == -5);
  CHECK(g.rb.points() == 2 + 0 + 2);
  // A T2 completion (+4) in production: still negative (-1), the total is unchanged.
  // Make puck 2 an S1 at M1 (T1, 4 s) and load it with puck 3 (S0) into M2 (T2).
  g.enter(M(1), 2);
  g.run_s(5);
  CHECK(g.state_of(2) == PuckState::kS1);
  g.leave(M(1), 2);
  g.step();
  g.command(command::LoadPuck{M(2), puck(3)});
  g.command(command::LoadPuck{M(2), puck(2)});
  g.step();
  CHECK(g.rb.phase_points(GamePhase::kProduction) == -1);
  CHECK(g.rb.points() == 4);
  // The points equal the floored sums of the recorded awards.
  int expl = 0, prod = 0, wam = 0;
  for (const PointsAward& a : g.rb.awards()) {
    if (a.phase == GamePhase::kExploration) expl += a.points;
    if (a.phase == GamePhase::kProduction) prod += a.points;
    if (a.phase == GamePhase::kWhackAMoleChallenge) wam += a.points;
  }
  CHECK(g.rb.points() == std::max(0, expl) + std::max(0, prod) + std::max(0, wam));
}

TEST_CASE("WHACK_A_MOLE: moles are drawn from the refbox stream (same seed, same moles)") {
  auto moles = [](std::uint64_t seed) {
    Game g(test_config(), seed);
    start_challenge(g, GamePhase::kWhackAMoleChallenge);
    std::vector<int> seq;
    for (int i = 0; i < 40; ++i) seq.push_back(reach_mole(g).value());
    return seq;
  };
  const std::vector<int> a = moles(7);
  CHECK(a == moles(7));
  std::set<std::vector<int>> distinct;
  std::set<int> seen;
  for (std::uint64_t seed = 1; seed <= 5; ++seed) {
    const std::vector<int> s = moles(seed);
    distinct.insert(s);
    for (std::size_t i = 0; i < s.size(); ++i) {
      CHECK(s[i] >= 0);
      CHECK(s[i] < kProductionMachineCount);
      if (i > 0) CHECK(s[i] != s[i - 1]);
      seen.insert(s[i]);
    }
  }
  CHECK(distinct.size() == 5);
  CHECK(seen.size() == kProductionMachineCount);  // every machine of M1..M10 gets its turn
}

TEST_CASE("vision poses are kept per robot (Robot.vision_pose) by jersey number") {
  Game g(test_config());
  Beacon b;
  b.team = "Carologistics";
  b.peer_name = "R1";
  b.number = 1;
  b.host = "172.26.1.1";
  b.port = 4444;
  g.beacon(b);
  b.team = "Other";
  b.host = "172.26.1.9";
  g.beacon(b);
  g.step();
  REQUIRE(g.rb.robots().size() == 2);
  CHECK_FALSE(g.rb.robots()[0].vision_pose.has_value());
  g.vision(1, 1.5, 2.5);
  g.step();
  REQUIRE(g.rb.robots()[0].vision_pose.has_value());
  CHECK(g.rb.robots()[0].vision_pose->x == doctest::Approx(1.5));
  CHECK(g.rb.robots()[0].vision_pose->y == doctest::Approx(2.5));
  CHECK_FALSE(g.rb.robots()[1].vision_pose.has_value());  // another team's robot
}
