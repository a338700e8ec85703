// SPDX-License-Identifier: MIT
// `llsfsim exercise`: every exercise's reference solution (tests/app/exercises/, kept out of
// exercises/) passes on each of its 20 seeds (one `--seeds 1-20 --json` sweep per exercise), every
// unchanged skeleton fails with the friendly verdict, and broken skills (syntax error, endless
// loop, runtime error) are reported with file:line.
#include <doctest/doctest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "app/cli_fixture.h"
#include "llsf/app/cli.h"

namespace {

using llsf::test::has;
using llsf::test::llsfsim;
using llsf::test::Run;

const std::string kExercises = LLSF_SOURCE_DIR "/exercises/";
const std::string kReference = LLSF_SOURCE_DIR "/tests/app/exercises/";

std::string write_temp(const std::string& name, const std::string& text) {
  const auto path = std::filesystem::temp_directory_path() / name;
  std::ofstream(path) << text;
  return path.string();
}

/// Plays `exercise` with `skill` on seeds 1..n in one sweep (`--seeds 1-n --json`, the games on
/// threads); returns how many passed. Every passed seed's `value` meets the goal.
int passes(const std::string& exercise, const std::string& skill, int n) {
  const Run r = llsfsim({"exercise", kExercises + exercise, "--skill", skill, "--seeds",
                         "1-" + std::to_string(n), "--json"});
  INFO(exercise, "\n", r.out, r.err);
  CHECK(r.code != llsf::app::kExitBadInput);
  const nlohmann::json j = nlohmann::json::parse(r.out);
  CHECK(j.at("total") == n);
  const std::string goal = j.at("goal");
  for (const nlohmann::json& run : j.at("runs")) {
    INFO("seed ", run.at("seed"), ": ", run.dump());
    CHECK(run.at("result") == "PASS");
    REQUIRE(run.at("value").is_number());
    if (goal == "points") {
      CHECK(run.at("value").is_number_integer());
      CHECK(run.at("value").get<int>() > 0);
    } else {
      CHECK(run.at("value").get<double>() <= 0.3);
    }
  }
  CHECK((j.at("verdict") == "PASS") == (j.at("passed") == n));
  return j.at("passed").get<int>();
}

}  // namespace

TEST_CASE("llsfsim exercise --list shows every exercise with its goal") {
  const Run r = llsfsim({"exercise", "--list"});
  INFO(r.out, r.err);
  CHECK(r.code == 0);
  for (const char* e : {"01-drive-to-point", "02-find-red-puck", "03-bring-one-home",
                        "04-rescue-5-minutes", "05-two-robots"}) {
    CHECK(has(r.out, e));
  }
  CHECK_FALSE(has(r.out, "BAD:"));
}

TEST_CASE("exercise reference solutions pass on >= 20 seeds") {
  CHECK(passes("01-drive-to-point", kReference + "01-drive-to-point.lua", 20) == 20);
  CHECK(passes("02-find-red-puck", kReference + "02-find-red-puck.lua", 20) == 20);
  CHECK(passes("03-bring-one-home", kReference + "rescue.lua", 20) == 20);
  CHECK(passes("04-rescue-5-minutes", kReference + "rescue.lua", 20) == 20);
  CHECK(passes("05-two-robots", kReference + "rescue.lua", 20) == 20);
}

TEST_CASE("exercise: each unchanged skeleton fails with the friendly 'not solved yet' verdict") {
  for (const char* e : {"01-drive-to-point", "02-find-red-puck", "03-bring-one-home",
                        "04-rescue-5-minutes", "05-two-robots"}) {
    const std::string skel = kExercises + e + "/skill.lua";
    const Run r = llsfsim({"exercise", e, "--skill", skel});
    INFO(e, "\n", r.out, r.err);
    CHECK(r.code == llsf::app::kExitFailed);
    CHECK(has(r.out, "not solved yet"));
    CHECK(has(r.out, "hint     this is the unchanged skeleton"));
    CHECK(has(r.out, "result   FAIL"));
    CHECK_FALSE(has(r.out, "stack traceback"));
  }
}

TEST_CASE("exercise: a syntax error is reported with file:line and a hint, exit 2") {
  const std::string path = write_temp("llsfex_syntax.lua", R"lua(name = "drive_to_point"
fsm = SkillHSM:new{name=name, start="DRIVE"}
depends_skills = {"drive_to"}
documentation = [==[x]==]
fsm:define_states{ export_to=_M,
   {"DRIVE", SkillJumpState, skills={{drive_to}}, final_to="FINAL"},
}
function DRIVE:init()
   if self.fsm.vars.x then
      self.args["drive_to"] = {x = self.fsm.vars.x, y = self.fsm.vars.y}
end
)lua");
  const Run r = llsfsim({"exercise", "01", "--skill", path});
  INFO(r.out, r.err);
  CHECK(r.code == llsf::app::kExitBadInput);
  CHECK(has(r.out, "error    " + path + ":"));
  CHECK(has(r.out, "'end' expected"));
  CHECK(has(r.out, "hint     a block is not closed"));
  CHECK(has(r.out, "NOT RUN"));
  CHECK_FALSE(has(r.out, "llsfex-"));  // the temporary copy's path never shows
}

