// SPDX-License-Identifier: MIT
// The issue-level speed bars of the llsfsim command, for scenarios/default.yaml (3 robots, the
// LLSF 2013 agent with locks, physical skills, ground-truth levels, exploration + production =
// 1080 s of game):
//   game:     one game on one core -- real-time factor and wall seconds (median of 5, each game
//             in a fresh child process so that peak_rss_mb is that game's own peak memory)
//   batch100: 100 such games (seeds 1..100) with 2 jobs into a fresh statistics store, with
//             recordings, as `llsfsim batch scenarios/default.yaml --runs 100 --jobs 2` does.
// Wall-clock time here measures, it never enters a game.
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "harness.h"
#include "llsf/study/batch.h"
#include "llsf/study/runner.h"
#include "llsf/study/scenario.h"
#include "llsf/study/stats_store.h"

using namespace llsf;

namespace {

std::string scenario() { return bench::tree() + "/scenarios/default.yaml"; }
std::string move_base_scenario() { return bench::tree() + "/bench/move_base_game.yaml"; }

double wall_now() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

struct ChildGame {
  double wall_s = 0.0;
  double game_s = 0.0;
  double peak_rss_mb = 0.0;
  int points = 0;
  bool ok = false;
};

// Plays seed 1 in a child process; the child writes wall seconds, game seconds and points to a
// pipe, the parent reads its peak resident set size from wait4().
ChildGame game_in_child(const std::string& path) {
  ChildGame g;
  int fds[2];
  if (pipe(fds) != 0) return g;
  const pid_t pid = fork();
  if (pid < 0) return g;
  if (pid == 0) {
    close(fds[0]);
    const study::ScenarioFile f = study::load_scenario(path);
    const double t0 = wall_now();
    const study::RunResult r = study::run_game(f.variants[0], 1);
    const double wall = wall_now() - t0;
    char buf[128];
    const int n = std::snprintf(buf, sizeof buf, "%.6f %.3f %d", wall, r.game_time_s, r.points);
    (void)!write(fds[1], buf, static_cast<std::size_t>(n));
    close(fds[1]);
    _exit(0);
  }
  close(fds[1]);
  char buf[128] = {};
  const ssize_t n = read(fds[0], buf, sizeof buf - 1);
  close(fds[0]);
  int status = 0;
  rusage usage{};
  if (wait4(pid, &status, 0, &usage) != pid || !WIFEXITED(status) || WEXITSTATUS(status) != 0 ||
      n <= 0) {
    return g;
  }
  g.ok = std::sscanf(buf, "%lf %lf %d", &g.wall_s, &g.game_s, &g.points) == 3;
  g.peak_rss_mb = static_cast<double>(usage.ru_maxrss) / 1024.0;  // ru_maxrss is in KiB
  return g;
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n == 0 ? 0.0 : n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

// Plays `path`'s seed 1 five times, each in a child process, and reports the medians as `name`.
void games_in_children(const char* name, const std::string& path) {
  std::vector<double> wall, rss;
  double game_s = 0.0;
  for (int i = 0; i < 5; ++i) {
    const ChildGame g = game_in_child(path);
    if (!g.ok) {
      std::fprintf(stderr, "%s: the child process failed\n", name);
      return;
    }
    wall.push_back(g.wall_s);
    rss.push_back(g.peak_rss_mb);
    game_s = g.game_s;
  }
  const double w = median(wall);
  bench::report(name, "rtf", game_s / w, "x");
  bench::report(name, "wall_s", w, "s");
  bench::report(name, "peak_rss_mb", median(rss), "MB");
}

}  // namespace

LLSF_BENCH(game,
           "scenarios/default.yaml, seed 1, in a child process: real-time factor, wall seconds "
           "and peak memory of one 1080 s 3-robot game (median of 5)") {
  games_in_children("game", scenario());
}

LLSF_BENCH(game_move_base,
           "bench/move_base_game.yaml (the default game under robotino-2013: the "
           "move_base-2013 navigation, the laser on), seed 1, in a child process: real-time "
           "factor, wall seconds and peak memory (median of 5)") {
  games_in_children("game_move_base", move_base_scenario());
}

LLSF_BENCH(batch100,
           "100 games of scenarios/default.yaml (seeds 1..100) with 2 jobs into a fresh "
           "statistics store, recorded: wall seconds") {
  namespace fs = std::filesystem;
  const fs::path dir = fs::temp_directory_path() /
                       ("llsf_bench_batch100_" + std::to_string(static_cast<long>(getpid())));
  fs::remove_all(dir);
  fs::create_directories(dir);
  const study::ScenarioFile f = study::load_scenario(scenario());
  double wall = 0.0;
  int played = 0;
  {
    study::StatsStore store((dir / "batch.db").string());
    study::BatchOptions o;
    o.runs = 100;
    o.jobs = 2;
    o.recordings_dir = (dir / "recordings").string();
    const double t0 = wall_now();
    const study::BatchResult b = study::run_batch(f, "bench", store, o);
    wall = wall_now() - t0;
    played = b.played;
  }
  fs::remove_all(dir);
  if (played != 100) {
    std::fprintf(stderr, "batch100: only %d of 100 games played\n", played);
    return;
  }
  bench::report("batch100", "wall_s", wall, "s");
  bench::report("batch100", "games_per_min", 100.0 * 60.0 / wall, "games/min");
}
