// SPDX-License-Identifier: MIT
// GameDriver (the one way to play a game), the frozen GameConfig, and the radio's game side.
#include "llsf/sim/driver.h"

#include <doctest/doctest.h>
#include <llsf_agent_msgs/LockMessage.pb.h>

#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "fixture.h"
#include "llsf/sim/hackathon_extension.h"

using namespace llsf;
using namespace llsf::sim;

namespace {

AgentBrainConfig llsf2013_agent() {
  AgentBrainConfig c;
  c.agent_files = {LLSF_SOURCE_DIR "/clips/agents/common",
                   LLSF_SOURCE_DIR "/clips/agents/llsf2013"};
  return c;
}

int reload_writes = 1;  // seconds added to each written file's modification time

/// Counts its cycles; plugged by its owner.
struct CountingBrain final : RobotBrain {
  int skill_cycles = 0;
  void on_skill_cycle(lua::RobotApi&) override { ++skill_cycles; }
};

}  // namespace

TEST_CASE("GameDriver: owns and plugs brains, starts the refbox, stops when the hook asks") {
  GameDriver driver(test::small_game(2, 3));
  Game& game = driver.game();
  CHECK(game.robot(0).brain() == nullptr);  // no brain until one is plugged
  SkillBrain& skills = driver.plug_skills(0);
  CHECK(game.robot(0).brain() == &skills);
  CHECK(driver.skills(0) == &skills);
  CHECK(driver.agent(0) == nullptr);
  AgentBrain& agent = driver.plug_agent(0, llsf2013_agent());  // replaces the skill engine
  CHECK(game.robot(0).brain() == &agent);
  CHECK(driver.skills(0) == nullptr);
  CHECK(driver.agent(0) == &agent);
  CountingBrain mine;
  driver.plug(1, &mine);
  CHECK(game.robot(1).brain() == &mine);
  CHECK_THROWS(driver.plug_skills(2));  // two robots only

  driver.start(refbox::GamePhase::kExploration);
  int ticks = 0;
  const bool stopped = driver.run_until(core::SimTime::from_sec(10), [&](const Game& g) {
    ++ticks;
    return g.time() >= core::SimTime::from_sec(2);
  });
  CHECK(stopped);
  CHECK(game.time() == core::SimTime::from_sec(2));
  CHECK(ticks == game.ticks());
  CHECK(game.refbox().phase() == refbox::GamePhase::kExploration);
  CHECK(mine.skill_cycles == 60);  // 30 Hz
  CHECK_FALSE(driver.run_until(core::SimTime::from_sec(3)));
  CHECK(game.time() == core::SimTime::from_sec(3));
  driver.plug(1, nullptr);
}

TEST_CASE("GameDriver: no start leaves the refbox in PRE_GAME; same config, same game") {
  auto play = [](std::optional<refbox::GamePhase> phase) {
    GameDriver driver(test::small_game(1, 5));
    driver.plug_agent(0, llsf2013_agent());
    driver.start(phase);
    driver.run_until(core::SimTime::from_sec(20));
    return driver.game().summary();
  };
  const GameSummary none = play(std::nullopt);
  CHECK(none.phase == refbox::GamePhase::kPreGame);
  const GameSummary a = play(refbox::GamePhase::kExploration);
  const GameSummary b = play(refbox::GamePhase::kExploration);
  CHECK(a.phase == refbox::GamePhase::kExploration);
  CHECK(a.world_hash == b.world_hash);
  CHECK(a.refbox_hash == b.refbox_hash);
  CHECK(a.world_hash != none.world_hash);
}

TEST_CASE("prepare_game_config: the config the game plays; the hackathon layout drawn before it") {
  GameConfig c = test::small_game(1, 11);
  set_hackathon(c, HackathonConfig{});
  const GameConfig prepared = prepare_game_config(c);
  CHECK(prepared.world.obstacles.size() == c.world.obstacles.size() + 4);
  CHECK(prepared.planner.places.extra.size() == c.planner.places.extra.size() + 1);
  // The game plays the prepared config and never changes it; its extension keeps the layout
  // that was put into the world.
  Game game(c);
  CHECK(game.config().world.obstacles.size() == prepared.world.obstacles.size());
  CHECK(game.config().planner.places.extra.size() == prepared.planner.places.extra.size());
  const HackathonExtension* h = hackathon_of(game);
  REQUIRE(h != nullptr);
  REQUIRE(h->layout().pucks.size() == prepared.world.pucks.size());
  for (std::size_t i = 0; i < h->layout().pucks.size(); ++i) {
    CHECK(h->layout().pucks[i].id.value() == prepared.world.pucks[i].id);
    CHECK(h->layout().pucks[i].position.x() == prepared.world.pucks[i].position.x());
  }
  // Without the variant nothing is added and the game has no extension.
  const GameConfig plain = prepare_game_config(test::small_game(1, 11));
  CHECK(plain.world.obstacles.size() == test::small_game(1, 11).world.obstacles.size());
  const Game plain_game(test::small_game(1, 11));
  CHECK(hackathon_of(plain_game) == nullptr);
  CHECK(plain_game.extension_count() == 0);
}

