// SPDX-License-Identifier: MIT
// Skills written for Fawkes' Lua skiller (docs/fawkes.md, "Skills written for Fawkes"): require
// of helper modules (skill and module directories only), files that define no skill, the
// self.skills[i] arguments of a SkillJumpState, fawkes.load_yaml_navgraph, fawkes.tf and the
// tf transformer, the config, Fawkes' interface API (messages, fields, has_writer) and the
// generic skill ppgoto. The skills are tests/lua/fawkes/, written for these tests.
#include <doctest/doctest.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <string>

#include "lua/fake_robot.h"
#include "support/temp_dir.h"

using namespace llsf;
using lua::SkillStatus;
using test::FakeRobot;

namespace {

const std::string kDir = LLSF_SOURCE_DIR "/tests/lua/fawkes";

lua::SkillEngineConfig fawkes_config() {
  lua::SkillEngineConfig cfg;
  cfg.skill_dirs = {LLSF_SOURCE_DIR "/lua/skills/fawkes", kDir + "/skills"};
  cfg.module_dirs = {kDir + "/modules"};
  cfg.cfg_dirs = {kDir + "/cfg"};
  cfg.fawkes_config["/skills/nudge/near_dist"] = "0.05";
  return cfg;
}

bool contains(const std::string& text, const std::string& needle) {
  return text.find(needle) != std::string::npos;
}

std::string load_error_of(const lua::SkillEngine& engine, const std::string& name) {
  for (const lua::SkillInfo& s : engine.skills()) {
    if (s.name == name) return s.load_error;
  }
  return "(no skill " + name + ")";
}

void write(const std::string& path, const std::string& text) { std::ofstream(path) << text; }

// A Fawkes-style skill whose DO state runs `body` (Lua statements) once.
std::string skill_running(const std::string& name, const std::string& body,
                          const std::string& interfaces = "") {
  return "module(..., skillenv.module_init)\nname = '" + name +
         "'\nfsm = SkillHSM:new{name=name, start='DO'}\ndepends_interfaces = {" + interfaces +
         "}\ndocumentation = 'test'\nskillenv.skill_module(_M)\n"
         "fsm:define_states{export_to=_M, {'DO', JumpState}}\n"
         "fsm:add_transitions{{'DO', 'FINAL', cond=true}}\n"
         "function DO:init()\n" +
         body + "\nend\n";
}

}  // namespace

TEST_CASE("Fawkes-style skills load: require of helper modules, helper files are no skills") {
  FakeRobot robot;
  lua::SkillEngine engine(fawkes_config(), robot);
  CHECK(engine.load_errors().empty());
  std::vector<std::string> names;
  for (const lua::SkillInfo& s : engine.skills()) names.push_back(s.name);
  // place_table.lua declares nothing of a skill: a helper module, not listed, not callable.
  CHECK(names == std::vector<std::string>{"drive_node", "nudge", "ppgoto", "probe", "read_light",
                                          "transitions"});
  const lua::ExecResult r = engine.exec("place_table{}");
  REQUIRE(r);
  CHECK(test::run_cycles(engine, robot, 1) == SkillStatus::kFailed);
  CHECK(contains(engine.error(), "'place_table' is no skill"));
}

TEST_CASE("a skill directory whose init.lua names its skills (a Fawkes skill space)") {
  test::TempDir dir;
  dir.write("init.lua",
            "require('fawkes.modinit')\nmodule(..., fawkes.modinit.register_all)\n"
            "print('Initializing the space')\n"
            "skillenv.use_skill('skills.space.named')\n"
            "skillenv.use_skill('skills.generic.ppgoto')\n");
  dir.write("named.lua", skill_running("named", "self.fsm.result = require('helper').answer"));
  dir.write("helper.lua", "answer = 'forty-two'\n");
  dir.write("left_out.lua", "this is no Lua\n");
  lua::SkillEngineConfig cfg = fawkes_config();
  cfg.skill_dirs = {LLSF_SOURCE_DIR "/lua/skills/fawkes", dir.path.string()};
  FakeRobot robot;
  lua::SkillEngine engine(cfg, robot);
  // left_out.lua is not named: not loaded (it would not load); ppgoto of another directory.
  CHECK(engine.load_errors().empty());
  std::vector<std::string> names;
  for (const lua::SkillInfo& s : engine.skills()) names.push_back(s.name);
  CHECK(names == std::vector<std::string>{"named", "ppgoto"});
  // A file the space does not name is a module for require.
  REQUIRE(engine.exec("named{}"));
  CHECK(test::run_cycles(engine, robot, 1) == SkillStatus::kFinal);
  CHECK(engine.result() == "forty-two");
}

