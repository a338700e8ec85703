// SPDX-License-Identifier: MIT
// Protobuf feature: protobuf-msg facts, the pb-* functions over reflection (scalars, enums,
// nested and repeated fields), broadcast, and the message pool's lifetimes.
#include <doctest/doctest.h>
#include <llsf_agent_msgs/LockMessage.pb.h>
#include <llsf_agent_msgs/Worldmodel.pb.h>

#include "llsf/clips/testing.h"
#include "llsf/clips/trace.h"
#include "llsf/comm/registry.h"

using namespace llsf;
using namespace llsf::clips;

namespace {

comm::MessageRegistry agent_registry() {
  comm::MessageRegistry r;
  comm::add_agent_messages(r);
  return r;
}

std::unique_ptr<llsf_agent_msgs::LockMessage> lock(const char* agent, const char* resource) {
  auto m = std::make_unique<llsf_agent_msgs::LockMessage>();
  m->set_type(llsf_agent_msgs::LockMessage::GET);
  m->set_agent(agent);
  m->set_resource(resource);
  return m;
}

}  // namespace

TEST_CASE("a received message becomes a protobuf-msg fact for one cycle") {
  const auto reg = agent_registry();
  AgentFixture f({}, &reg);
  f.load(
      "(defrule lock-get\n"
      "  ?pf <- (protobuf-msg (type \"llsf_agent_msgs.LockMessage\") (ptr ?p) (rcvd-from ?from "
      "?id)\n"
      "                       (comp-id ?c) (msg-type ?t) (rcvd-at ?s ?u))\n"
      "  =>\n"
      "  (retract ?pf)\n"
      "  (assert (lock (pb-field-value ?p \"type\") (pb-field-value ?p \"agent\")\n"
      "                (pb-field-value ?p \"resource\") ?from ?id ?c ?t ?s ?u)))\n");
  f.step();
  f.agent().receive(lock("robot2", "M1"), "robot2", 2, core::SimTime::from_ms(1050));
  CHECK(f.agent().live_messages() == 0);
  f.step();
  CHECK(f.has("(lock GET \"robot2\" \"M1\" \"robot2\" 2 2100 1 1 50000)"));
  CHECK(f.agent().live_messages() == 0);  // freed at the end of the cycle
  CHECK(f.facts("protobuf-msg").empty());
}

TEST_CASE("unconsumed protobuf-msg facts are cleaned up and their messages freed") {
  const auto reg = agent_registry();
  AgentFixture f({}, &reg);
  f.load(
      "(defrule keep-ptr (protobuf-msg (ptr ?p)) => (assert (kept ?p)))\n"
      "(defrule use-later ?k <- (kept ?p) (later) => (retract ?k) (pb-field-value ?p agent))\n");
  f.step();
  f.agent().receive(lock("robot2", "M1"), "robot2", 2, f.now());
  f.agent().receive(lock("robot3", "M2"), "robot3", 3, f.now());
  f.step();
  CHECK(f.facts("protobuf-msg").empty());
  CHECK(f.agent().live_messages() == 0);
  // A pointer kept past its cycle is refused (runtime error), not dereferenced.
  f.assert_fact("(later)");
  const CycleResult r = f.step();
  CHECK(r.runtime_errors == 2);
  CHECK(f.logged("not a live message"));
}

