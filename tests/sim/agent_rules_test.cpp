// SPDX-License-Identifier: MIT
// The LLSF 2013 agent's rules without the world (AgentFixture): production decisions from the
// world model, outcomes updating it, exploration reports.
#include <doctest/doctest.h>
#include <llsf_msgs/MachineReport.pb.h>

#include <string>
#include <utility>
#include <vector>

#include "llsf/clips/testing.h"
#include "llsf/comm/registry.h"
#include "llsf/sim/agent_brain.h"
#include "llsf/sim/game.h"

using namespace llsf;
using clips::SkillStatus;
using clips::Value;

namespace {

struct Rules {
  explicit Rules(clips::ConfigEntries extra = {})
      : f(config(std::move(extra)), &registry_for_tests()) {
    for (const std::string& file : sim::agent_files(
             {LLSF_SOURCE_DIR "/clips/agents/common", LLSF_SOURCE_DIR "/clips/agents/llsf2013"})) {
      f.load_file(file);
    }
    f.load(
        "(deffunction t-type (?n ?t) (do-for-fact ((?m machine)) (eq ?m:name ?n) "
        "(modify ?m (mtype ?t))))\n"
        "(deffunction t-loaded (?n $?l) (do-for-fact ((?m machine)) (eq ?m:name ?n) "
        "(modify ?m (loaded-with ?l))))\n"
        "(deffunction t-game (?p ?s) (do-for-fact ((?g game)) TRUE (modify ?g (phase ?p) "
        "(state ?s))))\n"
        "(deffunction t-hold (?p) (do-for-fact ((?h holding)) TRUE (modify ?h (puck ?p))))\n",
        "test-helpers.clp");
    f.step();  // (reset) and the deffacts
  }
  static clips::AgentConfig config(clips::ConfigEntries extra) {
    clips::AgentConfig c;
    c.robot_name = "robot1";
    c.robot_number = 1;
    c.config = std::move(extra);
    return c;
  }
  static const comm::MessageRegistry& registry_for_tests() {
    static const comm::MessageRegistry r = [] {
      comm::MessageRegistry reg;
      sim::add_refbox_messages(reg);
      comm::add_agent_messages(reg);
      return reg;
    }();
    return r;
  }
  void eval(const std::string& e) {
    f.agent().eval(e);
    REQUIRE(f.agent().runtime_errors() == 0);
  }
  /// The 2013 plan of these tests: T1 at M1 and M8, T2 at M4, T3 at M3, T4 at M9, T5 at M6.
  void production(const std::string& role, const std::string& target) {
    eval("(t-type M1 T1)");
    eval("(t-type M8 T1)");
    eval("(t-type M4 T2)");
    eval("(t-type M3 T3)");
    eval("(t-type M9 T4)");
    eval("(t-type M6 T5)");
    f.assert_fact("(role (name " + role + ") (target " + target + "))");
    eval("(t-game PRODUCTION RUNNING)");
  }
  std::string last_call() { return f.skills().calls().empty() ? "" : f.skills().calls().back(); }
  clips::AgentFixture f;
};

}  // namespace

TEST_CASE("production: where a held puck goes follows the target machine's needs") {
  Rules r;
  r.production("P1", "M3");
  r.f.agent().set_pose({2.0, 1.0, 0.0});
  // Holding nothing: an S0 from the storage.
  r.f.steps(2);
  CHECK(r.last_call() == "get_s0{}");
  r.f.skills().set_status(SkillStatus::kFinal);
  r.f.steps(2);
  CHECK(r.f.find("holding", {{"puck", Value::symbol("S0")}}).size() == 1);
  // An S0 for an empty T3: the T3 takes it first.
  CHECK(r.last_call() == "finish_puck_at{place=\"M3\"}");
  r.f.skills().set_result("WAITING");
  r.f.skills().set_status(SkillStatus::kFinal);
  r.f.steps(2);
  const auto m3 = r.f.find("machine", {{"name", Value::symbol("M3")}});
  REQUIRE(m3.size() == 1);
  CHECK(m3[0].slot("loaded-with").items.size() == 1);
  CHECK(r.f.find("holding", {{"puck", Value::symbol("NONE")}}).size() == 1);
  // The T3 has its S0: the next S0 goes to the nearest T1 (M8 from (2.0, 1.0)) for an S1.
  r.eval("(t-hold S0)");
  r.f.skills().set_status(SkillStatus::kFinal);  // the get_s0 the robot started meanwhile
  r.f.steps(3);
  CHECK(r.last_call() == "finish_puck_at{place=\"M8\"}");
  CHECK(r.f.agent().runtime_errors() == 0);
}

