// SPDX-License-Identifier: MIT
// Benchmark of the game loop: three robots driving loops of places with their navigators in
// PRODUCTION, with the refbox (and its protocol adapter) and the radio on; CPU time per tick and
// the real-time factor (simulated seconds per CPU second).
#include <llsf_msgs/GameState.pb.h>

#include <string>
#include <vector>

#include "harness.h"
#include "llsf/refbox/protocol.h"
#include "llsf/sim/driver.h"
#include "llsf/sim/game.h"

using namespace llsf;

namespace {

/// Drives its robot round a loop of places, the next one as soon as the navigator has ended.
class LoopBrain : public sim::RobotBrain {
 public:
  explicit LoopBrain(std::vector<std::string> places) : places_(std::move(places)) {}
  void on_skill_cycle(lua::RobotApi& robot) override {
    if (robot.navigator().status == lua::NavStatus::kRunning) return;
    if (robot.navigator().status == lua::NavStatus::kArrived) ++arrivals;
    robot.goto_place(places_[next_++ % places_.size()], false);
  }
  int arrivals = 0;

 private:
  std::vector<std::string> places_;
  std::size_t next_ = 0;
};

constexpr int kSimSeconds = 300;
constexpr int kRepeats = 3;

struct Run {
  double us_per_tick = 0.0;
  double real_time_factor = 0.0;
  int arrivals = 0;
};

Run game_loop() {
  sim::GameConfig config;  // the 2013 world (3 robots, laser on), ground-truth levels
  config.seed = 2013;
  std::vector<LoopBrain> brains{LoopBrain({"M1_look", "D2_look", "M8_look", "INS_2"}),
                                LoopBrain({"M4_look", "R1_look", "M9_look", "WAIT_INS"}),
                                LoopBrain({"M10_look", "TST_look", "M5_look", "LATE_ORDER"})};
  sim::GameDriver driver(config);
  const sim::Game& game = driver.game();
  driver.start(refbox::GamePhase::kProduction);
  for (int i = 0; i < 3; ++i) driver.plug(i, &brains[static_cast<std::size_t>(i)]);
  const core::SimTime end = core::SimTime::from_sec(kSimSeconds);
  const double t0 = bench::cpu_seconds();
  driver.run_until(end);
  const double cpu = bench::cpu_seconds() - t0;
  Run r;
  r.us_per_tick = cpu * 1e6 / static_cast<double>(game.ticks());
  r.real_time_factor = kSimSeconds / cpu;
  for (const auto& b : brains) r.arrivals += b.arrivals;
  return r;
}

}  // namespace

LLSF_BENCH(game_tick, "Game::step, 3 robots driving place loops in PRODUCTION, refbox + hub on") {
  game_loop();  // warm-up
  std::vector<Run> runs;
  const double us = bench::median_of(kRepeats, [&] {
    runs.push_back(game_loop());
    return runs.back().us_per_tick;
  });
  double rtf = 0.0;
  for (const Run& r : runs) {
    if (r.us_per_tick == us) rtf = r.real_time_factor;
  }
  bench::report("game_tick", "us_per_tick", us, "us");
  bench::report("game_tick", "real_time_factor", rtf, "x");
  bench::report("game_tick", "arrivals_per_300s", runs.back().arrivals, "count");
}
