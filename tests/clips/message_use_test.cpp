// SPDX-License-Identifier: MIT
// Which message types an agent's rules can match (message_use.h), and that a message no rule can
// match makes no protobuf-msg fact while every other one still does.
#include "message_use.h"

#include <doctest/doctest.h>
#include <llsf_agent_msgs/LockMessage.pb.h>
#include <llsf_agent_msgs/Worldmodel.pb.h>

#include <string>
#include <vector>

#include "llsf/clips/testing.h"
#include "llsf/clips/trace.h"
#include "llsf/comm/registry.h"

using namespace llsf;
using namespace llsf::clips;
using llsf::clips::detail::matched_message_types;
using llsf::clips::detail::TypeNames;

namespace {

std::optional<TypeNames> types_of(std::vector<std::string> texts) {
  return matched_message_types(texts);
}

}  // namespace

TEST_CASE("message use: the types named by the rules' protobuf-msg patterns") {
  const std::string a =
      "(defrule MAIN::a (declare (salience 10)) ?pf <- (protobuf-msg (type \"x.A\") (ptr ?p) "
      "(rcvd-from ?f $?)) => (retract ?pf) (printout t (pb-field-value ?p \"n\") crlf))";
  const auto t = types_of({
      a,
      "(defrule MAIN::b \"a comment\" (game) (not (protobuf-msg (type \"x.B\"))) => (assert (c)))",
      "(defrule MAIN::c (exists (protobuf-msg (type \"x.A\"))) (test (> 2 1)) =>)",
      "(deffunction MAIN::f (?x) (+ ?x 1))",
      "(defglobal MAIN ?*G* = 0)",
  });
  REQUIRE(t.has_value());
  CHECK(*t == TypeNames{"x.A", "x.B"});
  CHECK(types_of({})->empty());  // no rule wants any message
}

TEST_CASE("message use: any other mention of protobuf-msg means every type") {
  const std::vector<std::string> any = {
      "(defrule MAIN::r (protobuf-msg (ptr ?p)) =>)",                    // no type
      "(defrule MAIN::r (protobuf-msg (type ?t)) =>)",                   // a variable
      "(defrule MAIN::r (protobuf-msg (type \"x.A\"|\"x.B\")) =>)",      // alternatives
      "(defrule MAIN::r (protobuf-msg (type ?t&:(eq ?t \"x.A\"))) =>)",  // a test
      "(defrule MAIN::r (protobuf-msg (type \"x.A\") (type \"x.B\")) =>)",
      "(defrule MAIN::r (protobuf-msg (type \"x.A\") (ptr ?p&:(eval \"TRUE\"))) =>)",
      "(defrule MAIN::r (go) => (do-for-all-facts ((?m protobuf-msg)) TRUE (retract ?m)))",
      "(defrule MAIN::r (go) (test (any-factp ((?m protobuf-msg)) TRUE)) =>)",
      "(deffunction MAIN::f () (find-all-facts ((?m protobuf-msg)) TRUE))",
      "(defrule MAIN::r (go) => (build \"(defrule s (go) =>)\"))",
      "(defrule MAIN::r (go) => (eval \"(facts)\"))",
      "(defrule MAIN::r (go) => (facts))",
      "(defrule MAIN::r (go) => (bind ?l (get-fact-list)))",
      "(defrule MAIN::r (go) => (printout t \"protobuf-msg\" crlf))",
      "(defrule MAIN::r (protobuf-msg (type \"x.A\") =>",  // unbalanced: not understood
  };
  for (const std::string& text : any) {
    INFO(text);
    CHECK_FALSE(types_of({"(defrule MAIN::ok (protobuf-msg (type \"x.A\")) =>)", text}));
  }
}

namespace {

comm::MessageRegistry agent_registry() {
  comm::MessageRegistry r;
  comm::add_agent_messages(r);
  return r;
}

std::unique_ptr<llsf_agent_msgs::LockMessage> lock_msg() {
  auto m = std::make_unique<llsf_agent_msgs::LockMessage>();
  m->set_type(llsf_agent_msgs::LockMessage::GET);
  m->set_agent("robot2");
  m->set_resource("M1");
  return m;
}

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
  f.agent().receive(lock_msg(), "robot2", 2, f.now());
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