TEST_CASE("production: an S1 goes to a T2 holding an S0 when the target needs an S2") {
  Rules r;
  r.production("P2", "M9");
  r.eval("(t-loaded M9 S0 S1)");
  r.eval("(t-loaded M4 S0)");
  r.eval("(t-hold S1)");
  r.f.agent().set_pose({3.0, 1.0, 0.0});
  r.f.steps(2);
  CHECK(r.last_call() == "finish_puck_at{place=\"M4\"}");
  // DONE: the S2 is in the holder, the T2's S0 is now a consumed puck beside it.
  r.f.skills().set_result("DONE");
  r.f.skills().set_status(SkillStatus::kFinal);
  r.f.step();
  CHECK(r.f.find("holding", {{"puck", Value::symbol("S2")}}).size() == 1);
  const auto m4 = r.f.find("machine", {{"name", Value::symbol("M4")}});
  REQUIRE(m4.size() == 1);
  CHECK(m4[0].slot("consumed") == Value::integer_value(1));
  CHECK(m4[0].slot("loaded-with").items.empty());
  r.f.steps(2);
  CHECK(r.last_call() == "finish_puck_at{place=\"M9\"}");
}

TEST_CASE("production: products are delivered; a down machine is avoided for 30 s") {
  Rules r;
  r.production("P3", "NONE");
  r.eval("(t-hold P3)");
  r.f.steps(2);
  CHECK(r.last_call() == "deliver{}");
  r.f.skills().set_status(SkillStatus::kFinal);
  r.f.steps(2);
  CHECK(r.last_call() == "get_s0{}");
  r.f.skills().set_status(SkillStatus::kFinal);
  r.f.steps(2);
  CHECK(r.last_call() == "finish_puck_at{place=\"M6\"}");
  r.f.skills().set_status(SkillStatus::kFailed, "finish_puck_at: M6 is down (red)");
  r.f.steps(2);
  // The only T5 is down: the robot waits (no skill) instead of driving there again.
  CHECK(r.last_call() == "finish_puck_at{place=\"M6\"}");
  CHECK(r.f.find("task", {{"kind", Value::symbol("WAIT")}}).size() == 1);
  r.f.steps(340);  // after the 30 s (and the 3 s wait then running) the T5 is tried again
  CHECK(r.last_call() == "finish_puck_at{place=\"M6\"}");
  CHECK(r.f.skills().calls().size() == 4);
}

TEST_CASE("exploration: the read code is matched to a type and reported to the refbox") {
  Rules r;
  r.f.assert_fact("(signal (type T3) (code \"red=ON yellow=ON green=OFF\"))");
  r.f.assert_fact("(signal (type T1) (code \"red=OFF yellow=OFF green=ON\"))");
  r.eval("(t-game EXPLORATION RUNNING)");
  r.f.steps(2);
  CHECK(r.last_call() == "explore_machine{place=\"M8\"}");  // robot1 starts at M8
  r.f.skills().set_result("M8 red=ON yellow=ON green=OFF");
  r.f.skills().set_status(SkillStatus::kFinal);
  r.f.steps(2);
  bool reported = false;
  for (const auto& m : r.f.sent()) {
    const auto* rep = dynamic_cast<const llsf_msgs::MachineReport*>(m.get());
    if (rep == nullptr) continue;
    REQUIRE(rep->machines_size() == 1);
    CHECK(rep->machines(0).name() == "M8");
    CHECK(rep->machines(0).type() == "T3");
    reported = true;
  }
  CHECK(reported);
  // The next machine along the ring.
  CHECK(r.last_call() == "explore_machine{place=\"M4\"}");
}

