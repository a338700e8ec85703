// SPDX-License-Identifier: MIT
// Fawkes' agent model (AgentConfig::fawkes, docs/fawkes.md): an entry file run as a batch file,
// path-load (also from rules) inside the agent directory only, (reset), config-load, the feature
// facts, Fawkes' utility functions, (now) and timers, the pb-* peer functions and writable
// nested messages, the agent's own lock template, per-robot (seed). The agents here are small
// Fawkes-style agents written for these tests.
#include <doctest/doctest.h>
#include <llsf_agent_msgs/Worldmodel.pb.h>

#include <filesystem>
#include <map>

#include "llsf/clips/testing.h"
#include "llsf/comm/registry.h"
#include "support/fawkes_agent.h"
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

// The AgentLoadError of loading the entry file `path` into `f`, or "" if it loads.
std::string load_error(AgentFixture& f, const std::string& path) {
  try {
    f.load_file(path);
  } catch (const AgentLoadError& e) {
    return e.what();
  }
  return "";
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
  const std::string what = load_error(f, d.path("demo/demo.clp"));
  INFO(what);
  CHECK(what.find("demo/bad.clp:4: [PRNTUTIL2] Syntax Error") != std::string::npos);
  CHECK(what.find("demo.clp:1: ") == std::string::npos);  // the file's own place only
  CHECK(what.find("demo.clp:2: path-load: ") != std::string::npos);
  CHECK(what.find("is outside the agent directory") != std::string::npos);
  CHECK(what.find("demo.clp:3: path-load: no file demo/missing.clp") != std::string::npos);
  CHECK(what.find("demo.clp:4: [EXPRNPSR3] Missing function declaration for no-such-function") !=
        std::string::npos);
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

TEST_CASE("an entry file's places count the lines in strings; what is not a form is an error") {
  AgentDir d;
  d.write("demo/demo.clp",
          "; a comment (with a parenthesis\n"    // 1
          "(printout t \"a ; no comment\n"       // 2
          "b \\\"c\\\" \\\n"                     // 3: an escaped quote, an escaped newline
          "\" crlf) ; a comment\n"               // 4
          "(no-such-function 1)\n"               // 5
          "(defrule r (a) => (assert (b)))\n"    // 6
          "x (printout t \"not run\" crlf)\n");  // 7
  AgentFixture f(fawkes_config(d));
  const std::string what = load_error(f, d.path("demo/demo.clp"));
  INFO(what);
  CHECK(what.find("demo.clp:5: [EXPRNPSR3] Missing function declaration for no-such-function") !=
        std::string::npos);
  CHECK(what.find("demo.clp:7: expected a command or construct in parentheses") !=
        std::string::npos);
  CHECK(f.logged("b \"c\""));
  CHECK_FALSE(f.logged("not run"));
  d.write("demo/stray.clp", "(deffacts none)\n\n) (printout t \"x\" crlf)\n");
  AgentFixture g(fawkes_config(d));
  CHECK_THROWS_WITH_AS(g.load_file(d.path("demo/stray.clp")),
                       doctest::Contains("stray.clp:3: expected a command or construct"),
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
  test::write_blackboard_agent(d.dir, "", "demo",
                               {{"Position3DInterface", "Pose"},
                                {"RobotinoLightInterface", "Light_State"},
                                {"NoSuchInterface", "x"}},
                               R"clp(
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

namespace {

// The robot's blackboard as a test sets it: interface data by (type, id), the writes and
// messages the agent made.
class FakeBlackboard final : public Blackboard {
 public:
  std::map<std::pair<std::string, std::string>, InterfaceReading> data;
  std::vector<std::pair<std::string, InterfaceFields>> writes;  // uid, fields
  struct Sent {
    std::string uid, message;
    InterfaceFields fields;
  };
  std::vector<Sent> sent;

  bool read(std::string_view type, std::string_view id, InterfaceReading& out,
            std::string& error) override {
    const auto it = data.find({std::string(type), std::string(id)});
    if (it == data.end()) {
      out = InterfaceReading{};
      return true;  // a known type nothing writes
    }
    (void)error;
    out = it->second;
    return true;
  }
  std::string write(std::string_view type, std::string_view id,
                    const InterfaceFields& fields) override {
    writes.emplace_back(std::string(type) + "::" + std::string(id), fields);
    return {};
  }
  std::int64_t send(std::string_view type, std::string_view id, std::string_view message,
                    const InterfaceFields& fields, std::string& error) override {
    if (message == "TurnMessage") {
      error = "no turning here";
      return 0;
    }
    sent.push_back({std::string(type) + "::" + std::string(id), std::string(message), fields});
    return 40 + static_cast<std::int64_t>(sent.size());
  }
  void set(const std::string& type, const std::string& id, core::SimTime written,
           InterfaceFields fields, bool robot = true) {
    InterfaceReading& r = data[{type, id}];
    r.has_writer = true;
    r.robot_writer = robot;
    r.written = written;
    r.fields = std::move(fields);
  }
};

}  // namespace

TEST_CASE("blackboard: every interface type the skills have, read from the robot's blackboard") {
  AgentDir d;
  test::write_blackboard_agent(d.dir, "", "demo",
                               {{"NavigatorInterface", "Pathplan"},
                                {"MotorInterface", "Robotino"},
                                {"SwitchInterface", "ampel_red"},
                                {"RobotinoAmpelInterface", "Ampel"},
                                {"LaserClusterInterface", "laser-cluster"},
                                {"SkillerInterface", "Skiller"},
                                {"RobotinoSensorInterface", "Robotino"}},
                               R"clp(
(defrule nav (NavigatorInterface (id "Pathplan") (msgid ?m) (final ?f) (dest_x ?x) (drive_mode ?dm))
  => (assert (nav ?m ?f ?x ?dm)))
(defrule motor (MotorInterface (id "Robotino") (vx ?vx) (controller_thread_name ?n))
  => (assert (motor ?vx ?n)))
(defrule switch (SwitchInterface (id "ampel_red") (enabled ?e)) => (assert (switch ?e)))
(defrule ampel (RobotinoAmpelInterface (state ?s)) => (assert (ampel ?s)))
(defrule cluster (LaserClusterInterface (max_x ?m)) => (assert (cluster ?m)))
(defrule skiller (SkillerInterface (status ?s) (skill_string ?str)) => (assert (skiller ?s ?str)))
(defrule sensor (RobotinoSensorInterface (distance $? ?d9) (digital_in $?di))
  => (assert (sensor ?d9 (length$ ?di))))
)clp");
  FakeBlackboard bb;
  const auto t1 = core::SimTime::from_ms(100);
  bb.set("NavigatorInterface", "Pathplan", t1,
         {{"msgid", Value::integer_value(3)},
          {"final", Value::boolean(true)},
          {"dest_x", Value::integer_value(2)}});  // an integer where Fawkes has a float
  bb.set("MotorInterface", "Robotino", t1,
         {{"vx", Value::float_value(0.25)},
          {"controller_thread_name", Value::string("skiller")},
          {"no_such_field", Value::integer_value(1)}});
  bb.set("SwitchInterface", "ampel_red", t1, {{"enabled", Value::boolean(true)}});
  bb.set("RobotinoAmpelInterface", "Ampel", t1, {{"state", Value::symbol("RED")}}, false);
  bb.set("SkillerInterface", "Skiller", t1,
         {{"status", Value::integer_value(2)}, {"skill_string", Value::string("ppgoto{}")}});
  bb.set("RobotinoSensorInterface", "Robotino", t1,
         {{"distance", Value::multifield({Value::float_value(0.0), Value::float_value(0.1)})}});
  AgentFixture f(fawkes_config(d), nullptr, &bb);
  f.load_file(d.path("demo/demo.clp"));
  f.step();
  CHECK(f.has("(nav 3 TRUE 2.0 MovingNotAllowed)"));  // coerced; the enum's first value
  CHECK(f.has("(motor 0.25 \"skiller\")"));
  CHECK(f.has("(switch TRUE)"));
  CHECK(f.has("(ampel RED)"));
  CHECK(f.facts("cluster").empty());                 // nothing writes it
  CHECK(f.has("(skiller S_RUNNING \"ppgoto{}\")"));  // the enum's value by its number
  CHECK(f.has("(sensor 0.0 8)"));                    // the array at its length, the rest defaults
  CHECK(f.facts("NavigatorInterface").empty());      // retracted at the end of the cycle
  // Not written since: no new fact; written again: one.
  f.agent().load_string("(defrule count-nav (NavigatorInterface) => (assert (nav-seen (gensym*))))",
                        "count.clp");
  f.step();
  CHECK(f.facts("nav-seen").empty());
  bb.data[{"NavigatorInterface", "Pathplan"}].written = core::SimTime::from_ms(200);
  f.step();
  CHECK(f.facts("nav-seen").size() == 1);
  // The template has every field of Fawkes' definition, in its order.
  f.agent().assert_fact("(LaserClusterInterface (id \"x\") (time 1 2) (max_x 0.5))");
  const std::vector<Fact> lc = f.facts("LaserClusterInterface");
  REQUIRE(lc.size() == 1);
  CHECK(lc[0].slots.size() == 3);
  f.agent().assert_fact("(MotorInterface (id \"x\") (time 1 2))");
  const std::vector<Fact> mi = f.facts("MotorInterface");
  REQUIRE(mi.size() == 1);
  REQUIRE(mi[0].slots.size() == 19);
  CHECK(mi[0].slots[15].first == "des_vy");
  CHECK(f.agent().runtime_errors() == 0);
}

TEST_CASE("blackboard: the agent writes interfaces and sends messages") {
  AgentDir d;
  d.write("demo/demo.clp", R"clp(
(defglobal ?*msg* = FALSE)
(deffunction go-to (?x ?y)
  (bind ?m (blackboard-create-msg "NavigatorInterface::Pathplan" "CartesianGotoMessage"))
  (blackboard-set-msg-field ?m "x" ?x)
  (blackboard-set-msg-field ?m "y" ?y)
  (blackboard-send-msg ?m))
)clp");
  FakeBlackboard bb;
  bb.set("SwitchInterface", "ampel_green", core::SimTime{}, {});
  AgentFixture f(fawkes_config(d), nullptr, &bb);
  f.load_file(d.path("demo/demo.clp"));
  AgentHost& a = f.agent();
  // Writing: open, set fields (type-checked), write.
  a.eval("(blackboard-open-writing \"SwitchInterface\" \"vision_switch\")");
  a.eval("(blackboard-set \"SwitchInterface::vision_switch\" \"enabled\" TRUE)");
  a.eval("(blackboard-set \"SwitchInterface::vision_switch\" \"value\" 2)");
  a.eval("(blackboard-write \"SwitchInterface::vision_switch\")");
  REQUIRE(bb.writes.size() == 1);
  CHECK(bb.writes[0].first == "SwitchInterface::vision_switch");
  const InterfaceFields& w = bb.writes[0].second;
  REQUIRE(w.size() == 6);
  CHECK(w[0] == std::pair<std::string, Value>{"enabled", Value::boolean(true)});
  CHECK(w[1] == std::pair<std::string, Value>{"value", Value::float_value(2.0)});
  CHECK(a.runtime_errors() == 0);
  a.eval("(blackboard-set \"SwitchInterface::vision_switch\" \"enabled\" 1)");  // not a bool
  CHECK(a.runtime_errors() == 1);
  CHECK(f.logged("field enabled takes TRUE or FALSE, not 1"));
  a.eval("(blackboard-set \"SwitchInterface::vision_switch\" \"nope\" 1)");
  CHECK(f.logged("SwitchInterface::vision_switch has no field nope"));
  a.eval("(blackboard-set \"SwitchInterface::other\" \"enabled\" TRUE)");  // not opened
  CHECK(f.logged("SwitchInterface::other is not opened for writing"));
  CHECK(a.runtime_errors() == 3);
  // Arrays: blackboard-set-multifield.
  a.eval("(blackboard-open-writing \"Position3DInterface\" \"Goal\")");
  a.eval("(blackboard-set-multifield \"Position3DInterface::Goal\" \"translation\" 1.0 2.0)");
  a.eval("(blackboard-write \"Position3DInterface::Goal\")");
  REQUIRE(bb.writes.size() == 2);
  CHECK(bb.writes[1].second[3].second ==
        Value::multifield(
            {Value::float_value(1.0), Value::float_value(2.0), Value::float_value(0.0)}));
  // One writer per interface: what llsfsim's sensors write cannot be opened for writing.
  a.eval("(blackboard-open-writing \"SwitchInterface\" \"ampel_green\")");
  CHECK(f.logged("SwitchInterface::ampel_green has a writer"));
  a.eval("(blackboard-set \"SwitchInterface::ampel_green\" \"enabled\" TRUE)");
  CHECK(a.runtime_errors() == 4);

  // Messages: of an interface opened for reading; fields listed, set, sent (the id back).
  a.eval("(go-to 1 2)");           // not opened: a warning, FALSE, and FALSE is no message
  CHECK(a.runtime_errors() == 5);  // (set-msg-field on FALSE)
  CHECK(f.logged("no interface NavigatorInterface::Pathplan opened for reading"));
  a.eval("(blackboard-open \"NavigatorInterface\" \"Pathplan\")");
  const int errors = a.runtime_errors();
  CHECK(a.eval("(go-to 1.5 2)") == Value::integer_value(41));
  REQUIRE(bb.sent.size() == 1);
  CHECK(bb.sent[0].uid == "NavigatorInterface::Pathplan");
  CHECK(bb.sent[0].message == "CartesianGotoMessage");
  CHECK(bb.sent[0].fields == InterfaceFields{{"x", Value::float_value(1.5)},
                                             {"y", Value::float_value(2.0)},
                                             {"orientation", Value::float_value(0.0)}});
  a.load_string(
      "(defglobal ?*p* = (blackboard-create-msg \"NavigatorInterface::Pathplan\" "
      "\"PlaceGotoMessage\"))",
      "p.clp");
  CHECK(a.eval("(blackboard-list-msg-fields ?*p*)") == Value::multifield({Value::symbol("place")}));
  a.eval("(blackboard-set-msg-field ?*p* \"place\" \"M3\")");
  CHECK(a.eval("(blackboard-send-msg ?*p*)") == Value::integer_value(42));
  CHECK(bb.sent[1].fields == InterfaceFields{{"place", Value::string("M3")}});
  CHECK(a.runtime_errors() == errors);
  a.eval("(blackboard-send-msg ?*p*)");  // sent already
  CHECK(f.logged("not a message of blackboard-create-msg (or one already sent)"));
  CHECK(a.eval("(blackboard-create-msg \"NavigatorInterface::Pathplan\" \"FlyMessage\")") ==
        Value::boolean(false));
  CHECK(f.logged("NavigatorInterface has no message FlyMessage"));
  a.load_string(
      "(defglobal ?*t* = (blackboard-create-msg \"NavigatorInterface::Pathplan\" "
      "\"TurnMessage\"))",
      "t.clp");
  a.eval("(blackboard-send-msg ?*t*)");  // the writer refuses it: a runtime error
  CHECK(f.logged("no turning here"));
  CHECK(a.runtime_errors() == errors + 2);
}

TEST_CASE("blackboard: without a robot blackboard, what the agent writes it reads") {
  AgentDir d;
  d.write("demo/demo.clp", R"clp(
(blackboard-enable-time-read)
(blackboard-open-writing "RobotinoAmpelInterface" "Ampel")
(blackboard-open "RobotinoAmpelInterface" "Ampel")
(defrule seen (RobotinoAmpelInterface (id "Ampel") (state ?s)) => (assert (seen ?s)))
(defrule write (start) =>
  (blackboard-set "RobotinoAmpelInterface::Ampel" "state" GREEN)
  (blackboard-write "RobotinoAmpelInterface::Ampel"))
)clp");
  AgentFixture f(fawkes_config(d));
  f.load_file(d.path("demo/demo.clp"));
  f.step();
  CHECK(f.facts("seen").empty());
  f.assert_fact("(start)");
  f.step();  // the write
  f.step();  // read at the next cycle's start
  CHECK(f.has("(seen GREEN)"));
  CHECK(f.agent().runtime_errors() == 0);
}

TEST_CASE("blackboard: messages created and never sent are bounded") {
  AgentDir d;
  d.write("demo/demo.clp", "(blackboard-open \"NavigatorInterface\" \"Pathplan\")\n");
  FakeBlackboard bb;
  AgentFixture f(fawkes_config(d), nullptr, &bb);
  f.load_file(d.path("demo/demo.clp"));
  AgentHost& a = f.agent();
  a.eval(R"clp((loop-for-count 1000
    (blackboard-create-msg "NavigatorInterface::Pathplan" "CartesianGotoMessage")))clp");
  CHECK_FALSE(f.logged("messages created and not yet sent"));
  CHECK(a.eval("(blackboard-create-msg \"NavigatorInterface::Pathplan\" "
               "\"CartesianGotoMessage\")")
            .is_symbol("FALSE"));
  CHECK(f.logged("1000 messages created and not yet sent; send one"));
  CHECK(a.runtime_errors() == 0);
}

TEST_CASE("Fawkes' search path: path-add, path-add-subst, path-get, path-string, path-reset") {
  AgentDir d;
  std::filesystem::create_directories(d.dir.path / "demo" / "lib");
  d.write("demo/lib/extra.clp", "(deffacts extra (extra-loaded))\n");
  d.write("demo/demo.clp", "(deffacts none)\n");
  AgentFixture f(fawkes_config(d));
  f.load_file(d.path("demo/demo.clp"));
  AgentHost& a = f.agent();
  const std::string home = d.dir.path.string() + "/";
  CHECK(a.eval("(path-get)") == Value::multifield({Value::string(home)}));
  CHECK(a.eval("(path-resolve \"extra.clp\")") == Value::boolean(false));
  a.eval("(path-add-subst \"@LIB@\" \"demo/lib\")");
  a.eval("(path-add \"@LIB@/\")");
  CHECK(a.eval("(path-string)") == Value::string(home + ":demo/lib/"));
  CHECK(a.eval("(path-resolve \"extra.clp\")") ==
        Value::string((d.dir.path / "demo/lib/extra.clp").string()));
  CHECK(a.eval("(path-load \"extra.clp\")") == Value::boolean(true));
  // A directory outside the agent directory resolves nothing (the sandbox).
  a.eval("(path-add \"/etc/\")");
  CHECK(a.eval("(path-resolve \"passwd\")") == Value::boolean(false));
  // The path survives a reset; path-reset empties it.
  a.eval("(reset)");
  CHECK(a.eval("(path-get)").items.size() == 3);
  a.eval("(path-reset)");
  CHECK(a.eval("(path-get)") == Value::multifield({}));
  CHECK(a.eval("(path-resolve \"demo/demo.clp\")") == Value::boolean(false));
  CHECK(a.runtime_errors() == 0);
}

TEST_CASE("skill-update facts set the skill's status; pb-server-enable is accepted") {
  AgentDir d;
  d.write("demo/demo.clp", R"clp(
(defrule call (start ?) => (skill-call ppgoto place "M1"))
(defrule done (skill (name "ppgoto") (status FINAL)) => (assert (done)))
)clp");
  AgentFixture f(fawkes_config(d));
  f.load_file(d.path("demo/demo.clp"));
  f.assert_fact("(start 1)");
  f.step();
  REQUIRE(f.facts("skill").size() == 1);
  f.skills().set_status(SkillStatus::kRunning);
  f.step();
  f.assert_fact("(skill-update (name \"ppgoto\") (status FINAL))");  // as Fawkes' clips-agent
  f.step();
  CHECK(f.has("(done)"));
  CHECK(f.facts("skill-update").empty());
  // The host's next update of the skill leaves one skill fact, not two.
  f.agent().assert_fact("(start 2)");
  f.step();
  f.agent().assert_fact("(skill-update (name \"ppgoto\") (status RUNNING))");
  f.step();  // a rule modified the host's fact: the host follows it
  f.skills().set_status(SkillStatus::kFailed, "stuck");
  f.step();
  CHECK(f.find("skill", {{"status", Value::symbol("RUNNING")}}).empty());
  CHECK(f.agent().runtime_errors() == 0);

  f.agent().eval("(pb-server-enable 4444)");
  f.agent().eval("(pb-server-disable)");
  CHECK(f.agent().runtime_errors() == 0);
  f.agent().eval("(pb-server-enable 0)");
  CHECK(f.logged("pb-server-enable: expects a port (1..65535)"));
  CHECK(f.agent().runtime_errors() == 1);
}
