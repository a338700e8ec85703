// SPDX-License-Identifier: MIT
// Messages that name the participant's mistake (docs/exercises.md, "Mistakes and their
// messages"): the shown path (display_paths), undefined states, missing declarations, typos,
// globals not available in skills, errors of library wrappers at the skill's line, the line of
// a memory error, fsm.result's type, and the warnings for silent mistakes.
#include <doctest/doctest.h>

#include <string>

#include "lua/fake_robot.h"
#include "support/temp_dir.h"

using namespace llsf;
using lua::SkillStatus;
using test::FakeRobot;
using test::TempDir;

namespace {

bool contains(const std::string& text, const std::string& needle) {
  return text.find(needle) != std::string::npos;
}

std::string load_error_of(const lua::SkillEngine& engine, const std::string& name) {
  for (const lua::SkillInfo& s : engine.skills()) {
    if (s.name == name) return s.load_error;
  }
  return "(no skill " + name + ")";
}

}  // namespace

TEST_CASE("display_paths: messages name the shown path, never the real one") {
  FakeRobot robot;
  TempDir dir;
  dir.write("broken.lua", "name = 'broken'\ndocumentation = 'x'\nfunction execute( end\n");
  dir.write("crash.lua",
            "name = 'crash'\ndocumentation = 'x'\nfunction execute()\n  local t = nil\n"
            "  return t.x\nend\n");
  lua::SkillEngineConfig cfg;
  cfg.skill_dirs = {dir.path.string()};
  cfg.display_paths[dir.file("broken.lua")] = "my/broken_skill.lua";
  cfg.display_paths[dir.path.string() + "/./crash.lua"] = "mine.lua";  // another spelling
  lua::SkillEngine engine(cfg, robot);
  const std::string err = load_error_of(engine, "broken");
  INFO(err);
  CHECK(contains(err, "my/broken_skill.lua:3:"));
  CHECK_FALSE(contains(err, dir.path.string()));

  REQUIRE(engine.exec("crash{}"));
  CHECK(engine.cycle() == SkillStatus::kFailed);
  INFO(engine.error());
  CHECK(contains(engine.error(), "mine.lua:5: attempt to index a nil value"));
  CHECK_FALSE(contains(engine.error(), dir.path.string()));
  // SkillInfo keeps the real path.
  for (const lua::SkillInfo& s : engine.skills()) CHECK(contains(s.path, dir.path.string()));
}