namespace {

/// What a robot did in a minute of an empty storage.
struct EmptyStorage {
  std::vector<std::string> calls;  ///< the skills it called
  int get_consumed_tasks = 0;      ///< cycles with a GET_CONSUMED task
  int wait_tasks = 0;              ///< cycles with a WAIT task
};

/// Plays 60 s of a P3 robot holding nothing whose every get_s0 finds the storage empty, with a
/// consumed puck lying beside M4.
EmptyStorage empty_storage_minute(Rules& r) {
  r.production("P3", "NONE");
  r.eval("(do-for-fact ((?m machine)) (eq ?m:name M4) (modify ?m (consumed 1)))");
  r.f.agent().set_pose({2.0, 1.0, 0.0});
  EmptyStorage out;
  for (int i = 0; i < 600; ++i) {
    r.f.step();
    if (!r.f.find("task", {{"kind", Value::symbol("GET_S0")}, {"state", Value::symbol("RUNNING")}})
             .empty()) {
      r.f.skills().set_status(SkillStatus::kFailed, "get_s0: no puck seen at INS_1, INS_2");
    }
    if (!r.f.find("task", {{"kind", Value::symbol("GET_CONSUMED")}}).empty()) {
      ++out.get_consumed_tasks;
    }
    if (!r.f.find("task", {{"kind", Value::symbol("WAIT")}}).empty()) ++out.wait_tasks;
    REQUIRE(r.f.agent().runtime_errors() == 0);
  }
  out.calls = r.f.skills().calls();
  return out;
}

int calls_of(const EmptyStorage& e, const std::string& skill_call) {
  int n = 0;
  for (const std::string& c : e.calls) n += c.rfind(skill_call, 0) == 0 ? 1 : 0;
  return n;
}

}  // namespace

TEST_CASE("recycle never: no consumed puck is taken, also when the storage looks empty") {
  SUBCASE("recycle-when-empty unset (default FALSE): the robot waits and looks again in 30 s") {
    Rules r({clips::ConfigEntry::of("/clips-agent/recycle", "never")});
    const EmptyStorage e = empty_storage_minute(r);
    CHECK(e.get_consumed_tasks == 0);
    CHECK(calls_of(e, "get_consumed") == 0);
    CHECK(e.wait_tasks > 250);            // the empty storage was seen and waited out ...
    CHECK(calls_of(e, "get_s0{}") >= 2);  // ... and looked at again
  }
  SUBCASE("recycle-when-empty FALSE") {
    Rules r({clips::ConfigEntry::of("/clips-agent/recycle", "never"),
             clips::ConfigEntry::of("/clips-agent/recycle-when-empty", false)});
    const EmptyStorage e = empty_storage_minute(r);
    CHECK(e.get_consumed_tasks == 0);
    CHECK(calls_of(e, "get_s0{}") >= 2);
  }
  SUBCASE("recycle-when-empty TRUE: the consumed puck beside M4 instead of waiting") {
    Rules r({clips::ConfigEntry::of("/clips-agent/recycle", "never"),
             clips::ConfigEntry::of("/clips-agent/recycle-when-empty", true)});
    const EmptyStorage e = empty_storage_minute(r);
    CHECK(calls_of(e, "get_consumed{place=\"M4\"}") == 1);
    CHECK(e.get_consumed_tasks > 0);
  }
}

TEST_CASE("production: a T3 that rejects the S0 has one: noted, and the next S0 goes elsewhere") {
  // An insert that failed half-way (the robot stuck after the puck reached the reader) still
  // counted at the machine; without noting it the agent brought S0 after S0 to the same T3,
  // each rejected (yellow blinking), for the rest of the game (robotino-2013, now
  // robotino-2013-omniscient, seed 50).
  Rules r;
  r.production("P1", "M3");
  r.f.agent().set_pose({2.0, 1.0, 0.0});
  r.eval("(t-hold S0)");
  r.f.steps(2);
  REQUIRE(r.last_call() == "finish_puck_at{place=\"M3\"}");
  r.f.skills().set_status(SkillStatus::kFailed,
                          "finish_puck_at: M3 rejected the puck (yellow blinking: invalid input)");
  r.f.steps(2);
  const auto m3 = r.f.find("machine", {{"name", Value::symbol("M3")}});
  REQUIRE(m3.size() == 1);
  REQUIRE(m3[0].slot("loaded-with").items.size() == 1);
  CHECK(m3[0].slot("loaded-with").items[0] == Value::symbol("S0"));
  CHECK(r.f.find("holding", {{"puck", Value::symbol("UNKNOWN")}}).size() == 1);
  // The rejected puck is left aside; with the S0 noted at the T3, the next S0 goes to a T1.
  CHECK(r.last_call().rfind("leave_puck", 0) == 0);
  r.f.skills().set_status(SkillStatus::kFinal);
  r.f.steps(2);
  CHECK(r.last_call() == "get_s0{}");
  r.f.skills().set_status(SkillStatus::kFinal);
  r.f.steps(2);
  CHECK(r.last_call() == "finish_puck_at{place=\"M8\"}");
  CHECK(r.f.agent().runtime_errors() == 0);
}