TEST_CASE("pb-create, set, add-list, nested messages and broadcast") {
  const auto reg = agent_registry();
  AgentFixture f({}, &reg);
  f.load(
      "(defrule send (send) =>\n"
      "  (bind ?w (pb-create \"llsf_agent_msgs.Worldmodel\"))\n"
      "  (pb-set-field ?w \"sender\" ?*ROBOT-NAME*)\n"
      "  (pb-set-field ?w \"seq\" 7)\n"
      "  (bind ?m (pb-create \"llsf_agent_msgs.MachineState\"))\n"
      "  (pb-set-field ?m \"name\" \"M1\")\n"
      "  (pb-add-list ?m \"loaded_with\" S1)\n"
      "  (pb-add-list ?m \"loaded_with\" P3)\n"
      "  (pb-set-field ?m \"produce_blocked\" TRUE)\n"
      "  (pb-set-field ?m \"prod_finished_time\" 12)\n"
      "  (pb-add-list ?w \"machines\" ?m)\n"
      "  (pb-destroy ?m)\n"
      "  (pb-broadcast ?w)\n"
      "  (assert (sent ?w)))\n");
  f.step();
  f.assert_fact("(send)");
  CHECK(f.step().runtime_errors == 0);
  REQUIRE(f.sent().size() == 1);
  const auto* w = dynamic_cast<const llsf_agent_msgs::Worldmodel*>(f.sent()[0].get());
  REQUIRE(w != nullptr);
  CHECK(w->sender() == "robot1");
  CHECK(w->seq() == 7);
  REQUIRE(w->machines_size() == 1);
  CHECK(w->machines(0).name() == "M1");
  REQUIRE(w->machines(0).loaded_with_size() == 2);
  CHECK(w->machines(0).loaded_with(1) == llsf_agent_msgs::P3);
  CHECK(w->machines(0).produce_blocked());
  CHECK(w->machines(0).prod_finished_time() == 12.0);
  CHECK(f.agent().live_messages() == 1);  // ?w lives until pb-destroy

  // Reading back: nested messages as pointers, repeated fields as multifields.
  auto& a = f.agent();
  f.load("(defglobal ?*w* = nil)");
  a.eval("(do-for-fact ((?s sent)) TRUE (bind ?*w* (nth$ 1 ?s:implied)))");
  CHECK(a.eval("(pb-field-value ?*w* \"seq\")") == Value::integer_value(7));
  CHECK(a.eval("(length$ (pb-field-list ?*w* \"machines\"))") == Value::integer_value(1));
  CHECK(a.eval("(pb-field-list (nth$ 1 (pb-field-list ?*w* \"machines\")) \"loaded_with\")") ==
        Value::multifield({Value::symbol("S1"), Value::symbol("P3")}));
  CHECK(a.eval("(pb-field-value (nth$ 1 (pb-field-list ?*w* machines)) produce_blocked)")
            .is_symbol("TRUE"));
  CHECK(a.eval("(pb-has-field ?*w* \"storage\")").is_symbol("FALSE"));
  CHECK(a.eval("(pb-has-field ?*w* \"machines\")").is_symbol("TRUE"));
  CHECK(a.eval("(pb-field-is-list ?*w* \"machines\")").is_symbol("TRUE"));
  CHECK(a.eval("(nth$ 1 (pb-field-names ?*w*))") == Value::string("sender"));
  CHECK(a.runtime_errors() == 0);
  a.eval("(pb-destroy ?*w*)");
  f.step();
  CHECK(f.agent().live_messages() == 0);
}

TEST_CASE("pb-* errors are runtime errors") {
  const auto reg = agent_registry();
  AgentFixture f({}, &reg);
  f.step();
  auto& a = f.agent();
  f.load("(defglobal ?*m* = (pb-create \"llsf_agent_msgs.LockMessage\"))");
  int errors = a.runtime_errors();
  auto expect_error = [&](const char* expr, const char* text) {
    a.eval(expr);
    CHECK_MESSAGE(a.runtime_errors() == errors + 1, expr);
    CHECK_MESSAGE(f.logged(text), expr);
    errors = a.runtime_errors();
  };
  expect_error("(pb-create \"llsf_msgs.Nope\")", "is not registered");
  expect_error("(pb-set-field ?*m* \"nope\" 1)", "has no field nope");
  expect_error("(pb-set-field ?*m* \"type\" MAYBE)", "expects a value of llsf_agent_msgs");
  expect_error("(pb-set-field ?*m* \"agent\" 3)", "expects a string");
  expect_error("(pb-add-list ?*m* \"agent\" \"x\")", "is not repeated");
  expect_error("(pb-broadcast ?*m*)", "lacks required fields");
  a.eval("(pb-set-field ?*m* \"type\" 3)");  // enums also by number
  CHECK(a.eval("(pb-field-value ?*m* \"type\")").is_symbol("ACCEPT"));
  CHECK(a.runtime_errors() == errors);
}

