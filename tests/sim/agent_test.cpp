// SPDX-License-Identifier: MIT
// The LLSF 2013 team agent (clips/agents/llsf2013) playing whole games in the game loop.
#include <doctest/doctest.h>

#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>
#include <vector>

#include "fixture.h"
#include "llsf/sim/agent_brain.h"
#include "llsf/sim/game.h"

using namespace llsf;
using namespace llsf::sim;

namespace {

struct AgentGame {
  AgentGame(int robots, std::uint64_t seed, clips::ConfigEntries config, bool print = false,
            bool locks = false)
      : game(make_config(robots, seed)) {
    for (int i = 0; i < robots; ++i) {
      AgentBrainConfig c;
      c.agent_files = {LLSF_SOURCE_DIR "/clips/agents/common",
                       LLSF_SOURCE_DIR "/clips/agents/llsf2013"};
      c.config = config;
      c.locks = locks;
      brains.push_back(
          std::make_unique<AgentBrain>(game, i, c, [this, print](const clips::LogRecord& r) {
            if (r.level >= clips::LogLevel::kWarn) ++warnings;
            const std::string_view text = r.text;
            if (text.find("role change") != std::string_view::npos) ++role_changes;
            if (text.find("took a consumed puck") != std::string_view::npos) ++consumed_taken;
            if (print || r.level == clips::LogLevel::kError) {
              std::printf("%8.2f %s %s: %.*s\n", r.time.seconds(), std::string(r.agent).c_str(),
                          clips::to_string(r.level), static_cast<int>(r.text.size()),
                          r.text.data());
            }
          }));
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
  Game game;
  std::vector<std::unique_ptr<AgentBrain>> brains;
  int warnings = 0;
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
