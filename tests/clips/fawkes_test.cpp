// SPDX-License-Identifier: MIT
// Fawkes' agent model (AgentConfig::fawkes, docs/fawkes.md): an entry file run as a batch file,
// path-load (also from rules) inside the agent directory only, (reset), config-load, the feature
// facts, Fawkes' utility functions, (now) and timers, the pb-* peer functions and writable
// nested messages, the agent's own lock template, per-robot (seed). The agents here are small
// Fawkes-style agents written for these tests.
#include <doctest/doctest.h>
#include <llsf_agent_msgs/Worldmodel.pb.h>

#include <filesystem>

#include "llsf/clips/testing.h"
#include "llsf/comm/registry.h"
#include "support/temp_dir.h"

using namespace llsf;
using namespace llsf::clips;

namespace {

// An agent directory laid out as Fawkes' clips-dirs: the agent's files in a subdirectory.
struct AgentDir {
  test::TempDir dir{"llsf_fawkes"};
  AgentDir() { std::filesystem::create_directories(dir.path / "demo"); }
  void write(const std::string& name, const std::string& text) const { dir.write(name, text); }
  std::string path(const std::string& name) const { return dir.file(name); }
};

AgentConfig fawkes_config(const AgentDir& d) {
  AgentConfig c;
  c.fawkes = true;
  c.agent_dir = d.dir.path.string();
  c.config = {ConfigEntry::of("/clips-agent/demo/robot-name", "R-1"),
              ConfigEntry::of("/clips-agent/demo/peer-port", 4444),
              ConfigEntry::of("/other/value", 1)};
  return c;
}

// The entry file: top-level commands, path-load of the others (one from a rule), (reset).
constexpr const char* kEntry = R"clp(
; demo.clp - a Fawkes-style entry file
(path-load demo/globals.clp)
(printout t "entry file running" crlf)

(defrule load-config
  (init)
  =>
  (config-load "/clips-agent"))

(deffacts startup (init))

(defrule enable-protobuf
  (ff-feature protobuf)
  =>
  (ff-feature-request "protobuf"))

(defrule initialize
  (agent-init)
  (ff-feature-loaded protobuf)
  =>
  (path-load demo/rules.clp)
  (reset))
)clp";

constexpr const char* kGlobals = R"clp(
(defglobal ?*ROBOT-NAME* = "?")
(defrule globals-robot-name
  (confval (path "/clips-agent/demo/robot-name") (type STRING) (value ?n))
  =>
  (bind ?*ROBOT-NAME* ?n))
)clp";

constexpr const char* kRules = R"clp(
(deffacts demo-facts (state IDLE))
(defrule ready
  (state IDLE)
  (confval (path "/clips-agent/demo/peer-port") (value ?p))
  =>
  (assert (ready ?p)))
)clp";

}  // namespace

TEST_CASE("a Fawkes-style entry file runs as Fawkes' clips-agent ran it") {
  AgentDir d;
  d.write("demo/demo.clp", kEntry);
  d.write("demo/globals.clp", kGlobals);
  d.write("demo/rules.clp", kRules);
  AgentFixture f(fawkes_config(d));
  f.load_file(d.path("demo/demo.clp"));
  CHECK(f.logged("entry file running"));
  // After the agent's (reset): its deffacts, the feature facts kept, its config loaded again by
  // its own rule (only the prefix it asked for), the rules of the file path-loaded by a rule.
  CHECK(f.has("(init)"));
  CHECK(f.has("(state IDLE)"));
  CHECK(f.has("(ff-feature protobuf)"));
  CHECK(f.has("(ff-feature-loaded protobuf)"));
  CHECK(f.has("(ff-feature-loaded config)"));  // the clips-agent's own request
  CHECK_FALSE(f.has("(agent-init)"));          // gone with the reset, as in Fawkes
  CHECK(f.has("(ready 4444)"));
  CHECK(f.find("confval", {{"path", Value::string("/other/value")}}).empty());
  CHECK(f.agent().eval("?*ROBOT-NAME*") == Value::string("R-1"));
  f.step();
  CHECK(f.agent().runtime_errors() == 0);
}

TEST_CASE("/clips-agent/auto-start asserts (start) once the agent has started") {
  AgentDir d;
  d.write("demo/demo.clp", "(defrule go (start) => (assert (going)))\n");
  AgentConfig c = fawkes_config(d);
  c.config.push_back(ConfigEntry::of("/clips-agent/auto-start", true));
  AgentFixture f(c);
  f.load_file(d.path("demo/demo.clp"));
  CHECK(f.has("(start)"));
  f.step();
  CHECK(f.has("(going)"));
}

