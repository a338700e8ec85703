// SPDX-License-Identifier: MIT
// The hackathon variant: seeded layouts, the colour camera's cone and error rates, the score, a
// rescue skill on a fixed seed, and config errors with file:line.
#include <doctest/doctest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "llsf/core/error.h"
#include "llsf/sim/game.h"
#include "llsf/sim/hackathon.h"
#include "llsf/sim/hackathon_extension.h"
#include "llsf/sim/skill_brain.h"

using namespace llsf;
using namespace llsf::sim;

namespace {

double box_distance(const core::Vec2& p, const core::OrientedBox& b) {
  const core::Vec2 l = b.pose.to_local(p);
  const core::Vec2 n(std::clamp(l.x(), -b.half_extents.x(), b.half_extents.x()),
                     std::clamp(l.y(), -b.half_extents.y(), b.half_extents.y()));
  return (l - n).norm();
}

/// A stack of robot1 without a world, fed with synthetic percepts (as levels_test.cpp), with
/// the hackathon's part of robot1 (as HackathonExtension gives it) as its add-on.
struct CameraRig {
  explicit CameraRig(HackathonConfig h, std::uint64_t seed = 5)
      : config(make(std::move(h), seed)),
        planner(field_map_from_world(config.world), config.planner),
        stack("robot1", 0, config.world.robots[0].pose, config, planner, {"robot1"}, {},
              core::Rng(seed)),
        info(hackathon_rescue_info(*hackathon_config(config), config.world)),
        add_on(*hackathon_config(config), core::Rng(seed).stream("sim/robot1/colour"), &info) {
    stack.set_add_on(&add_on);
  }
  static GameConfig make(HackathonConfig h, std::uint64_t seed) {
    GameConfig c;
    c.seed = seed;
    set_hackathon(c, std::move(h));
    return c;
  }
  void tick() {
    now += SimTime::from_ms(10);
    RobotPercept p;
    p.now = now;
    p.true_pose = pose;
    p.sensors = &sensors;
    p.lights = lights;
    p.pucks = pucks;
    stack.sense(p);
    add_on.update(now, pose, pucks, colours);  // the extension's step 6, after the stacks
  }
  GameConfig config;
  planner::Planner planner;
  RobotStack stack;
  lua::RescueInfo info;
  HackathonRobot add_on;
  kinematic::RobotSensors sensors;
  std::array<kinematic::SignalLights, kinematic::kDeviceCount> lights{};
  std::vector<core::Vec2> pucks;
  std::vector<int> colours;
  core::Pose2D pose{2.0, 2.0, 0.0};
  SimTime now;
};

std::string write_temp(const std::string& name, const std::string& text) {
  const auto path = std::filesystem::temp_directory_path() / name;
  std::ofstream(path) << text;
  return path.string();
}

}  // namespace

TEST_CASE("hackathon layout: deterministic per seed, valid, different seeds differ") {
  const HackathonConfig h;
  const kinematic::WorldConfig w = kinematic::WorldConfig::default_2013();
  const double r = w.puck.radius_m;
  for (std::uint64_t seed = 1; seed <= 20; ++seed) {
    const HackathonLayout a = generate_hackathon_layout(h, w, core::Rng(seed));
    const HackathonLayout b = generate_hackathon_layout(h, w, core::Rng(seed));
    REQUIRE(a.pucks.size() == 12);
    for (std::size_t i = 0; i < a.pucks.size(); ++i) {
      const HackathonPuck& p = a.pucks[i];
      CHECK(p.id.value() == static_cast<int>(i) + 1);
      CHECK(p.position == b.pucks[i].position);
      CHECK(p.colour == b.pucks[i].colour);
      const core::Vec2 x = p.position;
      CHECK(x.x() - r >= 0.0);
      CHECK(x.y() - r >= 0.0);
      CHECK(x.x() + r <= w.field.width_m);
      CHECK(x.y() + r <= w.field.height_m);
      CHECK_FALSE(h.safe_area.contains(x));
      for (const auto& d : w.devices) CHECK(box_distance(x, d.footprint()) >= r);
      for (const auto& o : h.obstacles) CHECK(box_distance(x, o.footprint()) >= r);
      for (std::size_t j = 0; j < i; ++j) {
        CHECK((x - a.pucks[j].position).norm() >= h.puck_spacing_m);
      }
    }
    // The world accepts it.
    kinematic::WorldConfig applied = w;
    apply_hackathon_layout(h, a, applied);
    CHECK_NOTHROW(applied.validate());
  }
  const HackathonLayout s1 = generate_hackathon_layout(h, w, core::Rng(1));
  const HackathonLayout s2 = generate_hackathon_layout(h, w, core::Rng(2));
  CHECK(s1.pucks[0].position != s2.pucks[0].position);
}