TEST_CASE("recycling: consumed pucks the robot cannot drive up to are given up") {
  // A consumed puck beside M10 lay too close to the wall for the navigator (INVALID_GOAL);
  // robots tried to fetch it again and again for the rest of the game (ideal, P1-P2-P3-RD, 68).
  Rules r({clips::ConfigEntry::of("/clips-agent/recycle", "ifpossible")});
  r.production("P1", "M3");
  r.f.agent().set_pose({2.0, 1.0, 0.0});
  r.eval("(do-for-fact ((?m machine)) (eq ?m:name M1) (modify ?m (consumed 1)))");
  r.f.steps(2);
  REQUIRE(r.last_call() == "get_consumed{place=\"M1\"}");
  r.f.skills().set_status(SkillStatus::kFailed,
                          "get_consumed: TAKE()/take_puck failed: APPROACH()/drive_to failed: "
                          "navigator INVALID_GOAL: goal (4.2, 1.2) is 0.232 m from wall y=0; the "
                          "robot needs 0.260 m");
  r.f.steps(2);
  const auto m1 = r.f.find("machine", {{"name", Value::symbol("M1")}});
  REQUIRE(m1.size() == 1);
  CHECK(m1[0].slot("consumed") == Value::integer_value(0));
  // Whatever the robot does next, it does not go back for that puck.
  bool s0 = false;
  for (int i = 0; i < 5 && !s0; ++i) {
    CHECK(r.last_call() != "get_consumed{place=\"M1\"}");
    s0 = r.last_call() == "get_s0{}";
    r.f.skills().set_status(SkillStatus::kFinal);
    r.f.steps(2);
  }
  CHECK(s0);
  CHECK(r.f.agent().runtime_errors() == 0);
}

TEST_CASE("role change time-left: only between two productions, never one under way") {
  // The 2013 agent changed P1P2 -> P3 when too little time was left "and nothing is loaded"; a
  // rule that changed whenever the robot held nothing turned every game's P1P2 robot into a P3
  // at exactly 420 s left, abandoning the pucks already in its T3 (thesis experiment, F3).
  Rules r({clips::ConfigEntry::of("/clips-agent/role-change/time-left", 420)});
  r.production("P1P2", "M3");
  r.f.agent().set_pose({2.0, 1.0, 0.0});
  r.eval("(t-loaded M3 S0 S1)");
  r.eval("(do-for-fact ((?g game)) TRUE (modify ?g (time 600.0)))");  // 300 s left
  r.f.steps(2);
  CHECK(r.f.find("role", {{"name", Value::symbol("P1P2")}}).size() == 1);
  // The product is taken out: nothing loaded any more, and too little time for another one.
  r.eval("(t-loaded M3)");
  r.f.steps(2);
  CHECK(r.f.find("role", {{"name", Value::symbol("P3")}}).size() == 1);
  CHECK(r.f.agent().runtime_errors() == 0);
}

TEST_CASE("role change time-left: not while enough time is left") {
  Rules r({clips::ConfigEntry::of("/clips-agent/role-change/time-left", 420)});
  r.production("P1P2", "M3");
  r.eval("(do-for-fact ((?g game)) TRUE (modify ?g (time 400.0)))");  // 500 s left
  r.f.steps(2);
  CHECK(r.f.find("role", {{"name", Value::symbol("P1P2")}}).size() == 1);
  r.eval("(do-for-fact ((?g game)) TRUE (modify ?g (time 481.0)))");  // 419 s left
  r.f.steps(2);
  CHECK(r.f.find("role", {{"name", Value::symbol("P3")}}).size() == 1);
}
