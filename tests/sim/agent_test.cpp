// SPDX-License-Identifier: MIT
// The LLSF 2013 team agent (clips/agents/llsf2013) playing whole games in the game loop.
#include <doctest/doctest.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "fixture.h"
#include "llsf/sim/agent_brain.h"
#include "llsf/sim/driver.h"
#include "llsf/sim/game.h"

using namespace llsf;
using namespace llsf::sim;

namespace {

struct AgentGame {
  AgentGame(int robots, std::uint64_t seed, clips::ConfigEntries config, bool print = false,
            bool locks = false)
      : driver(make_config(robots, seed)), game(driver.game()) {
    for (int i = 0; i < robots; ++i) {
      AgentBrainConfig c;
      c.agent_files = {LLSF_SOURCE_DIR "/clips/agents/common",
                       LLSF_SOURCE_DIR "/clips/agents/llsf2013"};
      c.config = config;
      c.locks = locks;
      brains.push_back(&driver.plug_agent(
          i, c,
          [this, print](const clips::LogRecord& r) {
            if (r.level >= clips::LogLevel::kWarn) ++warnings;
            const std::string_view text = r.text;
            if (text.find("task GET_S0 failed") != std::string_view::npos) {
              get_s0_failures.emplace_back(text);
            }
            if (text.find("took a consumed puck") != std::string_view::npos) ++consumed_taken;
            if (print || r.level == clips::LogLevel::kError) {
              std::printf("%8.2f %s %s: %.*s\n", r.time.seconds(), std::string(r.agent).c_str(),
                          clips::to_string(r.level), static_cast<int>(r.text.size()),
                          r.text.data());
            }
          },
          {}, AgentReports{{}, [this](const clips::AgentEvent& e) {
                             // Role changes as the agent declares them (agent-event), not as it
                             // words its log.
                             if (e.kind == clips::AgentEventKind::kRoleChange) ++role_changes;
                           }}));
    }
  }
  static GameConfig make_config(int robots, std::uint64_t seed) {
    GameConfig c = test::small_game(robots, seed);
    return c;
  }
  int runtime_errors() const {
    int n = 0;
    for (const auto& b : brains) n += b->agent().runtime_errors();
    return n;
  }
  GameDriver driver;
  Game& game;
  std::vector<AgentBrain*> brains;  // owned by the driver
  int warnings = 0;
  std::vector<std::string> get_s0_failures;  ///< "task GET_S0 failed: ..." of every robot
  int role_changes = 0;
  int consumed_taken = 0;
};

}  // namespace

TEST_CASE("the LLSF 2013 agent explores with three robots and reports the machines") {
  AgentGame g(3, 7, {});
  test::start_phase(g.game, refbox::GamePhase::kExploration);
  g.game.run_until(SimTime::from_sec(180));
  const GameSummary s = g.game.summary();
  MESSAGE("exploration points: ", s.exploration_points);
  CHECK(g.runtime_errors() == 0);
  CHECK(s.exploration_points >= 20);
}

TEST_CASE("the LLSF 2013 agent produces and delivers with three robots") {
  AgentGame g(3, 7, {}, std::getenv("LLSF_AGENT_LOG") != nullptr);
  test::start_phase(g.game, refbox::GamePhase::kProduction);
  g.game.run_until(SimTime::from_sec(900));
  const GameSummary s = g.game.summary();
  MESSAGE("production points: ", s.production_points);
  CHECK(g.runtime_errors() == 0);
  CHECK(s.production_points >= 20);
  // The shipped agent stays far below the work budget of a cycle (docs/clips.md, "Budgets").
  std::int64_t steps = 0;
  for (const AgentBrain* b : g.brains) steps = std::max(steps, b->agent().max_cycle_steps());
  MESSAGE("most CLIPS steps in one agent cycle: ", steps);
  CHECK(steps * 100 < clips::AgentConfig{}.max_steps_per_cycle);
}

