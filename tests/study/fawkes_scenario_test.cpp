// SPDX-License-Identifier: MIT
// Fawkes-style agents in a scenario (docs/fawkes.md): robots.agent {fawkes, entry, protos}, the
// agent's own .proto files registered with the radio (its messages travel between the robots),
// its own lock template beside the host (host locks off), its peer, and the scenario's errors.
// The agent is a small Fawkes-style agent written for this test.
#include <doctest/doctest.h>

#include <filesystem>
#include <string>

#include "llsf/core/error.h"
#include "llsf/sim/agent_brain.h"
#include "llsf/sim/driver.h"
#include "llsf/study/player.h"
#include "llsf/study/runner.h"
#include "llsf/study/scenario.h"
#include "support/fawkes_agent.h"
#include "support/temp_dir.h"

using namespace llsf;
using namespace llsf::study;

namespace {

// A "ping" agent: its own message type (package demo_msgs, not compiled into llsfsim), its own
// lock template, a peer enabled from its config; each robot pings once a second, counts the
// pings of the others and records them as lock facts of its own template.
constexpr const char* kProto = R"pb(
  syntax = "proto2"
  ;
package demo_msgs;
import "Stamp.proto";
message Ping {
  enum CompType {
    COMP_ID  = 3000;
    MSG_TYPE = 1;
  }
  required string agent = 1;
  optional Stamp stamp = 2;
}
)pb";

constexpr const char* kStampProto = R"pb(
  syntax = "proto2"
  ;
package demo_msgs;
message Stamp {
  required int64 sec = 1;
  required int64 usec = 2;
}
)pb";

constexpr const char* kEntry = R"clp(
(path-load ping/globals.clp)
(defrule load-config (init) => (config-load "/clips-agent"))
(deffacts init (init))
(defrule enable-protobuf (ff-feature protobuf) => (ff-feature-request "protobuf"))
(defrule initialize
  (agent-init)
  (ff-feature-loaded protobuf)
  =>
  (path-load ping/lock.clp)
  (path-load ping/net.clp)
  (reset))
)clp";

constexpr const char* kGlobals = R"clp(
(defglobal ?*NAME* = "?")
(defrule name-from-config
  (confval (path "/clips-agent/ping/robot-name") (type STRING) (value ?n))
  =>
  (bind ?*NAME* ?n))
)clp";

// The agent's own lock template: the agent is a STRING, unlike llsfsim's host template.
constexpr const char* kLock = R"clp(
(deftemplate lock
  (slot type (type SYMBOL) (allowed-values GET REFUSE ACCEPT RELEASE RELEASE_RVCD))
  (slot agent (type STRING))
  (slot resource (type SYMBOL)))
(deffacts lock-facts (timer (name ping) (time (create$ 0 0))))
)clp";

constexpr const char* kNet = R"clp(
(defrule net-enable
  (confval (path "/clips-agent/ping/peer-address") (value ?a))
  (confval (path "/clips-agent/ping/peer-port") (value ?p))
  (not (peer-enabled))
  =>
  (pb-peer-enable ?a ?p ?p)
  (assert (peer-enabled)))

(defrule ping
  (peer-enabled)
  (time $?now)
  ?t <- (timer (name ping) (time $?last&:(timeout ?now ?last 1.0)))
  =>
  (modify ?t (time ?now))
  (bind ?m (pb-create "demo_msgs.Ping"))
  (pb-set-field ?m "agent" ?*NAME*)
  (bind ?s (pb-create "demo_msgs.Stamp"))
  (pb-set-field ?s "sec" (nth$ 1 ?now))
  (pb-set-field ?s "usec" (nth$ 2 ?now))
  (pb-set-field ?m "stamp" ?s)
  (pb-destroy ?s)
  (pb-broadcast ?m)
  (pb-destroy ?m))