TEST_CASE("Fawkes' utility functions, (now) as (sec usec), timers start now") {
  AgentDir d;
  d.write("demo/demo.clp", "(defrule t (time $?now) => (assert (timer (name beacon))))\n");
  AgentFixture f(fawkes_config(d));
  f.load_file(d.path("demo/demo.clp"));
  f.step(core::SimTime::from_ms(1500));
  CHECK(f.agent().eval("(now)") ==
        Value::multifield({Value::integer_value(1), Value::integer_value(500000)}));
  const auto timers = f.facts("timer");
  REQUIRE(timers.size() == 1);
  CHECK(timers[0].slot("time") == f.agent().eval("(now)"));
  CHECK(f.agent().eval("(append$ (create$ a b) c d)") ==
        Value::multifield(
            {Value::symbol("a"), Value::symbol("b"), Value::symbol("c"), Value::symbol("d")}));
  CHECK(f.agent().eval("(set-diff (create$ a b c) (create$ b))") ==
        Value::multifield({Value::symbol("a"), Value::symbol("c")}));
  CHECK(f.agent().eval("(set-eq (create$ a b) (create$ b a))") == Value::boolean(true));
  CHECK(f.agent().eval("(is-odd-int 3)") == Value::boolean(true));
  CHECK(f.agent().eval("(is-even-int 3)") == Value::boolean(false));
  CHECK(f.agent().eval("(str-replace \"a-b-c\" \"-\" \"+\")") == Value::string("a+b-c"));
  CHECK(f.agent().eval("(string> \"b\" \"a\")") == Value::boolean(true));
  CHECK(f.agent().eval("(debug 3)") == Value::boolean(false));  // ?*DEBUG* is 2
  CHECK(f.agent().eval("(length$ (randomize$ (create$ 1 2 3 4)))") == Value::integer_value(4));
}

TEST_CASE("path-load reads only the agent directory; load errors name file and line") {
  AgentDir d;
  test::TempDir outside("llsf_fawkes_outside");
  outside.write("secret.clp", "(defrule stolen => (assert (stolen)))\n");
  const std::string escape =
      std::filesystem::relative(outside.file("secret.clp"), d.dir.path).string();
  d.write("demo/demo.clp", "(path-load demo/bad.clp)\n(path-load \"" + escape +
                               "\")\n(path-load demo/missing.clp)\n(no-such-function 1)\n");
  d.write("demo/bad.clp", "(defrule ok => (assert (ok)))\n\n(defrule broken =>\n");
  AgentFixture f(fawkes_config(d));
  try {
    f.load_file(d.path("demo/demo.clp"));
    FAIL("no load error");
  } catch (const AgentLoadError& e) {
    const std::string what = e.what();
    INFO(what);
    CHECK(what.find("demo/bad.clp:4: [PRNTUTIL2] Syntax Error") != std::string::npos);
    CHECK(what.find("demo.clp:1: ") == std::string::npos);  // the file's own place only
    CHECK(what.find("demo.clp:2: path-load: ") != std::string::npos);
    CHECK(what.find("is outside the agent directory") != std::string::npos);
    CHECK(what.find("demo.clp:3: path-load: no file demo/missing.clp") != std::string::npos);
    CHECK(what.find("demo.clp:4: [EXPRNPSR3] Missing function declaration for no-such-function") !=
          std::string::npos);
  }
  CHECK_FALSE(f.has("(stolen)"));
  // Still no file access otherwise.
  CHECK_THROWS_AS(f.load("(defrule r => (open \"x\" f \"w\"))"), AgentLoadError);
}

TEST_CASE("a path-load during the game that fails is a runtime error naming the rule") {
  AgentDir d;
  d.write("demo/demo.clp", "(defrule later (time $?) => (path-load demo/none.clp))\n");
  AgentFixture f(fawkes_config(d));
  f.load_file(d.path("demo/demo.clp"));
  f.step();
  CHECK(f.agent().runtime_errors() == 1);
  CHECK(f.logged("runtime error in rule later"));
  CHECK(f.logged("path-load: no file demo/none.clp"));
}

TEST_CASE("an unbalanced entry file is a load error at the form's line") {
  AgentDir d;
  d.write("demo/demo.clp", "(printout t \"x\" crlf)\n\n(defrule r\n  (a) => (assert (b))\n");
  AgentFixture f(fawkes_config(d));
  CHECK_THROWS_WITH_AS(f.load_file(d.path("demo/demo.clp")),
                       doctest::Contains("demo.clp:3: the form that starts here is not closed"),
                       AgentLoadError);
}

