// SPDX-License-Identifier: MIT
// Messages that name the participant's mistake (docs/exercises.md, "Mistakes and their
// messages"): the shown path (display_paths), undefined states, missing declarations, typos,
// globals not available in skills, errors of library wrappers at the skill's line, the line of
// a memory error, fsm.result's type, and the warnings for silent mistakes.
#include <doctest/doctest.h>

#include <memory>
#include <string>
#include <vector>

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

namespace {

// A skill `s` with `body` after the usual declarations and one state S (JumpState) whose loop
// is `loop` and which ends FINAL when vars.done is set.
std::string skill_with(const std::string& body, const std::string& loop = "") {
  return "name = 's'\n"                                               // 1
         "fsm = SkillHSM:new{name=name, start='S'}\n"                 // 2
         "documentation = 'x'\n"                                      // 3
         "fsm:define_states{ export_to=_M, {'S', JumpState} }\n"      // 4
         "fsm:add_transitions{ {'S', 'FINAL', cond='vars.done'} }\n"  // 5
         "function S:loop()\n"                                        // 6
         "  " +
         loop +
         "\n"       // 7
         "end\n" +  // 8
         body;
}

struct Engine {
  TempDir dir{"llsf_hints"};
  FakeRobot robot;
  std::unique_ptr<lua::SkillEngine> engine;
  std::vector<std::string> log;

  /// Skill s from `text`, and skill t from `t_text` if given.
  explicit Engine(const std::string& text, const std::string& t_text = "") {
    const std::string file = "s.lua";
    dir.write(file, text);
    if (!t_text.empty()) dir.write("t.lua", t_text);
    lua::SkillEngineConfig cfg;
    cfg.skill_dirs = {dir.path.string()};
    cfg.instruction_budget = 200'000;
    cfg.display_paths[dir.file(file)] = "mine.lua";
    engine = std::make_unique<lua::SkillEngine>(cfg, robot);
    engine->set_log_sink([this](lua::LogLevel level, std::string_view line) {
      log.push_back((level == lua::LogLevel::kWarn ? "warn: " : "") + std::string(line));
    });
  }
  std::string load_error() const { return load_error_of(*engine, "s"); }
  /// Runs s{} for `cycles` cycles (or until it ends); the status.
  SkillStatus run(int cycles = 1) {
    REQUIRE(engine->exec("s{}"));
    return test::run_until_done(*engine, robot, cycles);
  }
  std::string error() const { return engine->error(); }
  bool logged(const std::string& part) const {
    for (const std::string& l : log) {
      if (contains(l, part)) return true;
    }
    return false;
  }
  int count(const std::string& part) const {
    int n = 0;
    for (const std::string& l : log) n += contains(l, part) ? 1 : 0;
    return n;
  }
};

}  // namespace

namespace {
bool e_run_fails(Engine& e) { return e.load_error().empty() && e.run() == SkillStatus::kFailed; }
}  // namespace

TEST_CASE("globals skills do not have say so and what to use instead, at the line") {
  for (const char* name : {"io", "os", "package", "dofile", "loadfile", "load", "loadstring",
                           "debug", "coroutine", "collectgarbage", "_G", "unpack"}) {
    Engine e(skill_with("", std::string("local x = ") + name));
    REQUIRE(e.load_error().empty());
    CHECK(e.run() == SkillStatus::kFailed);
    INFO(name, ": ", e.error());
    CHECK(contains(e.error(),
                   std::string("mine.lua:7: '") + name + "' is not available in skills: "));
  }
  // require loads only helper modules of the skill directories (docs/skills.md).
  Engine req(skill_with("", "local x = require('socket')"));
  CHECK(e_run_fails(req));
  CHECK(contains(req.error(),
                 "mine.lua:7: module 'socket' is not available in skills: require "
                 "loads only the Lua files of the skill and module directories"));
  // At load time too.
  Engine e(skill_with("local f = io.open('/etc/passwd')\n"));
  CHECK(contains(e.load_error(),
                 "mine.lua:9: 'io' is not available in skills: no files or "
                 "terminal: print(...) / printf(fmt, ...) write to the "
                 "log"));
}

