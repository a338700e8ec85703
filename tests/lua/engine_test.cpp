// SPDX-License-Identifier: MIT
// The engine around the DSL: skill strings (abort, stop), errors with file:line, containment of
// endless loops and broken files, the sandbox, the robot interfaces, hot reload.
#include <doctest/doctest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <iterator>

#include "llsf/core/error.h"
#include "lua/fake_robot.h"
#include "support/temp_dir.h"

using namespace llsf;
using lua::SkillStatus;
using test::FakeRobot;

namespace {

lua::SkillEngineConfig config() {
  lua::SkillEngineConfig cfg;
  cfg.skill_dirs = {test::example_skills_dir(), test::test_skills_dir()};
  cfg.instruction_budget = 200'000;
  return cfg;
}

std::string test_skill(const std::string& name) {
  return test::test_skills_dir() + "/" + name + ".lua";
}

bool contains(const std::string& text, const std::string& needle) {
  return text.find(needle) != std::string::npos;
}

bool starts_with(const std::string& text, const std::string& prefix) {
  return text.rfind(prefix, 0) == 0;
}

bool ends_with(const std::string& text, const std::string& suffix) {
  return text.size() >= suffix.size() &&
         text.compare(text.size() - suffix.size(), suffix.size(), suffix) == 0;
}

std::string load_error_of(const lua::SkillEngine& engine, const std::string& name) {
  for (const lua::SkillInfo& s : engine.skills()) {
    if (s.name == name) return s.load_error;
  }
  return "(no skill " + name + ")";
}

// A scratch skill directory, removed at the end of the test.
using llsf::test::TempDir;

std::string hello_skill(const std::string& greeting) {
  return "name = 'hot'\n"
         "documentation = 'prints a greeting'\n"
         "function execute() print('" +
         greeting + "') return S_FINAL end\n";
}

}  // namespace

TEST_CASE("a new skill string aborts the running one; stop() stops the robot") {
  FakeRobot robot;
  robot.nav_steps = 1000;
  lua::SkillEngine engine(config(), robot);
  REQUIRE(engine.exec("goto_place{place='M3'}"));
  CHECK(test::run_cycles(engine, robot, 3) == SkillStatus::kRunning);
  CHECK(robot.nav.status == lua::NavStatus::kRunning);

  // The new string aborts goto_place: its DRIVE:exit() stops the navigator.
  REQUIRE(engine.exec("wait_for{secs=0.2}"));
  CHECK(engine.skill_string() == "wait_for{secs=0.2}");
  CHECK(robot.stops == 1);
  CHECK(robot.nav.status == lua::NavStatus::kAborted);
  CHECK(engine.skill_status("goto_place") == SkillStatus::kInactive);
  CHECK(test::run_cycles(engine, robot, 2) == SkillStatus::kRunning);

  engine.stop();
  CHECK(engine.status() == SkillStatus::kInactive);
  CHECK(engine.cycle() == SkillStatus::kInactive);
  CHECK(robot.stops == 2);
  CHECK(engine.skill_status("wait_for") == SkillStatus::kInactive);

  // A skill restarted after an abort starts over from its start state with the new arguments.
  REQUIRE(engine.exec("goto_place{place='M1'}"));
  test::run_cycles(engine, robot, 1);
  CHECK(robot.nav_goal == "M1");
  CHECK(engine.skill_state("goto_place") == "DRIVE");
}

TEST_CASE("skill-string errors: syntax refused at exec, unknown skill fails with the line") {
  FakeRobot robot;
  lua::SkillEngine engine(config(), robot);
  const lua::ExecResult r = engine.exec("say_hello{who='x'");
  CHECK_FALSE(r.ok);
  CHECK(contains(r.error, "skill string:1:"));
  CHECK(engine.status() == SkillStatus::kFailed);
  CHECK(engine.error() == r.error);

  REQUIRE(engine.exec("say_hello{}\ngoto_plaec{place='M1'}"));
  CHECK(engine.cycle() == SkillStatus::kFailed);
  CHECK(engine.error() == "skill string:2: unknown skill 'goto_plaec'");

  REQUIRE(engine.exec("say_hello('M1')"));
  CHECK(engine.cycle() == SkillStatus::kFailed);
  CHECK(contains(engine.error(), "arguments must be a table"));
}

