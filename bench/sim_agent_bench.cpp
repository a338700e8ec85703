// SPDX-License-Identifier: MIT
// Whole games with the LLSF 2013 team agent: 3 robots, exploration (180 s) + production
// (900 s), ground-truth levels, physical skills; 20 seeds without and with 20 % per-link radio
// loss, without and with the lock protocol (agent_games), and the CPU cost of one agent cycle in
// such a game (agent_cycle).
// LLSF_BENCH_VERBOSE=1 prints every game.
#include <llsf_msgs/GameState.pb.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "harness.h"
#include "llsf/refbox/protocol.h"
#include "llsf/sim/agent_brain.h"
#include "llsf/sim/driver.h"
#include "llsf/sim/game.h"
#include "llsf/study/runner.h"
#include "llsf/study/scenario.h"

using namespace llsf;

namespace {

constexpr int kSeeds = 20;

/// Forwards to an AgentBrain and measures the CPU time of its agent cycles.
class TimedBrain : public sim::RobotBrain {
 public:
  explicit TimedBrain(sim::AgentBrain& inner) : inner_(inner) {}
  void on_skill_cycle(lua::RobotApi& robot) override { inner_.on_skill_cycle(robot); }
  void on_agent_cycle(lua::RobotApi& robot, sim::RobotRadio& radio) override {
    const double t0 = bench::cpu_seconds();
    inner_.on_agent_cycle(robot, radio);
    cpu += bench::cpu_seconds() - t0;
    ++cycles;
  }
  double cpu = 0.0;
  long cycles = 0;