TEST_CASE("hackathon camera: cone, range, field of view, robot frame") {
  HackathonConfig h;
  h.camera.miss_rate = 0.0;
  h.camera.false_colour_rate = 0.0;
  h.camera.position_noise_m = 0.0;
  CameraRig rig(h);
  rig.pose = {2.0, 2.0, core::kPi / 2};  // facing +y
  // ahead 0.5 m (seen), ahead 0.7 m (too far), 30 deg off at 0.4 m (outside 25 deg), 20 deg
  // off at 0.4 m (seen), behind (not seen), an uncoloured puck ahead (not seen).
  auto at = [&](double dist, double bearing_deg) {
    const double a = rig.pose.theta + bearing_deg * core::kPi / 180.0;
    return core::Vec2(2.0 + dist * std::cos(a), 2.0 + dist * std::sin(a));
  };
  rig.pucks = {at(0.5, 0), at(0.7, 0), at(0.4, 30), at(0.4, -20), at(0.3, 180), at(0.3, 5)};
  rig.colours = {0, 1, 2, 3, 0, -1};
  rig.tick();
  const auto seen = rig.stack.colour_pucks();
  REQUIRE(seen.size() == 2);
  CHECK(seen[0].colour == "red");
  CHECK(seen[0].position.x() == doctest::Approx(0.5).epsilon(1e-9));
  CHECK(seen[0].position.y() == doctest::Approx(0.0).scale(1.0).epsilon(1e-9));
  CHECK(seen[0].distance_m == doctest::Approx(0.5));
  CHECK(seen[1].colour == "yellow");
  CHECK(seen[1].bearing_rad == doctest::Approx(-20.0 * core::kPi / 180.0));
  CHECK(seen[1].position.y() < 0.0);  // right of the robot
  // The rescue interface.
  const lua::RescueInfo* info = rig.stack.rescue();
  REQUIRE(info != nullptr);
  CHECK(info->safe_place == "SAFE");
  CHECK(info->counted == std::vector<std::string>{"red", "green", "blue"});
  CHECK(info->decoys == std::vector<std::string>{"yellow"});
}

TEST_CASE("hackathon camera: miss and false-colour rates over many frames") {
  HackathonConfig h;
  h.camera.miss_rate = 0.2;
  h.camera.false_colour_rate = 0.1;
  CameraRig rig(h);
  rig.pose = {2.0, 2.0, 0.0};
  rig.pucks = {{2.3, 2.0}, {2.4, 2.1}};
  rig.colours = {0, 2};
  int frames = 0, sightings = 0, wrong = 0;
  double err = 0.0;
  for (int t = 0; t < 40000; ++t) {  // 400 s at 10 Hz: 4,000 frames
    rig.tick();
    const auto seen = rig.stack.colour_pucks();
    if (rig.now.ns() % SimTime::from_ms(100).ns() != 0) continue;  // one look per frame
    ++frames;
    for (const auto& s : seen) {
      ++sightings;
      const bool first = s.position.x() < 0.35;
      if (s.colour != (first ? "red" : "blue")) ++wrong;
      err += std::abs(s.position.x() - (first ? 0.3 : 0.4));
    }
  }
  const double seen_rate = static_cast<double>(sightings) / (2.0 * frames);
  const double wrong_rate = static_cast<double>(wrong) / sightings;
  CHECK(frames >= 3990);
  CHECK(seen_rate == doctest::Approx(0.8).epsilon(0.03));
  CHECK(wrong_rate == doctest::Approx(0.1).epsilon(0.2));
  CHECK(err / sightings == doctest::Approx(0.008).epsilon(0.25));  // E|N(0, 1 cm)| = 0.8 cm
}