TEST_CASE("a syntax error in a skill file is a load error with file:line and is contained") {
  FakeRobot robot;
  lua::SkillEngine engine(config(), robot);
  const std::string where = test::marked_line(test_skill("broken_syntax"));
  const std::string err = load_error_of(engine, "broken_syntax");
  CHECK(contains(err, where + ":"));
  CHECK(contains(err, "unexpected symbol near 'then'"));
  bool listed = false;
  for (const std::string& e : engine.load_errors()) listed |= contains(e, where);
  CHECK(listed);

  REQUIRE(engine.exec("broken_syntax{}"));
  CHECK(engine.cycle() == SkillStatus::kFailed);
  CHECK(contains(engine.error(), "skill 'broken_syntax' is not available: "));
  CHECK(contains(engine.error(), where));

  // A skill depending on it is unavailable too, and says why.
  CHECK(contains(load_error_of(engine, "needs_broken"), "depends on skill 'broken_syntax'"));
  // The rest works.
  REQUIRE(engine.exec("say_hello{}"));
  CHECK(engine.cycle() == SkillStatus::kFinal);
}

TEST_CASE("an endless loop is stopped by the instruction budget with file:line") {
  FakeRobot robot;
  lua::SkillEngine engine(config(), robot);

  SUBCASE("in a loop hook") {
    REQUIRE(engine.exec("endless{}"));
    CHECK(engine.cycle() == SkillStatus::kFailed);
    CHECK(contains(engine.error(), "endless: SPIN: "));
    CHECK(contains(engine.error(), test::marked_line(test_skill("endless")) +
                                       ": instruction budget exhausted (200000 instructions"));
  }
  SUBCASE("caught by pcall in the skill: still fails") {
    REQUIRE(engine.exec("endless_catch{}"));
    CHECK(engine.cycle() == SkillStatus::kFailed);
    CHECK(contains(engine.error(), test::marked_line(test_skill("endless_catch"))));
    CHECK(contains(engine.error(), "instruction budget exhausted"));
  }
  SUBCASE("in the skill string") {
    REQUIRE(engine.exec("while true do end"));
    CHECK(engine.cycle() == SkillStatus::kFailed);
    CHECK(contains(engine.error(), "skill string:1: instruction budget exhausted"));
  }
  SUBCASE("while a file loads") {
    CHECK(contains(load_error_of(engine, "endless_load"),
                   test::marked_line(test_skill("endless_load")) + ": instruction budget"));
  }
  // The engine goes on.
  REQUIRE(engine.exec("wait_for{secs=0.1}"));
  CHECK(test::run_until_done(engine, robot) == SkillStatus::kFinal);
}

TEST_CASE("declaration errors: unknown dependency and interface type, undeclared interface") {
  FakeRobot robot;
  lua::SkillEngine engine(config(), robot);
  CHECK(ends_with(load_error_of(engine, "unknown_dep"),
                  test::marked_line(test_skill("unknown_dep")) +
                      ": depends_skills: unknown skill 'no_such_skill'"));
  CHECK(contains(load_error_of(engine, "bad_iface"),
                 test::marked_line(test_skill("bad_iface")) +
                     ": depends_interfaces[1]: unknown interface type 'FooInterface' (known: "));

  REQUIRE(engine.exec("undeclared_iface{}"));
  CHECK(engine.cycle() == SkillStatus::kFailed);
  CHECK(starts_with(engine.error(), "undeclared_iface: DRIVE: "));
  CHECK(ends_with(engine.error(), test::marked_line(test_skill("undeclared_iface")) +
                                      ": interface 'navigator' is used but not declared in "
                                      "depends_interfaces (e.g. {v=\"navigator\", "
                                      "type=\"NavigatorInterface\"})"));
  CHECK(robot.nav.goal_id == 0);
}

TEST_CASE("a runtime error fails the skill with state and file:line") {
  FakeRobot robot;
  lua::SkillEngine engine(config(), robot);
  REQUIRE(engine.exec("runtime_error{}"));
  CHECK(engine.cycle() == SkillStatus::kRunning);
  CHECK(engine.cycle() == SkillStatus::kFailed);
  CHECK(starts_with(engine.error(), "runtime_error: WORK: "));
  CHECK(ends_with(engine.error(), test::marked_line(test_skill("runtime_error")) +
                                      ": attempt to index a nil value (local 't')"));
}