TEST_CASE("a helper module in a skill directory that returns a table: require gives that table") {
  // The engine loads every file of a skill directory, in name order: aa_helper.lua before the
  // skill that requires it, zz_helper.lua after (then require loads it first). Either way
  // require gives what the file returned, as the docs say, not the file's globals.
  test::TempDir dir;
  const std::string helper = "local M = {}\nM.answer = 'forty-two'\nreturn M\n";
  dir.write("aa_helper.lua", helper);
  dir.write("zz_helper.lua", helper);
  dir.write("mid_user.lua", skill_running("mid_user",
                                          "self.fsm.result = require('aa_helper').answer .. ' ' .. "
                                          "require('zz_helper').answer"));
  lua::SkillEngineConfig cfg = fawkes_config();
  cfg.skill_dirs = {LLSF_SOURCE_DIR "/lua/skills/fawkes", dir.path.string()};
  FakeRobot robot;
  lua::SkillEngine engine(cfg, robot);
  CHECK(engine.load_errors().empty());
  REQUIRE(engine.exec("mid_user{}"));
  CHECK(test::run_cycles(engine, robot, 1) == SkillStatus::kFinal);
  CHECK(engine.result() == "forty-two forty-two");
}

TEST_CASE("require finds only Lua files of the skill and module directories") {
  test::TempDir dir;
  const std::string skills = dir.path.string() + "/skills";
  std::filesystem::create_directories(skills);
  std::filesystem::create_directories(dir.path.string() + "/outside");
  write(dir.path.string() + "/outside/secret.lua", "return {x = 1}\n");
  const std::string modules = dir.path.string() + "/modules";
  std::filesystem::create_directories(modules);
  std::filesystem::create_symlink(dir.path.string() + "/outside/secret.lua",
                                  modules + "/linked.lua");
  write(skills + "/missing.lua", skill_running("missing", "local m = require('nowhere')"));
  write(skills + "/escape.lua", skill_running("escape", "local m = require('../outside/secret')"));
  write(skills + "/via_link.lua", skill_running("via_link", "local m = require('linked')"));
  write(skills + "/loop_a.lua", "local b = require('loop_b')\n");
  write(skills + "/loop_b.lua", "local a = require('loop_a')\n");
  // A skill file required before or after it loaded as a skill.
  write(skills + "/b_user.lua", skill_running("b_user", "local m = require('zz_skill')"));
  write(skills + "/zz_skill.lua", skill_running("zz_skill", ""));
  write(skills + "/c_early.lua", "local m = require('zz_skill')\n" + skill_running("c_early", ""));
  write(skills + "/zz_user.lua", skill_running("zz_user", "local m = require('b_user')"));
  write(skills + "/a_user.lua",
        "local a = require('loop_a')\nname = 'a_user'\ndocumentation = 'x'\n"
        "function execute() return S_FINAL end\n");
  lua::SkillEngineConfig cfg;
  cfg.skill_dirs = {skills};
  cfg.module_dirs = {modules};
  FakeRobot robot;
  lua::SkillEngine engine(cfg, robot);
  const auto run = [&](const std::string& s) {
    REQUIRE(engine.exec(s));
    CHECK(test::run_cycles(engine, robot, 1) == SkillStatus::kFailed);
    return engine.error();
  };
  const std::string missing = run("missing{}");
  CHECK(contains(missing,
                 "missing.lua:10: module 'nowhere' is not available in skills: require "
                 "loads only the Lua files of the skill and module directories ("));
  CHECK(contains(missing, "(no nowhere.lua or nowhere/init.lua in them); to use another skill"));
  CHECK(contains(run("escape{}"), "'../outside/secret' is no module name"));
  // A symbolic link out of the directory is not followed.
  CHECK(contains(run("via_link{}"), "module 'linked' is not available in skills"));
  CHECK(contains(load_error_of(engine, "a_user"), "module 'loop_a' requires itself (a cycle)"));
  CHECK(contains(run("b_user{}"),
                 "b_user.lua:10: require: 'zz_skill' is a skill: name it in "
                 "depends_skills"));
  CHECK(contains(run("zz_user{}"), "zz_user.lua:10: require: 'b_user' is a skill"));
  CHECK(
      contains(load_error_of(engine, "c_early"), "c_early.lua:1: require: 'zz_skill' is a skill"));
  CHECK(load_error_of(engine, "zz_skill").empty());
}

