// SPDX-License-Identifier: MIT
// Benchmarks of the kinematic world: the cost of a physics step with three driving robots and
// twenty pucks at 100 Hz (sleeping on), and the cost of a 360-beam laser scan.
#include "harness.h"
#include "llsf/kinematic/demo_scene.h"

using namespace llsf;
using namespace llsf::kinematic;

namespace {

constexpr int kSteps = 20000;  // 200 s of simulated time per run
constexpr int kRepeats = 5;

// CPU microseconds per DemoScene step (scripted drivers + World::step) over kSteps steps, after
// a warm-up that gets every robot moving.
double us_per_step(const WorldConfig& cfg) {
  DemoScene scene(cfg, 1, /*patrol_forever=*/true);
  for (int i = 0; i < 1500; ++i) scene.step();
  const double t0 = bench::cpu_seconds();
  for (int i = 0; i < kSteps; ++i) scene.step();
  return (bench::cpu_seconds() - t0) * 1e6 / kSteps;
}

}  // namespace

LLSF_BENCH(world_step, "World::step, 3 robots driving waypoints, 20 pucks, 100 Hz, no laser") {
  WorldConfig cfg = WorldConfig::default_2013();
  cfg.sensors.laser.enabled = false;
  const double us = bench::median_of(kRepeats, [&] { return us_per_step(cfg); });
  bench::report("world_step", "us_per_step", us, "us");
  bench::report("world_step", "real_time_factor", 1e4 / us, "x");
}

LLSF_BENCH(laser_scan, "one 360-beam laser scan with noise, and 3 robots scanning at 5 Hz") {
  WorldConfig off = WorldConfig::default_2013();
  off.sensors.laser.enabled = false;
  WorldConfig every_step = WorldConfig::default_2013();
  every_step.sensors.laser.rate_hz = 100.0;  // one scan per robot per step
  WorldConfig five_hz = WorldConfig::default_2013();
  const double base = bench::median_of(kRepeats, [&] { return us_per_step(off); });
  const double all = bench::median_of(kRepeats, [&] { return us_per_step(every_step); });
  const double at5 = bench::median_of(kRepeats, [&] { return us_per_step(five_hz); });
  const int robots = static_cast<int>(off.robots.size());
  const double per_scan = (all - base) / robots;
  bench::report("laser_scan", "us_per_scan", per_scan, "us");
  // What 3 robots scanning at 5 Hz add per 100 Hz step, against the step without laser.
  const double added = per_scan * robots * 5.0 / 100.0;
  bench::report("laser_scan", "us_per_step_added_3_robots_5hz", added, "us");
  bench::report("laser_scan", "fraction_of_physics_3_robots_5hz", added / base, "ratio");
  bench::report("laser_scan", "us_per_step_with_laser_5hz", at5, "us");
}