 private:
  sim::AgentBrain& inner_;
};

struct GameResult {
  int exploration = 0;
  int production = 0;
  int total = 0;
  int deliveries = 0;
  int runtime_errors = 0;
  double wall_cpu = 0.0;
  double agent_us_per_cycle = 0.0;
};

/// Which agent plays: its second directory (after common) and its confval entries.
struct AgentVariant {
  const char* dir = "llsf2013";
  clips::ConfigEntries config;
};

GameResult play(std::uint64_t seed, double loss, bool locks, const AgentVariant& agent = {}) {
  sim::GameConfig config;
  config.seed = seed;
  if (loss > 0.0) {
    config.hub.loss_model = comm::LossModel::kPerLink;
    config.hub.loss_probability = loss;
  }
  std::vector<std::unique_ptr<TimedBrain>> timed;  // (destroyed after the driver's brains)
  sim::GameDriver driver(config);
  sim::Game& game = driver.game();
  for (int i = 0; i < game.robot_count(); ++i) {
    sim::AgentBrainConfig c;
    c.agent_files = {bench::tree() + "/clips/agents/common",
                     bench::tree() + "/clips/agents/" + agent.dir};
    c.config = agent.config;
    c.locks = locks;
    timed.push_back(std::make_unique<TimedBrain>(driver.plug_agent(i, c)));
    driver.plug(i, timed.back().get());
  }
  driver.start(refbox::GamePhase::kExploration);
  const double t0 = bench::cpu_seconds();
  driver.run_until(core::SimTime::from_sec(180 + 900));
  GameResult r;
  r.wall_cpu = bench::cpu_seconds() - t0;
  const sim::GameSummary s = game.summary();
  r.exploration = s.exploration_points;
  r.production = s.production_points;
  r.total = s.points;
  for (const auto& o : game.refbox().orders()) r.deliveries += o.quantity_delivered;
  double cpu = 0.0;
  long cycles = 0;
  for (const auto& t : timed) {
    cpu += t->cpu;
    cycles += t->cycles;
  }
  r.agent_us_per_cycle = cycles > 0 ? cpu * 1e6 / static_cast<double>(cycles) : 0.0;
  for (int i = 0; i < game.robot_count(); ++i) {
    r.runtime_errors += driver.agent(i)->agent().runtime_errors();
  }
  if (std::getenv("LLSF_BENCH_VERBOSE") != nullptr) {
    std::fprintf(
        stderr,
        "seed %2llu loss %.2f locks %d: exploration %3d production %4d total %4d deliveries %2d "
        "errors %d cpu %.2f s\n",
        static_cast<unsigned long long>(seed), loss, locks ? 1 : 0, r.exploration, r.production,
        r.total, r.deliveries, r.runtime_errors, r.wall_cpu);
  }
  return r;
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 == 1 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

void report_series(const std::string& name, double loss, bool locks,
                   const AgentVariant& agent = {}) {
  std::vector<double> expl, total, rtf;
  int no_delivery = 0;
  int errors = 0;
  for (std::uint64_t seed = 1; seed <= kSeeds; ++seed) {
    const GameResult r = play(seed, loss, locks, agent);
    expl.push_back(r.exploration);
    total.push_back(r.total);
    rtf.push_back(1080.0 / r.wall_cpu);
    if (r.deliveries == 0) ++no_delivery;
    errors += r.runtime_errors;
  }
  bench::report(name, "exploration_points_median", median(expl), "points");
  bench::report(name, "total_points_median", median(total), "points");
  bench::report(name, "total_points_min", *std::min_element(total.begin(), total.end()), "points");
  bench::report(name, "games_without_delivery", no_delivery, "count");
  bench::report(name, "runtime_errors", errors, "count");
  bench::report(name, "real_time_factor_median", median(rtf), "x");
}

}  // namespace

LLSF_BENCH(
    agent_games,
    "LLSF 2013 agent, 3 robots, full games on 20 seeds, 0 % / 20 % loss, without/with locks") {
  report_series("agent_games", 0.0, false);
  report_series("agent_games_loss20", 0.2, false);
  report_series("agent_games_locks", 0.0, true);
  report_series("agent_games_locks_loss20", 0.2, true);
}

LLSF_BENCH(agent_cycle, "CPU per agent cycle of the LLSF 2013 agent in a full 3-robot game") {
  std::vector<double> us;
  for (std::uint64_t seed : {1, 2, 3}) us.push_back(play(seed, 0.0, false).agent_us_per_cycle);
  bench::report("agent_cycle", "us_per_robot_cycle", median(us), "us");
}

LLSF_BENCH(
    agent_compare,
    "20 seeds, 3 robots, locks on: roles P1P2-P3-P3 (default), P3-P3-P3, and the auction agent") {
  report_series("agent_compare_roles_P1P2-P3-P3", 0.0, true);
  AgentVariant p3{
      "llsf2013",
      {clips::ConfigEntry::list("/clips-agent/roles", std::vector<std::string>{"P3", "P3", "P3"})}};
  report_series("agent_compare_roles_P3-P3-P3", 0.0, true, p3);
  report_series("agent_compare_auction", 0.0, true, AgentVariant{"auction", {}});
  report_series("agent_compare_auction_loss20", 0.2, true, AgentVariant{"auction", {}});
}

LLSF_BENCH(full_game,
           "scenarios/default.yaml: a whole 3-robot game (1080 s), CPU and where the tick goes") {
  const study::ScenarioFile f = study::load_scenario(bench::tree() + "/scenarios/default.yaml");
  study::RunHooks plain;
  std::vector<study::RunResult> runs;
  const double cpu = bench::median_of(5, [&] {
    runs.push_back(study::run_game(f.variants[0], 1, plain));
    return runs.back().cpu_s;
  });
  bench::report("full_game", "cpu_s", cpu, "s");
  bench::report("full_game", "real_time_factor", 1080.0 / cpu, "x");
  bench::report("full_game", "points", runs.back().points, "points");
  // The split, from one profiled run (the clock reads add a little).
  study::RunHooks prof;
  prof.profile = true;
  const std::string rec = (std::filesystem::temp_directory_path() /
                           ("llsf_bench_full_game_" + std::to_string(getpid()) + ".jsonl.gz"))
                              .string();
  prof.record_path = rec;  // recorded, as llsfsim run does
  const study::RunResult p = study::run_game(f.variants[0], 1, prof);
  std::filesystem::remove(rec);
  double total = 0.0;
  for (const auto& [name, s] : p.time_split) total += s;
  for (const auto& [name, s] : p.time_split) {
    if (s <= 0.0) continue;
    bench::report("full_game", "share_" + name, s / total, "fraction");
  }
}