TEST_CASE("self.skills[i] arguments, a navgraph's nodes and ppgoto drive the navigator") {
  FakeRobot robot;
  robot.nav_steps = 10;  // longer than the state's timeout=0.1, which a Fawkes-style file ignores
  lua::SkillEngine engine(fawkes_config(), robot);
  REQUIRE(engine.exec("drive_node{place='M1'}"));
  CHECK(test::run_until_done(engine, robot) == SkillStatus::kFinal);
  // The approach node from the helper module, then the node itself (its pos and orientation).
  CHECK(engine.result() == "M1_APPROACH 2.00 1.00 1 /map");
  CHECK(robot.pose_estimate.pose.theta == doctest::Approx(1.57));
  CHECK(robot.nav.goal_id == 2);

  // The navgraph's closest node: M1's nearest node with an orientation (LONELY is unconnected).
  REQUIRE(engine.exec("drive_node{place='START'}"));
  CHECK(test::run_until_done(engine, robot) == SkillStatus::kFinal);
  CHECK(engine.result().rfind("M1_APPROACH 0.50 0.50", 0) == 0);
}

TEST_CASE("ppgoto: poses, places, stop and its failures") {
  FakeRobot robot;
  lua::SkillEngine engine(fawkes_config(), robot);
  REQUIRE(engine.exec("ppgoto{x=1.5, y=2.5, ori=0.5}"));
  CHECK(test::run_until_done(engine, robot) == SkillStatus::kFinal);
  CHECK(robot.pose_estimate.pose.x == doctest::Approx(1.5));
  CHECK(robot.pose_estimate.pose.theta == doctest::Approx(0.5));
  CHECK(robot.nav_forward);  // "Pathplan" (the team's move_base) never drives backwards
  // An llsfsim place when no navgraph has the node.
  robot.nav_forward = false;
  REQUIRE(engine.exec("ppgoto{place='M2'}"));
  CHECK(test::run_until_done(engine, robot) == SkillStatus::kFinal);
  CHECK(robot.nav_goal == "M2");
  CHECK(robot.nav_forward);
  REQUIRE(engine.exec("ppgoto{}"));
  CHECK(test::run_until_done(engine, robot) == SkillStatus::kFailed);
  CHECK(contains(engine.error(), "needs x and y, place or stop"));
  // Another goal replaces ppgoto's: it fails once the navigator has another goal id.
  REQUIRE(engine.exec("ppgoto{place='M3'}"));
  CHECK(test::run_cycles(engine, robot, 1) == SkillStatus::kRunning);
  robot.goto_place("M1", false);
  CHECK(test::run_until_done(engine, robot) == SkillStatus::kFailed);
  CHECK(contains(engine.error(), "the goal was replaced"));
}

TEST_CASE("Fawkes' MotorInterface and RobotinoSensorInterface, tf and config in a skill") {
  FakeRobot robot;
  robot.pose_estimate.pose = {1.0, 1.0, core::kPi / 2};
  robot.ir_m = 0.3;
  lua::SkillEngine engine(fawkes_config(), robot);
  REQUIRE(engine.exec("nudge{x=1.0, y=3.0}"));
  CHECK(test::run_cycles(engine, robot, 2) == SkillStatus::kRunning);
  // (1, 3) in /map is 2 m straight ahead in /base_link: TransRot(0.2, 0, 0).
  CHECK(robot.vx == doctest::Approx(0.2));
  CHECK(robot.vy == doctest::Approx(0.0).epsilon(1e-9));
  robot.ir_m = 0.04;  // distance[8] below the configured near_dist
  CHECK(test::run_until_done(engine, robot) == SkillStatus::kFinal);
  CHECK(robot.vx == 0.0);  // DRIVE:exit() sent TransRot(0, 0, 0)
}

