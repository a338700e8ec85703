// SPDX-License-Identifier: MIT
// Budgets for work the instruction count hook cannot see (it never fires inside a C function):
// string.rep, table.move and friends, the pattern functions, the allocation budget; the shared
// library tables are read-only, and a skill meets another only as its read-only handle. Each
// hostile call must fail the skill at its line, quickly.
#include <doctest/doctest.h>
#include <lua.hpp>

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

// `text` without the scratch directory's path (messages then name "probe.lua:4").
std::string without_dir(std::string text, const TempDir& dir) {
  const std::string prefix = dir.path.string() + "/";
  for (std::size_t at = text.find(prefix); at != std::string::npos; at = text.find(prefix)) {
    text.erase(at, prefix.size());
  }
  return text;
}

lua::SkillEngineConfig budget_config(const TempDir& dir) {
  lua::SkillEngineConfig cfg;
  cfg.skill_dirs = {dir.path.string()};
  cfg.instruction_budget = 200'000;
  cfg.memory_limit_bytes = 16 << 20;
  cfg.allocation_budget_bytes = 32 << 20;
  return cfg;
}

// A skill `probe` whose execute() runs `body` from line 4 of probe.lua, then finishes.
std::string probe_skill(const std::string& body) {
  return "name = 'probe'\n"
         "documentation = 'runs a probe'\n"
         "function execute()\n" +
         body +
         "\n"
         "  return S_FINAL\n"
         "end\n";
}

struct Outcome {
  SkillStatus status = SkillStatus::kInactive;
  std::string error;
  std::vector<std::string> log;
};

// Runs `probe{}` for one cycle with `body` in a fresh engine.
Outcome run_probe(const std::string& body, std::int64_t instruction_budget = 200'000) {
  TempDir dir("llsf_budget");
  dir.write("probe.lua", probe_skill(body));
  FakeRobot robot;
  lua::SkillEngineConfig cfg = budget_config(dir);
  cfg.instruction_budget = instruction_budget;
  lua::SkillEngine engine(cfg, robot);
  Outcome out;
  engine.set_log_sink([&](lua::LogLevel, std::string_view text) { out.log.emplace_back(text); });
  REQUIRE(engine.skills().size() == 1);
  REQUIRE(engine.skills()[0].load_error.empty());
  REQUIRE(engine.exec("probe{}"));
  out.status = engine.cycle();
  out.error = without_dir(engine.error(), dir);
  return out;
}

}  // namespace

TEST_CASE(
    "string.rep: results over the memory limit fail at the caller's line; empty ones are "
    "free") {
  Outcome r = run_probe("  local s = string.rep('', 2^50) .. string.rep('', 2^50, '')");
  CHECK(r.status == SkillStatus::kFinal);
  r = run_probe("  local s = string.rep('x', 2^40)");
  CHECK(r.status == SkillStatus::kFailed);
  CHECK(r.error ==
        "probe: probe.lua:4: string.rep: result of 1099511627776 bytes over the limit of "
        "16777216 bytes");
  r = run_probe("  local s = ('ab'):rep(2^40, ',')");
  CHECK(contains(r.error, "probe.lua:4: string.rep: result of 3298534883327 bytes"));
  r = run_probe(
      "  assert(('ab'):rep(3, ',') == 'ab,ab,ab' and ('x'):rep(1) == 'x' and ('x'):rep(0) == '')\n"
      "  assert(('ab'):rep(4) == 'abababab' and (''):rep(3, '-') == '--' and ('a'):rep(-1) == '')");
  CHECK(r.status == SkillStatus::kFinal);
  CHECK(r.error.empty());
}

