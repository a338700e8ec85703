// SPDX-License-Identifier: MIT
// Exploration reports and scoring (spec §5, §7), points per phase, penalties, and robots from
// beacons: lost robots, warnings, maintenance and disqualification (spec §10).
#include <doctest/doctest.h>

#include "fixture.h"

using namespace llsf;
using namespace llsf::refbox;
using namespace llsf::refbox::test;

namespace {

MachineReport report_of(std::initializer_list<std::pair<const char*, const char*>> entries) {
  MachineReport r;
  for (const auto& [name, type] : entries) r.machines.push_back({name, type});
  return r;
}

void start_exploration(Game& g) {
  g.command(command::SetGamePhase{GamePhase::kExploration});
  g.command(command::SetGameState{GameState::kRunning});
  g.step();
}

Beacon beacon(const Game& g, const char* name, int number, int port,
              const char* host = "172.26.1.1", const char* team = "Carologistics") {
  Beacon b;
  b.time = g.now;
  b.team = team;
  b.peer_name = name;
  b.number = number;
  b.host = host;
  b.port = port;
  b.pose = core::Pose2D{1.0, 2.0, 0.5};
  return b;
}

}  // namespace

TEST_CASE("exploration: first report per machine counts, +4 / -3, floored at 0 per phase") {
  Game g(test_config());
  // Reports before exploration are dropped.
  g.report(report_of({{"M1", "T1"}}));
  g.step();
  CHECK(g.awards.empty());
  start_exploration(g);
  // Test plan: M1 T1, M2 T2, M3 T3, M4 T4, M5 T5.
  g.report(report_of({{"M1", "T2"}, {"M2", "T2"}, {"R1", "RECYCLE"}, {"X", "T1"}}));
  g.step();
  CHECK(g.rb.phase_points(GamePhase::kExploration) == 1);
  CHECK(g.rb.points() == 1);
  CHECK(g.m(M(1)).correctly_reported == false);
  CHECK(g.m(M(2)).correctly_reported == true);
  CHECK_FALSE(g.m(M(3)).correctly_reported.has_value());
  // A repeated report cannot correct the wrong one, nor score twice.
  g.report(report_of({{"M1", "T1"}, {"M2", "T2"}}));
  g.step();
  CHECK(g.rb.phase_points(GamePhase::kExploration) == 1);
  REQUIRE(g.rb.reported_machines().size() == 2);
  CHECK(g.rb.reported_machines()[0] == M(1));
  CHECK(g.rb.reported_machines()[1] == M(2));
  // Type strings are compared exactly.
  g.report(report_of({{"M3", "t3"}, {"M4", "T5"}, {"M5", "T5"}}));
  g.step();
  CHECK(g.rb.phase_points(GamePhase::kExploration) == 1 - 3 - 3 + 4);
  CHECK(g.rb.points() == 0);  // the phase sum -1 counts as 0
  CHECK(g.awards.size() == 5);
  CHECK(g.awards[0].reason == AwardReason::kExplorationWrong);
  CHECK(g.awards[0].device == M(1));
  CHECK(g.awards[1].reason == AwardReason::kExplorationCorrect);
  // Production points are added to the floored exploration points.
  g.command(command::SetGamePhase{GamePhase::kProduction});
  g.step();
  g.report(report_of({{"M6", "T1"}}));  // reports after exploration are dropped
  g.enter(M(2), 1);
  g.step();
  g.run_s(2.1);
  g.leave(M(2), 1);
  g.step();
  g.enter(M(1), 2);
  g.step();
  g.run_s(4.1);
  g.leave(M(1), 2);
  g.enter(M(2), 2);
  g.step();
  g.run_s(20.1);
  CHECK(g.rb.phase_points(GamePhase::kProduction) == 4);
  CHECK(g.rb.points() == 4);
  const GameReport r = g.rb.report();
  REQUIRE(r.phase_totals.size() == 2);
  CHECK(r.phase_totals[0].phase == GamePhase::kExploration);
  CHECK(r.phase_totals[0].sum == -1);
  CHECK(r.phase_totals[0].counted == 0);
  CHECK(r.phase_totals[1].counted == 4);
  CHECK(r.total_points == 4);
}

TEST_CASE("exploration: all ten right gives 40; reports also count while paused") {
  Game g(test_config());
  start_exploration(g);
  g.command(command::SetGameState{GameState::kPaused});
  g.step();
  MachineReport r;
  const GameParams p = test_params();
  for (int i = 0; i < kProductionMachineCount; ++i) {
    r.machines.push_back(
        {std::string(kDeviceNames[i]), std::string(to_string(p.machine_types[i]))});
  }
  g.report(r);
  g.step();
  CHECK(g.rb.points() == 40);
}

TEST_CASE("referee penalties: minor -25 % (at least 1), major -50 % (at least 5)") {
  Game g(test_config());
  g.start_production();
  g.command(command::Penalty{false});
  g.step();
  CHECK(g.awards.back().points == -1);
  CHECK(g.rb.points() == 0);
  Game h(test_config());
  start_exploration(h);
  MachineReport r;
  for (int i = 0; i < kProductionMachineCount; ++i) {
    r.machines.push_back(
        {std::string(kDeviceNames[i]), std::string(to_string(test_params().machine_types[i]))});
  }
  h.report(r);
  h.command(command::Penalty{true});  // commands come before reports in a step: 0 -> -5
  h.step();
  CHECK(h.rb.points() == 35);
  h.command(command::Penalty{true});
  h.step();
  CHECK(h.awards.back().reason == AwardReason::kPenaltyMajor);
  CHECK(h.rb.points() == 35 - 17);
}

