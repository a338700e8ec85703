// SPDX-License-Identifier: MIT
// The C++ example of docs/clips.md, "Testing rules without the world", as written there: keep
// the two equal.
#include <doctest/doctest.h>
#include "llsf/clips/agent_files.h"  // expand_agent_files: a directory -> its *.clp in name order
#include "llsf/clips/testing.h"
using namespace llsf;
using clips::SkillStatus;
using clips::Value;

TEST_CASE("an idle P3 robot fetches an S0, then takes it to the T5") {
  clips::AgentFixture f;  // AgentFixture(cfg, &registry) for pb-*
  for (const std::string& file : clips::expand_agent_files(
           {LLSF_SOURCE_DIR "/clips/agents/common", LLSF_SOURCE_DIR "/clips/agents/llsf2013"}))
    f.load_file(file);  // throws AgentLoadError (file:line)
  f.step();             // start: (reset), deffacts, 1st cycle
  f.agent().eval("(do-for-fact ((?m machine)) (eq ?m:name M6) (modify ?m (mtype T5)))");
  f.agent().eval("(do-for-fact ((?g game)) TRUE (modify ?g (phase PRODUCTION) (state RUNNING)))");
  f.assert_fact("(role (name P3) (target NONE))");
  f.steps(2);  // +200 ms, two cycles
  REQUIRE(f.skills().calls().back() == "get_s0{}");
  f.skills().set_status(SkillStatus::kFinal);  // the skill succeeds
  f.steps(2);
  CHECK(f.find("holding", {{"puck", Value::symbol("S0")}}).size() == 1);
  CHECK(f.skills().calls().back() == "finish_puck_at{place=\"M6\"}");
  CHECK(f.agent().runtime_errors() == 0);
  CHECK_FALSE(f.logged("runtime error"));
}