TEST_CASE("ff-feature-request: TRUE for what the host offers, FALSE otherwise") {
  AgentDir d;
  d.write("demo/demo.clp", "(defglobal ?*A* = (ff-feature-request \"motor-switch\"))\n");
  AgentFixture f(fawkes_config(d));
  f.load_file(d.path("demo/demo.clp"));
  CHECK(f.agent().eval("?*A*") == Value::boolean(true));
  CHECK(f.agent().eval("(ff-feature-request \"navgraph\")") == Value::boolean(false));
  CHECK(f.logged("the host offers no feature navgraph"));
}

TEST_CASE("motor-enable and motor-disable switch the robot's motors") {
  std::vector<bool> switched;
  AgentIo io;
  io.motor = [&switched](bool on) { switched.push_back(on); };
  AgentHost a(AgentConfig{}, io);
  a.eval("(motor-disable)");
  a.eval("(motor-enable)");
  CHECK(switched == std::vector<bool>{false, true});
}

TEST_CASE("(seed n) draws per robot: same n, other robot, other numbers; same robot, same") {
  auto draws = [](std::uint64_t robot_seed) {
    AgentConfig c;
    c.seed = robot_seed;
    AgentFixture f(c);
    f.agent().eval("(seed 42)");
    return f.agent().eval("(create$ (random 0 1000000) (random 0 1000000) (random 0 1000000))");
  };
  CHECK(draws(7) == draws(7));
  CHECK_FALSE(draws(7) == draws(8));
}

TEST_CASE("a nested message read from an unset field can be filled and set") {
  comm::MessageRegistry reg;
  comm::add_agent_messages(reg);
  for (const bool fawkes : {false, true}) {
    CAPTURE(fawkes);
    AgentConfig c;
    c.fawkes = fawkes;
    AgentFixture f(c, &reg);
    f.agent().eval("(pb-peer-enable \"172.26.255.255\" 4444)");
    f.load(
        "(defrule send (time $?) (not (sent)) =>\n"
        "  (assert (sent))\n"
        "  (bind ?m (pb-create \"llsf_agent_msgs.WorldmodelChange\"))\n"
        "  (bind ?in (pb-field-value ?m \"incoming\"))\n"  // not set: a new message
        "  (pb-set-field ?in \"action\" \"FINISH\")\n"
        "  (pb-set-field ?in \"agent\" \"robot1\")\n"
        "  (pb-set-field ?m \"incoming\" ?in)\n"
        "  (pb-set-field ?m \"change\" ADD_LOADED_WITH)\n"
        "  (pb-set-field ?m \"agent\" \"robot1\")\n"
        "  (pb-set-field ?m \"id\" 7)\n"
        "  (pb-broadcast ?m)\n"
        "  (pb-destroy ?m))");
    f.step();
    CHECK(f.agent().runtime_errors() == 0);
    REQUIRE(f.sent().size() == 1);
    const auto& m = dynamic_cast<const llsf_agent_msgs::WorldmodelChange&>(*f.sent()[0]);
    CHECK(m.incoming().action() == "FINISH");
  }
}

TEST_CASE("blackboard-open: interface facts from the pose and from written interfaces") {
  AgentDir d;
  d.write("demo/demo.clp", R"clp(
(defrule use-blackboard
  (ff-feature blackboard)
  =>
  (ff-feature-request "blackboard")
  (blackboard-enable-time-read)
  (blackboard-open "Position3DInterface" "Pose")
  (blackboard-open "RobotinoLightInterface" "Light_State")
  (blackboard-open "NoSuchInterface" "x")
  (path-load demo/sense.clp))  ; its rules match the interface templates just defined
)clp");
  d.write("demo/sense.clp", R"clp(
(defrule seen-pose
  (Position3DInterface (id "Pose") (translation ?x ?y ?) (rotation $?q))
  =>
  (assert (seen-pose ?x ?y (nth$ 4 ?q))))
(defrule seen-light
  (RobotinoLightInterface (id "Light_State") (red ?r) (ready TRUE) (visibility_history ?v))
  =>
  (assert (seen-light ?r ?v)))
)clp");
  AgentFixture f(fawkes_config(d));
  f.load_file(d.path("demo/demo.clp"));
  CHECK(f.logged("blackboard-open: no interface type NoSuchInterface"));
  f.agent().set_pose({1.5, 2.0, 0.0});
  f.step();
  CHECK(f.has("(seen-pose 1.5 2.0 1.0)"));
  CHECK(f.facts("Position3DInterface").empty());     // retracted at the end of the cycle
  CHECK(f.facts("RobotinoLightInterface").empty());  // nothing written yet
  f.agent().write_interface("RobotinoLightInterface", "Light_State",
                            {{"red", Value::symbol("ON")},
                             {"yellow", Value::symbol("OFF")},
                             {"green", Value::symbol("BLINKING")},
                             {"visibility_history", Value::integer_value(25)},
                             {"ready", Value::boolean(true)}});
  f.step();
  CHECK(f.has("(seen-light ON 25)"));
  CHECK(f.agent().runtime_errors() == 0);
}

