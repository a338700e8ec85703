// SPDX-License-Identifier: MIT
// A failed skill string's reason code (lua::FailReason, docs/skills.md "Failure reasons"): the
// same whatever the error text says, declared by the skill (fsm.reason) or given by the engine,
// and handed on by a parent skill that failed because its sub-skill did.
#include <doctest/doctest.h>

#include <string>

#include "lua/fake_robot.h"
#include "support/temp_dir.h"

using namespace llsf;
using lua::FailReason;
using lua::SkillStatus;
using test::FakeRobot;

namespace {

// A skill that fails at once with `error`, declaring `reason` (Lua text, "nil" for none).
std::string failing_skill(const std::string& name, const std::string& error,
                          const std::string& reason) {
  return "name = '" + name +
         "'\n"
         "documentation = 'fails at once'\n"
         "fsm = SkillHSM:new{name=name, start='LOOK'}\n"
         "depends_skills = nil\n"
         "fsm:define_states{ export_to=_M, {'LOOK', JumpState} }\n"
         "fsm:add_transitions{ {'LOOK', 'FAILED', cond=function(self)\n"
         "  self.fsm.error = '" +
         error + "'\n  self.fsm.reason = " + reason + "\n  return true end} }\n";
}

FailReason run(lua::SkillEngine& engine, FakeRobot& robot, const std::string& string) {
  if (!engine.exec(string)) return engine.fail_reason();
  test::run_until_done(engine, robot);
  REQUIRE(engine.status() == SkillStatus::kFailed);
  return engine.fail_reason();
}

}  // namespace

TEST_CASE("fail reason: a declared reason stays when the error text is reworded") {
  test::TempDir dir("llsf_fail_reason");
  dir.write("look_a.lua", failing_skill("look_a", "look_a: no puck seen at INS_1", "'not-found'"));
  dir.write("look_b.lua",
            failing_skill("look_b", "look_b: the storage looked empty (reworded)", "'not-found'"));
  dir.write("plain.lua", failing_skill("plain", "plain: no puck seen at INS_1", "nil"));
  dir.write("typo.lua", failing_skill("typo", "typo: gave up", "'not_found'"));
  lua::SkillEngineConfig cfg;
  cfg.skill_dirs = {test::example_skills_dir(), dir.path.string()};
  FakeRobot robot;
  lua::SkillEngine engine(cfg, robot);
  CHECK(run(engine, robot, "look_a{}") == FailReason::kNotFound);
  CHECK(engine.error() == "look_a: no puck seen at INS_1");
  CHECK(run(engine, robot, "look_b{}") == FailReason::kNotFound);
  // The same words without a declared reason: the skill's own verdict, not "not found".
  CHECK(run(engine, robot, "plain{}") == FailReason::kFailed);
  // A reason the engine does not know is a mistake of the skill, said so in the error.
  CHECK(run(engine, robot, "typo{}") == FailReason::kError);
  CHECK(engine.error().find("fsm.reason must be") != std::string::npos);
  CHECK(std::string(lua::to_string(FailReason::kNotFound)) == "not-found");
}

TEST_CASE("fail reason: the engine's reasons and a sub-skill's reason handed on") {
  FakeRobot robot;
  lua::SkillEngineConfig cfg;
  cfg.skill_dirs = {test::example_skills_dir()};
  lua::SkillEngine engine(cfg, robot);
  CHECK(run(engine, robot, "say_hello{who='x'") == FailReason::kBadString);
  CHECK(run(engine, robot, "goto_plaec{place='M1'}") == FailReason::kUnknownSkill);
  CHECK(run(engine, robot, "say_hello('M1')") == FailReason::kError);
  CHECK(run(engine, robot, "goto_place{place='nowhere'}") == FailReason::kFailed);

  // The navigator's goal aborted under goto_place: goto_place says so (fsm.reason), and
  // visit_place, which failed because goto_place did (fail_to), hands the reason on.
  robot.nav_steps = 1000;
  for (const char* string : {"goto_place{place='M3'}", "visit_place{place='M3'}"}) {
    CAPTURE(string);
    REQUIRE(engine.exec(string));
    CHECK(test::run_cycles(engine, robot, 2) == SkillStatus::kRunning);
    robot.nav.status = lua::NavStatus::kAborted;
    test::run_until_done(engine, robot);
    REQUIRE(engine.status() == SkillStatus::kFailed);
    CHECK(engine.error().find("ABORTED") != std::string::npos);
    CHECK(engine.fail_reason() == FailReason::kAborted);
  }
  REQUIRE(engine.exec("say_hello{}"));
  test::run_until_done(engine, robot);
  CHECK(engine.fail_reason() == FailReason::kNone);  // not failed
}