(defrule pinged
  ?f <- (protobuf-msg (type "demo_msgs.Ping") (ptr ?p))
  =>
  (retract ?f)
  (bind ?from (pb-field-value ?p "agent"))
  (bind ?sec (pb-field-value (pb-field-value ?p "stamp") "sec"))
  (assert (lock (type GET) (agent ?from) (resource (sym-cat M ?sec)))))
)clp";

struct PingAgent {
  test::TempDir dir{"llsf_fawkes_scenario"};
  PingAgent() {
    namespace fs = std::filesystem;
    fs::create_directories(dir.path / "agents/ping/msgs");
    dir.write("agents/ping/ping.clp", kEntry);
    dir.write("agents/ping/globals.clp", kGlobals);
    dir.write("agents/ping/lock.clp", kLock);
    dir.write("agents/ping/net.clp", kNet);
    dir.write("agents/ping/msgs/Ping.proto", kProto);
    dir.write("agents/ping/msgs/Stamp.proto", kStampProto);
  }
  std::string scenario(const std::string& robots_extra = "") const {
    const std::string text = R"yaml(
name: fawkes ping
duration_s: 6
robots:
  count: 2
  agent: {fawkes: agents, entry: ping/ping, protos: [ping/msgs]}
  config: {ping: {peer-address: 172.26.255.255, peer-port: 4444}}
  each:
    - {config: {ping: {robot-name: R-1}}}
    - {config: {ping: {robot-name: R-2}}}
)yaml" + robots_extra;
    dir.write("s.yaml", text);
    return dir.file("s.yaml");
  }
};

// Plays robot 0 of `s` (its agent as the scenario configures it) to `seconds` and returns its
// agent, checked to have had no runtime error.
const clips::AgentHost& play_robot_0(sim::GameDriver& driver, const Scenario& s, double seconds) {
  sim::AgentBrain& brain = driver.plug_agent(0, agent_config(s, s.robots.at(0)));
  driver.run_until(core::SimTime::from_seconds(seconds));
  CHECK(brain.agent().runtime_errors() == 0);
  return brain.agent();
}

}  // namespace

TEST_CASE("a Fawkes-style agent's own messages travel between the robots") {
  const PingAgent a;
  const ScenarioFile f = load_scenario(a.scenario());
  const Scenario& s = f.variants.at(0);
  REQUIRE(s.robots.at(0).fawkes);
  REQUIRE(s.game.agent_protos.size() == 1);
  sim::GameDriver driver(s.game);
  std::vector<sim::AgentBrain*> brains;
  for (int i = 0; i < 2; ++i) {
    brains.push_back(&driver.plug_agent(i, agent_config(s, s.robots[static_cast<std::size_t>(i)])));
  }
  driver.run_until(core::SimTime::from_seconds(5.0));
  for (int i = 0; i < 2; ++i) {
    CAPTURE(i);
    const clips::AgentHost& agent = brains[static_cast<std::size_t>(i)]->agent();
    CHECK(agent.runtime_errors() == 0);
    // The other robot's pings, as the agent's own lock facts (agent a STRING).
    const std::string other = i == 0 ? "R-2" : "R-1";
    const auto locks = agent.find_facts("lock", {{"agent", clips::Value::string(other)}});
    CHECK(locks.size() >= 3);
    CHECK(agent.find_facts("lock", {{"agent", clips::Value::string(i == 0 ? "R-1" : "R-2")}})
              .empty());  // a broadcast does not come back to its sender
  }
}

TEST_CASE("a Fawkes-style agent's scenario: the host's locks off, paths inside, protos parsed") {
  const PingAgent a;
  CHECK_THROWS_WITH_AS(load_scenario(a.scenario("  locks: true\n")),
                       doctest::Contains("the host's lock protocol is off for a Fawkes-style"),
                       core::ConfigError);
  a.dir.write("bad.yaml", R"yaml(
name: escape
robots:
  agent: {fawkes: agents, entry: ../s.yaml}
)yaml");
  CHECK_THROWS_WITH_AS(load_scenario(a.dir.file("bad.yaml")),
                       doctest::Contains("is outside the agent directory"), core::ConfigError);
  a.dir.write("agents/ping/msgs/Broken.proto", "syntax = \"proto2\";\nmessage { }\n");
  CHECK_THROWS_WITH_AS(load_scenario(a.scenario()), doctest::Contains("Broken.proto:2:"),
                       core::ConfigError);
}

