// SPDX-License-Identifier: MIT
// llsf-world-demo: the kinematic world on its own. Three robots drive scripted waypoints on the
// 2013 field; robot1 pushes puck 16 from the input storage under M1's RFID reader. Prints the
// world's events and the final state hash (equal seeds give equal hashes).
#include <fmt/core.h>
#include <CLI/CLI.hpp>

#include <cstdio>

#include "llsf/core/error.h"
#include "llsf/kinematic/demo_scene.h"

using namespace llsf;
using namespace llsf::kinematic;

namespace {
const char* collision_name(CollisionKind k) {
  switch (k) {
    case CollisionKind::kRobotRobot:
      return "robot";
    case CollisionKind::kRobotWall:
      return "wall";
    case CollisionKind::kRobotDevice:
      return "device";
  }
  return "?";
}
}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "llsf-world-demo: three Robotinos on the LLSF 2013 field; robot1 pushes puck 16 from the\n"
      "input storage under M1's RFID reader. Prints RFID and collision events and the state hash."};
  std::uint64_t seed = 1;
  double seconds = 50.0;
  std::string config_path;
  std::string holder;
  bool quiet = false;
  app.add_option("--seed", seed, "scenario seed (sensor noise streams)")->capture_default_str();
  app.add_option("--seconds", seconds, "simulated seconds to run")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 1e6));
  app.add_option("--world", config_path,
                 "world config YAML on top of the 2013 defaults (docs/world-config.md)")
      ->check(CLI::ExistingFile);
  app.add_option("--holder", holder, "puck-holder abstraction level")
      ->check(CLI::IsMember({"physical", "assisted"}));
  app.add_flag("--quiet,-q", quiet, "print only the summary");
  CLI11_PARSE(app, argc, argv);

  try {
    WorldConfig cfg =
        config_path.empty() ? WorldConfig::default_2013() : load_world_config_file(config_path);
    if (!holder.empty())
      cfg.robot.holder.mode = holder == "physical" ? HolderMode::kPhysical : HolderMode::kAssisted;
    DemoScene scene(cfg, seed, /*patrol_forever=*/false);
    World& world = scene.world();
    const auto end = core::SimTime::from_seconds(seconds);
    int rfid_events = 0, collisions = 0;
    while (world.time() < end) {
      const WorldEvents& ev = scene.step();
      for (const RfidEvent& e : ev.rfid) {
        ++rfid_events;
        if (!quiet)
          fmt::print("{:8.2f}s  rfid   puck {:2d} {} {}\n", e.time.seconds(), e.puck.value(),
                     e.kind == RfidEventKind::kEntered ? "entered" : "left   ",
                     device_name(e.device));
      }
      for (const CollisionEvent& e : ev.collisions) {
        ++collisions;
        if (!quiet)
          fmt::print("{:8.2f}s  touch  {} touches {} {}\n", e.time.seconds(),
                     world.config().robots[e.robot.value()].name, collision_name(e.kind),
                     e.kind == CollisionKind::kRobotDevice ? std::string(device_name(e.device))
                     : e.kind == CollisionKind::kRobotRobot
                         ? world.config().robots[e.other_robot.value()].name
                         : std::string());
      }
    }
    fmt::print("simulated {:.2f} s in {} steps; {} RFID events, {} collisions\n",
               world.time().seconds(), world.time() / world.config().physics.step, rfid_events,
               collisions);
    for (int i = 0; i < world.robot_count(); ++i) {
      const RobotId id(i);
      const Pose2D p = world.robot_pose(id);
      const Pose2D o = world.sensors(id).odometry.pose;
      fmt::print("{}: pose ({:.3f}, {:.3f}, {:.3f}) odometry ({:.3f}, {:.3f}, {:.3f})\n",
                 world.config().robots[i].name, p.x, p.y, p.theta, o.x, o.y, o.theta);
    }
    const Vec2 puck = world.puck_position(kDemoPuck);
    fmt::print("puck {} at ({:.3f}, {:.3f})\n", kDemoPuck.value(), puck.x(), puck.y());
    fmt::print("state hash {:016x}\n", world.state_hash());
  } catch (const core::ConfigError& e) {
    std::fprintf(stderr, "llsf-world-demo: %s\n", e.what());
    return 2;
  }
  return 0;
}