TEST_CASE("hackathon score: counted colours in the safe area, decoys cost, held pucks wait") {
  HackathonConfig h;
  h.colours = {{"red", 2, false}, {"yellow", 1, true}, {"blue", 1, false}};
  HackathonLayout layout;
  layout.pucks = {{core::PuckId(1), 0, {2, 2}},
                  {core::PuckId(2), 0, {2, 3}},
                  {core::PuckId(3), 1, {3, 3}},
                  {core::PuckId(4), 2, {3, 4}}};
  const core::Vec2 in(0.25, 2.8), out(2.0, 2.0);
  std::vector<HackathonPuckState> s = {{core::PuckId(1), in, true, false},
                                       {core::PuckId(2), in, true, true},  // still held
                                       {core::PuckId(3), in, true, false},
                                       {core::PuckId(4), out, true, false}};
  HackathonScore score = score_hackathon(h, layout, s);
  CHECK(score.rescued == 1);
  CHECK(score.decoys == 1);
  CHECK(score.rescuable == 3);
  CHECK(score.total_pucks == 4);
  CHECK(score.points == 10 - 5);
  CHECK(score.colours[0].in_safe_area == 1);
  CHECK(score.colours[1].in_safe_area == 1);
  CHECK(score.in_safe_area == std::vector<core::PuckId>{core::PuckId(1), core::PuckId(3)});
  s[1].held = false;
  s[3].position = {0.0, 2.3};  // the corner counts (closed rectangle)
  score = score_hackathon(h, layout, s);
  CHECK(score.rescued == 3);
  CHECK(score.points == 30 - 5);
}

TEST_CASE("hackathon game: a Lua skill sees a puck, takes it and brings it to the safe area") {
  GameConfig c;
  c.seed = 4;
  c.world.robots.resize(1);
  HackathonConfig h;
  h.colours = {{"red", 1, false}, {"yellow", 2, true}};
  h.puck_clearance_m = 0.45;  // take_puck may approach from any side
  h.camera.range_m = 8.0;     // the test's skill searches with a wide camera
  h.camera.fov_rad = 2.0 * core::kPi;
  h.camera.miss_rate = 0.0;
  h.camera.false_colour_rate = 0.0;
  set_hackathon(c, h);
  Game game(c);
  REQUIRE(hackathon_of(game) != nullptr);
  CHECK(game.world().pucks().size() == 3);
  CHECK(game.planner().place("SAFE") != nullptr);
  CHECK(hackathon_score(game)->points == 0);

  const std::string dir =
      (std::filesystem::temp_directory_path() / "llsf_hackathon_skill").string();
  std::filesystem::create_directories(dir);
  write_temp("llsf_hackathon_skill/rescue_one.lua", R"lua(
name               = "rescue_one"
fsm                = SkillHSM:new{name=name, start="LOOK"}
depends_skills     = {"take_puck", "drive_to", "leave_puck"}
depends_interfaces = {
   {v = "pose", type = "Position3DInterface"},
   {v = "puck_detector", type = "ColourPuckInterface"},
   {v = "rescue", type = "RescueInterface"},
}
documentation      = [==[Takes the nearest puck of a counted colour to the safe area.]==]

fsm:define_states{ export_to=_M,
   {"LOOK", JumpState},
   {"TAKE", SkillJumpState, skills={{take_puck}}, final_to="BRING", fail_to="FAILED"},
   {"BRING", SkillJumpState, skills={{drive_to}}, final_to="LEAVE", fail_to="FAILED"},
   {"LEAVE", SkillJumpState, skills={{leave_puck}}, final_to="CHECK", fail_to="FAILED"},
   {"CHECK", JumpState},
}
fsm:add_transitions{
   {"LOOK", "TAKE", cond=function(self, vars)
      local x, y, d, b, colour = puck_detector:nearest(rescue:colours())
      if not x then return false end
      local px, py, th = pose:get()
      vars.px = px + math.cos(th) * x - math.sin(th) * y
      vars.py = py + math.sin(th) * x + math.cos(th) * y
      vars.colour = colour
      return true
   end},
   {"LOOK", "FAILED", timeout={2, error="no counted puck in sight"}},
   {"CHECK", "FINAL", cond=true},
}
function TAKE:init() self.args["take_puck"] = {x = self.fsm.vars.px, y = self.fsm.vars.py} end
function BRING:init() self.args["drive_to"] = {place = rescue:safe_place()} end
function LEAVE:init() self.args["leave_puck"] = {distance = 0.3} end
)lua");
  lua::SkillEngineConfig ec;
  ec.skill_dirs = skill_library_dirs(c.levels.skill);
  ec.skill_dirs.push_back(dir);
  SkillBrain brain(game, 0, ec);
  game.set_brain(0, &brain);
  REQUIRE(brain.engine().load_errors().empty());
  REQUIRE(brain.exec("rescue_one{}"));
  const SimTime end = SimTime::from_sec(120);
  while (game.time() < end && brain.engine().status() == lua::SkillStatus::kRunning) game.step();
  INFO(brain.engine().error());
  CHECK(brain.engine().status() == lua::SkillStatus::kFinal);
  const HackathonScore score = *hackathon_score(game);
  CHECK(score.rescued == 1);
  CHECK(score.decoys == 0);
  CHECK(score.points == 10);
  std::filesystem::remove_all(dir);
}
