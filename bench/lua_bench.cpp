// SPDX-License-Identifier: MIT
// Benchmarks of the skill engine: the cost of one skill cycle of one robot running a typical
// skill (goto_place while driving; visit_place with a sub-skill), of exec(), and of loading the
// skill files into a new interpreter.
#include <filesystem>
#include <string>

#include "../tests/lua/fake_robot.h"
#include "harness.h"

using namespace llsf;

namespace {

constexpr int kCycles = 200000;
constexpr int kRepeats = 5;

// The example skills next to this file's folder (absolute: __FILE__ comes from CMake).
lua::SkillEngineConfig bench_config() {
  lua::SkillEngineConfig cfg;
  cfg.skill_dirs = {
      (std::filesystem::path(__FILE__).parent_path().parent_path() / "lua/skills/examples")
          .string()};
  cfg.hot_reload = false;
  return cfg;
}

// CPU microseconds per cycle of `skill_string` run again and again: each run drives 10 s (the
// navigator arrives 300 cycles after its goal), so exec() is amortised as in a game. Returns -1
// if a run fails.
double us_per_cycle(const std::string& skill_string) {
  test::FakeRobot robot;
  robot.nav_steps = 300;
  lua::SkillEngine engine(bench_config(), robot);
  const core::SimTime dt = engine.cycle_period();
  auto run = [&](int cycles) {
    for (int i = 0; i < cycles; ++i) {
      if (engine.status() != lua::SkillStatus::kRunning) {
        if (engine.status() == lua::SkillStatus::kFailed || !engine.exec(skill_string)) {
          return false;
        }
      }
      robot.advance(dt);
      engine.cycle();
    }
    return true;
  };
  if (!run(1000)) return -1.0;  // warm-up (and the GC's first rounds)
  const double t0 = bench::cpu_seconds();
  if (!run(kCycles)) return -1.0;
  return (bench::cpu_seconds() - t0) * 1e6 / kCycles;
}

}  // namespace

LLSF_BENCH(skill_cycle,
           "SkillEngine::cycle of one robot: goto_place (10 s drives), visit_place (+ 2 s wait)") {
  const double us =
      bench::median_of(kRepeats, [] { return us_per_cycle("goto_place{place='M1'}"); });
  bench::report("skill_cycle", "us_per_robot_cycle", us, "us");
  const double sub =
      bench::median_of(kRepeats, [] { return us_per_cycle("visit_place{place='M1', secs=2}"); });
  bench::report("skill_cycle", "us_per_robot_cycle_with_subskill", sub, "us");
  // 3 robots at 30 Hz over an 18-minute game.
  bench::report("skill_cycle", "cpu_s_per_game_3_robots", us * 1e-6 * 3 * 30 * 1080, "s");
}

LLSF_BENCH(skill_exec, "SkillEngine::exec (abort + compile) and building an interpreter") {
  test::FakeRobot robot;
  lua::SkillEngine engine(bench_config(), robot);
  const double exec_us = bench::median_of(kRepeats, [&] {
    constexpr int kExecs = 20000;
    const double t0 = bench::cpu_seconds();
    for (int i = 0; i < kExecs; ++i) {
      engine.exec(i % 2 == 0 ? "goto_place{place='M1'}" : "visit_place{place='M2'}");
      engine.cycle();
    }
    return (bench::cpu_seconds() - t0) * 1e6 / kExecs;
  });
  bench::report("skill_exec", "us_per_exec_and_first_cycle", exec_us, "us");
  // The same with hot reload on: exec() also stats every skill file.
  lua::SkillEngineConfig hot_cfg = bench_config();
  hot_cfg.hot_reload = true;
  lua::SkillEngine hot(hot_cfg, robot);
  const double hot_us = bench::median_of(kRepeats, [&] {
    constexpr int kExecs = 5000;
    const double t0 = bench::cpu_seconds();
    for (int i = 0; i < kExecs; ++i) {
      hot.exec(i % 2 == 0 ? "goto_place{place='M1'}" : "visit_place{place='M2'}");
      hot.cycle();
    }
    return (bench::cpu_seconds() - t0) * 1e6 / kExecs;
  });
  bench::report("skill_exec", "us_per_exec_and_first_cycle_hot_reload", hot_us, "us");
  const double load_ms = bench::median_of(kRepeats, [&] {
    constexpr int kLoads = 200;
    const double t0 = bench::cpu_seconds();
    for (int i = 0; i < kLoads; ++i) engine.reload();
    return (bench::cpu_seconds() - t0) * 1e3 / kLoads;
  });
  bench::report("skill_exec", "ms_per_interpreter_load", load_ms, "ms");
}