TEST_CASE("an undeclared global names the nearest known name, if one is near") {
  Engine typo(skill_with("", "local v = mth.floor(1.5)"));
  CHECK(typo.run() == SkillStatus::kFailed);
  CHECK(contains(typo.error(), "mine.lua:7: undeclared global 'mth' (did you mean 'math'?)"));
  Engine state(
      "name = 's'\nfsm = SkillHSM:new{name=name, start='DRIVE'}\ndocumentation = 'x'\n"
      "fsm:define_states{ export_to=_M, {'DRIVE', JumpState} }\n"
      "function Drive:init() end\n");
  CHECK(contains(state.load_error(),
                 "mine.lua:5: undeclared global 'Drive' (did you mean 'DRIVE'?)"));
  Engine far(skill_with("", "local v = completely_unknown_thing"));
  CHECK(far.run() == SkillStatus::kFailed);
  CHECK(contains(far.error(), "mine.lua:7: undeclared global 'completely_unknown_thing'"));
  CHECK_FALSE(contains(far.error(), "did you mean"));
  // A state used before fsm:define_states made it -- or a constant used before it is defined:
  // the message names both.
  Engine early(
      "name = 's'\nfsm = SkillHSM:new{name=name, start='GO'}\ndocumentation = 'x'\n"
      "function GO:init() end\n");
  CHECK(contains(early.load_error(),
                 "mine.lua:4: undeclared global 'GO': if it is a state, no state is defined "
                 "yet: call fsm:define_states{...} before using it (function GO:init() ...); "
                 "otherwise define it before this line (local GO = ...)"));
}

TEST_CASE("states that do not exist: the nearest and the list") {
  Engine to(skill_with("fsm:add_transitions{ {'S', 'FINLA', cond=true} }\n"));
  CHECK(contains(to.load_error(),
                 "mine.lua:9: add_transitions: {\"S\", \"FINLA\"} goes to an "
                 "unknown state 'FINLA' (did you mean 'FINAL'? states: S, "
                 "FINAL, FAILED)"));
  Engine from(skill_with("fsm:add_transitions{ {'X', 'FINAL', cond=true} }\n"));
  INFO(from.load_error());
  CHECK(contains(from.load_error(),
                 "mine.lua:9: add_transitions: {\"X\", \"FINAL\"} starts in an "
                 "unknown state 'X' (states: S, FINAL, FAILED)"));
  Engine final_to(
      "name = 's'\nfsm = SkillHSM:new{name=name, start='A'}\ndocumentation = 'x'\n"
      "depends_skills = {'t'}\n"
      "fsm:define_states{ export_to=_M, {'A', SkillJumpState, skills={{t}}, final_to='FINSH'} }\n",
      "name = 't'\ndocumentation = 'x'\nfunction execute() return S_FINAL end\n");
  CHECK(contains(final_to.load_error(),
                 "mine.lua:5: state 'A': final_to=\"FINSH\" names an "
                 "unknown state 'FINSH' (did you mean 'FINAL'? states: A, "
                 "FINAL, FAILED)"));
  Engine start(
      "name = 's'\nfsm = SkillHSM:new{name=name, start='STRAT'}\ndocumentation = 'x'\n"
      "fsm:define_states{ export_to=_M, {'START', JumpState} }\n");
  CHECK(contains(start.load_error(),
                 "mine.lua:2: start=\"STRAT\" names an unknown state 'STRAT' "
                 "(did you mean 'START'? states: START, FINAL, FAILED)"));
  Engine none("name = 's'\nfsm = SkillHSM:new{name=name, start='GO'}\ndocumentation = 'x'\n");
  CHECK(contains(none.load_error(),
                 "mine.lua:2: the state machine has no states: "
                 "fsm:define_states{...} is missing"));
  Engine timeout(skill_with("fsm:define_states{ {'T', JumpState, timeout={2, 'NXT'}} }\n"));
  CHECK(contains(timeout.load_error(),
                 "mine.lua:9: state 'T': timeout goes to an unknown state 'NXT'"));
}

