// SPDX-License-Identifier: MIT
// The abstraction levels of RobotStack, driven by synthetic percepts: no World is involved, which
// is also the proof that a stack sees the world only through what the game hands it.
#include <doctest/doctest.h>

#include <array>
#include <cmath>
#include <vector>

#include "fixture.h"
#include "llsf/sim/game.h"
#include "llsf/sim/robot_stack.h"

using namespace llsf;
using namespace llsf::sim;

namespace {

/// One RobotStack fed with percepts every 10 ms.
struct Rig {
  explicit Rig(RobotLevelsConfig levels, std::uint64_t seed = 3)
      : config(make_config(levels, seed)),
        planner(field_map_from_world(config.world), config.planner),
        stack("robot1", 0, config.world.robots[0].pose, config, planner, {"robot1"},
              devices(config.world), core::Rng(seed)) {}

  static GameConfig make_config(RobotLevelsConfig levels, std::uint64_t seed) {
    GameConfig c;
    c.levels = levels;
    c.seed = seed;
    return c;
  }
  static std::vector<DeviceView> devices(const kinematic::WorldConfig& w) {
    std::vector<DeviceView> out;
    for (int i = 0; i < kinematic::kDeviceCount; ++i) {
      const kinematic::DeviceConfig& d = w.devices[static_cast<std::size_t>(i)];
      out.push_back(
          {std::string(kinematic::device_name(core::DeviceId(i))), d.pose, d.rfid_center()});
    }
    return out;
  }

  /// Advances 10 ms and senses at `pose`.
  void tick() {
    now += SimTime::from_ms(10);
    RobotPercept p;
    p.now = now;
    p.true_pose = pose;
    p.sensors = &sensors;
    p.lights = lights;
    p.pucks = pucks;
    stack.sense(p);
  }

  GameConfig config;
  planner::Planner planner;
  RobotStack stack;
  kinematic::RobotSensors sensors;
  std::array<kinematic::SignalLights, kinematic::kDeviceCount> lights{};
  std::vector<core::Vec2> pucks;
  core::Pose2D pose;
  SimTime now;
};

/// A pose `d` metres in front of device `i`, facing it.
core::Pose2D facing(const kinematic::WorldConfig& w, int i, double d) {
  const core::Pose2D dev = w.devices[static_cast<std::size_t>(i)].pose;
  const core::Vec2 p = dev.position() + d * core::unit(dev.theta);
  return {p.x(), p.y(), core::normalize_angle(dev.theta + core::kPi)};
}

constexpr kinematic::LampState kOn = kinematic::LampState::kOn;
constexpr kinematic::LampState kOff = kinematic::LampState::kOff;
constexpr kinematic::LampState kBlink = kinematic::LampState::kBlink;

bool shows(const lua::LightReading& r, lua::Lamp red, lua::Lamp yellow, lua::Lamp green) {
  return r.visible && r.red == red && r.yellow == yellow && r.green == green;
}

}  // namespace

TEST_CASE("light ground_truth: the device in front, its lamps at once") {
  Rig rig({});
  rig.pose = facing(rig.config.world, 2, 0.6);  // M3
  rig.lights[2] = {kOff, kOn, kBlink};
  rig.tick();
  lua::LightReading r = rig.stack.light();
  CHECK(r.visible);
  CHECK(r.device == "M3");
  CHECK(shows(r, lua::Lamp::kOff, lua::Lamp::kOn, lua::Lamp::kBlink));
  // Turned away: nothing in front.
  rig.pose.theta = core::normalize_angle(rig.pose.theta + core::kPi);
  rig.tick();
  CHECK_FALSE(rig.stack.light().visible);
  // Too far (nothing else in front of M1 either).
  rig.pose = facing(rig.config.world, 0, 1.5);
  rig.tick();
  CHECK_FALSE(rig.stack.light().visible);
}

