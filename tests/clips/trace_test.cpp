// SPDX-License-Identifier: MIT
// Tracing an agent (docs/clips.md, "Tracing"): rule firings with the facts that matched, fact
// assertions and retractions, messages in and out, log lines and CLIPS' own (watch ...) output.
#include <doctest/doctest.h>

#include <llsf_agent_msgs/LockMessage.pb.h>

#include <algorithm>
#include <string>
#include <vector>

#include "llsf/clips/agent.h"
#include "llsf/clips/testing.h"
#include "llsf/clips/trace.h"
#include "llsf/comm/registry.h"

using namespace llsf;
using namespace llsf::clips;

namespace {

/// Collects the trace lines of an agent.
struct Lines {
  std::vector<std::string> lines;
  TraceSink sink() {
    return [this](const TraceEvent& e) {
      if (e.kind != TraceEvent::Kind::kCycleEnd) lines.push_back(trace_line(e));
    };
  }
  bool has(std::string_view text) const {
    return std::any_of(lines.begin(), lines.end(),
                       [&](const std::string& l) { return l.find(text) != std::string::npos; });
  }
  std::string all() const {
    std::string out;
    for (const auto& l : lines) out += l + "\n";
    return out;
  }
};

constexpr const char* kSmallAgent =
    "(deftemplate machine (slot name) (slot mtype))\n"
    "(deffacts start (state IDLE) (machine (name M1) (mtype T1)))\n"
    "(defrule go\n"
    "  ?s <- (state IDLE)\n"
    "  (machine (name ?m) (mtype T1))\n"
    "  =>\n"
    "  (retract ?s)\n"
    "  (assert (state GOTO ?m)))\n";

}  // namespace

TEST_CASE("a trace shows each firing with the facts that matched, and the fact changes") {
  AgentFixture f;
  f.load(kSmallAgent);
  Lines t;
  f.agent().set_trace({.rules = true, .facts = true, .messages = true, .log = true}, t.sink());
  f.step();
  INFO(t.all());
  // The deffacts: f-1 (state IDLE), f-2 (machine ...) after the (initial-fact) f-0.
  CHECK(t.has("[   0.10] robot1 ==> f-1 (state IDLE)"));
  CHECK(t.has("[   0.10] robot1 ==> f-2 (machine (name M1) (mtype T1))"));
  CHECK(t.has("[   0.10] robot1 FIRE go  f-1 (state IDLE), f-2 (machine (name M1) (mtype T1))"));
  CHECK(t.has("[   0.10] robot1 <== f-1 (state IDLE)"));
  CHECK(t.has("==> f-"));
  CHECK(t.has("(state GOTO M1)"));
  // The host retracts the time fact at the end of the run, without a rule.
  CHECK(t.has("[   0.10] robot1 <== f-4 (time 0 100000)"));
  CHECK_FALSE(t.has("time-retract"));
}

TEST_CASE("fact_text and fact_texts print facts as CLIPS does") {
  AgentFixture f;
  f.load(kSmallAgent);
  f.step();
  std::vector<std::pair<std::int64_t, std::string>> all;
  f.agent().fact_texts(all);
  REQUIRE(!all.empty());
  bool found = false;
  for (const auto& [index, text] : all) {
    CHECK(f.agent().fact_text(index) == text);
    if (text == "(state GOTO M1)") found = true;
  }
  CHECK(found);
  CHECK(all.size() == f.agent().facts().size());
  CHECK(f.agent().fact_text(9999).empty());
  f.agent().assert_fact("(note \"a \\\"quoted\\\" string\")");
  f.agent().fact_texts(all);
  // As CLIPS 6.30 prints a fact: quotes inside a string are not escaped.
  CHECK(all.back().second == "(note \"a \"quoted\" string\")");
}

TEST_CASE("a trace selects its kinds; without a sink nothing is traced") {
  AgentFixture f;
  f.load(kSmallAgent);
  Lines t;
  f.agent().set_trace({.rules = true}, t.sink());
  f.step();
  CHECK(t.has("FIRE go"));
  CHECK_FALSE(t.has("==>"));
  t.lines.clear();
  f.agent().set_trace({}, {});
  f.assert_fact("(state IDLE)");
  f.step();
  CHECK(t.lines.empty());
  CHECK(f.has("(state GOTO M1)"));
}

TEST_CASE("(watch facts) and (watch rules) in agent code reach the log and the trace") {
  AgentFixture f;
  f.load(
      "(defrule watch-on (declare (salience 100)) (not (watching)) => (watch facts) (watch rules)"
      " (assert (watching)))\n"
      "(defrule hello (watching) (not (said)) => (printout t \"hello\" crlf) (assert (said)))\n");
  Lines t;
  f.agent().set_trace({.log = true}, t.sink());
  f.step();
  INFO(t.all());
  CHECK(f.logged("hello"));
  CHECK(t.has("log info hello"));
  // CLIPS' own watch output arrives at debug level, in the log and in the trace.
  CHECK(f.logged("==> f-"));
  CHECK(f.logged("FIRE"));
  CHECK(t.has("log debug FIRE"));
  CHECK(t.has("(said)"));
}

TEST_CASE("a trace shows messages in and out") {
  comm::MessageRegistry reg;
  comm::add_agent_messages(reg);
  AgentFixture f({}, &reg);
  f.load(
      "(defrule answer ?pf <- (protobuf-msg (type \"llsf_agent_msgs.LockMessage\")) =>\n"
      "  (retract ?pf)\n"
      "  (bind ?m (pb-create \"llsf_agent_msgs.LockMessage\"))\n"
      "  (pb-set-field ?m \"type\" ACCEPT) (pb-set-field ?m \"agent\" \"robot1\")\n"
      "  (pb-set-field ?m \"resource\" \"M2\")\n"
      "  (pb-broadcast ?m) (pb-destroy ?m))\n");
  Lines t;
  f.agent().set_trace({.messages = true}, t.sink());
  f.step();
  auto m = std::make_unique<llsf_agent_msgs::LockMessage>();
  m->set_type(llsf_agent_msgs::LockMessage::GET);
  m->set_agent("robot2");
  m->set_resource("M1");
  f.agent().receive(std::move(m), "robot2", 2, core::SimTime::from_ms(150));
  f.step();
  INFO(t.all());
  CHECK(
      t.has("[   0.15] robot1 msg <- robot2 LockMessage {type: GET agent: \"robot2\" "
            "resource: \"M1\"}"));
  CHECK(
      t.has("[   0.20] robot1 msg -> LockMessage {type: ACCEPT agent: \"robot1\" resource: "
            "\"M2\"}"));
  CHECK(f.sent().size() == 1);
}

TEST_CASE("a traced host can be moved") {
  AgentConfig cfg;
  AgentIo io;
  auto host = std::make_unique<AgentHost>(cfg, io);
  host->load_string(kSmallAgent, "small.clp");
  Lines t;
  host->set_trace({.rules = true}, t.sink());
  AgentHost moved(std::move(*host));
  host.reset();
  moved.cycle(core::SimTime::from_ms(100));
  CHECK(t.has("FIRE go  f-1 (state IDLE), f-2 (machine (name M1) (mtype T1))"));
}