TEST_CASE("missing declarations name the file and the line of name = ...") {
  Engine doc("-- a comment\nname = 's'\nfunction execute() return S_FINAL end\n");
  CHECK(contains(doc.load_error(), "mine.lua:2: the skill declares no 'documentation' string"));
  Engine fsm("name = 's'\ndocumentation = 'x'\n");
  CHECK(contains(fsm.load_error(),
                 "mine.lua:1: the skill has no state machine: add fsm = "
                 "SkillHSM:new{name=name, start=\"STATE\"}"));
  Engine no_name("documentation = 'x'\n");
  CHECK(contains(no_name.load_error(),
                 "mine.lua:1: the skill declares no 'name': add name = "
                 "\"s\" at the top of the file"));
  Engine start("name = 's'\nfsm = SkillHSM:new{name=name}\n");
  CHECK(contains(start.load_error(), "mine.lua:2: SkillHSM:new{...} needs start=\"STATE\""));
}

TEST_CASE("errors of the library wrappers name the skill's line, never the prelude") {
  const char* const calls[] = {
      "printf('%d', 1.5)",        "table.insert(nil, 1)",   "table.concat({{}})",
      "table.sort({3, 1, 'x'})",  "table.unpack(nil)",      "setmetatable(1, {})",
      "rawset(nil, 1, 2)",        "string.byte(nil, 1, 2)", "utf8.len(nil)",
      "table.move(nil, 1, 2, 1)", "table.remove({}, 'x')"};
  for (const char* call : calls) {
    Engine e(skill_with("", call));
    CHECK(e.run() == SkillStatus::kFailed);
    INFO(call, ": ", e.error());
    CHECK(contains(e.error(), "s: S: mine.lua:7: "));
    CHECK_FALSE(contains(e.error(), "prelude"));
  }
  Engine e(skill_with("", "printf('%d', 1.5)"));
  e.run();
  INFO(e.error());
  CHECK(contains(e.error(),
                 "mine.lua:7: bad argument #2 to 'printf' (number has no integer "
                 "representation)"));
  // A comparator's own error keeps its position.
  Engine cmp(skill_with("", "table.sort({1, 2, 3}, function(a, b) return a.x < b end)"));
  cmp.run();
  CHECK(contains(cmp.error(), "s: S: mine.lua:7: attempt to index a number value"));
  // printf still prints.
  Engine ok(skill_with("", "printf('%d %s', 3, 'x') self.fsm.vars.done = true"));
  CHECK(ok.run(3) == SkillStatus::kFinal);
  CHECK(ok.logged("3 x"));
}

TEST_CASE("a memory error names the line that was running") {
  Engine e(skill_with("seen = {}\n",
                      "for i = 1, 2000 do seen[#seen + 1] = string.rep('x', 10000) .. i end"));
  CHECK(e.run(10) == SkillStatus::kFailed);
  INFO(e.error());
  CHECK(contains(e.error(), "s: S: mine.lua:7: not enough memory (heap limit of 67108864 bytes)"));
  // While the file loads.
  Engine load(
      skill_with("local t = {} for i = 1, 60 do t[i] = string.rep('y', 2 << 20) .. i end\n"));
  CHECK(contains(load.load_error(), "mine.lua:9: not enough memory (heap limit of"));
}

TEST_CASE("fsm.result must be a string or a number") {
  Engine table(skill_with("", "self.fsm.result = {1, 2}"));
  CHECK(table.run() == SkillStatus::kFailed);
  CHECK(contains(table.error(),
                 "s: S: mine.lua:7: fsm.result must be a string (e.g. \"1.20 "
                 "3.40\") or a number, not a table"));
  Engine boolean(skill_with("", "self.fsm.result = true"));
  CHECK(boolean.run() == SkillStatus::kFailed);
  CHECK(contains(boolean.error(), "not a boolean"));
  // Through rawset (no line to name): the string fails when it ends.
  Engine raw(skill_with("", "rawset(self.fsm, 'result', {}) self.fsm.vars.done = true"));
  CHECK(raw.run(3) == SkillStatus::kFailed);
  CHECK(contains(raw.error(), "fsm.result must be a string"));
  // Strings and numbers are results; reading back works.
  Engine text(skill_with("",
                         "self.fsm.result = '1.20 3.40' self.fsm.vars.done = "
                         "self.fsm.result == '1.20 3.40'"));
  CHECK(text.run(3) == SkillStatus::kFinal);
  CHECK(text.engine->result() == "1.20 3.40");
  Engine number(skill_with("", "self.fsm.result = 7 self.fsm.vars.done = true"));
  CHECK(number.run(3) == SkillStatus::kFinal);
  CHECK(number.engine->result() == "7");
}

