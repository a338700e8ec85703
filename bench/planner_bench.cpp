// SPDX-License-Identifier: MIT
// Benchmarks of the planner on the 2013 field: the CPU time of one query (median, p90) over a
// game's worth of queries -- 300 plans between the named places, a third of them around two
// other robots -- and the total of those 300.
#include <algorithm>
#include <vector>

#include "harness.h"
#include "llsf/core/rng.h"
#include "llsf/planner/navigator.h"
#include "llsf/planner/planner.h"

#if __has_include("llsf/kinematic/world_config.h")
#include "llsf/kinematic/world_config.h"

using namespace llsf;
using namespace llsf::planner;

namespace {

// The kinematic world's 2013 field as a FieldMap (the conversion sim/ owns).
FieldMap field_2013() {
  const auto w = kinematic::WorldConfig::default_2013();
  FieldMap m;
  m.width_m = w.field.width_m;
  m.height_m = w.field.height_m;
  for (int i = 0; i < kinematic::kDeviceCount; ++i) {
    const auto& d = w.devices[i];
    const auto kind = kinematic::device_kind(core::DeviceId(i));
    const DeviceRole role = kind == kinematic::DeviceKind::kProduction  ? DeviceRole::kProduction
                            : kind == kinematic::DeviceKind::kRecycling ? DeviceRole::kRecycling
                            : kind == kinematic::DeviceKind::kTest      ? DeviceRole::kTest
                                                                        : DeviceRole::kDelivery;
    m.devices.push_back({std::string(kinematic::device_name(core::DeviceId(i))), role, d.pose,
                         d.footprint(), d.rfid_center()});
  }
  return m;
}

constexpr int kQueries = 300;
constexpr int kRepeats = 5;

struct Run {
  std::vector<double> ms;           // per query
  std::vector<double> searched_ms;  // per query that needed OMPL (no straight line)
  double total_ms = 0.0;
};

// One game's worth of queries with a fixed seed: place to place, every third one around two
// robots standing on the straight line between them.
Run game_queries() {
  Planner p(field_2013(), PlannerConfig{});
  core::RandomStream rng(2013);
  const auto& places = p.places();
  const int n = static_cast<int>(places.size());
  Run run;
  for (int k = 0; k < kQueries; ++k) {
    const Place& a = places[rng.uniform_int(0, n - 1)];
    const Place& b = places[rng.uniform_int(0, n - 1)];
    std::vector<DiscObstacle> robots;
    if (k % 3 == 2) {
      const Vec2 m1 = a.pose.position() + 0.35 * (b.pose.position() - a.pose.position());
      const Vec2 m2 = a.pose.position() + 0.7 * (b.pose.position() - a.pose.position());
      robots = {{1, m1, 0.26}, {2, m2, 0.26}};
    }
    const double t0 = bench::cpu_seconds();
    const PlanResult r = p.plan({a.pose, b.pose, robots, 0.06, rng.next_u64()});
    const double t1 = bench::cpu_seconds();
    run.ms.push_back((t1 - t0) * 1e3);
    if (r.iterations > 0) run.searched_ms.push_back((t1 - t0) * 1e3);
    run.total_ms += (t1 - t0) * 1e3;
  }
  return run;
}

double quantile(std::vector<double> v, double q) {
  std::sort(v.begin(), v.end());
  return v[static_cast<std::size_t>(q * static_cast<double>(v.size() - 1) + 0.5)];
}

// Three navigators on ideal kinematics (the pose integrates the command), each driving a loop
// of places and seeing the others as discs; returns CPU us per Navigator::update.
double us_per_nav_update() {
  Planner p(field_2013(), PlannerConfig{});
  const core::Rng rng(7);
  std::vector<Navigator> navs;
  std::vector<Pose2D> poses{{0.6, 0.4, 0.0}, {0.6, 1.0, 0.0}, {0.6, 1.6, 0.0}};
  const std::vector<std::vector<const char*>> routes{{"M1", "D2", "M8_left", "INS_2"},
                                                     {"M4_look", "R1", "M9", "WAIT_INS"},
                                                     {"M10_look", "TST", "M5_right", "LATE_ORDER"}};
  for (int i = 0; i < 3; ++i) {
    navs.emplace_back(p, ControllerConfig{}, rng.stream("planner/robot" + std::to_string(i)));
  }
  std::vector<int> leg(3, 0);
  std::vector<DiscObstacle> others;
  const double dt = 0.01;
  const int steps = 30000;  // 300 s
  core::SimTime now;
  const double t0 = bench::cpu_seconds();
  for (int k = 0; k < steps; ++k) {
    for (int i = 0; i < 3; ++i) {
      if (navs[i].status().outcome != NavOutcome::kRunning) {
        navs[i].go_to_place(routes[i][leg[i]++ % 4]);
      }
      others.clear();
      for (int j = 0; j < 3; ++j) {
        if (j != i) others.push_back({j, poses[j].position(), 0.26});
      }
      const VelocityCommand c = navs[i].update(now, poses[i], others);
      const Vec2 v = core::rotate(Vec2(c.vx_mps, c.vy_mps), poses[i].theta);
      poses[i].x += v.x() * dt;
      poses[i].y += v.y() * dt;
      poses[i].theta = core::normalize_angle(poses[i].theta + c.omega_rps * dt);
    }
    now += core::SimTime::from_ms(10);
  }
  return (bench::cpu_seconds() - t0) * 1e6 / (3.0 * steps);
}

}  // namespace

LLSF_BENCH(nav_update, "Navigator::update, 3 robots driving place loops (ideal kinematics)") {
  us_per_nav_update();  // warm-up
  bench::report("nav_update", "us_per_update", bench::median_of(kRepeats, us_per_nav_update), "us");
}

LLSF_BENCH(plan_query, "one planner query on the 2013 field (300 place-to-place queries)") {
  game_queries();  // warm-up: page in OMPL, allocator
  std::vector<double> med, p90, total, smed, sp90;
  double searched = 0.0;
  for (int r = 0; r < kRepeats; ++r) {
    const Run run = game_queries();
    med.push_back(quantile(run.ms, 0.5));
    p90.push_back(quantile(run.ms, 0.9));
    smed.push_back(quantile(run.searched_ms, 0.5));
    sp90.push_back(quantile(run.searched_ms, 0.9));
    total.push_back(run.total_ms);
    searched = static_cast<double>(run.searched_ms.size());
  }
  bench::report("plan_query", "median_ms", quantile(med, 0.5), "ms");
  bench::report("plan_query", "p90_ms", quantile(p90, 0.5), "ms");
  bench::report("plan_query", "total_ms_300_queries", quantile(total, 0.5), "ms");
  // The queries whose straight line was blocked, so that RRTConnect ran.
  bench::report("plan_query", "searched_queries", searched, "count");
  bench::report("plan_query", "searched_median_ms", quantile(smed, 0.5), "ms");
  bench::report("plan_query", "searched_p90_ms", quantile(sp90, 0.5), "ms");
}

#endif