TEST_CASE("an exception from the robot becomes a skill error at the calling line") {
  FakeRobot robot;
  robot.throw_on_pose = true;
  lua::SkillEngine engine(config(), robot);
  REQUIRE(engine.exec("pose_user{}"));
  CHECK(engine.cycle() == SkillStatus::kFailed);
  CHECK(starts_with(engine.error(), "pose_user: "));
  CHECK(ends_with(engine.error(),
                  test::marked_line(test_skill("pose_user")) + ": robot: localization lost"));
}

TEST_CASE("the sandbox: no files, processes, network, debug, bytecode or finalizers") {
  FakeRobot robot;
  lua::SkillEngine engine(config(), robot);
  REQUIRE(engine.exec("sandbox_probe{}"));
  CHECK(engine.cycle() == SkillStatus::kFinal);
  CHECK(engine.error().empty());
  // Nor from the skill string.
  REQUIRE(engine.exec("io.open('/etc/passwd')"));
  CHECK(engine.cycle() == SkillStatus::kFailed);
  CHECK(engine.error() == "skill string:1: unknown skill 'io'");
  CHECK_FALSE(engine.exec(std::string("\x1bLua", 4)).ok);  // binary chunks are refused
}

TEST_CASE("string.rep beyond the heap limit fails the skill at its line; the engine goes on") {
  FakeRobot robot;
  lua::SkillEngineConfig cfg = config();
  cfg.memory_limit_bytes = 16 << 20;
  lua::SkillEngine engine(cfg, robot);
  REQUIRE(engine.exec("memory_hog{}"));
  CHECK(engine.cycle() == SkillStatus::kFailed);
  CHECK(contains(engine.error(), test::marked_line(test_skill("memory_hog")) +
                                     ": string.rep: result of 1073741824 bytes over the limit of "
                                     "16777216 bytes"));
  REQUIRE(engine.exec("say_hello{}"));
  CHECK(engine.cycle() == SkillStatus::kFinal);
}

TEST_CASE("the robot interfaces read the RobotApi and command it") {
  FakeRobot robot;
  robot.pose_estimate.pose = {1.5, 2.25, 0.5};
  robot.puck = true;
  robot.ir_m = 0.04;
  robot.optical_sensors.right = true;
  robot.light_reading.visible = true;
  robot.light_reading.device = "M4";
  robot.light_reading.red = lua::Lamp::kOn;
  robot.light_reading.green = lua::Lamp::kBlink;
  robot.light_reading.stable_since = core::SimTime::from_ms(500);
  robot.time = core::SimTime::from_sec(2);
  robot.puck_sightings = {{{1.0, 0.5}}, {{0.3, -0.4}}};
  robot.laser_ranges.assign(360, 4.0F);
  robot.laser_ranges[180] = 0.75F;  // straight ahead (angle 0)
  lua::SkillEngine engine(config(), robot);
  test::LogCapture log;
  log.attach(engine);
  REQUIRE(engine.exec("read_sensors{}"));
  CHECK(engine.cycle() == SkillStatus::kFinal);
  CHECK(log.contains("pose 1.50 2.25 0.50 valid=true"));
  CHECK(log.contains("holder puck=true ir=0.04 optical=false,true"));
  CHECK(log.contains("light M4 visible=true red=ON yellow=OFF green=BLINKING on=false stable=1.5"));
  CHECK(log.contains("pucks 2 nearest 0.30 -0.40 0.50"));
  CHECK(log.contains("laser 360 ahead 0.75"));
  CHECK(robot.vx == 0.25);
  CHECK(robot.omega == 0.5);
}