TEST_CASE("a Fawkes-style agent's messages collide with llsfsim's 2013 lock numbering") {
  const PingAgent a;
  // A LockMessage of the agent's own at the 2013 pair, as the team's agent has it.
  a.dir.write("agents/ping/msgs/LockMessage.proto", R"pb(
    syntax = "proto2"
    ;
package llsf_msgs;
message LockMessage {
  enum CompType { COMP_ID = 2000; MSG_TYPE = 1337; }
  required string agent = 1;
}
)pb");
  const ScenarioFile ok = load_scenario(a.scenario());
  CHECK_NOTHROW(sim::GameDriver(ok.variants.at(0).game));
  const ScenarioFile clash = load_scenario(a.scenario("radio: {lock_messages: 2013}\n"));
  CHECK_THROWS_WITH_AS(sim::GameDriver(clash.variants.at(0).game),
                       doctest::Contains("collides with llsf_agent_msgs.LockMessage"),
                       core::ConfigError);
}

TEST_CASE("a Fawkes-style agent reads the light detection as RobotinoLightInterface Light_State") {
  test::TempDir dir{"llsf_fawkes_light"};
  test::write_blackboard_agent(dir, "agents", "light", {{"RobotinoLightInterface", "Light_State"}},
                               R"clp(
(defrule seen-light
  (RobotinoLightInterface (id "Light_State") (red ?r) (ready ?ready) (visibility_history ?v))
  =>
  (assert (seen-light ?r ?ready ?v)))
)clp");
  dir.write("s.yaml", R"yaml(
name: fawkes light
duration_s: 3
robots:
  count: 1
  agent: {fawkes: agents, entry: light/light}
)yaml");
  const ScenarioFile f = load_scenario(dir.file("s.yaml"));
  sim::GameDriver driver(f.variants.at(0).game);
  const clips::AgentHost& agent = play_robot_0(driver, f.variants.at(0), 2.0);
  // At its start pose the robot sees no signal: UNKNOWN, not ready, and a visibility history
  // that counts down from -1 in frames of the skill rate (30 Hz), one fact per agent cycle.
  const auto seen = agent.facts("seen-light");
  REQUIRE(seen.size() >= 10);
  bool unknown_not_ready = true;
  std::int64_t lowest = 0;
  for (const clips::Fact& fact : seen) {
    const std::vector<clips::Value>& v = fact.fields();
    REQUIRE(v.size() == 3);
    unknown_not_ready = unknown_not_ready && v[0].text == "UNKNOWN" && v[1].text == "FALSE";
    lowest = std::min(lowest, v[2].integer);
  }
  CHECK(unknown_not_ready);
  CHECK(lowest <= -50);  // about 2 s at 30 frames per second
}

