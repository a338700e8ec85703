// SPDX-License-Identifier: MIT
// Time feature ((time), now, timeout, timers) and skills feature (skill-call, skill facts).
#include <doctest/doctest.h>

#include "llsf/clips/testing.h"

using namespace llsf;
using namespace llsf::clips;

TEST_CASE("one (time sec usec) fact per cycle, retracted at the end") {
  AgentFixture f;
  f.load("(defrule see-time (time ?s ?u) => (assert (saw ?s ?u)))");
  f.step(core::SimTime::from_ms(1250));
  CHECK(f.has("(saw 1 250000)"));
  CHECK(f.facts("time").empty());
  f.step();
  CHECK(f.has("(saw 1 350000)"));
  CHECK(f.agent().eval("(now)") == Value::float_value(1.35));
}

TEST_CASE("time helpers") {
  AgentFixture f;
  f.step();
  auto& a = f.agent();
  CHECK(a.eval("(time-diff-sec (create$ 5 500000) (create$ 3 0))") == Value::float_value(2.5));
  CHECK(a.eval("(time-diff (create$ 5 0) (create$ 3 500000))") ==
        Value::multifield({Value::integer_value(1), Value::integer_value(500000)}));
  CHECK(a.eval("(timeout (create$ 5 0) (create$ 3 0) 1.5)").is_symbol("TRUE"));
  CHECK(a.eval("(timeout (create$ 5 0) (create$ 3 0) 2.5)").is_symbol("FALSE"));
  CHECK(a.eval("(timeout 5.0 3 1)").is_symbol("TRUE"));
  CHECK(a.eval("(time> (create$ 5 1) (create$ 5 0))").is_symbol("TRUE"));
  CHECK(a.runtime_errors() == 0);
  a.eval("(timeout abc 3 1)");
  CHECK(a.runtime_errors() == 1);
}

TEST_CASE("a timer fires periodically") {
  AgentFixture f;
  f.load(
      "(deffacts timers (timer (name beacon)))\n"
      "(defrule send-beacon (time $?now)\n"
      "  ?t <- (timer (name beacon) (time $?last&:(timeout ?now ?last 1.0)) (seq ?seq))\n"
      "  => (modify ?t (time ?now) (seq (+ ?seq 1))))\n");
  f.steps(35);  // 3.5 s: more than 1 s after the last send: at 1.1, 2.2 and 3.3 s
  const auto t = f.facts("timer");
  REQUIRE(t.size() == 1);
  CHECK(t[0].slot("seq") == Value::integer_value(4));
}

TEST_CASE("skill-call builds the skill string as Fawkes does") {
  AgentFixture f;
  f.step();
  auto& a = f.agent();
  a.eval("(skill-call drive_to place M1)");
  a.eval("(skill-call goto x 1 y -2.5 ori 0.0)");
  a.eval("(skill-call say text \"a \\\"quoted\\\" word\" loud true)");
  a.eval("(skill-call move args \"{1, 2}\")");
  a.eval("(skill-call stop)");
  const auto& calls = f.skills().calls();
  REQUIRE(calls.size() == 5);
  CHECK(calls[0] == "drive_to{place=\"M1\"}");
  CHECK(calls[1] == "goto{x=1, y=-2.5, ori=0}");
  CHECK(calls[2] == "say{text=\"a \\\"quoted\\\" word\", loud=true}");
  CHECK(calls[3] == "move{args={1, 2}}");
  CHECK(calls[4] == "stop{}");
}

TEST_CASE("the skill fact follows the runner: IDLE, RUNNING, FINAL, then retracted") {
  AgentFixture f;
  f.load(
      "(defrule start (start) => (skill-call drive_to place M1))\n"
      "(defrule done (skill (name \"drive_to\") (status FINAL)) => (assert (arrived)))\n");
  f.step();
  f.assert_fact("(start)");
  f.step();
  auto s = f.facts("skill");
  REQUIRE(s.size() == 1);
  CHECK(s[0].slot("name") == Value::string("drive_to"));  // a STRING, as in Fawkes
  CHECK(s[0].slot("status") == Value::symbol("IDLE"));
  CHECK(s[0].slot("skill-string") == Value::string("drive_to{place=\"M1\"}"));
  f.step();  // the fake runner reports RUNNING after exec()
  s = f.facts("skill");
  REQUIRE(s.size() == 1);
  CHECK(s[0].slot("status") == Value::symbol("RUNNING"));
  f.skills().set_status(SkillStatus::kFinal);
  f.step();
  CHECK(f.has("(arrived)"));
  CHECK(f.facts("skill").empty());  // retracted at very low salience
}

TEST_CASE("a failed skill carries the runner's error; a new call aborts the old one") {
  AgentFixture f;
  f.load(
      "(defrule failed (skill (name ?n) (status FAILED) (error ?e)) => (assert (failed ?n ?e)))");
  f.step();
  f.agent().eval("(skill-call drive_to place M1)");
  f.step();
  f.skills().set_status(SkillStatus::kFailed, "no path");
  f.step();
  CHECK(f.has("(failed \"drive_to\" \"no path\")"));

  f.agent().eval("(skill-call drive_to place M2)");
  f.agent().eval("(skill-call get_s0)");
  f.step();
  CHECK(f.has("(failed \"drive_to\" \"aborted by skill-call get_s0{}\")"));
  const auto s = f.facts("skill");
  REQUIRE(s.size() == 1);
  CHECK(s[0].slot("name") == Value::string("get_s0"));

  f.agent().eval("(skill-stop)");
  f.step();
  CHECK(f.skills().stops() == 1);
  CHECK(f.has("(failed \"get_s0\" \"stopped by skill-stop\")"));
}

TEST_CASE("skill-call without a runner is a runtime error") {
  AgentHost host(AgentConfig{}, AgentIo{});
  host.cycle(core::SimTime::from_ms(100));
  host.eval("(skill-call drive_to place M1)");
  CHECK(host.runtime_errors() == 1);
}

TEST_CASE("a finished skill fact carries the runner's result") {
  AgentFixture f;
  f.load(
      "(defrule start (start) => (skill-call explore_machine place M3))\n"
      "(defrule done (skill (name \"explore_machine\") (status FINAL) (result ?r))\n"
      "  => (assert (code ?r)))\n");
  f.step();
  f.assert_fact("(start)");
  f.steps(2);
  f.skills().set_result("M3 red=ON yellow=OFF green=BLINK");
  f.skills().set_status(SkillStatus::kFinal);
  f.step();
  CHECK(f.has("(code \"M3 red=ON yellow=OFF green=BLINK\")"));
}