TEST_CASE("the thesis' configurations are configuration: P3-P3, P1P2-P3-R, P1-P2-P3-RD") {
  struct Variant {
    const char* name;
    int robots;
    std::vector<std::string> roles;
    std::string recycle;
    bool role_change;
  };
  const Variant variants[] = {
      {"P3-P3", 2, {"P3", "P3"}, "never", false},
      {"P1P2-P3-R", 2, {"P1P2", "P3"}, "ifpossible", false},
      {"P1-P2-P3-RD", 3, {"P1", "P2", "P3"}, "afterdeliver", true},
  };
  for (const Variant& v : variants) {
    CAPTURE(v.name);
    clips::ConfigEntries cfg{clips::ConfigEntry::list("/clips-agent/roles", v.roles),
                             clips::ConfigEntry::of("/clips-agent/recycle", v.recycle)};
    if (v.role_change) {
      cfg.push_back(
          clips::ConfigEntry::of("/clips-agent/role-change/after-complex-delivery", true));
      cfg.push_back(clips::ConfigEntry::of("/clips-agent/role-change/time-left", 300));
    }
    AgentGame g(v.robots, 11, cfg);
    test::start_phase(g.game, refbox::GamePhase::kProduction);
    g.game.run_until(SimTime::from_sec(900));
    const GameSummary s = g.game.summary();
    MESSAGE(std::string(v.name), ": ", s.production_points, " production points, ",
            g.consumed_taken, " consumed pucks taken, ", g.role_changes, " role changes");
    if (v.recycle != "never") CHECK(g.consumed_taken > 0);
    if (v.role_change) CHECK(g.role_changes > 0);
    CHECK(g.runtime_errors() == 0);
    CHECK(s.production_points > 0);
    // Every robot took the configured role.
    for (std::size_t i = 0; i < g.brains.size(); ++i) {
      const auto roles = g.brains[i]->agent().facts("role");
      REQUIRE(roles.size() == 1);
    }
  }
}

TEST_CASE("protobuf round trip: CLIPS on one robot -> radio -> CLIPS on another") {
  Game game(test::small_game(2, 3));
  AgentBrain a(game, 0, {});
  AgentBrain b(game, 1, {});
  game.set_brain(0, &a);
  game.set_brain(1, &b);
  a.agent().load_string(
      "(defrule send (time $?) (not (sent)) =>\n"
      "  (bind ?m (pb-create \"llsf_agent_msgs.WorldmodelChange\"))\n"
      "  (pb-set-field ?m \"id\" 7) (pb-set-field ?m \"agent\" \"robot1\")\n"
      "  (pb-set-field ?m \"change\" ADD_LOADED_WITH) (pb-set-field ?m \"machine\" \"M3\")\n"
      "  (pb-set-field ?m \"puck\" S1)\n"
      "  (pb-broadcast ?m) (pb-destroy ?m) (assert (sent)))\n",
      "sender.clp");
  b.agent().load_string(
      "(defrule got ?f <- (protobuf-msg (type \"llsf_agent_msgs.WorldmodelChange\") (ptr ?p)\n"
      "                               (rcvd-from ?from ?id)) =>\n"
      "  (retract ?f)\n"
      "  (assert (got ?from ?id (pb-field-value ?p \"machine\") (pb-field-value ?p \"puck\")\n"
      "               (pb-field-value ?p \"change\"))))\n",
      "receiver.clp");
  game.run_until(SimTime::from_sec(1));
  CHECK(b.agent().find_facts("got", {}).size() == 1);
  const auto got = b.agent().facts("got");
  REQUIRE(got.size() == 1);
  const auto& f = got[0].fields();
  REQUIRE(f.size() == 5);
  CHECK(f[0] == clips::Value::string("robot1"));
  CHECK(f[1] == clips::Value::integer_value(1));
  CHECK(f[2] == clips::Value::string("M3"));
  CHECK(f[3] == clips::Value::symbol("S1"));
  CHECK(f[4] == clips::Value::symbol("ADD_LOADED_WITH"));
  CHECK(a.agent().runtime_errors() == 0);
  CHECK(b.agent().runtime_errors() == 0);
}

TEST_CASE("with the lock protocol the robots share machines, storage and gates") {
  AgentGame free_for_all(3, 7, {});
  AgentGame locked(3, 7, {}, std::getenv("LLSF_AGENT_LOG") != nullptr, true);
  for (AgentGame* g : {&free_for_all, &locked}) {
    test::start_phase(g->game, refbox::GamePhase::kProduction);
    g->game.run_until(SimTime::from_sec(900));
  }
  const GameSummary a = free_for_all.game.summary();
  const GameSummary b = locked.game.summary();
  const int ca = a.collisions_robot_robot + a.collisions_robot_device;
  const int cb = b.collisions_robot_robot + b.collisions_robot_device;
  MESSAGE("without locks: ", a.production_points, " points, ", ca,
          " collisions; with locks: ", b.production_points, " points, ", cb, " collisions");
  CHECK(locked.runtime_errors() == 0);
  CHECK(b.production_points >= 20);
  // One robot is the master.
  int masters = 0;
  for (const auto& br : locked.brains) {
    masters += static_cast<int>(br->agent().find_facts("lock-role", {}).size() > 0 &&
                                !br->agent().facts("lock-role").empty() &&
                                br->agent().facts("lock-role")[0].fields().at(0) ==
                                    clips::Value::symbol("MASTER"));
  }
  CHECK(masters == 1);
}