TEST_CASE("pb peers, clients and Fawkes' field answers") {
  comm::MessageRegistry reg;
  comm::add_agent_messages(reg);
  AgentDir d;
  d.write("demo/demo.clp", "(deffacts none)\n");
  AgentConfig c = fawkes_config(d);
  std::vector<std::string> sent_to_server;
  int broadcasts = 0;
  AgentIo io;
  io.messages = &reg;
  io.broadcast = [&broadcasts](const google::protobuf::Message&) { ++broadcasts; };
  io.send = [&sent_to_server](const google::protobuf::Message& m) {
    sent_to_server.push_back(m.GetTypeName());
  };
  AgentHost a(c, io);
  a.load_file(d.path("demo/demo.clp"));
  a.load_string("(defglobal ?*m* = (pb-create \"llsf_agent_msgs.LockMessage\"))", "g.clp");
  a.eval("(pb-set-field ?*m* \"type\" GET)");
  a.eval("(pb-set-field ?*m* \"agent\" \"R-1\")");
  a.eval("(pb-set-field ?*m* \"resource\" \"M1\")");
  // No peer yet: nothing goes out (a warning), and nothing is heard.
  a.eval("(pb-broadcast ?*m*)");
  CHECK(broadcasts == 0);
  auto heard = std::make_unique<llsf_agent_msgs::WorldmodelChange>();
  a.receive(std::move(heard), "robot2", 2, core::SimTime::from_ms(50));
  a.load_string("(defrule heard (protobuf-msg) => (assert (heard)))", "r.clp");
  a.cycle(core::SimTime::from_ms(100));
  CHECK(a.facts("heard").empty());
  // The peer: the radio; a second form of pb-broadcast with its id.
  const Value peer = a.eval("(pb-peer-create \"172.26.255.255\" 4444)");
  CHECK(peer == Value::integer_value(1));
  a.eval("(pb-broadcast ?*m*)");
  a.eval("(pb-broadcast 1 ?*m*)");
  CHECK(broadcasts == 2);
  a.receive(std::make_unique<llsf_agent_msgs::WorldmodelChange>(), "robot2", 2,
            core::SimTime::from_ms(150));
  a.cycle(core::SimTime::from_ms(200));
  CHECK(a.facts("heard").size() == 1);
  const int errors = a.runtime_errors();
  a.eval("(pb-broadcast 7 ?*m*)");  // no such peer
  CHECK(broadcasts == 2);
  // A client of the game's stream server.
  const Value client = a.eval("(pb-connect \"localhost\" 4444)");
  REQUIRE(client.type == Value::Type::kInteger);
  a.eval("(pb-send " + client.to_string() + " ?*m*)");
  CHECK(sent_to_server == std::vector<std::string>{"llsf_agent_msgs.LockMessage"});
  a.eval("(pb-send 99 ?*m*)");  // no such connection
  CHECK(sent_to_server.size() == 1);
  a.eval("(pb-disconnect " + client.to_string() + ")");
  CHECK(a.eval("(any-factp ((?f protobuf-client-disconnected)) TRUE)") == Value::boolean(true));
  // Fawkes' answers for fields.
  CHECK(a.eval("(pb-field-type ?*m* \"agent\")") == Value::symbol("STRING"));
  CHECK(a.eval("(pb-field-label ?*m* \"type\")") == Value::symbol("REQUIRED"));
  CHECK(a.eval("(pb-field-value ?*m* \"no_field\")") == Value::symbol("DOES-NOT-EXIST"));
  a.load_string("(defglobal ?*w* = (pb-create \"llsf_agent_msgs.WorldmodelChange\"))", "w.clp");
  CHECK(a.eval("(pb-field-value ?*w* \"machine\")") == Value::symbol("NOT-SET"));
  CHECK(a.runtime_errors() == errors + 2);  // the unknown peer and the unknown connection
}
