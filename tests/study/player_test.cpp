// SPDX-License-Identifier: MIT
// The one way to set up and play a game above sim (study/player.h): a robot entry becomes an
// agent configuration in one place (agent_config, the sandbox included), and a Player plugs the
// agents, starts the refbox and plays with observers, as run_game does.
#include <doctest/doctest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "llsf/core/rng.h"
#include "llsf/study/player.h"
#include "llsf/study/runner.h"
#include "llsf/study/scenario.h"

using namespace llsf;
using namespace llsf::study;

namespace {

Scenario default_scenario() {
  return load_scenario(LLSF_SOURCE_DIR "/scenarios/default.yaml").variants.front();
}

}  // namespace

TEST_CASE("agent_config: every field of the robot entry and the scenario's skill engine") {
  Scenario s;
  s.skills.skill_dirs = {"/skills/mine"};
  s.skills.module_dirs = {"/modules"};
  RobotSpec spec;
  spec.agent = {"/agents/entry.clp"};
  spec.config = {clips::ConfigEntry::of("/clips-agent/demo/robot-name", "R-1")};
  spec.locks = true;
  spec.sandbox = false;
  spec.fawkes = true;
  spec.agent_dir = "/agents";
  spec.agent_start = core::SimTime::from_sec(5);
  const sim::AgentBrainConfig c = agent_config(s, spec);
  CHECK(c.agent_files == spec.agent);
  REQUIRE(c.config.size() == 1);
  CHECK(c.config.front().path == "/clips-agent/demo/robot-name");
  CHECK(c.skills.skill_dirs == s.skills.skill_dirs);
  CHECK(c.skills.module_dirs == s.skills.module_dirs);
  CHECK(c.locks);
  CHECK_FALSE(c.sandbox);  // AgentBrainConfig's default is on: only the mapping turns it off
  CHECK(c.fawkes);
  CHECK(c.agent_dir == "/agents");
  CHECK(c.start == core::SimTime::from_sec(5));
  spec.sandbox = true;
  CHECK(agent_config(s, spec).sandbox);
}

TEST_CASE("agent_config: robots.sandbox of a scenario file reaches the agent") {
  const auto dir = std::filesystem::temp_directory_path() / "llsf_player_sandbox";
  std::filesystem::create_directories(dir);
  const std::string path = (dir / "unsandboxed.yaml").string();
  std::ofstream(path) << "name: unsandboxed\n"
                         "robots:\n"
                         "  count: 1\n"
                         "  sandbox: false\n"
                         "  agent: [" LLSF_SOURCE_DIR "/clips/agents/common, " LLSF_SOURCE_DIR
                         "/clips/agents/llsf2013]\n";
  const Scenario s = load_scenario(path).variants.at(0);
  CHECK_FALSE(agent_config(s, s.robots.at(0)).sandbox);
  const Scenario d = default_scenario();
  CHECK(agent_config(d, d.robots.at(0)).sandbox);
  std::filesystem::remove_all(dir);
}

TEST_CASE("Player: plugs an agent for every robot entry that names one") {
  Scenario s = default_scenario();
  s.robots.at(1).agent.clear();
  Player player(s, 7);
  CHECK(player.game().config().seed == 7);
  CHECK(player.plug_agent(1) == nullptr);
  player.plug_agents();
  CHECK(player.driver().agent(0) != nullptr);
  CHECK(player.driver().agent(1) == nullptr);
  CHECK(player.driver().agent(2) != nullptr);
}

TEST_CASE("Player: observers in order after every tick; the first that says stop ends the game") {
  Scenario s = default_scenario();
  for (RobotSpec& r : s.robots) r.agent.clear();  // no brains: the robots stand still
  Player player(s, 1);
  std::string order;
  int ticks = 0;
  int late = 0;
  player.observe([&](const sim::Game&) {
    order += 'a';
    return ++ticks == 5;
  });
  player.observe([&](const sim::Game&) {
    order += 'b';
    ++late;
    return false;
  });
  CHECK(player.play_until(core::SimTime::from_sec(10)));  // stopped by the first
  CHECK(ticks == 5);
  CHECK(late == 4);  // not called in the tick the first stopped
  CHECK(order == "ababababa");
  const core::SimTime stopped = player.game().time();
  CHECK(stopped < core::SimTime::from_sec(1));
  CHECK_FALSE(player.play_until(stopped + core::SimTime::from_sec(1)));  // plays on
  CHECK(player.game().time() >= stopped + core::SimTime::from_sec(1));
}

TEST_CASE("Player: set up and played as run_game plays, the game is run_game's") {
  Scenario s = default_scenario();
  s.duration = core::SimTime::from_sec(40);
  s.tests.clear();
  const RunResult r = run_game(s, 3);
  Player player(s, 3);
  player.plug_agents();
  player.start();
  CHECK_FALSE(player.play_until(s.duration));
  const sim::GameSummary sum = player.game().summary();
  std::uint64_t h = core::kFnvOffset;  // RunResult::result_hash's mix (runner.cpp)
  auto mix = [&h](const auto& v) { h = core::fnv1a(&v, sizeof(v), h); };
  mix(sum.world_hash);
  mix(sum.refbox_hash);
  mix(sum.comm.sent);
  CHECK(r.messages_sent > 0);
  CHECK(sum.comm.sent == r.messages_sent);
  CHECK(h == r.result_hash);
}