TEST_CASE("robots: registered from beacons, lost after 5 s, removed after 1080 s") {
  Game g(test_config());
  g.beacon(beacon(g, "R-1", 1, 4444));
  g.beacon(beacon(g, "R-2", 2, 4445, "172.26.1.2"));
  g.step();
  REQUIRE(g.rb.robots().size() == 2);
  const Robot& r1 = g.rb.robots()[0];
  CHECK(r1.name == "R-1");
  CHECK(r1.team == "Carologistics");
  CHECK(r1.number == 1);
  CHECK(r1.state == RobotState::kActive);
  REQUIRE(r1.pose.has_value());
  CHECK(r1.pose->x == 1.0);
  CHECK(g.attention.empty());
  // R-2 keeps sending, R-1 stops.
  for (int i = 0; i < 6; ++i) {
    g.run_s(1);
    g.beacon(beacon(g, "R-2", 2, 4445, "172.26.1.2"));
  }
  g.step();
  CHECK(g.rb.robots()[0].lost);
  CHECK_FALSE(g.rb.robots()[1].lost);
  CHECK(g.attention_contains("R-1"));
  CHECK(g.attention_contains("lost"));
  const std::size_t warnings = g.attention.size();
  g.run_s(3);
  CHECK(g.attention.size() == warnings);  // once until seen again
  g.beacon(beacon(g, "R-1", 1, 4444));
  g.step();
  CHECK_FALSE(g.rb.robots()[0].lost);
  g.run(SimTime::from_sec(1081));
  CHECK(g.rb.robots().empty());
}

TEST_CASE(
    "robot warnings: clock offset, two sources on one host, number 0, duplicate number, "
    "another refbox") {
  Game g(test_config());
  Beacon off = beacon(g, "R-1", 1, 4444);
  off.time = g.now + SimTime::from_sec(4);
  g.beacon(off);
  g.step();
  CHECK(g.attention_contains("off by more than 3 s"));
  g.attention.clear();
  g.beacon(beacon(g, "R-1b", 3, 4999));  // same host, other port
  g.step();
  CHECK(g.attention_contains("Two beacon sources on host 172.26.1.1"));
  g.attention.clear();
  g.beacon(beacon(g, "R-0", 0, 4444, "172.26.1.5"));
  g.step();
  CHECK(g.attention_contains("jersey number 0"));
  g.attention.clear();
  g.beacon(beacon(g, "R-dup", 1, 4444, "172.26.1.6"));
  g.step();
  CHECK(g.attention_contains("Duplicate jersey number 1"));
  g.attention.clear();
  g.beacon(beacon(g, "RefBox", 0, 4444, "172.26.1.7", "LLSF"));
  g.step();
  CHECK(g.attention_contains("Another refbox"));
  CHECK(g.rb.robots().size() == 4);
  // A team change in PRE_GAME clears the list.
  g.command(command::SetTeamName{"Other"});
  g.step();
  CHECK(g.rb.robots().empty());
}

TEST_CASE(
    "maintenance: 120 s allowed, warning at 105 s, disqualified beyond 135 s or on a second "
    "maintenance; the time counts only while running") {
  Game g(test_config());
  g.start_production();
  auto keep_alive = [&](double seconds) {
    for (double t = 0; t < seconds; t += 1.0) {
      g.beacon(beacon(g, "R-1", 1, 4444));
      g.beacon(beacon(g, "R-2", 2, 4445, "172.26.1.2"));
      g.run_s(1.0);
    }
  };
  keep_alive(1);
  g.command(command::SetRobotMaintenance{1, true});
  g.step();
  CHECK(g.rb.robots()[0].state == RobotState::kMaintenance);
  CHECK(g.rb.robots()[0].maintenance_cycles == 1);
  keep_alive(50);
  // Paused: the maintenance clock stops.
  g.command(command::SetGameState{GameState::kPaused});
  keep_alive(100);
  g.command(command::SetGameState{GameState::kRunning});
  const double remaining = g.rb.robots()[0].maintenance_time_remaining_s(g.rb.rules());
  CHECK(remaining == doctest::Approx(70.0).epsilon(0.02));
  keep_alive(56);
  CHECK(g.attention_contains("maintenance time almost over"));
  g.command(command::SetRobotMaintenance{1, false});
  g.step();
  CHECK(g.rb.robots()[0].state == RobotState::kActive);
  // A second maintenance disqualifies.
  g.command(command::SetRobotMaintenance{1, true});
  g.step();
  CHECK(g.rb.robots()[0].state == RobotState::kDisqualified);
  // Overrunning 135 s disqualifies.
  g.command(command::SetRobotMaintenance{2, true});
  keep_alive(134);
  CHECK(g.rb.robots()[1].state == RobotState::kMaintenance);
  CHECK(g.rb.robots()[1].maintenance_time_remaining_s(g.rb.rules()) < 0.0);
  keep_alive(2);
  CHECK(g.rb.robots()[1].state == RobotState::kDisqualified);
  // Unknown numbers are reported.
  g.command(command::SetRobotMaintenance{3, true});
  g.step();
  CHECK(g.attention_contains("No robot with number 3"));
}