TEST_CASE("an unset nested message reads as a new message: filled and set, not in place") {
  const auto reg = agent_registry();
  AgentFixture f({}, &reg);
  f.step();
  auto& a = f.agent();
  f.load("(defglobal ?*c* = (pb-create \"llsf_agent_msgs.WorldmodelChange\"))");
  CHECK(a.eval("(pb-field-value (pb-field-value ?*c* incoming) action)") == Value::string(""));
  const int errors = a.runtime_errors();
  // Writing the new message changes neither the default instance nor the message...
  a.eval("(pb-set-field (pb-field-value ?*c* incoming) action \"x\")");
  CHECK(a.runtime_errors() == errors);
  CHECK(llsf_agent_msgs::Incoming::default_instance().action().empty());
  CHECK(a.eval("(pb-has-field ?*c* incoming)") == Value::boolean(false));
  // ... until it is set (as Fawkes' agents fill a nested message and set it).
  f.load("(defglobal ?*in* = (pb-field-value ?*c* incoming))");
  a.eval("(pb-set-field ?*in* action \"FINISH\")");
  a.eval("(pb-set-field ?*c* incoming ?*in*)");
  CHECK(a.eval("(pb-field-value (pb-field-value ?*c* incoming) action)") ==
        Value::string("FINISH"));
  // A set field read in place and set from itself stays as it is.
  a.eval("(pb-set-field ?*c* incoming (pb-field-value ?*c* incoming))");
  CHECK(a.eval("(pb-field-value (pb-field-value ?*c* incoming) action)") ==
        Value::string("FINISH"));
  CHECK(a.runtime_errors() == errors);
}

TEST_CASE("pb-unchanged tells a message that repeats the last one with the same key") {
  const auto reg = agent_registry();
  AgentFixture f({}, &reg);
  f.step();
  auto& a = f.agent();
  f.load(
      "(defglobal ?*a* = (pb-create \"llsf_agent_msgs.Worldmodel\")"
      "           ?*b* = (pb-create \"llsf_agent_msgs.Worldmodel\")"
      "           ?*l* = (pb-create \"llsf_agent_msgs.LockMessage\")"
      "           ?*ms* = (pb-create \"llsf_agent_msgs.MachineState\"))");
  a.eval("(pb-set-field ?*a* sender robot2)");
  a.eval("(pb-set-field ?*a* seq 1)");
  a.eval("(pb-set-field ?*b* sender robot2)");
  a.eval("(pb-set-field ?*b* seq 2)");
  const int errors = a.runtime_errors();
  CHECK(a.eval("(pb-unchanged ?*a* robot2)").is_symbol("FALSE"));  // the first with this key
  CHECK(a.eval("(pb-unchanged ?*a* robot2)").is_symbol("TRUE"));
  CHECK(a.eval("(pb-unchanged ?*a* \"robot2\")").is_symbol("TRUE"));   // a string key: the same
  CHECK(a.eval("(pb-unchanged ?*b* robot2)").is_symbol("FALSE"));      // seq differs
  CHECK(a.eval("(pb-unchanged ?*a* robot2 seq)").is_symbol("FALSE"));  // (b was kept whole)
  CHECK(a.eval("(pb-unchanged ?*b* robot2 seq)").is_symbol("TRUE"));   // but for seq: the same
  CHECK(a.eval("(pb-unchanged ?*a* robot3 seq)").is_symbol("FALSE"));  // keys are separate
  CHECK(a.eval("(pb-unchanged ?*b* 7 \"seq\")").is_symbol("FALSE"));
  CHECK(a.eval("(pb-unchanged ?*a* 7 \"seq\")").is_symbol("TRUE"));  // an integer key
  // a change in a nested message counts
  a.eval("(pb-set-field ?*ms* name M1)");
  a.eval("(pb-add-list ?*a* machines ?*ms*)");
  CHECK(a.eval("(pb-unchanged ?*a* robot2 seq)").is_symbol("FALSE"));
  CHECK(a.eval("(pb-unchanged ?*a* robot2 seq)").is_symbol("TRUE"));
  // the same key with an empty message of another type is not the same
  CHECK(a.eval("(pb-unchanged ?*l* robot4)").is_symbol("FALSE"));
  CHECK(a.eval("(pb-unchanged (pb-create \"llsf_agent_msgs.Worldmodel\") robot4)")
            .is_symbol("FALSE"));
  CHECK(a.runtime_errors() == errors);
  // the message given is not changed by the fields left out of the comparison
  CHECK(a.eval("(pb-field-value ?*b* seq)") == Value::integer_value(2));
  CHECK(a.eval("(pb-unchanged ?*a* robot6 machines seq machines)").is_symbol("FALSE"));
  CHECK(a.eval("(pb-unchanged ?*b* robot6 seq machines)").is_symbol("TRUE"));
  CHECK(a.eval("(length$ (pb-field-list ?*a* machines))") == Value::integer_value(1));
  CHECK(a.eval("(pb-field-value ?*a* seq)") == Value::integer_value(1));

  a.eval("(pb-unchanged ?*a* robot2 nope)");
  CHECK(f.logged("has no field nope"));
  a.eval("(pb-unchanged ?*a* (create$ x))");
  CHECK(f.logged("the key (argument 2) must be a symbol, string or integer"));
  CHECK(a.runtime_errors() == errors + 2);

  // (reset) forgets: the facts a skipped message would have made are gone too
  a.start(f.now());
  f.load("(defglobal ?*c* = (pb-create \"llsf_agent_msgs.Worldmodel\"))");
  CHECK(a.eval("(pb-unchanged ?*c* robot5)").is_symbol("FALSE"));
  CHECK(a.eval("(pb-unchanged ?*c* robot5)").is_symbol("TRUE"));
  a.start(f.now());
  f.load("(defglobal ?*d* = (pb-create \"llsf_agent_msgs.Worldmodel\"))");
  CHECK(a.eval("(pb-unchanged ?*d* robot5)").is_symbol("FALSE"));
}

