// SPDX-License-Identifier: MIT
// Outcomes as data (docs/clips.md, "Issues" and "Agent events"): the host reports runtime errors
// and rule loops with kind, rule, file and line as fields, and the events an agent declares with
// (agent-event KIND ...), checked against the kinds it knows.
#include <doctest/doctest.h>

#include <string>
#include <vector>

#include "llsf/clips/agent.h"

using namespace llsf;
using namespace llsf::clips;

namespace {

struct Seen {
  struct Issue {
    AgentIssueKind kind;
    std::string rule, file, text;
    int line;
  };
  struct Event {
    AgentEventKind kind;
    std::string rule;
    std::vector<Value> args;
  };
  std::vector<Issue> issues;
  std::vector<Event> events;
  AgentIo io() {
    AgentIo io;
    io.issues = [this](const AgentIssue& i) {
      issues.push_back(
          {i.kind, std::string(i.rule), std::string(i.file), std::string(i.text), i.line});
    };
    io.events = [this](const AgentEvent& e) {
      events.push_back({e.kind, std::string(e.rule), e.args});
    };
    return io;
  }
};

}  // namespace

TEST_CASE("agent-event: a declared role change is an event; an unknown kind a runtime error") {
  Seen seen;
  AgentHost host(AgentConfig{}, seen.io());
  host.load_string(
      "(defrule change (time $?) (not (changed)) => (assert (changed))\n"
      "  (agent-event role-change P1P2 P3 \"little time left\"))\n"
      "(defrule misspelt (changed) (not (misspelt)) => (assert (misspelt))\n"
      "  (agent-event role-chnage P1 P3))\n"
      "(defrule wrong-args (misspelt) (not (wrong)) => (assert (wrong))\n"
      "  (agent-event role-change \"P1\"))\n",
      "agents/events.clp");
  host.cycle(core::SimTime::from_sec(1));
  REQUIRE(seen.events.size() == 1);
  CHECK(seen.events[0].kind == AgentEventKind::kRoleChange);
  CHECK(seen.events[0].rule == "change");
  REQUIRE(seen.events[0].args.size() == 3);
  CHECK(seen.events[0].args[0] == Value::symbol("P1P2"));
  CHECK(seen.events[0].args[1] == Value::symbol("P3"));
  REQUIRE(seen.issues.size() == 2);
  CHECK(seen.issues[0].kind == AgentIssueKind::kRuntimeError);
  CHECK(seen.issues[0].rule == "misspelt");
  CHECK(seen.issues[0].file == "agents/events.clp");
  CHECK(seen.issues[0].line == 3);
  CHECK(seen.issues[0].text.find("unknown kind 'role-chnage' (kinds: role-change)") !=
        std::string::npos);
  CHECK(seen.issues[1].rule == "wrong-args");
  CHECK(seen.issues[1].line == 5);
  CHECK(seen.issues[1].text.find("role-change takes FROM TO") != std::string::npos);
  CHECK(host.runtime_errors() == 2);
  CHECK(std::string(to_string(AgentEventKind::kRoleChange)) == "role-change");
}

TEST_CASE("issues as data: a rule loop names the next rule and its place, not in log text") {
  Seen seen;
  AgentConfig config;
  config.max_rules_per_cycle = 50;
  AgentHost host(config, seen.io());
  host.load_string(
      "(deffacts start (spin 0))\n"
      "\n"
      "(defrule spin ?f <- (spin ?n) => (retract ?f) (assert (spin (+ ?n 1))))\n",
      "loop.clp");
  host.cycle(core::SimTime::from_sec(1));
  REQUIRE(seen.issues.size() == 1);
  CHECK(seen.issues[0].kind == AgentIssueKind::kRuleLoop);
  CHECK(seen.issues[0].rule == "spin");
  CHECK(seen.issues[0].file == "loop.clp");
  CHECK(seen.issues[0].line == 3);
  CHECK(seen.issues[0].text.find("rule firing limit of 50") == 0);
  CHECK(std::string(to_string(AgentIssueKind::kRuleLoop)) == "rule-loop");
}