TEST_CASE("light vision: a change shows about one delay later, a blink after a full period") {
  RobotLevelsConfig levels;
  levels.light.level = DetectionLevel::kVision;
  levels.light.error_rate = 0.0;
  Rig vision(levels);
  Rig truth({});
  for (Rig* r : {&vision, &truth}) {
    r->pose = facing(r->config.world, 0, 0.6);  // M1
    r->lights[0] = {kOn, kOff, kOff};
  }
  double truth_change = -1.0;
  double vision_first = -1.0;
  double vision_change = -1.0;
  for (int k = 0; k < 600; ++k) {  // 6 s
    for (Rig* r : {&vision, &truth}) {
      if (r->now == SimTime::from_sec(3)) r->lights[0] = {kOff, kOff, kOn};
      r->tick();
    }
    const double t = vision.now.seconds();
    if (truth_change < 0 &&
        shows(truth.stack.light(), lua::Lamp::kOff, lua::Lamp::kOff, lua::Lamp::kOn)) {
      truth_change = t;
    }
    if (vision_first < 0 && vision.stack.light().visible) vision_first = t;
    if (vision_change < 0 &&
        shows(vision.stack.light(), lua::Lamp::kOff, lua::Lamp::kOff, lua::Lamp::kOn)) {
      vision_change = t;
    }
    if (vision_first >= 0 && vision_change < 0) {
      // Until the change arrives the vision reads the old lamps (no misreads configured).
      CHECK(shows(vision.stack.light(), lua::Lamp::kOn, lua::Lamp::kOff, lua::Lamp::kOff));
    }
  }
  CHECK(truth_change == doctest::Approx(3.01).epsilon(1e-6));
  // First reading: a blink period of frames, then the delay.
  CHECK(vision_first >= 1.5);
  CHECK(vision_first <= 1.7);
  // The change: one delay late, plus at most a frame.
  CHECK(vision_change - truth_change >= 0.95);
  CHECK(vision_change - truth_change <= 1.15);
  CHECK(vision.stack.light().device == "M1");

  // Blinking: detected as blink, never as on/off once a period has been seen.
  Rig blink(levels);
  blink.pose = facing(blink.config.world, 4, 0.6);
  blink.lights[4] = {kOff, kBlink, kOff};
  int blink_readings = 0;
  for (int k = 0; k < 500; ++k) {
    blink.tick();
    const lua::LightReading r = blink.stack.light();
    if (!r.visible) continue;
    CHECK(r.yellow == lua::Lamp::kBlink);
    ++blink_readings;
  }
  CHECK(blink_readings > 300);
}

TEST_CASE(
    "light vision at 2 Hz: pixels alias a 2 Hz blink, reads_states tells it (robotino-2013)") {
  RobotLevelsConfig levels;
  levels.light.level = DetectionLevel::kVision;
  levels.light.error_rate = 0.0;
  levels.light.frame_rate_hz = 2.0;  // thesis §6.1.1: the webcam at 2 Hz
  for (const bool states : {false, true}) {
    CAPTURE(states);
    levels.light.reads_states = states;
    Rig rig(levels);
    rig.pose = facing(rig.config.world, 4, 0.6);
    rig.lights[4] = {kOff, kBlink, kOn};
    int readings = 0, blink = 0;
    double first = -1.0;
    for (int k = 0; k < 1000; ++k) {  // 10 s
      rig.tick();
      const lua::LightReading r = rig.stack.light();
      if (!r.visible) continue;
      if (first < 0) first = rig.now.seconds();
      ++readings;
      CHECK(r.red == lua::Lamp::kOff);
      CHECK(r.green == lua::Lamp::kOn);
      if (r.yellow == lua::Lamp::kBlink) ++blink;
    }
    CHECK(readings > 800);
    if (states) {
      CHECK(blink == readings);  // every reading: blinking
      CHECK(first <= 1.1);       // the first frame, one delay late
    } else {
      CHECK(blink == 0);  // one frame per blink period: always the same phase
    }
  }
}

TEST_CASE("light vision: must face the device, and the front of it") {
  RobotLevelsConfig levels;
  levels.light.level = DetectionLevel::kVision;
  levels.light.error_rate = 0.0;
  levels.light.delay = SimTime();
  Rig rig(levels);
  rig.lights[5] = {kOn, kOn, kOn};
  // Behind the device (opposite its front), looking at it: ground truth would see it, vision not.
  const core::Pose2D dev = rig.config.world.devices[5].pose;
  const core::Vec2 behind = dev.position() - 0.7 * core::unit(dev.theta);
  rig.pose = {behind.x(), behind.y(), dev.theta};
  for (int k = 0; k < 100; ++k) rig.tick();
  CHECK_FALSE(rig.stack.light().visible);
  rig.pose = facing(rig.config.world, 5, 0.7);
  for (int k = 0; k < 100; ++k) rig.tick();
  CHECK(rig.stack.light().visible);
  CHECK(rig.stack.light().device == "M6");
}