TEST_CASE("hot reload between skill strings; reload() on demand") {
  FakeRobot robot;
  TempDir dir;
  dir.write("hot.lua", hello_skill("v1"));
  lua::SkillEngineConfig cfg;
  cfg.skill_dirs = {dir.path.string()};
  lua::SkillEngine engine(cfg, robot);
  test::LogCapture log;
  log.attach(engine);
  REQUIRE(engine.exec("hot{}"));
  CHECK(engine.cycle() == SkillStatus::kFinal);
  CHECK(log.contains("v1"));
  REQUIRE(engine.exec("hot{}"));
  CHECK(engine.load_count() == 1);  // unchanged files are not reloaded

  dir.write("hot.lua",
            hello_skill("version 2"));  // another size: a change even within one mtime tick
  REQUIRE(engine.exec("hot{}"));
  CHECK(engine.load_count() == 2);
  CHECK(engine.cycle() == SkillStatus::kFinal);
  CHECK(log.contains("version 2"));

  // A broken edit fails the skill, not the engine; fixing it brings it back.
  dir.write("hot.lua", "name = 'hot'\ndocumentation = 'x'\nfunction execute( return S_FINAL end\n");
  REQUIRE(engine.exec("hot{}"));
  CHECK(engine.cycle() == SkillStatus::kFailed);
  CHECK(contains(engine.error(), "hot.lua:3:"));
  dir.write("hot.lua", hello_skill("version three"));
  dir.write("cold.lua",
            "name = 'cold'\ndocumentation = 'x'\nfunction execute() return S_FINAL end\n");
  REQUIRE(engine.exec("hot{} cold{}"));
  CHECK(engine.cycle() == SkillStatus::kFinal);
  CHECK(log.contains("version three"));

  cfg.hot_reload = false;
  lua::SkillEngine frozen(cfg, robot);
  dir.write("cold.lua", "name = 'cold'\ndocumentation = 'changed'\nfunction execute( end\n");
  REQUIRE(frozen.exec("cold{}"));
  CHECK(frozen.cycle() == SkillStatus::kFinal);
  frozen.reload();
  CHECK(frozen.load_count() == 2);
  CHECK_FALSE(load_error_of(frozen, "cold").empty());
}

TEST_CASE("bad configurations throw ConfigError naming the field") {
  FakeRobot robot;
  lua::SkillEngineConfig cfg = config();
  cfg.skill_dirs.push_back("/nonexistent/skills");
  CHECK_THROWS_WITH_AS(lua::SkillEngine(cfg, robot),
                       doctest::Contains("skill directory '/nonexistent/skills' does not exist"),
                       core::ConfigError);
  cfg = config();
  cfg.instruction_budget = 10;
  CHECK_THROWS_AS(lua::SkillEngine(cfg, robot), core::ConfigError);
  cfg = config();
  cfg.allocation_budget_bytes = 1000;
  CHECK_THROWS_WITH_AS(lua::SkillEngine(cfg, robot),
                       doctest::Contains("allocation_budget_bytes: must be in [1048576, "),
                       core::ConfigError);

  // Each bad figure of a YAML map is named at its own key's line.
  for (const auto& [line, key] : std::vector<std::pair<std::string, std::string>>{
           {"rate_hz: 0.0001", "rate_hz"},
           {"instruction_budget: 100000000000", "instruction_budget"},
           {"memory_limit_bytes: 10", "memory_limit_bytes"},
           {"max_cycle_wall_s: 1e300", "max_cycle_wall_s"}}) {
    const core::ConfigNode bad =
        core::ConfigNode::parse("skills:\n  hot_reload: false\n  " + line + "\n", "bad.yaml");
    CHECK_THROWS_WITH_AS(lua::SkillEngineConfig::from_config(bad["skills"]),
                         doctest::Contains("bad.yaml:3:"), core::ConfigError);
    const std::string expected = "skills." + key + ": must be in";
    CHECK_THROWS_WITH_AS(lua::SkillEngineConfig::from_config(bad["skills"]),
                         doctest::Contains(expected.c_str()), core::ConfigError);
  }

  const core::ConfigNode node = core::ConfigNode::parse(
      "skills:\n  skill_dirs: [" + test::example_skills_dir() +
          "]\n  rate_hz: 15\n  instruction_budget: 5000\n  allocation_budget_bytes: 2000000\n"
          "  hot_reload: false\n",
      "robot.yaml");
  const lua::SkillEngineConfig parsed = lua::SkillEngineConfig::from_config(node["skills"]);
  CHECK(parsed.skill_dirs == std::vector<std::string>{test::example_skills_dir()});
  CHECK(parsed.rate_hz == 15.0);
  CHECK(parsed.instruction_budget == 5000);
  CHECK(parsed.allocation_budget_bytes == 2'000'000);
  CHECK_FALSE(parsed.hot_reload);
  const core::ConfigNode bad = core::ConfigNode::parse("skills:\n  rate: 15\n", "robot.yaml");
  CHECK_THROWS_WITH_AS(lua::SkillEngineConfig::from_config(bad["skills"]),
                       doctest::Contains("robot.yaml:2"), core::ConfigError);
}