TEST_CASE("table functions charge the elements they touch to the instruction budget") {
  Outcome r = run_probe("  table.move({}, 1, 2^50, 2)");
  CHECK(r.status == SkillStatus::kFailed);
  CHECK(r.error ==
        "probe: probe.lua:4: instruction budget exhausted (200000 instructions per cycle; "
        "table.move of 1125899906842624 elements)");
  // Each call is affordable; the loop is not (the count hook alone sees ~20 instructions a call).
  r = run_probe(
      "  local t = {string.byte(string.rep('x', 100000), 1, -1)}\n"
      "  for i = 1, 1000 do local s = table.concat(t) end");
  CHECK(contains(r.error,
                 "probe.lua:5: instruction budget exhausted (200000 instructions per "
                 "cycle; table.concat of 100000 elements)"));
  r = run_probe(
      "  local t = {} for i = 1, 10000 do t[i] = i end\n"
      "  for i = 1, 1000 do table.insert(t, 1, i) end");
  CHECK(contains(r.error, "probe.lua:5: instruction budget exhausted"));
  CHECK(contains(r.error, "table.insert moving"));
  // Legitimate use still works and gives Lua's results.
  r = run_probe(
      "  local t = table.move({1, 2, 3}, 1, 3, 2)\n"
      "  assert(table.concat(t, ',') == '1,1,2,3')\n"
      "  table.insert(t, 1, 0) assert(table.remove(t, 1) == 0 and #t == 4)\n"
      "  table.sort(t, function(a, b) return a > b end) assert(t[1] == 3)\n"
      "  assert(select('#', table.unpack(t)) == 4 and ('abc'):byte(1, -1) == 97)");
  CHECK(r.status == SkillStatus::kFinal);
  CHECK(r.error.empty());
}

TEST_CASE("backtracking patterns exhaust the instruction budget at the caller's line") {
  const std::string subject = "  local s = string.rep('a', 30000)\n";
  Outcome r = run_probe(subject + "  string.find(s, 'a*a*a*a*a*b')");
  CHECK(r.status == SkillStatus::kFailed);
  CHECK(r.error ==
        "probe: probe.lua:5: instruction budget exhausted (200000 instructions per cycle; "
        "string.find: pattern matching)");
  r = run_probe(subject + "  s:match('.-.-.-b')");
  CHECK(contains(r.error,
                 "probe.lua:5: instruction budget exhausted (200000 instructions per "
                 "cycle; string.match: pattern matching)"));
  r = run_probe(subject + "  s:gsub('a*a*b', '')");
  CHECK(contains(r.error,
                 "probe.lua:5: instruction budget exhausted (200000 instructions per "
                 "cycle; string.gsub: pattern matching)"));
  r = run_probe(subject + "  for x in s:gmatch('a*a*b') do end");
  CHECK(contains(r.error,
                 "probe.lua:5: instruction budget exhausted (200000 instructions per "
                 "cycle; string.gmatch: pattern matching)"));
  r = run_probe(subject + "  s:find(string.rep('a', 20000) .. 'b', 1, true)");
  CHECK(contains(r.error,
                 "probe.lua:5: instruction budget exhausted (200000 instructions per "
                 "cycle; string.find: plain search)"));
  // A skill's pcall cannot swallow the exhausted budget.
  r = run_probe(subject + "  local ok = pcall(string.find, s, 'a*a*a*b')\n  assert(not ok)");
  CHECK(r.status == SkillStatus::kFailed);
  CHECK(contains(r.error, "instruction budget exhausted"));
  // Deep nesting and malformed patterns are errors at the line, not crashes.
  r = run_probe("  string.find(string.rep('x', 300), string.rep('x?', 300))");
  CHECK(contains(r.error, "probe.lua:4: pattern too complex (over 200 nested items)"));
  r = run_probe("  string.find('x', '[x')");
  CHECK(contains(r.error, "probe.lua:4: malformed pattern (missing ']')"));
}

TEST_CASE("the allocation budget stops copying big strings in a loop; pcall cannot catch it") {
  Outcome r = run_probe(
      "  local s = string.rep('x', 4 << 20)\n"
      "  for i = 1, 1000 do local ok = pcall(function() return s .. s end) end");
  CHECK(r.status == SkillStatus::kFailed);
  // The line that was running when the allocation was refused (Lua's memory error has none).
  CHECK(r.error ==
        "probe: probe.lua:5: allocation budget exhausted (33554432 bytes allocated per cycle; "
        "copying big strings in a loop?)");
  r = run_probe("  local s = 'x' while true do s = s .. s end");
  CHECK(r.status == SkillStatus::kFailed);
  CHECK(r.error == "probe: probe.lua:4: not enough memory (heap limit of 16777216 bytes)");
}