TEST_CASE("light laser_cluster view: the nearest RFID zone in the cluster window, from any side") {
  RobotLevelsConfig levels;
  levels.light.view = LightView::kLaserCluster;
  Rig rig(levels);
  rig.lights[4] = {kOn, kOff, kOn};  // M5
  const kinematic::DeviceConfig& m5 = rig.config.world.devices[4];
  const core::Vec2 zone = m5.rfid_center();
  // Beside the device, a little behind the plane of its front, looking at its zone: the front
  // view (and its vision level) needs the robot on the front's side; the cluster does not.
  const core::Vec2 side =
      zone - 0.1 * core::unit(m5.pose.theta) + 0.5 * core::unit(m5.pose.theta + core::kPi / 2);
  const core::Vec2 to_zone = zone - side;
  const double at_zone = std::atan2(to_zone.y(), to_zone.x());
  rig.pose = {side.x(), side.y(), at_zone};
  rig.tick();
  CHECK(rig.stack.light().device == "M5");
  CHECK(shows(rig.stack.light(), lua::Lamp::kOn, lua::Lamp::kOff, lua::Lamp::kOn));
  // Behind the device, looking at it (the zone 0.64 m ahead): still M5.
  const core::Vec2 behind = m5.pose.position() - 0.5 * core::unit(m5.pose.theta);
  rig.pose = {behind.x(), behind.y(), m5.pose.theta};
  rig.tick();
  CHECK(rig.stack.light().device == "M5");
  // The zone beyond the window's 0.8 m, or behind the robot: nothing.
  const core::Vec2 far = zone - 0.9 * core::unit(m5.pose.theta + core::kPi / 2);
  rig.pose = {far.x(), far.y(), core::normalize_angle(m5.pose.theta + core::kPi / 2)};
  rig.tick();
  CHECK_FALSE(rig.stack.light().visible);
  rig.pose = {side.x(), side.y(), core::normalize_angle(at_zone + core::kPi)};  // behind
  rig.tick();
  CHECK(rig.stack.light().device != "M5");
  // The front view from beside M5 (the same pose as first): nothing.
  Rig front({});
  front.lights[4] = {kOn, kOff, kOn};
  front.pose = {side.x(), side.y(), at_zone};
  front.tick();
  CHECK_FALSE(front.stack.light().visible);
}

TEST_CASE("light vision: misreads at about the configured rate") {
  for (const double rate : {0.05, 0.25}) {
    RobotLevelsConfig levels;
    levels.light.level = DetectionLevel::kVision;
    levels.light.error_rate = rate;
    Rig rig(levels, 11);
    rig.pose = facing(rig.config.world, 7, 0.6);
    rig.lights[7] = {kOff, kOn, kOn};
    int readings = 0;
    int wrong = 0;
    for (int k = 0; k < 30000; ++k) {  // 300 s: ~3,000 frames
      rig.tick();
      const lua::LightReading r = rig.stack.light();
      if (!r.visible) continue;
      ++readings;
      if (!shows(r, lua::Lamp::kOff, lua::Lamp::kOn, lua::Lamp::kOn)) ++wrong;
    }
    REQUIRE(readings > 29000);
    const double observed = static_cast<double>(wrong) / readings;
    INFO("rate ", rate, " observed ", observed);
    // ~3,000 independent frames: the standard error is below 0.008.
    CHECK(std::abs(observed - rate) < 0.03);
  }
}

TEST_CASE("puck detection: ground truth sees all in range, vision its view with merged blobs") {
  RobotLevelsConfig gt_levels;
  RobotLevelsConfig vision_levels;
  vision_levels.puck.level = DetectionLevel::kVision;
  Rig gt(gt_levels);
  Rig vision(vision_levels);
  for (Rig* r : {&gt, &vision}) {
    r->pose = {2.0, 2.0, core::kPi / 2};
    // Robot frame (x forward, y left) -> field: forward is +y, left is -x.
    auto at = [&](double fx, double ly) { return r->pose.to_parent(core::Vec2(fx, ly)); };
    r->pucks = {at(0.5, 0.0), at(0.55, 0.02),  // 5.4 cm apart: one blob
                at(0.7, 0.3),                  // alone, in view
                at(-0.5, 0.0),                 // behind
                at(1.5, 0.0)};                 // beyond the camera's range
    r->tick();
  }
  REQUIRE(gt.stack.pucks().size() == 5);
  CHECK(gt.stack.pucks()[0].position.x() == doctest::Approx(0.5));
  CHECK(gt.stack.pucks()[3].position.x() == doctest::Approx(-0.5));
  const auto seen = vision.stack.pucks();
  REQUIRE(seen.size() == 2);
  CHECK(seen[0].position.x() == doctest::Approx(0.525));
  CHECK(seen[0].position.y() == doctest::Approx(0.01));
  CHECK(seen[1].position.x() == doctest::Approx(0.7));
  CHECK(seen[1].position.y() == doctest::Approx(0.3));
}

TEST_CASE("GameConfig::validate names the field") {
  GameConfig c;
  c.levels.light.error_rate = 1.5;
  CHECK_THROWS_WITH_AS(c.validate(), doctest::Contains("game.levels.light.error_rate"),
                       core::ConfigError);
  c = GameConfig{};
  c.skill_rate_hz = 0.0;
  CHECK_THROWS_WITH_AS(c.validate(), doctest::Contains("game.skill_rate_hz"), core::ConfigError);
  c = GameConfig{};
  c.levels.localization.correction_gain = 0.0;
  CHECK_THROWS_WITH_AS(c.validate(), doctest::Contains("correction_gain"), core::ConfigError);
  c = GameConfig{};
  c.agent_rate_hz = 1000.0;  // above the 100 Hz physics
  CHECK_THROWS_WITH_AS(c.validate(), doctest::Contains("game.agent_rate_hz"), core::ConfigError);
  CHECK_NOTHROW(GameConfig{}.validate());
}
