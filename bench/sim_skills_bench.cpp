// SPDX-License-Identifier: MIT
// Benchmark of the skill library in the game loop: one robot runs get_s0 / finish_puck_at (a T1)
// / put the S1 down in the insertion area, over and over, for 900 s of PRODUCTION, at the
// physical and at the symbolic skill level. Real-time factor = simulated s per CPU s.
// LLSF_BENCH_VERBOSE=1 prints every skill failure (time, skill string, error) to stderr.
#include <llsf_msgs/GameState.pb.h>

#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "harness.h"
#include "llsf/refbox/protocol.h"
#include "llsf/sim/driver.h"
#include "llsf/sim/game.h"
#include "llsf/sim/skill_brain.h"

using namespace llsf;

namespace {

constexpr int kSimSeconds = 900;
constexpr int kRepeats = 3;

struct Run {
  double real_time_factor = 0.0;
  double us_per_tick = 0.0;
  int s1_made = 0;
  int failures = 0;
};

Run skill_loop(sim::SkillLevel level) {
  sim::GameConfig config;  // the 2013 world, laser on, ground-truth levels
  config.seed = 2013;
  config.world.robots.resize(1);
  config.levels.skill = level;
  sim::GameDriver driver(config);
  const sim::Game& game = driver.game();
  driver.start(refbox::GamePhase::kProduction);
  driver.run_until(game.time() + game.config().world.physics.step);
  // A T1 (the game plan is fixed by the seed).
  std::string t1 = "M1";
  for (int i = 0; i < refbox::kProductionMachineCount; ++i) {
    if (game.refbox().params()->machine_types[static_cast<std::size_t>(i)] ==
        refbox::MachineType::kT1) {
      t1 = std::string(kinematic::device_name(core::DeviceId(i)));
      break;
    }
  }
  sim::SkillBrain& brain = driver.plug_skills(0);
  Run r;
  int step = 0;
  int round = 0;
  const core::SimTime end = core::SimTime::from_sec(kSimSeconds);
  const double t0 = bench::cpu_seconds();
  // Gives the robot its next skill when the last one ended; before every tick.
  auto next_skill = [&] {
    if (brain.engine().status() != lua::SkillStatus::kRunning) {
      if (brain.engine().status() == lua::SkillStatus::kFailed) {
        ++r.failures;
        if (std::getenv("LLSF_BENCH_VERBOSE") != nullptr) {
          std::fprintf(stderr, "%8.2f %s: %s\n", game.time().seconds(),
                       brain.engine().skill_string().c_str(), brain.engine().error().c_str());
        }
      }
      if (step == 2 && brain.engine().status() == lua::SkillStatus::kFinal &&
          brain.engine().result() == "DONE") {
        ++r.s1_made;
      }
      step = (step % 4) + 1;
      switch (step) {
        case 1:
          brain.exec("get_s0{}");
          break;
        case 2:
          brain.exec("finish_puck_at{place=\"" + t1 + "\"}");
          break;
        case 3:
          brain.exec("drive_to{x=0.65, y=" + std::to_string(0.35 + 0.12 * (round++ % 15)) +
                     ", ori=math.pi}");
          break;
        default:
          brain.exec("leave_puck{}");
          break;
      }
    }
  };
  next_skill();
  driver.run_until(end, [&](const sim::Game&) {
    next_skill();
    return false;
  });
  const double cpu = bench::cpu_seconds() - t0;
  r.real_time_factor = kSimSeconds / cpu;
  r.us_per_tick = cpu * 1e6 / static_cast<double>(game.ticks());
  return r;
}

void report_level(sim::SkillLevel level) {
  const std::string name = std::string("skill_loop_") + sim::to_string(level);
  skill_loop(level);  // warm-up
  std::vector<Run> runs;
  const double rtf = bench::median_of(kRepeats, [&] {
    runs.push_back(skill_loop(level));
    return runs.back().real_time_factor;
  });
  bench::report(name, "real_time_factor", rtf, "x");
  bench::report(name, "us_per_tick", runs.back().us_per_tick, "us");
  bench::report(name, "s1_made_per_900s", runs.back().s1_made, "count");
  bench::report(name, "skill_failures_per_900s", runs.back().failures, "count");
}

}  // namespace

LLSF_BENCH(skill_loop, "one robot: get_s0, finish_puck_at a T1, put it down; 900 s, both levels") {
  report_level(sim::SkillLevel::kPhysical);
  report_level(sim::SkillLevel::kSymbolic);
}