TEST_CASE("exercise: an endless loop is stopped by the instruction budget, exit 1") {
  const std::string path = write_temp("llsfex_endless.lua", R"lua(name = "drive_to_point"
fsm = SkillHSM:new{name=name, start="SPIN"}
documentation = [==[x]==]
fsm:define_states{ export_to=_M, {"SPIN", JumpState} }
fsm:add_transitions{ {"SPIN", "FINAL", cond="vars.done"} }
function SPIN:loop()
   local n = 0
   while true do n = n + 1 end
end
)lua");
  const Run r = llsfsim({"exercise", "01", "--skill", path});
  INFO(r.out, r.err);
  CHECK(r.code == llsf::app::kExitFailed);
  CHECK(has(r.out, "error    " + path + ":8: instruction budget exhausted"));
  CHECK(has(r.out, "hint     an endless loop"));
  CHECK(has(r.out, "result   FAIL"));
  // The process survives and plays on: the next run works.
  CHECK(llsfsim({"exercise", "01", "--skill", kReference + "01-drive-to-point.lua", "-q"}).code ==
        0);
}

TEST_CASE("exercise: work the count hook cannot see is stopped at file:line with a hint, exit 1") {
  struct Bomb {
    const char* line;
    const char* error;
    const char* hint;
  };
  const Bomb bombs[] = {
      {"string.find(string.rep('a', 30000), 'a*a*a*a*a*b')",
       ":7: instruction budget exhausted (1000000 instructions per cycle; string.find: pattern "
       "matching)",
       "hint     a string search that takes too long"},
      {"table.move({}, 1, 2^50, 2)",
       ":7: instruction budget exhausted (1000000 instructions per cycle; table.move of "
       "1125899906842624 elements)",
       "hint     a table function over too many elements"},
      {"local s = string.rep('', 2^50) .. string.rep('x', 2^40)",
       ":7: string.rep: result of 1099511627776 bytes over the limit of", "hint     string.rep"},
      {"string.format = nil", ":7: string is read-only (shared by every skill)",
       "hint     the libraries"},
  };
  for (const Bomb& b : bombs) {
    const std::string path = write_temp("llsfex_bomb.lua", std::string(R"lua(name = "drive_to_point"
fsm = SkillHSM:new{name=name, start="S"}
documentation = [==[x]==]
fsm:define_states{ export_to=_M, {"S", JumpState} }
fsm:add_transitions{ {"S", "FINAL", cond="vars.done"} }
function S:loop()
   )lua") + b.line + "\nend\n");
    const Run r = llsfsim({"exercise", "01", "--skill", path});
    INFO(b.line, "\n", r.out, r.err);
    CHECK(r.code == llsf::app::kExitFailed);
    CHECK(has(r.out, "error    " + path + b.error));
    CHECK(has(r.out, b.hint));
    CHECK(has(r.out, "result   FAIL"));
  }
}

TEST_CASE("exercise: a runtime error names file:line with a hint; bad input exits 2") {
  const std::string path = write_temp("llsfex_nil.lua", R"lua(name = "drive_to_point"
fsm = SkillHSM:new{name=name, start="S"}
documentation = [==[x]==]
fsm:define_states{ export_to=_M, {"S", JumpState} }
fsm:add_transitions{ {"S", "FINAL", cond=true} }
function S:init()
   local t = self.fsm.vars.nothing.x
end
)lua");
  Run r = llsfsim({"exercise", "01", "--skill", path});
  INFO(r.out, r.err);
  CHECK(r.code == llsf::app::kExitFailed);
  CHECK(has(r.out, "error    " + path + ":7: attempt to index a nil value"));
  CHECK(has(r.out, "hint     something is nil"));

  r = llsfsim({"exercise", "99-nothing", "--skill", path});
  CHECK(r.code == llsf::app::kExitBadInput);
  CHECK(has(r.err, "unknown exercise '99-nothing'"));
  r = llsfsim({"exercise", "01", "--skill", "/no/such/file.lua"});
  CHECK(r.code == llsf::app::kExitBadInput);
  CHECK(has(r.err, "no such skill file"));
  r = llsfsim({"exercise", "01"});
  CHECK(r.code == llsf::app::kExitBadInput);
  CHECK(has(r.err, "--skill"));
}

TEST_CASE("exercise: a bad exercise.yaml names file:line:key") {
  const auto dir = std::filesystem::temp_directory_path() / "llsfex_bad";
  std::filesystem::create_directories(dir);
  std::ofstream(dir / "exercise.yaml") << "title: x\nskill: s\ngoal:\n  find: {colour: purple}\n"
                                          "scenario:\n  hackathon: {}\n";
  const Run r = llsfsim({"exercise", dir.string(), "--skill", kReference + "rescue.lua"});
  INFO(r.out, r.err);
  CHECK(r.code == llsf::app::kExitBadInput);
  CHECK(has(r.err, "exercise.yaml:4:"));
  CHECK(has(r.err, "goal.find.colour"));
  std::filesystem::remove_all(dir);
}

TEST_CASE("exercise --serve --serve-exit serves the live game and exits") {
  const Run r = llsfsim({"exercise", "01", "--skill", kReference + "01-drive-to-point.lua",
                         "--serve", "--port", "0", "--serve-exit"});
  INFO(r.out, r.err);
  CHECK(r.code == 0);
  CHECK(has(r.out, "llsfsim serve: http://127.0.0.1:"));
  CHECK(has(r.out, "#/live"));
}
