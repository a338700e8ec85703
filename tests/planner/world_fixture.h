// SPDX-License-Identifier: MIT
// Test helpers: a scene that drives robots in the kinematic World with navigators, on the map the
// game builds from the world (sim::field_map_from_world: devices, marked areas and obstacles).
#pragma once

#include <string>
#include <vector>

#include "llsf/kinematic/world.h"
#include "llsf/planner/navigator.h"
#include "llsf/sim/game.h"

namespace llsf::test {

inline kinematic::MotorCommand to_motor(const planner::VelocityCommand& c) {
  return {c.vx_mps, c.vy_mps, c.omega_rps};
}

/// The 2013 world without pucks and laser (faster), with the given robot starts.
inline kinematic::WorldConfig test_world(const std::vector<core::Pose2D>& starts) {
  kinematic::WorldConfig w = kinematic::WorldConfig::default_2013();
  w.sensors.laser.enabled = false;
  w.pucks.clear();
  w.robots.clear();
  for (std::size_t i = 0; i < starts.size(); ++i) {
    w.robots.push_back({"robot" + std::to_string(i + 1), starts[i]});
  }
  return w;
}

/// Robots of a kinematic World driven by one navigator each, with the others as discs.
class NavScene {
 public:
  NavScene(const kinematic::WorldConfig& world_config, std::uint64_t seed,
           planner::PlannerConfig pc = {}, planner::ControllerConfig cc = {})
      : rng_(seed),
        world_(world_config, rng_),
        planner_(sim::field_map_from_world(world_config), pc) {
    for (int i = 0; i < world_.robot_count(); ++i) {
      navs_.emplace_back(planner_, cc, rng_.stream("planner/robot" + std::to_string(i + 1)));
    }
  }

  kinematic::World& world() { return world_; }
  planner::Planner& planner() { return planner_; }
  planner::Navigator& nav(int i) { return navs_[i]; }
  int robot_count() const { return static_cast<int>(navs_.size()); }
  /// Robot-robot contacts seen so far.
  int robot_contacts() const { return robot_contacts_; }
  /// Robot-device/wall contacts seen so far.
  int static_contacts() const { return static_contacts_; }
  /// Smallest centre distance between two robots seen so far.
  double min_robot_distance() const { return min_robot_distance_; }

  /// The other robots of robot i as discs of the planning radius.
  std::vector<planner::DiscObstacle> others(int i) const {
    std::vector<planner::DiscObstacle> out;
    for (int j = 0; j < world_.robot_count(); ++j) {
      if (j == i) continue;
      out.push_back({j, world_.robot_pose(core::RobotId(j)).position(),
                     planner_.config().inflated_radius_m()});
    }
    return out;
  }

  /// One world step; navigator i is updated if active[i] (others stand still).
  void step() {
    const core::SimTime now = world_.time();
    for (int i = 0; i < robot_count(); ++i) {
      const core::RobotId id(i);
      const auto o = others(i);
      world_.set_command(id, to_motor(navs_[i].update(now, world_.robot_pose(id), o)));
    }
    const auto& ev = world_.step();
    for (const auto& c : ev.collisions) {
      if (c.kind == kinematic::CollisionKind::kRobotRobot)
        ++robot_contacts_;
      else
        ++static_contacts_;
    }
    for (int i = 0; i < robot_count(); ++i) {
      for (int j = i + 1; j < robot_count(); ++j) {
        const double d = (world_.robot_pose(core::RobotId(i)).position() -
                          world_.robot_pose(core::RobotId(j)).position())
                             .norm();
        min_robot_distance_ = std::min(min_robot_distance_, d);
      }
    }
  }

  /// Steps until no navigator is running (or `max_s` simulated seconds); returns the time.
  double run(double max_s) {
    const core::SimTime end = world_.time() + core::SimTime::from_seconds(max_s);
    while (world_.time() < end) {
      step();
      bool running = false;
      for (const auto& n : navs_) running |= n.status().outcome == planner::NavOutcome::kRunning;
      if (!running) break;
    }
    return world_.time().seconds();
  }

 private:
  core::Rng rng_;
  kinematic::World world_;
  planner::Planner planner_;
  std::vector<planner::Navigator> navs_;
  int robot_contacts_ = 0;
  int static_contacts_ = 0;
  double min_robot_distance_ = 1e9;
};

}  // namespace llsf::test