namespace {

/// What one P3 robot did in the first 150 s of production with a puck where it should not be.
struct StrayPuck {
  int already_holding = 0;  ///< get_s0 failures "already holding a puck"
  int get_s0_failures = 0;
  bool had_s0 = false;         ///< the agent held an S0 at some time
  core::Vec2 stray{0.0, 0.0};  ///< where the stray puck lies at the end
};

constexpr core::PuckId kStray{30};

/// Plays 150 s of production with one P3 robot (robot1, whose get_s0 starts at INS_1);
/// `stray(game, INS_1, second)` puts puck kStray somewhere before the start (second 0) or after
/// each second of play. Prints the agent's log with LLSF_AGENT_LOG.
StrayPuck stray_puck_game(const std::function<void(Game&, const planner::Place&, int)>& stray) {
  AgentGame g(1, 7, {clips::ConfigEntry::list("/clips-agent/roles", {"P3"})},
              std::getenv("LLSF_AGENT_LOG") != nullptr);
  const planner::Place* ins1 = g.game.planner().place("INS_1");
  REQUIRE(ins1 != nullptr);
  stray(g.game, *ins1, 0);
  test::start_phase(g.game, refbox::GamePhase::kProduction);
  StrayPuck out;
  for (int s = 1; s <= 150; ++s) {
    g.game.run_until(g.game.time() + SimTime::from_sec(1));
    stray(g.game, *ins1, s);
    out.had_s0 =
        out.had_s0 ||
        !g.brains[0]->agent().find_facts("holding", {{"puck", clips::Value::symbol("S0")}}).empty();
  }
  CHECK(g.runtime_errors() == 0);
  for (const std::string& e : g.get_s0_failures) {
    MESSAGE(e);
    ++out.get_s0_failures;
    if (e.find("already holding a puck") != std::string::npos) ++out.already_holding;
  }
  out.stray = g.game.world().puck_position(kStray);
  return out;
}

/// True if `p` lies in the input storage or in front of it, where robots stand to take an S0.
bool at_the_storage(const core::Vec2& p) { return p.x() < 1.3 && p.y() > 2.0 && p.y() < 3.6; }

}  // namespace

TEST_CASE("a stray puck picked up on the way to the storage does not lock get_s0 up") {
  // Driving to the storage from the middle of the field, the robot sweeps a stray puck into its
  // holder (as robots do with pucks beside machines) and arrives with it at INS_1's look
  // position, where get_s0 finds its holder full. Left where the robot stands, the puck is taken
  // up again by every later get_s0 driving to that look position.
  const StrayPuck r = stray_puck_game([](Game& game, const planner::Place&, int second) {
    if (second == 0) game.world().teleport_robot(core::RobotId(0), {3.4, 2.2, core::kPi});
    if (second != 2) return;
    const core::Pose2D at = game.world().robot_pose(core::RobotId(0));
    game.world().add_puck(kStray, at.to_parent({0.2225, 0.0}));
  });
  CHECK(r.had_s0);
  CHECK(r.already_holding <= 1);
  CHECK(r.get_s0_failures <= 2);
  INFO("stray puck at ", r.stray.x(), ", ", r.stray.y());
  CHECK_FALSE(at_the_storage(r.stray));
}

TEST_CASE("a puck pressed into the storage's wall does not lock get_s0 up") {
  // Pushed by robots, a puck can end pressed into the wall at the back of the storage (x 0.01,
  // seen in whole games): the holder's arms touch the wall before the puck is in, take_puck is
  // blocked with the puck half in the holder. The storage's front pucks near INS_1 are gone.
  const StrayPuck r = stray_puck_game([](Game& game, const planner::Place& ins1, int second) {
    if (second != 0) return;
    const std::vector<core::PuckId> ids(game.world().pucks().begin(), game.world().pucks().end());
    for (const core::PuckId id : ids) {
      if (game.world().puck_position(id).y() < 2.9) game.world().remove_puck(id);
    }
    game.world().add_puck(kStray, {0.01, ins1.target.y()});
  });
  CHECK(r.had_s0);
  CHECK(r.already_holding <= 1);
  CHECK(r.get_s0_failures <= 2);
}