// written_interfaces asks the interpreter only when the blackboard's version changed: a write
// after an empty answer is still reported, once.
TEST_CASE("Fawkes' blackboard: every write is reported once, also after an empty answer") {
  FakeRobot robot;
  robot.light_reading.visible = true;
  robot.light_reading.device = "M1";
  robot.light_reading.green = lua::Lamp::kOn;
  lua::SkillEngine engine(fawkes_config(), robot);
  for (int round = 0; round < 3; ++round) {
    CAPTURE(round);
    REQUIRE(engine.exec("read_light{}"));
    CHECK(test::run_until_done(engine, robot) == SkillStatus::kFinal);
    const std::vector<lua::WrittenInterface> written = engine.written_interfaces();
    REQUIRE(written.size() == 1);
    CHECK(written[0].id == "Light determined");
    CHECK(engine.written_interfaces().empty());
    CHECK(engine.written_interfaces().empty());
  }
}

TEST_CASE("Fawkes' light, switch and sensor interfaces; a skill writes Light determined") {
  FakeRobot robot;
  robot.light_reading.visible = true;
  robot.light_reading.device = "M1";
  robot.light_reading.green = lua::Lamp::kOn;
  robot.light_reading.yellow = lua::Lamp::kBlink;
  robot.optical_sensors.right = true;
  lua::SkillEngine engine(fawkes_config(), robot);
  REQUIRE(engine.exec("read_light{}"));
  CHECK(test::run_until_done(engine, robot) == SkillStatus::kFinal);
  CHECK(engine.result() == "OFF BLINKING ON green=true switch=false optical=0,10");
  // What the skill wrote, for the agent's blackboard: once.
  const std::vector<lua::WrittenInterface> written = engine.written_interfaces();
  REQUIRE(written.size() == 1);
  CHECK(written[0].type == "RobotinoLightInterface");
  CHECK(written[0].id == "Light determined");
  std::map<std::string, std::string> fields;
  for (const lua::InterfaceField& f : written[0].fields) {
    fields[f.name] =
        f.texts.empty() ? std::to_string(static_cast<int>(f.numbers.at(0))) : f.texts.at(0);
  }
  CHECK(fields == std::map<std::string, std::string>{{"green", "ON"},
                                                     {"ready", "1"},
                                                     {"red", "OFF"},
                                                     {"visibility_history", "0"},
                                                     {"yellow", "BLINKING"}});
  CHECK(engine.written_interfaces().empty());

  robot.light_reading.visible = false;
  REQUIRE(engine.exec("read_light{}"));
  CHECK(test::run_until_done(engine, robot) == SkillStatus::kFailed);
  CHECK(contains(engine.error(), "WAIT: timeout after 2 s"));
}

TEST_CASE("Fawkes' add_transitions and nil globals in a file written for Fawkes") {
  FakeRobot robot;
  lua::SkillEngine engine(fawkes_config(), robot);
  test::LogCapture log;
  log.attach(engine);
  REQUIRE(engine.exec("transitions{}"));
  CHECK(test::run_until_done(engine, robot) == SkillStatus::kFinal);
  CHECK(engine.result() == "count=3 closure=nil");
  // The closure's unknown function: a warning at its line, once.
  int warnings = 0;
  for (const std::string& l : log.lines) {
    warnings += contains(l, "transitions.lua:15: undeclared global 'no_such_function'") ? 1 : 0;
  }
  CHECK(warnings == 1);
  // precond= is a precondition too: FAILED on entry.
  REQUIRE(engine.exec("transitions{fail=true}"));
  CHECK(test::run_cycles(engine, robot, 1) == SkillStatus::kFailed);
  CHECK(contains(engine.error(), "START: precondition vars.fail"));
}

