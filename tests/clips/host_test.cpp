// SPDX-License-Identifier: MIT
// Agent host: loading (file:line errors), the cycle (firing limit, runtime errors), output
// routing, identity, pose, config facts, seeded random, the test fixture itself.
#include <doctest/doctest.h>

#include <cstdio>
#include <fstream>

#include "llsf/clips/agent.h"
#include "llsf/clips/testing.h"
#include "llsf/core/config.h"

using namespace llsf;
using namespace llsf::clips;

namespace {

std::string load_error(AgentFixture& f, std::string_view code, std::string_view name) {
  try {
    f.load(code, name);
  } catch (const AgentLoadError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST_CASE("a syntax error names the file and line") {
  AgentFixture f;
  const std::string err = load_error(f,
                                     "(defrule ok (a) => (assert (b)))\n"
                                     "\n"
                                     "(deftemplate machine (slot name))\n"
                                     "(defrule bad\n"
                                     "  (machine (nmae M1))\n"
                                     "  =>\n"
                                     "  (assert (c)))\n",
                                     "agents/demo.clp");
  CHECK(err.find("agents/demo.clp:5: ") == 0);
  CHECK(err.find("nmae") != std::string::npos);
  CHECK(err.find("defrule MAIN::bad") != std::string::npos);
}

TEST_CASE("every error is listed, one line each") {
  AgentFixture f;
  const std::string err = load_error(f,
                                     "(defrule a (x) => (no-such-function))\n"
                                     "(defrule b (y) =>\n"
                                     "  (also-missing 1))\n",
                                     "two.clp");
  CHECK(err.find("two.clp:1: ") == 0);
  CHECK(err.find("\ntwo.clp:3: ") != std::string::npos);
  CHECK(err.find("no-such-function") != std::string::npos);
}

TEST_CASE("unbalanced parentheses and garbage fail to load") {
  AgentFixture f;
  CHECK(load_error(f, "(defrule a (x) => (assert (y))\n", "open.clp").find("open.clp:") == 0);
  CHECK(load_error(f, "hello\n", "junk.clp").find("junk.clp:1:") == 0);
}

TEST_CASE("load_file reads the file and reports its path") {
  const std::string path = "llsf_clips_test_agent.clp";
  {
    std::ofstream out(path);
    out << "; comment\n(defrule r (go) => (assert (went)))\n(defrule s =>\n  (bogus))\n";
  }
  AgentFixture f;
  try {
    f.load_file(path);
    FAIL("no error");
  } catch (const AgentLoadError& e) {
    CHECK(std::string(e.what()).find(path + ":4: ") == 0);
  }
  std::remove(path.c_str());
  CHECK_THROWS_AS(f.load_file("/nonexistent/agent.clp"), AgentLoadError);
}

TEST_CASE("a cycle runs to quiescence") {
  AgentFixture f;
  f.load(
      "(defrule count (counter ?n&:(< ?n 5)) ?c <- (counter ?n) => (retract ?c) (assert (counter "
      "(+ "
      "?n 1))))");
  f.step();
  f.assert_fact("(counter 0)");
  const CycleResult r = f.step();
  CHECK(r.rules_fired == 5);  // (the host retracts the time fact: no rule fires for it)
  CHECK_FALSE(r.limit_reached);
  CHECK(f.has("(counter 5)"));
}

TEST_CASE("an endless rule loop is cut at the firing limit and reported") {
  AgentConfig cfg;
  cfg.max_rules_per_cycle = 50;
  AgentFixture f(cfg);
  f.load("(defrule spin ?f <- (spin ?n) => (retract ?f) (assert (spin (+ ?n 1))))");
  f.step();
  f.assert_fact("(spin 0)");
  const CycleResult r = f.step();
  CHECK(r.limit_reached);
  CHECK(r.rules_fired == 50);
  CHECK(f.agent().limit_hits() == 1);
  CHECK(f.logged("rule firing limit of 50"));
  // The next cycle gets a fresh budget and still works.
  CHECK(f.step().rules_fired == 50);
}

TEST_CASE("a runtime error is logged with the rule name and the agent keeps going") {
  AgentFixture f;
  f.load(
      "(defrule bad (value ?v) => (assert (sum (+ 1 ?v))))\n"
      "(defrule good (declare (salience -1)) (value ?) => (assert (still-running)))\n");
  f.step();
  f.assert_fact("(value abc)");
  const CycleResult r = f.step();
  CHECK(r.runtime_errors == 1);
  CHECK(f.agent().runtime_errors() == 1);
  CHECK(f.logged("runtime error in rule bad"));
  CHECK(f.has("(still-running)"));
  // Wrong arguments to one of our functions: same path.
  f.load("(defrule bad-call (call-it) => (skill-call drive_to place))");
  f.assert_fact("(call-it)");
  CHECK(f.step().runtime_errors == 1);
  CHECK(
      f.logged("runtime error in rule bad-call (test.clp:1): [LLSF1] skill-call: arguments must "
               "come in key"));
  CHECK(f.agent().runtime_errors() == 2);
}

TEST_CASE("rules are named with their file:line in runtime errors and the firing limit") {
  AgentConfig cfg;
  cfg.max_rules_per_cycle = 50;
  AgentFixture f(cfg);
  f.load(
      "; (defrule commented-out => )\n"
      "(defrule ok => (assert (ok)))\n"
      "\n"
      "(defrule\n  spin ?f <- (spin ?n) => (retract ?f) (assert (spin (+ ?n 1))))\n"
      "(defrule bad (value ?v) => (assert (sum (+ 1 ?v))))\n",
      "agent/spin.clp");
  f.step();
  f.assert_fact("(value abc)");
  CycleResult r = f.step();
  CHECK(r.runtime_errors == 1);
  CHECK(f.logged("runtime error in rule bad (agent/spin.clp:6): "));
  f.assert_fact("(spin 0)");
  r = f.step();
  CHECK(r.limit_reached);
  CHECK(f.logged("(endless rule loop?); next: rule spin (agent/spin.clp:4)"));
}

TEST_CASE("the work budget stops a runaway rule's actions, names it, and the game goes on") {
  AgentConfig cfg;
  cfg.max_steps_per_cycle = 100'000;
  AgentFixture f(cfg);
  f.load(
      "(defrule forever (go) => (bind ?i 0) (while TRUE (bind ?i (+ ?i 1))))\n"
      "(defrule flood (flood) => (loop-for-count (?i 20000000) (assert (x ?i))))\n"
      "(defrule alive (time $?) => (assert (alive)))\n",
      "runaway.clp");
  f.step();
  const std::int64_t normal_steps = f.agent().max_cycle_steps();
  CHECK(normal_steps > 0);
  CHECK(normal_steps < 1'000);
  f.assert_fact("(go)");
  CycleResult r = f.step();
  CHECK(r.budget_exceeded);
  CHECK(r.runtime_errors == 1);
  CHECK(r.steps > 100'000);
  CHECK(
      f.logged("runtime error in rule forever (runaway.clp:1): stopped after 100000 steps of "
               "work in one agent cycle (an endless loop in its actions?); the game goes on"));
  // The next cycle has a fresh budget: the agent goes on.
  r = f.step();
  CHECK_FALSE(r.budget_exceeded);
  CHECK(r.runtime_errors == 0);
  CHECK(f.has("(alive)"));
  // 20 million asserts in one rule's actions: stopped the same way.
  f.assert_fact("(flood)");
  r = f.step();
  CHECK(r.budget_exceeded);
  CHECK(f.logged("runtime error in rule flood (runaway.clp:2): stopped after 100000 steps"));
  CHECK(f.agent().runtime_errors() == 2);
  CHECK_FALSE(f.step().budget_exceeded);
}

TEST_CASE("recursion without end in deffunctions stops at the call depth, names the function") {
  AgentFixture f;
  f.load(
      "(deffunction down (?n) (+ 1 (down (+ ?n 1))))\n"
      "(deffunction pong (?n))\n"
      "(deffunction ping (?n) (pong ?n))\n"
      "(deffunction pong (?n) (ping ?n))\n"
      "(defgeneric spiral)\n"
      "(defmethod spiral ((?n INTEGER)) (spiral (+ ?n 1)))\n"
      "(deffunction depth (?n) (if (> ?n 0) then (+ 1 (depth (- ?n 1))) else 0))\n"
      "(deffunction fib (?n) (if (< ?n 2) then ?n else (+ (fib (- ?n 1)) (fib (- ?n 2)))))\n"
      "(defrule r-down (down) => (assert (got (down 0))))\n"
      "(defrule r-ping (ping) => (ping 1))\n"
      "(defrule r-spiral (spiral) => (spiral 1))\n"
      "(defrule r-deep (deep) => (assert (deep-result (depth 1500))))\n"
      "(defrule r-fib (fib) => (assert (fib-result (fib 40))))\n"
      "(defrule alive (time $?) => (assert (alive)))\n",
      "recurse.clp");
  const int depth = AgentConfig{}.max_call_depth;
  f.step();
  f.assert_fact("(down)");
  CycleResult r = f.step();
  CHECK(r.budget_exceeded);
  CHECK(r.runtime_errors == 1);
  CHECK(f.logged("runtime error in rule r-down (recurse.clp:9): stopped at a call depth of " +
                 std::to_string(depth) +
                 " in down (recurse.clp:1) (a recursion without end?); the game goes on"));
  // The game goes on: the next cycle runs normally.
  r = f.step();
  CHECK_FALSE(r.budget_exceeded);
  CHECK(f.has("(alive)"));
  // Mutual recursion and a generic function's method: the same.
  f.assert_fact("(ping)");
  CHECK(f.step().budget_exceeded);
  CHECK(f.logged("runtime error in rule r-ping (recurse.clp:10): stopped at a call depth of"));
  f.assert_fact("(spiral)");
  CHECK(f.step().budget_exceeded);
  CHECK(f.logged("in spiral (recurse.clp:6) (a recursion without end?)"));
  // A deep but finite recursion within the limit works.
  f.assert_fact("(deep)");
  r = f.step();
  CHECK_FALSE(r.budget_exceeded);
  CHECK(f.has("(deep-result 1500)"));
  // Shallow but exponential work: every call is a step of the work budget.
  f.assert_fact("(fib)");
  r = f.step();
  CHECK(r.budget_exceeded);
  CHECK(f.logged("runtime error in rule r-fib (recurse.clp:13): stopped after 1000000 steps"));
  CHECK(f.agent().runtime_errors() == 4);
  CHECK_FALSE(f.step().budget_exceeded);
}

TEST_CASE("printout and log functions reach the sink with the simulated time") {
  AgentFixture f;
  f.load(
      "(defrule hello (time $?) (not (said)) => (assert (said))\n"
      "  (printout t \"hello \" ?*ROBOT-NAME* crlf)\n"
      "  (printout warn \"careful\" crlf)\n"
      "  (log-error \"bad \" 42 \" \" 1.5))\n");
  f.steps(3);
  REQUIRE(f.log().size() >= 3);
  const auto& hello = f.log()[0];
  CHECK(hello.text == "hello robot1");
  CHECK(hello.level == LogLevel::kInfo);
  CHECK(hello.time == core::SimTime::from_ms(100));
  CHECK(f.log()[1].level == LogLevel::kWarn);
  CHECK(f.log()[2].text == "bad 42 1.5");
  CHECK(f.log()[2].level == LogLevel::kError);
}

TEST_CASE("identity globals and robot-info") {
  AgentConfig cfg;
  cfg.robot_name = "robot3";
  cfg.robot_number = 3;
  cfg.team_name = "Team Test";
  AgentFixture f(cfg);
  f.step();
  CHECK(f.agent().eval("?*ROBOT-NAME*") == Value::symbol("robot3"));
  CHECK(f.agent().eval("?*ROBOT-NUMBER*") == Value::integer_value(3));
  CHECK(f.agent().eval("?*TEAM-NAME*") == Value::string("Team Test"));
  const auto info = f.facts("robot-info");
  REQUIRE(info.size() == 1);
  CHECK(info[0].slot("name") == Value::symbol("robot3"));
  CHECK(info[0].slot("team") == Value::string("Team Test"));
}

TEST_CASE("bad configs are refused") {
  AgentConfig cfg;
  cfg.robot_name = "robot 1";
  CHECK_THROWS_AS(AgentFixture{cfg}, std::invalid_argument);
  cfg = {};
  cfg.max_rules_per_cycle = 0;
  CHECK_THROWS_AS(AgentFixture{cfg}, std::invalid_argument);
}

TEST_CASE("the pose fact follows set_pose and changes only when the pose does") {
  AgentFixture f;
  f.step();
  CHECK(f.facts("pose").empty());
  f.agent().set_pose({1.5, 2.0, 0.25});
  f.step();
  auto p = f.facts("pose");
  REQUIRE(p.size() == 1);
  CHECK(p[0].slot("x") == Value::float_value(1.5));
  CHECK(p[0].slot("ori") == Value::float_value(0.25));
  const auto index = p[0].index;
  f.agent().set_pose({1.5, 2.0, 0.25});
  f.step();
  CHECK(f.facts("pose")[0].index == index);
  f.agent().set_pose({1.6, 2.0, 0.25});
  f.step();
  p = f.facts("pose");
  REQUIRE(p.size() == 1);
  CHECK(p[0].slot("x") == Value::float_value(1.6));
}

TEST_CASE("confval facts from entries and from YAML") {
  AgentConfig cfg;
  cfg.config.push_back(ConfigEntry::of("/clips-agent/llsf2013/team-name", "Carologistics"));
  cfg.config.push_back(ConfigEntry::of("/clips-agent/llsf2013/lock-timeout", 0.5));
  cfg.config.push_back(ConfigEntry::of("/clips-agent/llsf2013/enable-sim", true));
  cfg.config.push_back(
      ConfigEntry::list("/clips-agent/llsf2013/machines", std::vector<std::string>{"M1", "M2"}));
  const auto node = core::ConfigNode::parse(
      "llsf2013:\n  robot-timeout: 30\n  offset: -2\n  role: P3\n  ratios: [0.5, 1.5]\n",
      "agent.yaml");
  for (auto& e : config_from_node(node, "/clips-agent")) cfg.config.push_back(e);
  AgentFixture f(cfg);
  f.load(
      "(defrule team (confval (path \"/clips-agent/llsf2013/team-name\") (value ?t))\n"
      "  => (assert (team ?t)))");
  f.step();
  CHECK(f.has("(team \"Carologistics\")"));
  auto c = f.find("confval", {{"path", Value::string("/clips-agent/llsf2013/lock-timeout")}});
  REQUIRE(c.size() == 1);
  CHECK(c[0].slot("type") == Value::symbol("FLOAT"));
  CHECK(c[0].slot("value") == Value::float_value(0.5));
  c = f.find("confval", {{"path", Value::string("/clips-agent/llsf2013/enable-sim")}});
  CHECK(c[0].slot("value") == Value::symbol("TRUE"));
  c = f.find("confval", {{"path", Value::string("/clips-agent/llsf2013/machines")}});
  CHECK(c[0].slot("is-list") == Value::symbol("TRUE"));
  CHECK(c[0].slot("list-value").items.size() == 2);
  c = f.find("confval", {{"path", Value::string("/clips-agent/llsf2013/robot-timeout")}});
  REQUIRE(c.size() == 1);
  CHECK(c[0].slot("type") == Value::symbol("UINT"));
  CHECK(c[0].slot("value") == Value::integer_value(30));
  c = f.find("confval", {{"path", Value::string("/clips-agent/llsf2013/offset")}});
  CHECK(c[0].slot("type") == Value::symbol("INT"));
  c = f.find("confval", {{"path", Value::string("/clips-agent/llsf2013/role")}});
  CHECK(c[0].slot("value") == Value::string("P3"));
  c = f.find("confval", {{"path", Value::string("/clips-agent/llsf2013/ratios")}});
  CHECK(c[0].slot("type") == Value::symbol("FLOAT"));
  CHECK(c[0].slot("list-value") ==
        Value::multifield({Value::float_value(0.5), Value::float_value(1.5)}));
}

TEST_CASE("random is seeded per agent and repeats") {
  auto draws = [](std::uint64_t seed) {
    AgentConfig cfg;
    cfg.seed = seed;
    AgentFixture f(cfg);
    f.step();
    std::vector<std::int64_t> out;
    for (int i = 0; i < 5; ++i) out.push_back(f.agent().eval("(random 1 1000)").integer);
    return out;
  };
  CHECK(draws(7) == draws(7));
  CHECK(draws(7) != draws(8));
  AgentFixture f;
  f.step();
  for (int i = 0; i < 20; ++i) {
    const auto v = f.agent().eval("(random 3 5)").integer;
    CHECK(v >= 3);
    CHECK(v <= 5);
  }
  f.agent().eval("(seed 99)");
  const auto a = f.agent().eval("(random)").integer;
  f.agent().eval("(seed 99)");
  CHECK(f.agent().eval("(random)").integer == a);
}

TEST_CASE("start() restarts the facts, the rules stay") {
  AgentFixture f;
  f.load(
      "(deffacts init (state IDLE)) (defrule go ?s <- (state IDLE) (go) => (retract ?s) (assert "
      "(state BUSY)))");
  f.step();
  CHECK(f.has("(state IDLE)"));
  f.assert_fact("(go)");
  f.step();
  CHECK(f.has("(state BUSY)"));
  f.agent().start(f.now());
  CHECK(f.has("(state IDLE)"));
  CHECK_FALSE(f.has("(go)"));
}

TEST_CASE("fixture helpers: bad facts and queries") {
  AgentFixture f;
  f.load("(deftemplate machine (slot name) (slot mtype))");
  f.step();
  CHECK_THROWS_AS(f.assert_fact("(machine (nope 1))"), std::invalid_argument);
  f.assert_fact("(machine (name M1) (mtype T1))");
  f.assert_fact("(machine (name M2) (mtype T2))");
  CHECK(f.facts("machine").size() == 2);
  CHECK(f.find("machine", {{"mtype", Value::symbol("T2")}}).size() == 1);
  CHECK(f.find("machine", {{"mtype", Value::symbol("T3")}}).empty());
  CHECK(f.agent().runtime_errors() == 0);
}

TEST_CASE("fact-by-slot finds the fact a do-for-fact query would, or FALSE") {
  AgentFixture f;
  f.load(
      "(deftemplate m (slot name) (slot n) (multislot l))\n"
      "(deffacts ms (m (name M1) (n 1)) (m (name M2) (n 2.0)) (m (name M2) (n 3)))\n");
  f.step();
  auto index = [&](const std::string& expr) { return f.agent().eval(expr); };
  // The first of two M2 facts, as find-fact (the query functions' order) gives it.
  const Value by_slot = index("(fact-index (fact-by-slot m name M2))");
  const Value by_query = index("(fact-index (nth$ 1 (find-fact ((?x m)) (eq ?x:name M2))))");
  CHECK(by_slot.type == Value::Type::kInteger);
  CHECK(by_slot == by_query);
  CHECK(index("(fact-slot-value (fact-by-slot m name M1) n)") == Value::integer_value(1));
  // eq semantics: 2 is not 2.0; unknown values give FALSE.
  CHECK(index("(fact-by-slot m n 2)") == Value::boolean(false));
  CHECK(index("(fact-slot-value (fact-by-slot m n 2.0) name)") == Value::symbol("M2"));
  CHECK(index("(fact-by-slot m name M9)") == Value::boolean(false));
  // Modified in a rule: the look-up sees the new fact.
  f.load(
      "(defrule rename (go) =>\n"
      "  (bind ?m (fact-by-slot m name M1))\n"
      "  (if ?m then (modify ?m (name M7))))\n");
  f.assert_fact("(go)");
  CHECK(f.step().runtime_errors == 0);
  CHECK(index("(fact-by-slot m name M1)") == Value::boolean(false));
  CHECK(index("(fact-slot-value (fact-by-slot m name M7) n)") == Value::integer_value(1));
  // Wrong templates and slots are runtime errors that name them.
  f.load(
      "(defrule bad-template (bad1) => (fact-by-slot nosuch name M1))\n"
      "(defrule bad-slot (bad2) => (fact-by-slot m nosuch M1))\n"
      "(defrule bad-multislot (bad3) => (fact-by-slot m l M1))\n");
  f.assert_fact("(bad1)");
  f.assert_fact("(bad2)");
  f.assert_fact("(bad3)");
  CHECK(f.step().runtime_errors == 3);
  CHECK(f.logged("fact-by-slot: no deftemplate with slots named nosuch"));
  CHECK(f.logged("fact-by-slot: deftemplate m has no slot nosuch"));
  CHECK(f.logged("fact-by-slot: deftemplate m has a multislot l: use a single-field slot"));
}

TEST_CASE("a misspelt function or slot gets the name meant, at load and at run time") {
  AgentFixture f;
  const std::string fn = load_error(f, "(defrule a (x) => (pritnout t \"hi\" crlf))\n", "fn.clp");
  CHECK(fn.find("fn.clp:1: [EXPRNPSR3] Missing function declaration for pritnout (did you mean "
                "'printout'?)") == 0);
  const std::string slot = load_error(f,
                                      "(deftemplate job (slot place) (slot state))\n"
                                      "(defrule b (job (plac M1)) => (assert (y)))\n",
                                      "slot.clp");
  CHECK(slot.find("plac") != std::string::npos);
  CHECK(slot.find("(did you mean 'place'?)") != std::string::npos);
  // A deffunction of the agent counts too; a name far from all gets no guess.
  f.load(
      "(deffunction double-it (?x) (* 2 ?x))\n"
      "(defrule c (go) => (eval \"(doubel-it 2)\"))\n"
      "(defrule d (go) => (eval \"(zzzzzz 1)\"))\n",
      "run.clp");
  f.step();  // (reset)
  f.assert_fact("(go)");
  f.step();
  CHECK(f.logged("Missing function declaration for doubel-it (did you mean 'double-it'?)"));
  CHECK(f.logged("Missing function declaration for zzzzzz"));
  CHECK_FALSE(f.logged("zzzzzz (did you mean"));
}