// Messages of a type no rule can match make no fact (docs/clips.md, "Protobuf"; the analysis of
// the rules' texts: message_use_test.cpp).
namespace {

std::unique_ptr<llsf_agent_msgs::Worldmodel> worldmodel() {
  auto m = std::make_unique<llsf_agent_msgs::Worldmodel>();
  m->set_sender("robot2");
  m->set_seq(7);
  return m;
}

/// The protobuf-msg facts asserted while `f` steps once with both messages received.
std::vector<std::string> message_facts(AgentFixture& f) {
  std::vector<std::string> seen;
  f.agent().set_trace({.facts = true}, [&seen](const TraceEvent& e) {
    if (e.kind == TraceEvent::Kind::kCycleEnd) return;
    const std::string line = trace_line(e);
    if (line.find("==> ") != std::string::npos && line.find("(protobuf-msg") != std::string::npos)
      seen.push_back(line.find("LockMessage") != std::string::npos ? "LockMessage" : "Worldmodel");
  });
  f.agent().receive(lock("robot2", "M1"), "robot2", 2, f.now());
  f.agent().receive(worldmodel(), "robot2", 2, f.now());
  f.step();
  f.agent().set_trace({}, {});
  return seen;
}

}  // namespace

TEST_CASE("message use: a message no rule can match makes no fact, the others do") {
  const auto reg = agent_registry();
  AgentFixture f({}, &reg);
  f.load(
      "(defrule wm ?pf <- (protobuf-msg (type \"llsf_agent_msgs.Worldmodel\") (ptr ?p)) =>\n"
      "  (retract ?pf) (assert (wm-seq (pb-field-value ?p \"seq\"))))\n");
  f.step();
  CHECK(message_facts(f) == std::vector<std::string>{"Worldmodel"});
  CHECK(f.has("(wm-seq 7)"));
  CHECK(f.agent().live_messages() == 0);  // the skipped message is freed as well

  // A rule loaded later that reads lock messages gets them from the next cycle on.
  f.load(
      "(defrule lk ?pf <- (protobuf-msg (type \"llsf_agent_msgs.LockMessage\")) =>\n"
      "  (retract ?pf) (assert (got-lock)))\n");
  CHECK(message_facts(f) == std::vector<std::string>{"LockMessage", "Worldmodel"});
  CHECK(f.has("(got-lock)"));

  // A fact query over all messages: every message is a fact again.
  AgentFixture g({}, &reg);
  g.load(
      "(defrule count (protobuf-msg (type \"llsf_agent_msgs.LockMessage\")) =>\n"
      "  (assert (n (length$ (find-all-facts ((?m protobuf-msg)) TRUE)))))\n");
  g.step();
  CHECK(message_facts(g) == std::vector<std::string>{"LockMessage", "Worldmodel"});
  CHECK(g.has("(n 2)"));
}