TEST_CASE("the relative navigator, the puck detection by id, fawkes.Time") {
  FakeRobot robot;
  robot.pose_estimate.pose = {1.0, 1.0, core::kPi / 2};
  robot.puck_sightings = {{{0.5, 0.1}}};
  robot.nav_steps = 5;
  lua::SkillEngine engine(fawkes_config(), robot);
  REQUIRE(engine.exec("probe{}"));
  CHECK(test::run_until_done(engine, robot) == SkillStatus::kFinal);
  // (1, 0) ahead of a robot at (1, 1) facing +y is (1, 2) in the map.
  CHECK(engine.result() ==
        "dest=1.00,2.00 puck1=0.50,0.10 vis1=true vis2=true closest=false elapsed=true "
        "skiller=probe{}/2");
  CHECK(robot.pose_estimate.pose.y == doctest::Approx(2.0));
  CHECK(robot.pose_estimate.pose.theta == doctest::Approx(core::kPi / 2));
  CHECK_FALSE(robot.nav_forward);  // the relative navigator may back up
}

TEST_CASE("bad Fawkes-style input: navgraph files, messages, config, interface ids") {
  test::TempDir dir;
  const std::string skills = dir.path.string() + "/skills";
  std::filesystem::create_directories(skills);
  write(skills + "/broken_graph.lua",
        skill_running("broken_graph", "fawkes.load_yaml_navgraph('broken-graph.yaml')"));
  write(skills + "/bad_edge.lua",
        skill_running("bad_edge", "fawkes.load_yaml_navgraph('bad-edge.yaml')"));
  write(skills + "/no_graph.lua",
        skill_running("no_graph", "fawkes.load_yaml_navgraph('../cfg/navgraph-test.yaml')"));
  write(skills + "/wrong_msg.lua",
        skill_running("wrong_msg", "motor:msgq_enqueue_copy(nav.StopMessage:new())",
                      "{v='motor', type='MotorInterface', id='Robotino'}, "
                      "{v='nav', type='NavigatorInterface', id='Pathplan'}"));
  write(skills + "/no_value.lua",
        skill_running("no_value", "local v = config:get_float('/skills/none')"));
  write(skills + "/bad_type.lua", skill_running("bad_type", "", "{v='w', type='WorldModel'}"));
  lua::SkillEngineConfig cfg = fawkes_config();
  cfg.skill_dirs = {skills};
  FakeRobot robot;
  lua::SkillEngine engine(cfg, robot);
  const auto run = [&](const std::string& s) {
    REQUIRE(engine.exec(s));
    CHECK(test::run_cycles(engine, robot, 1) == SkillStatus::kFailed);
    return engine.error();
  };
  CHECK(contains(run("broken_graph{}"),
                 "tests/lua/fawkes/cfg/broken-graph.yaml:6: node 'B': pos must be a list [x, y]"));
  CHECK(contains(run("bad_edge{}"), "bad-edge.yaml:6: connection to unknown node 'NOWHERE'"));
  CHECK(contains(run("no_graph{}"), "without '..'"));
  CHECK(contains(run("wrong_msg{}"),
                 "wrong_msg.lua:10: MotorInterface::Robotino:msgq_enqueue_copy: expected a "
                 "message of MotorInterface"));
  CHECK(contains(run("no_value{}"),
                 "no_value.lua:10: config:get_float(\"/skills/none\"): no such value"));
  CHECK(contains(load_error_of(engine, "bad_type"),
                 "depends_interfaces[1]: unknown interface type 'WorldModel' (known: "));
}

