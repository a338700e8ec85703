// SPDX-License-Identifier: MIT
// The LLSF 2013 team agent (clips/agents/llsf2013) playing whole games in the game loop.
#include <doctest/doctest.h>

#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "fixture.h"
#include "llsf/sim/agent_brain.h"
#include "llsf/sim/game.h"

using namespace llsf;
using namespace llsf::sim;

namespace {

struct AgentGame {
  AgentGame(int robots, std::uint64_t seed, clips::ConfigEntries config, bool print = false)
      : game(make_config(robots, seed)) {
    for (int i = 0; i < robots; ++i) {
      AgentBrainConfig c;
      c.agent_files = {LLSF_SOURCE_DIR "/clips/agents/llsf2013"};
      c.config = config;
      brains.push_back(std::make_unique<AgentBrain>(
          game, i, c, [this, print](const clips::LogRecord& r) {
            if (r.level >= clips::LogLevel::kWarn) ++warnings;
            if (print || r.level == clips::LogLevel::kError) {
              std::printf("%8.2f %s %s: %.*s\n", r.time.seconds(), std::string(r.agent).c_str(),
                          clips::to_string(r.level), static_cast<int>(r.text.size()),
                          r.text.data());
            }
          }));
    }
  }
  static GameConfig make_config(int robots, std::uint64_t seed) {
    GameConfig c = test::small_game(robots, seed);
    return c;
  }
  int runtime_errors() const {
    int n = 0;
    for (const auto& b : brains) n += b->agent().runtime_errors();
    return n;
  }
  Game game;
  std::vector<std::unique_ptr<AgentBrain>> brains;
  int warnings = 0;
};

}  // namespace

TEST_CASE("the LLSF 2013 agent explores with three robots and reports the machines") {
  AgentGame g(3, 7, {});
  test::start_phase(g.game, refbox::GamePhase::kExploration);
  g.game.run_until(SimTime::from_sec(180));
  const GameSummary s = g.game.summary();
  MESSAGE("exploration points: ", s.exploration_points);
  CHECK(g.runtime_errors() == 0);
  CHECK(s.exploration_points >= 20);
}

TEST_CASE("the LLSF 2013 agent produces and delivers with three robots") {
  AgentGame g(3, 7, {});
  test::start_phase(g.game, refbox::GamePhase::kProduction);
  g.game.run_until(SimTime::from_sec(900));
  const GameSummary s = g.game.summary();
  MESSAGE("production points: ", s.production_points);
  CHECK(g.runtime_errors() == 0);
  CHECK(s.production_points >= 20);
}