TEST_CASE("what a skill writes with Fawkes' API reaches a Fawkes-style agent's blackboard") {
  test::TempDir dir{"llsf_fawkes_written"};
  std::filesystem::create_directories(dir.path / "skills");
  test::write_blackboard_agent(dir, "agents", "mark",
                               {{"RobotinoLightInterface", "Light determined"}}, R"clp(
(defrule call-mark (time $?) (not (called)) => (assert (called)) (skill-call mark))
(defrule determined
  (RobotinoLightInterface (id "Light determined") (green ?g) (ready ?r))
  =>
  (assert (determined ?g ?r)))
)clp");
  dir.write("skills/mark.lua", R"lua(
module(..., skillenv.module_init)
name = "mark"
fsm = SkillHSM:new{name=name, start="SET"}
depends_interfaces = {
  {v="output", type="RobotinoLightInterface", id="Light determined", writing=true},
}
documentation = "writes Light determined"
skillenv.skill_module(_M)
fsm:define_states{export_to=_M, {"SET", JumpState}}
fsm:add_transitions{{"SET", "FINAL", cond=true}}
function SET:init()
  output:set_green(output.ON)
  output:set_ready(true)
end
)lua");
  dir.write("s.yaml", R"yaml(
name: fawkes written
duration_s: 3
robots:
  count: 1
  agent: {fawkes: agents, entry: mark/mark}
skills: {skill_dirs: [skills]}
)yaml");
  const ScenarioFile f = load_scenario(dir.file("s.yaml"));
  sim::GameDriver driver(f.variants.at(0).game);
  const clips::AgentHost& agent = play_robot_0(driver, f.variants.at(0), 2.0);
  const auto facts = agent.facts("determined");
  REQUIRE(facts.size() == 1);
  CHECK(facts[0].fields().at(0).text == "ON");
  CHECK(facts[0].fields().at(1).text == "TRUE");
}

TEST_CASE("a Fawkes-style agent drives by NavigatorInterface messages and reads the navigator") {
  test::TempDir dir{"llsf_fawkes_nav"};
  test::write_blackboard_agent(dir, "agents", "nav",
                               {{"Position3DInterface", "Pose"},
                                {"NavigatorInterface", "Pathplan"},
                                {"MotorInterface", "Robotino"}},
                               R"clp(
(defrule go
  (Position3DInterface (id "Pose") (translation ?x ?y ?))
  (not (goal $?))
  =>
  (bind ?m (blackboard-create-msg "NavigatorInterface::Pathplan" "PolarGotoMessage"))
  (blackboard-set-msg-field ?m "phi" 0.0)
  (blackboard-set-msg-field ?m "dist" 0.5)
  (assert (goal (blackboard-send-msg ?m) ?x ?y)))
(defrule arrived
  (goal ?id ?x0 ?y0)
  (NavigatorInterface (id "Pathplan") (msgid ?id) (final TRUE) (error_code 0))
  (Position3DInterface (id "Pose") (translation ?x ?y ?))
  (not (arrived $?))
  =>
  (assert (arrived (sqrt (+ (** (- ?x ?x0) 2) (** (- ?y ?y0) 2))))))
(defrule motor-odometry
  (MotorInterface (id "Robotino") (odometry_position_x ?x))
  =>
  (assert (odometry-read)))
)clp");
  dir.write("s.yaml", R"yaml(
name: fawkes navigator
duration_s: 12
robots:
  count: 1
  agent: {fawkes: agents, entry: nav/nav}
)yaml");
  const ScenarioFile f = load_scenario(dir.file("s.yaml"));
  const Scenario& s = f.variants.at(0);
  sim::GameDriver driver(s.game);
  sim::AgentBrainConfig c;
  c.agent_files = s.robots.at(0).agent;
  c.config = s.robots.at(0).config;
  c.fawkes = true;
  c.agent_dir = s.robots.at(0).agent_dir;
  sim::AgentBrain& brain = driver.plug_agent(0, c);
  driver.run_until(core::SimTime::from_seconds(10.0));
  const clips::AgentHost& agent = brain.agent();
  CHECK(agent.runtime_errors() == 0);
  const auto goal = agent.facts("goal");
  REQUIRE(goal.size() == 1);
  CHECK(goal[0].fields().at(0).integer > 0);  // the navigator's goal id
  const auto arrived = agent.facts("arrived");
  REQUIRE(arrived.size() == 1);
  CHECK(arrived[0].fields().at(0).real == doctest::Approx(0.5).epsilon(0.2));
  CHECK(agent.facts("odometry-read").size() == 1);
}