TEST_CASE("message classes are read-only: one skill cannot break another's nav.StopMessage") {
  test::TempDir dir;
  const std::string skills = dir.path.string() + "/skills";
  std::filesystem::create_directories(skills);
  const std::string nav = "{v='nav', type='NavigatorInterface', id='Pathplan'}";
  // Every skill of the robot gets the same class table for nav.StopMessage.
  write(skills + "/tamper_msg.lua",
        skill_running(
            "tamper_msg",
            "local stop, go = nav.StopMessage, nav.CartesianGotoMessage\n"
            "local tries = {\n"
            "  function() stop.new = function() end end,\n"
            "  function() rawset(stop, 'new', function() end) end,\n"
            "  function() go.fields[1] = 'y' end,\n"
            "  function() rawget(go, 'mt').__index = function() end end,\n"
            "}\n"
            "local refused = 0\n"
            "for _, f in ipairs(tries) do if not pcall(f) then refused = refused + 1 end end\n"
            "print('refused ' .. refused .. ', getmetatable ' .. tostring(getmetatable(stop)))\n"
            "stop.new = nil  -- MARK",
            nav));
  write(skills + "/send_msgs.lua",
        skill_running("send_msgs",
                      "nav:msgq_enqueue_copy(nav.StopMessage:new())\n"
                      "nav:msgq_enqueue_copy(nav.CartesianGotoMessage:new(1, 2, 0))",
                      nav));
  lua::SkillEngineConfig cfg = fawkes_config();
  cfg.skill_dirs = {skills};
  FakeRobot robot;
  lua::SkillEngine engine(cfg, robot);
  std::vector<std::string> log;
  engine.set_log_sink([&](lua::LogLevel, std::string_view text) { log.emplace_back(text); });
  REQUIRE(engine.exec("tamper_msg{}"));
  CHECK(test::run_cycles(engine, robot, 1) == SkillStatus::kFailed);
  CHECK(
      contains(engine.error(), test::marked_line(skills + "/tamper_msg.lua") +
                                   ": NavigatorInterface.StopMessage is read-only (shared by "
                                   "every skill): cannot set NavigatorInterface.StopMessage.new"));
  std::string refused;
  for (const std::string& line : log) {
    if (line.rfind("refused", 0) == 0) refused = line;
  }
  CHECK(refused == "refused 4, getmetatable false");
  REQUIRE(engine.exec("send_msgs{}"));
  CHECK(test::run_cycles(engine, robot, 1) == SkillStatus::kFinal);
  CHECK(engine.error() == "");
}

TEST_CASE("navgraphs are read-only: one skill cannot move another's place") {
  test::TempDir dir;
  const std::string skills = dir.path.string() + "/skills";
  std::filesystem::create_directories(skills);
  // The first graph loaded is where ppgoto's places come from (F.navgraph_node).
  write(skills + "/aa_mover.lua",
        skill_running(
            "aa_mover",
            "local graph = fawkes.load_yaml_navgraph('navgraph-test.yaml')\n"
            "local n = graph:node('M1')\n"
            "local tries = {\n"
            "  function() n.x_ = 9 end,\n"
            "  function() rawset(n, 'x_', 9) end,\n"
            "  function() n.props.orientation = '0' end,\n"
            "  function() graph:nodes()[1].y_ = 9 end,\n"
            "  function() graph.by_name.M1 = graph:node('FAR') end,\n"
            "  function() graph:node('NOWHERE').name_ = 'M1' end,\n"
            "}\n"
            "local refused = 0\n"
            "for _, f in ipairs(tries) do if not pcall(f) then refused = refused + 1 end end\n"
            "self.fsm.result = refused .. ' ' .. tostring(n:has_properties()) .. ' ' .. "
            "n:x() .. ' ' .. #n:reachable_nodes() .. ' ' .. #graph:nodes()"));
  write(skills + "/goer.lua",
        skill_running("goer", "nav:msgq_enqueue_copy(nav.PlaceGotoMessage:new('M1'))",
                      "{v='nav', type='NavigatorInterface', id='Pathplan'}"));
  lua::SkillEngineConfig cfg = fawkes_config();
  cfg.skill_dirs = {skills};
  FakeRobot robot;
  lua::SkillEngine engine(cfg, robot);
  CHECK(engine.load_errors().empty());
  REQUIRE(engine.exec("aa_mover{}"));
  CHECK(test::run_cycles(engine, robot, 1) == SkillStatus::kFinal);
  CHECK(engine.result() == "6 true 2.0 0 5");
  REQUIRE(engine.exec("goer{}"));
  CHECK(test::run_cycles(engine, robot, 1) == SkillStatus::kFinal);
  CHECK(robot.pose_estimate.pose.x == doctest::Approx(2.0));
  CHECK(robot.pose_estimate.pose.y == doctest::Approx(1.0));
  CHECK(robot.pose_estimate.pose.theta == doctest::Approx(1.57));
}

