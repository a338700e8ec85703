// SPDX-License-Identifier: MIT
// The demo scene, shared by `make run`, the tests and the benchmarks: on the 2013 field, robot1
// takes puck 16 from the input storage and pushes it under M1's RFID reader, turns away with it
// and leaves; robot2 and robot3 patrol the free lanes between the machines.
#pragma once

#include <memory>
#include <vector>

#include "llsf/kinematic/scripted_driver.h"
#include "llsf/kinematic/world.h"

namespace llsf::kinematic {

/// The puck robot1 carries in the demo.
inline constexpr PuckId kDemoPuck{16};

/// robot1's mission: storage -> puck 16 -> under M1's reader (up to `at_m1`) -> turn -> leave.
struct DemoMission {
  std::vector<Waypoint> route;
  int at_m1 = 0;  ///< index of the waypoint that places the puck under M1's reader
};
DemoMission demo_mission_route();
/// A patrol loop through the lanes between the machines (index 0 or 1).
std::vector<Waypoint> demo_patrol_route(int which);

/// The three robots of the 2013 default world driven by scripted waypoints.
class DemoScene {
 public:
  /// `patrol_forever`: robots loop their routes (benchmarks) instead of stopping when done.
  DemoScene(const WorldConfig& config, std::uint64_t seed, bool patrol_forever);

  /// Computes every robot's command and steps the world once.
  const WorldEvents& step();
  World& world() { return *world_; }
  const World& world() const { return *world_; }
  /// True when every robot has finished its route (never with patrol_forever).
  bool done() const;
  /// Index of the waypoint robot1 is driving to.
  int mission_index() const { return drivers_[0].index(); }

 private:
  std::unique_ptr<World> world_;
  std::vector<ScriptedDriver> drivers_;
  std::vector<std::vector<Waypoint>> routes_;
  std::vector<core::SimTime> starts_;
  bool loop_;
};

}  // namespace llsf::kinematic