TEST_CASE("same inputs, same outcome: math.random is seeded from the config") {
  TempDir dir;
  dir.write("roll.lua",
            "name = 'roll'\ndocumentation = 'x'\n"
            "function execute() print(math.random(1, 1000000)) return S_FINAL end\n");
  auto roll = [&](std::uint64_t seed) {
    FakeRobot robot;
    lua::SkillEngineConfig cfg;
    cfg.skill_dirs = {dir.path.string()};
    cfg.random_seed = seed;
    lua::SkillEngine engine(cfg, robot);
    test::LogCapture log;
    log.attach(engine);
    REQUIRE(engine.exec("roll{}"));
    engine.cycle();
    return log.lines.at(0);
  };
  CHECK(roll(7) == roll(7));
  CHECK(roll(7) != roll(8));
}

TEST_CASE("the example skill of docs/skills.md loads and runs") {
  std::ifstream in(LLSF_SOURCE_DIR "/docs/skills.md");
  const std::string doc((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::size_t begin = doc.find("```lua\n");
  REQUIRE(begin != std::string::npos);
  const std::size_t end = doc.find("```", begin + 7);
  REQUIRE(end != std::string::npos);
  TempDir dir;
  dir.write("visit_place.lua", doc.substr(begin + 7, end - begin - 7));

  FakeRobot robot;
  lua::SkillEngineConfig cfg = config();
  cfg.skill_dirs.push_back(dir.path.string());  // replaces the example visit_place
  lua::SkillEngine engine(cfg, robot);
  CHECK(load_error_of(engine, "visit_place").empty());
  robot.places.insert("M1_side");
  REQUIRE(engine.exec("visit_place{place='M1'}"));
  // Arrived, no light visible: sidesteps and looks again, and again.
  CHECK(test::run_cycles(engine, robot, 10) == SkillStatus::kRunning);
  CHECK(robot.nav_goal == "M1_side");
  CHECK(robot.nav.goal_id >= 2);
  robot.light_reading.visible = true;
  robot.light_reading.stable_since = robot.time;
  CHECK(test::run_until_done(engine, robot) == SkillStatus::kFinal);
  CHECK(robot.time - robot.light_reading.stable_since >= core::SimTime::from_sec(1));

  REQUIRE(engine.exec("visit_place{}"));
  CHECK(engine.cycle() == SkillStatus::kFailed);
  CHECK(engine.error() == "visit_place: visit_place needs place=...");
}

TEST_CASE("skill results: fsm.result of the string's skills when it ends, cleared by exec") {
  FakeRobot robot;
  lua::SkillEngine engine(config(), robot);
  REQUIRE(engine.exec("report_result{text='DONE'}"));
  CHECK(engine.result().empty());
  CHECK(test::run_cycles(engine, robot, 1) == SkillStatus::kFinal);
  CHECK(engine.result() == "DONE");
  // Also on failure; two skills in one string are joined.
  REQUIRE(engine.exec("report_result{text='M3 red=ON', fail=true}"));
  CHECK(test::run_cycles(engine, robot, 1) == SkillStatus::kFailed);
  CHECK(engine.result() == "M3 red=ON");
  CHECK(engine.error() == "report_result: asked to fail");
  REQUIRE(engine.exec("say_hello{}"));
  CHECK(engine.result().empty());
  CHECK(test::run_cycles(engine, robot, 1) == SkillStatus::kFinal);
  CHECK(engine.result().empty());  // say_hello reports nothing
  // A restarted skill starts without its old result.
  REQUIRE(engine.exec("report_result{}"));
  CHECK(test::run_cycles(engine, robot, 1) == SkillStatus::kFinal);
  CHECK(engine.result().empty());
}