TEST_CASE("a message's getters and setters, as Fawkes' msg:x() and msg:set_x(v)") {
  test::TempDir dir;
  const std::string skills = dir.path.string() + "/skills";
  std::filesystem::create_directories(skills);
  write(skills + "/getters.lua",
        skill_running("getters",
                      "local g = nav.CartesianGotoMessage:new(1.5, 2.5, 0.25)\n"
                      "g:set_y(3.5)\n"
                      "g.orientation = 0.75  -- (a plain assignment, as the value)\n"
                      "self.fsm.result = g:x() .. ' ' .. g:y() .. ' ' .. g:orientation()\n"
                      "nav:msgq_enqueue_copy(g)",
                      "{v='nav', type='NavigatorInterface', id='Pathplan'}"));
  lua::SkillEngineConfig cfg = fawkes_config();
  cfg.skill_dirs = {skills};
  FakeRobot robot;
  lua::SkillEngine engine(cfg, robot);
  REQUIRE(engine.exec("getters{}"));
  CHECK(test::run_cycles(engine, robot, 1) == SkillStatus::kFinal);
  CHECK(engine.error() == "");
  CHECK(engine.result() == "1.5 3.5 0.75");
  // The goal sent is what the getters read.
  CHECK(robot.nav_goal == "pose");
  CHECK(robot.pose_estimate.pose.x == doctest::Approx(1.5));
  CHECK(robot.pose_estimate.pose.y == doctest::Approx(3.5));
  CHECK(robot.pose_estimate.pose.theta == doctest::Approx(0.75));
}

TEST_CASE("skills: module_dirs, cfg_dirs and fawkes_config in a scenario's skills map") {
  const core::ConfigNode node = core::ConfigNode::parse(
      "skills:\n  module_dirs: [modules]\n  cfg_dirs: [cfg]\n"
      "  fawkes_config:\n    skills:\n      nudge: {near_dist: 0.05, name: x}\n"
      "    flag: true\n",
      "robot.yaml");
  const lua::SkillEngineConfig cfg = lua::SkillEngineConfig::from_config(node["skills"], kDir);
  CHECK(cfg.module_dirs == std::vector<std::string>{kDir + "/modules"});
  CHECK(cfg.cfg_dirs == std::vector<std::string>{kDir + "/cfg"});
  CHECK(cfg.fawkes_config ==
        std::map<std::string, std::string>{
            {"/flag", "true"}, {"/skills/nudge/name", "x"}, {"/skills/nudge/near_dist", "0.05"}});
  const core::ConfigNode list =
      core::ConfigNode::parse("skills:\n  fawkes_config: {a: [1, 2]}\n", "robot.yaml");
  CHECK_THROWS_WITH_AS(lua::SkillEngineConfig::from_config(list["skills"], kDir),
                       doctest::Contains("robot.yaml:2"), core::ConfigError);
  const core::ConfigNode missing =
      core::ConfigNode::parse("skills:\n  cfg_dirs: [no_such_dir]\n", "robot.yaml");
  CHECK_THROWS_WITH_AS(lua::SkillEngineConfig::from_config(missing["skills"], kDir),
                       doctest::Contains("cfg directory"), core::ConfigError);
}