TEST_CASE("warnings: self.args of a state that runs no such sub-skill") {
  Engine jump(skill_with("", "self.args['drive_to'] = {x = 1}"));
  CHECK(jump.run(5) == SkillStatus::kRunning);
  CHECK(jump.count("warn: mine.lua:7: s: state 'S' sets self.args[\"drive_to\"], but it runs no "
                   "sub-skill (it is a JumpState), so the arguments are ignored") == 1);
}

TEST_CASE("warnings: states that switch in every cycle without waiting, once per call") {
  const std::string bounce =
      "name = 's'\nfsm = SkillHSM:new{name=name, start='A'}\ndocumentation = 'x'\n"
      "fsm:define_states{ export_to=_M, {'A', JumpState}, {'B', JumpState} }\n"
      "fsm:add_transitions{\n"  // 5
      "  {'A', 'B', cond=true}, {'B', 'A', cond='true'} }\n";
  Engine e(bounce);
  CHECK(e.run(30 * 5) == SkillStatus::kRunning);
  CHECK(e.count("warn: mine.lua:5: s: states A -> B -> A keep switching without waiting") == 1);
  CHECK(e.logged("the transition {\"A\", \"B\", cond=true} fires at once"));
  // Not before 2 s of game time.
  Engine early(bounce);
  CHECK(early.run(30) == SkillStatus::kRunning);
  CHECK(early.log.empty());
  // A state that waits (a cond that is false for a while) or a timeout is no warning.
  Engine waits(
      "name = 's'\nfsm = SkillHSM:new{name=name, start='A'}\ndocumentation = 'x'\n"
      "fsm:define_states{ export_to=_M, {'A', JumpState}, {'B', JumpState} }\n"
      "local n = 0\n"
      "fsm:add_transitions{ {'A', 'B', cond=function() n = n + 1 return n % 3 == 0 end},"
      " {'B', 'A', timeout=0} }\n");
  CHECK(waits.run(30 * 5) == SkillStatus::kRunning);
  CHECK(waits.log.empty());
}

TEST_CASE("a print while the file loads reaches the sink set afterwards") {
  Engine e(skill_with("print('loaded', 3)\nprint_warn('careful')\n"));
  REQUIRE(e.log.size() == 2);
  CHECK(e.log[0] == "loaded\t3");
  CHECK(e.log[1] == "warn: careful");
}

TEST_CASE("a shown path longer than Lua keeps (60 characters) is written out in full") {
  FakeRobot robot;
  TempDir dir;
  dir.write("crash.lua",
            "name = 'crash'\ndocumentation = 'x'\nfunction execute()\n"
            "  print(select(2, pcall(function() error('boom') end)))\n"
            "  local t = nil\n  return t.x\nend\n");
  dir.write("broken.lua", "name = 'broken'\ndocumentation = 'x'\nfunction execute( end\n");
  const std::string long_dir = "/home/participant/hackathon/team-with-a-long-name/exercises/02/";
  lua::SkillEngineConfig cfg;
  cfg.skill_dirs = {dir.path.string()};
  cfg.display_paths[dir.file("crash.lua")] = long_dir + "my_crash.lua";
  cfg.display_paths[dir.file("broken.lua")] = long_dir + "my_broken.lua";
  lua::SkillEngine engine(cfg, robot);
  std::vector<std::string> log;
  engine.set_log_sink([&](lua::LogLevel, std::string_view line) { log.emplace_back(line); });
  const std::string load_error = load_error_of(engine, "broken");
  INFO(load_error);
  CHECK(load_error.rfind(long_dir + "my_broken.lua:3:", 0) == 0);
  REQUIRE(engine.exec("crash{}"));
  CHECK(engine.cycle() == SkillStatus::kFailed);
  INFO(engine.error());
  CHECK(contains(engine.error(), long_dir + "my_crash.lua:6: attempt to index a nil value"));
  CHECK_FALSE(contains(engine.error(), "..."));
  REQUIRE(log.size() == 1);
  CHECK(log[0] == long_dir + "my_crash.lua:4: boom");
}
