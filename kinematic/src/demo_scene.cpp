// SPDX-License-Identifier: MIT
#include "llsf/kinematic/demo_scene.h"

#include "llsf/core/assert.h"

namespace llsf::kinematic {

namespace {
constexpr double kPi = core::kPi;
Waypoint wp(double x, double y, double theta, double speed = 1.0, double tol = 0.02) {
  Waypoint w;
  w.pose = {x, y, theta};
  w.max_speed_mps = speed;
  w.tolerance_m = tol;
  w.angle_tolerance_rad = 0.03;
  return w;
}
}  // namespace

DemoMission demo_mission_route() {
  // Lanes run between the machine rows/columns at 1.12, 2.24, 3.36 and 4.48 m.
  DemoMission m;
  // Headings follow the direction of travel: an assisted holder lets its puck go when the
  // robot backs away, so a robot carrying a puck never drives backwards.
  m.route = {
      wp(0.90, 0.40, 0.0),  // leave the insertion area
      wp(0.90, 2.40, kPi / 2),
      wp(0.80, 2.85, kPi),               // in front of the storage, facing it
      wp(0.62, 2.85, kPi, 0.3, 0.005),   // line up with puck 16 at (0.28, 2.85)
      wp(0.50, 2.85, kPi, 0.15, 0.005),  // the puck slides into the holder
      wp(0.50, 2.85, -0.6, 0.5),         // turn towards the field with the puck
      wp(0.90, 2.60, -0.6, 0.6),
      wp(2.24, 2.24, -kPi / 2, 0.6),
      wp(2.24, 1.12, -kPi / 4, 0.6),
      wp(3.92, 1.00, 0.0, 0.6),              // below M1
      wp(3.92, 1.00, kPi / 2, 0.5),          // face its reader
      wp(3.92, 1.31, kPi / 2, 0.15, 0.005),  // puck under the reader
      wp(3.92, 1.31, -kPi / 2, 0.5),         // turn around: the held puck leaves the zone
      wp(3.92, 0.60, -kPi / 2, 0.5),
  };
  m.at_m1 = 11;
  return m;
}

std::vector<Waypoint> demo_patrol_route(int which) {
  if (which == 0) {
    return {wp(1.12, 1.30, kPi / 2), wp(1.12, 4.48, 0.0), wp(3.36, 4.48, -kPi / 2),
            wp(3.36, 3.36, kPi), wp(1.12, 3.36, kPi / 2)};
  }
  return {wp(1.12, 1.80, kPi / 2), wp(1.12, 2.24, 0.0),     wp(3.36, 2.24, -kPi / 2),
          wp(3.36, 1.12, kPi),     wp(2.24, 1.12, kPi / 2), wp(2.24, 2.24, kPi)};
}

DemoScene::DemoScene(const WorldConfig& config, std::uint64_t seed, bool patrol_forever)
    : world_(std::make_unique<World>(config, core::Rng(seed))), loop_(patrol_forever) {
  LLSF_DEMAND_MSG(world_->robot_count() >= 1, "the demo scene needs at least one robot");
  routes_.push_back(demo_mission_route().route);
  starts_.push_back(core::SimTime());
  for (int i = 1; i < world_->robot_count(); ++i) {
    routes_.push_back(demo_patrol_route((i - 1) % 2));
    // robot2 starts once robot1 has passed the left lane, robot3 once robot1 is done at M1.
    starts_.push_back(core::SimTime::from_sec(i == 1 ? 12 : 28));
  }
  for (const auto& r : routes_) drivers_.emplace_back(r, config.robot);
}

const WorldEvents& DemoScene::step() {
  const core::SimTime now = world_->time();
  for (int i = 0; i < static_cast<int>(drivers_.size()); ++i) {
    const RobotId id(i);
    if (now < starts_[i]) continue;
    if (drivers_[i].done() && loop_) {
      // Loop: patrols restart; robot1 patrols once its mission is over.
      drivers_[i] =
          ScriptedDriver(i == 0 ? demo_patrol_route(1) : routes_[i], world_->config().robot);
    }
    world_->set_command(id, drivers_[i].update(world_->robot_pose(id)));
  }
  return world_->step();
}

bool DemoScene::done() const {
  if (loop_) return false;
  for (const auto& d : drivers_)
    if (!d.done()) return false;
  return true;
}

}  // namespace llsf::kinematic