TEST_CASE("the agent's side of the blackboard: read, write and send to the skills' objects") {
  test::TempDir dir;
  dir.write("sw.lua", skill_running("sw",
                                    "self.fsm.result = tostring(sw:is_enabled()) .. ' ' .. "
                                    "tostring(sw:value()) .. ' ' .. tostring(amp:state())",
                                    "{v='sw', type='SwitchInterface', id='vision_switch'}, "
                                    "{v='amp', type='RobotinoAmpelInterface', id='Ampel'}"));
  lua::SkillEngineConfig cfg = fawkes_config();
  cfg.skill_dirs = {dir.path.string()};
  FakeRobot robot;
  robot.pose_estimate.pose = {1.0, 2.0, 0.0};
  lua::SkillEngine engine(cfg, robot);
  REQUIRE(engine.load_errors().empty());

  const auto field = [](const lua::InterfaceSnapshot& s, const std::string& name) {
    for (const lua::InterfaceField& f : s.fields)
      if (f.name == name) return f;
    return lua::InterfaceField{};
  };
  // What llsfsim's sensors write: fresh at every read, stamped now.
  robot.time = core::SimTime::from_ms(500);
  lua::InterfaceSnapshot motor = engine.read_interface("MotorInterface", "Robotino");
  REQUIRE(motor.known);
  CHECK(motor.has_writer);
  CHECK(motor.robot_writer);
  CHECK(motor.written == core::SimTime::from_ms(500));
  CHECK(field(motor, "odometry_position_y").numbers == std::vector<double>{2.0});
  CHECK(field(engine.read_interface("SkillerInterface", "Skiller"), "status").texts ==
        std::vector<std::string>{"S_INACTIVE"});
  // What nothing wrote yet: no writer, no time.
  lua::InterfaceSnapshot sw = engine.read_interface("SwitchInterface", "vision_switch");
  CHECK(sw.known);
  CHECK_FALSE(sw.robot_writer);
  CHECK_FALSE(sw.written);
  CHECK_FALSE(engine.read_interface("NoInterface", "x").known);

  // A message to the navigator drives the robot; its goal id comes back.
  std::string error;
  lua::InterfaceField x{"x", lua::InterfaceField::Kind::kFloat, false, {}, {3.0}};
  lua::InterfaceField y{"y", lua::InterfaceField::Kind::kFloat, false, {}, {1.0}};
  const std::int64_t msgid = engine.send_interface_message("NavigatorInterface", "Pathplan",
                                                           "CartesianGotoMessage", {x, y}, error);
  CHECK_MESSAGE(error.empty(), error);
  CHECK(msgid > 0);
  CHECK(robot.nav_goal == "pose");
  lua::InterfaceSnapshot nav = engine.read_interface("NavigatorInterface", "Pathplan");
  CHECK(field(nav, "dest_x").numbers == std::vector<double>{3.0});
  CHECK(field(nav, "msgid").numbers == std::vector<double>{static_cast<double>(msgid)});
  CHECK(engine.send_interface_message("NavigatorInterface", "Pathplan", "FlyMessage", {}, error) ==
        0);
  CHECK(contains(error, "NavigatorInterface::Pathplan has no message FlyMessage"));

  // What the agent writes, the skills read; the blackboard's version counts writes and messages
  // (reads leave it).
  robot.time = core::SimTime::from_ms(600);
  const std::int64_t version = engine.blackboard_version();
  (void)engine.read_interface("SwitchInterface", "vision_switch");
  CHECK(engine.blackboard_version() == version);
  lua::InterfaceField enabled{"enabled", lua::InterfaceField::Kind::kBool, false, {}, {1.0}};
  lua::InterfaceField value{"value", lua::InterfaceField::Kind::kFloat, false, {}, {0.5}};
  CHECK(engine.write_interface("SwitchInterface", "vision_switch", {enabled, value}).empty());
  lua::InterfaceField state{"state", lua::InterfaceField::Kind::kSymbol, false, {"RED"}, {}};
  CHECK(engine.write_interface("RobotinoAmpelInterface", "Ampel", {state}).empty());
  CHECK(
      contains(engine.write_interface("SwitchInterface", "vision_switch",
                                      {{"nope", lua::InterfaceField::Kind::kBool, false, {}, {1}}}),
               "SwitchInterface::vision_switch has no field nope"));
  CHECK(engine.blackboard_version() > version);
  sw = engine.read_interface("SwitchInterface", "vision_switch");
  CHECK(sw.written == core::SimTime::from_ms(600));
  REQUIRE(engine.exec("sw{}"));
  CHECK(test::run_until_done(engine, robot) == SkillStatus::kFinal);
  CHECK(engine.result() == "true 0.5 RED");
}