TEST_CASE("the radio's game side: robots by hub peer, inbox filled and cleared by the game") {
  Game game(test::small_game(3, 2));
  for (int i = 0; i < 3; ++i) {
    CHECK(game.robot_of(game.robot_peer(i)) == i);
    CHECK(game.robot(i).radio().peer() == game.robot_peer(i));
  }
  CHECK(game.robot_of(game.refbox_peer()) == -1);
  CHECK(game.robot_of(comm::PeerId()) == -1);

  RobotRadio radio;
  Received r;
  r.message = std::make_unique<llsf_agent_msgs::LockMessage>();
  r.from = "robot2";
  r.from_id = 2;
  radio.deliver(std::move(r));
  REQUIRE(radio.inbox().size() == 1);
  CHECK(radio.inbox()[0].from_id == 2);
  radio.clear_inbox();
  CHECK(radio.inbox().empty());
}

TEST_CASE("AgentBrain::reload_if_changed: changed CLIPS files restart the agent; bad ones do not") {
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("llsf-reload-" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  const auto write = [&](const std::string& text) {
    std::ofstream(dir / "agent.clp") << text;
    // A new modification time even on coarse file systems.
    std::filesystem::last_write_time(dir / "agent.clp",
                                     std::filesystem::last_write_time(dir / "agent.clp") +
                                         std::chrono::seconds(reload_writes++));
  };
  write("(defrule first (time $?) (not (v1)) => (assert (v1)))\n");
  GameDriver driver(test::small_game(1, 3));
  AgentBrainConfig c;
  c.agent_files = {dir.string()};
  std::vector<std::string> errors;
  AgentBrain& brain = driver.plug_agent(0, c, [&](const clips::LogRecord& r) {
    if (r.level == clips::LogLevel::kError) errors.emplace_back(r.text);
  });
  driver.start(refbox::GamePhase::kExploration);
  driver.run_until(core::SimTime::from_sec(1));
  CHECK(brain.agent().facts("v1").size() == 1);
  CHECK_FALSE(brain.reload_if_changed().changed);  // nothing changed

  write("(defrule second (time $?) (not (v2)) => (assert (v2)) (eval \"(no-such-fn)\"))\n");
  AgentBrain::Reload r = brain.reload_if_changed();
  CHECK(r.changed);
  CHECK(r.reloaded);
  CHECK(r.text.find("agent reloaded (") == 0);
  CHECK(r.text.find("agent.clp changed") != std::string::npos);
  driver.run_until(core::SimTime::from_sec(2));
  CHECK(brain.agent().facts("v1").empty());  // restarted: the old facts are gone
  CHECK(brain.agent().facts("v2").size() == 1);
  const int errors_after_second = brain.runtime_errors();
  CHECK(errors_after_second == 1);

  // A broken file: reported with file:line once, and the running agent goes on.
  write("(defrule broken (time $?) => (assert (v3))\n");
  r = brain.reload_if_changed();
  CHECK(r.changed);
  CHECK_FALSE(r.reloaded);
  CHECK(r.text.find("agent not reloaded") == 0);
  CHECK(r.text.find("agent.clp:") != std::string::npos);
  CHECK_FALSE(brain.reload_if_changed().changed);
  driver.run_until(core::SimTime::from_sec(3));
  CHECK(brain.agent().facts("v2").size() == 1);

  // Fixed again: reloaded; the runtime errors of the earlier agents still count.
  write("(defrule third (time $?) (not (v3)) => (assert (v3)) (eval \"(no-such-fn)\"))\n");
  CHECK(brain.reload_if_changed().reloaded);
  driver.run_until(core::SimTime::from_sec(4));
  CHECK(brain.agent().facts("v3").size() == 1);
  CHECK(brain.runtime_errors() == errors_after_second + 1);
  std::filesystem::remove_all(dir);
}
