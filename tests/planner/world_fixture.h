// SPDX-License-Identifier: MIT
// Test helpers: the kinematic world's field as a planner FieldMap (the conversion sim/ will own),
// and a scene that drives robots in the kinematic World with navigators.
#pragma once

#include <string>
#include <vector>

#include "llsf/kinematic/world.h"
#include "llsf/planner/navigator.h"

namespace llsf::test {

/// The conversion sim/ will own: devices with their footprints and RFID zone centres, and the
/// marked areas, copied one to one.
inline planner::FieldMap field_from_world(const kinematic::WorldConfig& w) {
  planner::FieldMap m;
  m.width_m = w.field.width_m;
  m.height_m = w.field.height_m;
  for (int i = 0; i < kinematic::kDeviceCount; ++i) {
    const core::DeviceId id(i);
    const kinematic::DeviceConfig& d = w.devices[i];
    planner::DeviceRole role = planner::DeviceRole::kProduction;
    switch (kinematic::device_kind(id)) {
      case kinematic::DeviceKind::kProduction:
        role = planner::DeviceRole::kProduction;
        break;
      case kinematic::DeviceKind::kRecycling:
        role = planner::DeviceRole::kRecycling;
        break;
      case kinematic::DeviceKind::kTest:
        role = planner::DeviceRole::kTest;
        break;
      case kinematic::DeviceKind::kDelivery:
        role = planner::DeviceRole::kDelivery;
        break;
    }
    m.devices.push_back(
        {std::string(kinematic::device_name(id)), role, d.pose, d.footprint(), d.rfid_center()});
  }
  auto rect = [](const kinematic::Rect& r) { return planner::AreaRect{r.lo, r.hi}; };
  m.insertion_area = rect(w.field.insertion_area);
  m.input_storage = rect(w.field.input_storage);
  m.late_order_area = rect(w.field.late_order_area);
  m.late_order_slot = w.field.late_order_slot;
  m.delivery_zone = rect(w.field.delivery_zone);
  return m;
}

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
      : rng_(seed), world_(world_config, rng_), planner_(field_from_world(world_config), pc) {
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
