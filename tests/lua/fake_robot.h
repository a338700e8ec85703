// SPDX-License-Identifier: MIT
// A deterministic in-memory robot for skill tests and benchmarks: the navigator arrives a fixed
// number of advance() calls after a goal; sensors are plain fields the test sets.
#pragma once

#include <fstream>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include "llsf/lua/robot_api.h"
#include "llsf/lua/skill_engine.h"

namespace llsf::test {

class FakeRobot : public lua::RobotApi {
 public:
  // Settings and sensor values a test sets directly.
  std::string robot_name = "robot1";
  int nav_steps = 3;  ///< advance() calls from a goal to arrival
  std::set<std::string, std::less<>> places{"M1", "M2", "M3", "D1", "INS_1"};
  bool puck = false;
  double ir_m = 0.3;
  lua::OpticalSensors optical_sensors;
  lua::LightReading light_reading;
  std::vector<lua::PuckSighting> puck_sightings;
  std::vector<float> laser_ranges;
  bool throw_on_pose = false;

  // What the robot was told.
  core::SimTime time;
  lua::PoseEstimate pose_estimate{{0.2, 0.4, 0.0}, {}, true};
  lua::NavState nav;
  std::string nav_goal;
  bool nav_forward = false;  ///< the last goal's forward_only
  int nav_left = 0;
  int stops = 0;
  double vx = 0.0, vy = 0.0, omega = 0.0;

  /// Advances simulated time by `dt`; a running goal gets one step closer to arrival.
  void advance(core::SimTime dt) {
    time += dt;
    if (nav.status == lua::NavStatus::kRunning && --nav_left <= 0) {
      nav.status = lua::NavStatus::kArrived;
    }
  }

  core::SimTime now() const override { return time; }
  std::string_view name() const override { return robot_name; }
  lua::PoseEstimate pose() const override {
    if (throw_on_pose) throw std::runtime_error("localization lost");
    return pose_estimate;
  }
  void goto_place(std::string_view place, bool forward) override {
    ++nav.goal_id;
    nav_forward = forward;
    nav_goal = std::string(place);
    nav.error.clear();
    if (places.find(place) == places.end()) {
      nav.status = lua::NavStatus::kInvalidGoal;
      nav.error = "unknown place '" + nav_goal + "'";
      return;
    }
    nav.status = lua::NavStatus::kRunning;
    nav_left = nav_steps;
  }
  void goto_pose(const core::Pose2D& p, bool forward) override {
    ++nav.goal_id;
    nav_forward = forward;
    nav_goal = "pose";
    pose_estimate.pose = p;
    nav.status = lua::NavStatus::kRunning;
    nav_left = nav_steps;
  }
  lua::NavState navigator() const override { return nav; }
  void stop() override {
    ++stops;
    if (nav.status == lua::NavStatus::kRunning) nav.status = lua::NavStatus::kAborted;
    vx = vy = omega = 0.0;
  }
  void set_velocity(double x, double y, double w) override {
    vx = x;
    vy = y;
    omega = w;
  }
  bool puck_in_holder() const override { return puck; }
  double ir_distance_m() const override { return ir_m; }
  lua::OpticalSensors optical() const override { return optical_sensors; }
  lua::LightReading light() const override { return light_reading; }
  std::span<const lua::PuckSighting> pucks() const override { return puck_sightings; }
  std::optional<lua::PlaceInfo> place(std::string_view name) const override {
    if (places.find(name) == places.end()) return std::nullopt;
    // Places on a line, 1 m apart in the order of the set, facing +x.
    double x = 0.0;
    for (const auto& p : places) {
      if (p == name) break;
      x += 1.0;
    }
    return lua::PlaceInfo{{x, 0.0, 0.0}, {x + 0.2225, 0.0}};
  }
  lua::LaserView laser() const override {
    return {-core::kPi, 2.0 * core::kPi / 360.0, laser_ranges};
  }
};

/// Runs `n` skill cycles at the engine's rate, advancing the robot before each; returns the
/// status after the last one.
inline lua::SkillStatus run_cycles(lua::SkillEngine& engine, FakeRobot& robot, int n) {
  lua::SkillStatus s = engine.status();
  for (int i = 0; i < n; ++i) {
    robot.advance(engine.cycle_period());
    s = engine.cycle();
  }
  return s;
}

/// Cycles until the string is no longer RUNNING or `max_cycles` passed.
inline lua::SkillStatus run_until_done(lua::SkillEngine& engine, FakeRobot& robot,
                                       int max_cycles = 1000) {
  lua::SkillStatus s = engine.status();
  for (int i = 0; i < max_cycles && s == lua::SkillStatus::kRunning; ++i) {
    robot.advance(engine.cycle_period());
    s = engine.cycle();
  }
  return s;
}

/// Collects what skills log.
struct LogCapture {
  std::vector<std::string> lines;
  void attach(lua::SkillEngine& engine) {
    engine.set_log_sink([this](lua::LogLevel, std::string_view text) { lines.emplace_back(text); });
  }
  bool contains(std::string_view needle) const {
    for (const std::string& l : lines) {
      if (l.find(needle) != std::string::npos) return true;
    }
    return false;
  }
};

/// "name.lua:N" for the line of `path` that carries the marker comment "-- MARK".
inline std::string marked_line(const std::string& path) {
  std::ifstream in(path);
  std::string line;
  for (int n = 1; std::getline(in, line); ++n) {
    if (line.find("-- MARK") != std::string::npos) {
      return path.substr(path.find_last_of('/') + 1) + ":" + std::to_string(n);
    }
  }
  return "(no marker in " + path + ")";
}

#ifdef LLSF_SOURCE_DIR
/// The example skills' directory and the test skills' directory.
inline std::string example_skills_dir() { return LLSF_SOURCE_DIR "/lua/skills/examples"; }
inline std::string test_skills_dir() { return LLSF_SOURCE_DIR "/tests/lua/skills"; }
#endif

}  // namespace llsf::test