TEST_CASE("the library tables are read-only: one skill cannot change another's string.format") {
  TempDir dir("llsf_budget");
  dir.write("tamper.lua",
            "name = 'tamper'\n"
            "documentation = 'tries to change the shared libraries'\n"
            "function execute()\n"
            "  local fake = function() return 'tampered' end\n"
            "  local tries = {\n"
            "    function() string.format = fake end,\n"
            "    function() rawset(string, 'format', fake) end,\n"
            "    function() table.concat = fake end,\n"
            "    function() math.floor = fake end,\n"
            "    function() utf8.char = fake end,\n"
            "    function() SkillHSM.new = fake end,\n"
            "    function() JumpState.kind = 'skill' end,\n"
            "    function() skillenv.module_init = fake end,\n"
            "    function() getmetatable('').__index.format = fake end,\n"
            "  }\n"
            "  local refused = 0\n"
            "  for _, f in ipairs(tries) do if not pcall(f) then refused = refused + 1 end end\n"
            "  print('refused ' .. refused)\n"
            "  string.format = fake  -- MARK\n"
            "end\n");
  dir.write("victim.lua",
            "name = 'victim'\n"
            "documentation = 'uses the libraries'\n"
            "function execute()\n"
            "  local n = 0 for _ in pairs(string) do n = n + 1 end\n"
            "  assert(n > 10 and #table == 0, 'pairs over the read-only library')\n"
            "  assert(string.format('%d', 7) == '7' and ('%d'):format(7) == '7')\n"
            "  assert(table.concat({1, 2}) == '12' and math.floor(1.5) == 1)\n"
            "  return S_FINAL\n"
            "end\n");
  FakeRobot robot;
  lua::SkillEngine engine(budget_config(dir), robot);
  std::vector<std::string> log;
  engine.set_log_sink([&](lua::LogLevel, std::string_view text) { log.emplace_back(text); });
  REQUIRE(engine.exec("tamper{}"));
  CHECK(engine.cycle() == SkillStatus::kFailed);
  CHECK(without_dir(engine.error(), dir) ==
        "tamper: " + test::marked_line(dir.file("tamper.lua")) +
            ": string is read-only (shared by every skill): cannot set "
            "string.format");
  CHECK(std::find(log.begin(), log.end(), "refused 9") != log.end());
  REQUIRE(engine.exec("victim{}"));
  CHECK(engine.cycle() == SkillStatus::kFinal);
  CHECK(engine.error().empty());
}

TEST_CASE("a skill sees other skills read-only: it can call them, not reach their internals") {
  TempDir dir("llsf_budget");
  dir.write("meddler.lua",
            "name = 'meddler'\n"
            "documentation = 'tries to change the skill it depends on'\n"
            "depends_skills = {'target'}\n"
            "function execute()\n"
            "  assert(target.name == 'target' and target.env == nil and target.fsm == nil)\n"
            "  assert(target.bindings == nil and getmetatable(target) == false)\n"
            "  assert(not pcall(rawset, target, 'load_error', 'broken'))\n"
            "  assert(target{} == S_FINAL and target.status == S_FINAL)\n"
            "  target.execute = nil  -- MARK\n"
            "end\n");
  dir.write("target.lua",
            "name = 'target'\n"
            "documentation = 'finishes'\n"
            "function execute() return S_FINAL end\n");
  FakeRobot robot;
  lua::SkillEngine engine(budget_config(dir), robot);
  REQUIRE(engine.exec("meddler{}"));
  CHECK(engine.cycle() == SkillStatus::kFailed);
  CHECK(without_dir(engine.error(), dir) ==
        "meddler: " + test::marked_line(dir.file("meddler.lua")) +
            ": skill 'target' is read-only: cannot set target.execute");
  REQUIRE(engine.exec("target{}"));
  CHECK(engine.cycle() == SkillStatus::kFinal);
}

