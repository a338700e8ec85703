// SPDX-License-Identifier: MIT
// SkillBrain's state listener sees every state a step went through, also within one cycle: a
// skill that goes GO -> NEXT -> GO in each step reports those changes, not nothing.
#include <doctest/doctest.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "fixture.h"
#include "llsf/sim/driver.h"
#include "llsf/sim/skill_brain.h"
#include "support/temp_dir.h"

using namespace llsf;

TEST_CASE("skill states passed within one cycle are reported, in order") {
  const llsf::test::TempDir dir("llsf_state_path_test");
  std::ofstream(dir.path / "hop.lua") << R"(-- SPDX-License-Identifier: MIT
name               = "hop"
fsm                = SkillHSM:new{name=name, start="GO"}
depends_skills     = {}
depends_interfaces = {}
documentation      = [==[Hops from GO to NEXT and back twice in each step, then ends.]==]
fsm:define_states{ export_to=_M, {"GO", JumpState}, {"NEXT", JumpState} }
fsm:add_transitions{
   {"GO", "FINAL", cond=function(self, vars) return (vars.n or 0) >= 2 end},
   {"GO", "NEXT", cond=true},
   {"NEXT", "GO", cond=true},
}
function NEXT:init() self.fsm.vars.n = (self.fsm.vars.n or 0) + 1 end
)";
  const sim::GameConfig config = llsf::test::small_game(1);
  sim::GameDriver driver(config);
  lua::SkillEngineConfig ec;
  ec.skill_dirs = sim::skill_library_dirs(config.levels.skill);
  ec.skill_dirs.push_back(dir.path.string());
  ec.hot_reload = false;
  sim::SkillBrain& brain = driver.plug_skills(0, ec);
  std::vector<std::string> changes;
  brain.set_state_listener(
      [&changes](const sim::SkillStateChange& c) { changes.push_back(c.from + ">" + c.to); });
  REQUIRE(brain.exec("hop{}"));
  driver.run_until(core::SimTime::from_seconds(1.0));
  // Step 1: GO -> NEXT -> GO (a state runs once per step); step 2: the same; step 3: FINAL.
  const std::vector<std::string> want = {">GO",     "GO>NEXT", "NEXT>GO",
                                         "GO>NEXT", "NEXT>GO", "GO>FINAL"};
  CHECK(changes == want);
}

TEST_CASE("with via, each state change says what took it there") {
  const llsf::test::TempDir dir("llsf_state_via_test");
  std::ofstream(dir.path / "hop.lua") << R"(-- SPDX-License-Identifier: MIT
name               = "hop"
fsm                = SkillHSM:new{name=name, start="GO"}
depends_skills     = {}
depends_interfaces = {}
documentation      = [==[GO -> NEXT at once, NEXT -> FINAL after 0.2 s.]==]
fsm:define_states{ export_to=_M, {"GO", JumpState}, {"NEXT", JumpState} }
fsm:add_transitions{
   {"GO", "NEXT", cond=true},
   {"NEXT", "FINAL", timeout=0.2},
}
)";
  const sim::GameConfig config = llsf::test::small_game(1);
  sim::GameDriver driver(config);
  lua::SkillEngineConfig ec;
  ec.skill_dirs = sim::skill_library_dirs(config.levels.skill);
  ec.skill_dirs.push_back(dir.path.string());
  ec.hot_reload = false;
  sim::SkillBrain& brain = driver.plug_skills(0, ec);
  std::vector<std::string> changes;
  brain.set_state_listener(
      [&changes](const sim::SkillStateChange& c) {
        changes.push_back(c.from + ">" + c.to + " " + c.via);
      },
      true);
  REQUIRE(brain.exec("hop{}"));
  driver.run_until(core::SimTime::from_seconds(1.0));
  const std::string hop = (dir.path / "hop.lua").string();
  const std::vector<std::string> want = {
      ">GO ", "GO>NEXT {\"GO\", \"NEXT\", cond=true} at " + hop + ":8",
      "NEXT>FINAL {\"NEXT\", \"FINAL\", timeout=0.2} at " + hop + ":8"};
  CHECK(changes == want);
}