namespace {

// Lua for the two skills below: where in the tables a skill can walk (next, rawget) from its
// own state and globals lies a real skill handle (is_skill set; another skill as skills see it
// is an empty proxy). Sorted paths, or "nothing".
constexpr const char* kHandleFinder = R"(
local function handles_from(...)
  local found, seen, queue, i = {}, {}, {}, 1
  for _, root in ipairs{...} do
    seen[root[1]] = true
    queue[#queue + 1] = root
  end
  while queue[i] do
    local t, path = queue[i][1], queue[i][2]
    i = i + 1
    if rawget(t, 'is_skill') then found[#found + 1] = path end
    for k, v in next, t do
      if type(v) == 'table' and not seen[v] then
        seen[v] = true
        queue[#queue + 1] = {v, path .. '.' .. tostring(k)}
      end
    end
  end
  table.sort(found)
  return #found == 0 and 'nothing' or table.concat(found, ', ')
end
)";

// `meddler` runs `worker` (three steps) from a SkillJumpState; each reports the real handles it
// can reach, and with vars.tamper = "down" (meddler) or "up" (worker) uses them: meddler makes
// worker end at once, worker makes meddler fail.
void write_meddler_and_worker(const TempDir& dir) {
  dir.write("meddler.lua", std::string(R"(name = 'meddler'
documentation = 'runs worker and reaches for its state machine'
depends_skills = {'worker'}
fsm = SkillHSM:new{name=name, start='RUN'}
fsm:define_states{{'RUN', SkillJumpState, skills={{worker}}, final_to='FINAL'}}
)") + kHandleFinder + R"(
function RUN:init()
  assert(self.skills[1][1] == worker and self.skills[1][1].name == 'worker')
  print('meddler reaches ' .. handles_from({self, 'self'}, {_M, '_M'}))
end
function RUN:loop()
  local subskills = rawget(self, 'subskills')
  if self.fsm.vars.tamper == 'down' and subskills then
    local w = subskills[1].handle.fsm
    w.current = w.final
  end
end
)");
  dir.write("worker.lua", std::string(R"(name = 'worker'
documentation = 'works for three steps and reaches for its caller'
fsm = SkillHSM:new{name=name, start='WORK'}
fsm:define_states{{'WORK'}}
fsm:add_transitions{{'WORK', 'FINAL', cond='vars.n == 3'}}
)") + kHandleFinder + R"(
function WORK:init()
  self.fsm.vars.n = 0
  print('worker reaches ' .. handles_from({self, 'self'}, {_M, '_M'}))
end
function WORK:loop()
  self.fsm.vars.n = self.fsm.vars.n + 1
  local me = rawget(self.fsm, 'skill')
  if self.fsm.vars.tamper == 'up' and me and me.child_of then
    me.child_of.fsm.error = 'stopped by worker'
  end
end
)");
}

// The first line of `log` that starts with `prefix` ("" if none).
std::string line_starting(const std::vector<std::string>& log, const std::string& prefix) {
  for (const std::string& line : log) {
    if (line.rfind(prefix, 0) == 0) return line;
  }
  return "";
}

// An engine with meddler and worker loaded, its log kept.
struct Meddling {
  TempDir dir{"llsf_budget"};
  FakeRobot robot;
  std::vector<std::string> log;
  lua::SkillEngine engine{config(dir), robot};
  Meddling() {
    engine.set_log_sink([this](lua::LogLevel, std::string_view text) { log.emplace_back(text); });
  }
  static lua::SkillEngineConfig config(TempDir& dir) {
    write_meddler_and_worker(dir);
    return budget_config(dir);
  }
};

}  // namespace

TEST_CASE("a SkillJumpState's state holds no real handle: a skill cannot end its sub-skill") {
  Meddling m;
  lua::SkillEngine& engine = m.engine;
  FakeRobot& robot = m.robot;
  const std::vector<std::string>& log = m.log;
  REQUIRE(engine.exec("meddler{tamper='down'}"));
  CHECK(test::run_cycles(engine, robot, 2) == SkillStatus::kRunning);
  CHECK(engine.skill_state("worker") == "WORK");
  CHECK(test::run_cycles(engine, robot, 1) == SkillStatus::kFinal);
  CHECK(engine.error() == "");
  CHECK(line_starting(log, "meddler reaches") == "meddler reaches nothing");
}

TEST_CASE("a sub-skill's state machine holds no real handle: it cannot fail its caller") {
  Meddling m;
  lua::SkillEngine& engine = m.engine;
  FakeRobot& robot = m.robot;
  const std::vector<std::string>& log = m.log;
  REQUIRE(engine.exec("meddler{tamper='up'}"));
  CHECK(test::run_cycles(engine, robot, 2) == SkillStatus::kRunning);
  CHECK(test::run_cycles(engine, robot, 1) == SkillStatus::kFinal);
  CHECK(engine.error() == "");
  CHECK(line_starting(log, "worker reaches") == "worker reaches nothing");
}

TEST_CASE("fsm.vars' metatable is not shared: a skill cannot change how others read vars") {
  TempDir dir("llsf_budget");
  dir.write("tamper.lua", R"(name = 'tamper'
documentation = 'makes every unset key of vars read true, for every skill'
fsm = SkillHSM:new{name=name, start='GO'}
fsm:define_states{{'GO'}}
fsm:add_transitions{{'GO', 'FINAL', cond=true}}
function GO:init()
  local mt = getmetatable(self.fsm.vars)
  print('getmetatable(vars): ' .. (type(mt) == 'table' and 'a table' or tostring(mt)))
  if type(mt) == 'table' then mt.__index = function() return true end end
end
)");
  dir.write("waiter.lua", R"(name = 'waiter'
documentation = 'waits for vars.done, which nothing sets'
fsm = SkillHSM:new{name=name, start='WAIT'}
fsm:define_states{{'WAIT'}}
fsm:add_transitions{{'WAIT', 'FINAL', cond='vars.done'}}
)");
  FakeRobot robot;
  lua::SkillEngine engine(budget_config(dir), robot);
  std::vector<std::string> log;
  engine.set_log_sink([&](lua::LogLevel, std::string_view text) { log.emplace_back(text); });
  REQUIRE(engine.exec("tamper{}"));
  CHECK(engine.cycle() == SkillStatus::kFinal);
  CHECK(line_starting(log, "getmetatable(vars)") == "getmetatable(vars): false");
  REQUIRE(engine.exec("waiter{}"));
  CHECK(test::run_cycles(engine, robot, 3) == SkillStatus::kRunning);
  CHECK(engine.skill_state("waiter") == "WAIT");
}

TEST_CASE("string positions count for the charges; error objects never show an address") {
  Outcome r = run_probe(
      "  local t = {string.byte(string.rep('x', 100000), 1, -1)}\n"
      "  for i = 1, 1000 do local s = table.concat(t, '', '1', '100000') end");
  CHECK(contains(r.error,
                 "probe.lua:5: instruction budget exhausted (200000 instructions per "
                 "cycle; table.concat of 100000 elements)"));
  r = run_probe("  error({})");
  CHECK(r.error == "probe: (error object is a table value)");
  r = run_probe("  do return S_FAILED, {} end");
  CHECK(r.error == "probe: (error object is a table value)");
}

TEST_CASE("an endless loop over a library wrapper is reported at the skill's line") {
  // The wrappers are prelude code: for some budgets the count hook fires inside them.
  for (std::int64_t budget = 200'000; budget < 230'000; budget += 1000) {
    const Outcome r = run_probe("  local t = {} while true do table.unpack(t) end", budget);
    CHECK(r.error == "probe: probe.lua:4: instruction budget exhausted (" + std::to_string(budget) +
                         " instructions per cycle; endless loop?)");
  }
}

TEST_CASE("a plain execute() skill is reset without an error") {
  const Outcome r = run_probe("  local x = 1");
  CHECK(r.status == SkillStatus::kFinal);
  CHECK(r.log.empty());  // was: "resetting skills: ...: undeclared global 'reset'"
}

namespace {

// Calls of the pattern functions, serialised (errors as "error"); the same text must come out of
// Lua's own string library and the engine's bounded one.
const char* const kPatternCases = R"lua(
local out = {}
local function ser(ok, ...)
  if not ok then return "error" end
  local t = {}
  for i = 1, select("#", ...) do t[#t + 1] = type((select(i, ...))) .. ":" .. tostring((select(i, ...))) end
  return table.concat(t, ",")
end
local function try(f, ...) out[#out + 1] = ser(pcall(f, ...)) end
local function all(s, p, init)
  try(function()
    local r = {}
    for a, b in string.gmatch(s, p, init) do r[#r + 1] = tostring(a) .. "/" .. tostring(b) end
    return table.concat(r, ";")
  end)
end
local subjects = {"hello world", "", "THE (quick) fox", "f(a(b)c)d", "key = value",
                  "  trim me  ", "2024-01-05", "abcabc", "aaab", "a.b+c[d]^e$", "a\0b\0",
                  "x = 1, y = 2", "]]^-%", "caf\xc3\xa9 na\xc3\xafve"}
local patterns = {"o w", "l+", "^h", "^e", "o$", "(l)(l)", "()ll()", "", ".", "%.", "+", "[]]",
                  "%((%a+)%)", "%b()", "%f[%a]%a+", "%f[%A]", "[^%l]", "^(%w+)%s*=%s*(.-)$",
                  "(abc)%1", "a-b", "a*", "a?b", "(%w+) = (%w+)", "^%s*(.-)%s*$",
                  "(%d+)-(%d+)-(%d+)", "%z", "\0", "[%a-z]+", "[a%-]+", "[%^]", "a^b", "[^]]+",
                  "[a-c]+", "[%d%s]+", "%u+", "%p", "%x+", "%c", "%g+", "$", "^$", "^", ".-$",
                  "(a)(b)", "((a)(b))", "()", "(()a)", "[\xc3][\x80-\xbf]", "%a*%d",
                  "%", "(x", "x)", "%1", "[x", "%b", "%bx", "%f", "%fx", "(()", "[%"}
for _, s in ipairs(subjects) do
  for _, p in ipairs(patterns) do
    try(string.find, s, p)
    try(string.match, s, p)
    try(string.find, s, p, 3)
    try(string.match, s, p, -4)
    try(string.find, s, p, 1, true)
    try(string.gsub, s, p, "<%0>")
    try(string.gsub, s, p, "%1", 2)
    all(s, p)
    all(s, p, 4)
  end
end
local s = "hello world from lua"
try(string.find, s, "o", 100) try(string.find, s, "", 21) try(string.find, s, "", 22)
try(string.find, s, "", -100) try(string.match, s, "()", 21)
try(string.gsub, s, "%w+", {hello = "HI", lua = false, world = 1})
try(string.gsub, s, "%w+", function(w) if w ~= "from" then return w:upper() end end)
try(string.gsub, s, "(%w+) (%w+)", "%2 %1") try(string.gsub, s, "o", "%%")
try(string.gsub, s, "o", "%9") try(string.gsub, s, "o", "%x") try(string.gsub, s, "o", "%")
try(string.gsub, s, "o", function() return {} end) try(string.gsub, s, "o", 5)
try(string.gsub, s, "o", true) try(string.gsub, s, "l", "L", 0) try(string.gsub, s, "l", "L", -1)
try(string.gsub, s, "()", "%1") try(string.gsub, "abc", "", "-") try(string.gsub, "abc", "b*", "-")
try(string.gsub, "abc", "^a", "x") try(string.gsub, "abc", "^", "x") try(string.gsub, "a", ".", "%0%0%0")
try(string.find, 12345, 3) try(string.gsub, 12345, 3, 9) try(string.match, "x", nil)
-- Random patterns and subjects (a fixed linear congruential sequence: the same on both sides).
local seed = 12345
local function rnd(n) seed = (seed * 1103515245 + 12345) % 2147483648 return seed % n + 1 end
local pat_chars = {"a", "b", "%", "(", ")", "[", "]", "^", "$", "*", "+", "-", "?", ".", "1",
                   "2", "f", "%a", "%d", "%b()", "%f[ab]", "[^a]", "[a-c]", "%1", "()"}
local subj_chars = {"a", "b", "c", "(", ")", "1", " ", "-", "^", "%", "]"}
for _ = 1, 2500 do
  local p, sub = {}, {}
  for i = 1, rnd(7) do p[i] = pat_chars[rnd(#pat_chars)] end
  for i = 1, rnd(12) - 1 do sub[i] = subj_chars[rnd(#subj_chars)] end
  p, sub = table.concat(p), table.concat(sub)
  try(string.find, sub, p)
  try(string.match, sub, p, rnd(5) - 2)
  try(string.gsub, sub, p, "<%0%1>")
  all(sub, p)
end
return table.concat(out, "\n")
)lua";

std::string stock_lua_results() {
  lua_State* L = luaL_newstate();
  luaL_openlibs(L);
  std::string out = "(stock Lua failed)";
  if (luaL_dostring(L, kPatternCases) == LUA_OK) {
    std::size_t n = 0;
    const char* text = lua_tolstring(L, -1, &n);
    out.assign(text, n);
  }
  lua_close(L);
  return out;
}

}  // namespace

TEST_CASE("the bounded pattern functions give Lua's results") {
  TempDir dir("llsf_budget");
  dir.write("patterns.lua", std::string("name = 'patterns'\n"
                                        "documentation = 'runs the pattern cases'\n"
                                        "local function cases()\n") +
                                kPatternCases +
                                "end\n"
                                "function execute() print(cases()) return S_FINAL end\n");
  FakeRobot robot;
  lua::SkillEngineConfig cfg = budget_config(dir);
  cfg.instruction_budget = 50'000'000;
  lua::SkillEngine engine(cfg, robot);
  std::string printed;
  engine.set_log_sink([&](lua::LogLevel, std::string_view text) { printed = text; });
  REQUIRE(engine.exec("patterns{}"));
  REQUIRE(engine.cycle() == SkillStatus::kFinal);
  const std::string expected = stock_lua_results();
  REQUIRE(expected.size() > 10000);
  // Line by line, so that a difference shows the case.
  std::size_t a = 0;
  std::size_t b = 0;
  int line = 1;
  int differences = 0;
  while (a <= expected.size() && b <= printed.size() && differences < 10) {
    const std::size_t ea = std::min(expected.find('\n', a), expected.size());
    const std::size_t eb = std::min(printed.find('\n', b), printed.size());
    const std::string want = expected.substr(a, ea - a);
    const std::string got = printed.substr(b, eb - b);
    if (want != got) {
      ++differences;
      INFO("case ", line);
      CHECK(got == want);
    }
    a = ea + 1;
    b = eb + 1;
    ++line;
  }
  CHECK(differences == 0);
  CHECK(printed.size() == expected.size());
}

TEST_CASE("comparing long strings in a loop is stopped by the wall-time budget") {
  // One `==` of two equal-length 4 MB strings is one VM instruction that compares 4 MB: 200,000
  // instructions of it take minutes, and no count sees the work. The wall budget ends it.
  TempDir dir("llsf_budget");
  dir.write("probe.lua", probe_skill("  local a = string.rep('x', 4000000)\n"
                                     "  local b = string.rep('x', 3999999) .. 'y'\n"
                                     "  local n = 0\n"
                                     "  while true do if a == b then n = n + 1 end end"));
  FakeRobot robot;
  lua::SkillEngineConfig cfg = budget_config(dir);
  cfg.instruction_budget = 100'000'000;
  cfg.max_cycle_wall_s = 0.2;
  lua::SkillEngine engine(cfg, robot);
  REQUIRE(engine.exec("probe{}"));
  CHECK(engine.cycle() == SkillStatus::kFailed);
  const std::string error = without_dir(engine.error(), dir);
  CHECK_MESSAGE(contains(error, "probe.lua:7: wall-time budget exhausted (0.2 s per cycle"), error);
}

TEST_CASE("max_cycle_wall_s is validated") {
  lua::SkillEngineConfig cfg;
  cfg.max_cycle_wall_s = 0.0;
  CHECK_THROWS_WITH_AS(cfg.validate(),
                       doctest::Contains("max_cycle_wall_s: must be in [0.01, 3600]"),
                       core::ConfigError);
}
