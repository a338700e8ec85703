// SPDX-License-Identifier: MIT
// Master/slave synchronisation and overtime (spec §8, §10): RefBoxMode, the slave taking the
// master's plan, the 1200 s gate schedule of synchronised games, the pause at the regular end
// and overtime only on equal non-zero points.
#include <doctest/doctest.h>

#include "fixture.h"
#include "llsf/core/error.h"

using namespace llsf;
using namespace llsf::refbox;
using namespace llsf::refbox::test;

namespace {

RefboxConfig mode_config(RefBoxMode mode, bool drawn) {
  RefboxConfig c = test_config();
  c.mode = mode;
  if (drawn) {
    c.params.reset();
  } else if (c.synchronised()) {
    c.params = test_params_synchronised();
  }
  return c;
}

/// Plays EXPLORATION with one correct report (+4 when `score`), then PRODUCTION up to its
/// regular end (step 1 s for speed, then 10 ms around the end).
void play_to_regular_end(Game& g, bool score) {
  g.command(command::SetGamePhase{GamePhase::kExploration});
  g.command(command::SetGameState{GameState::kRunning});
  g.step();
  if (score) g.report({{{"M1", "T1"}}});
  while (g.rb.phase() == GamePhase::kExploration) g.step(SimTime::from_sec(1));
  while (g.rb.game_time() < SimTime::from_sec(890)) g.step(SimTime::from_sec(1));
  while (g.rb.state() == GameState::kRunning) g.step();
}

/// Checks the structure of a drawn gate schedule ending at `end_s`.
void check_schedule(const GameParams& p, int end_s) {
  REQUIRE_FALSE(p.gate_schedule.empty());
  int t = 0;
  for (std::size_t i = 0; i < p.gate_schedule.size(); ++i) {
    const GatePeriod& g = p.gate_schedule[i];
    CHECK(g.start_s == t);
    CHECK(is_gate(g.gate));
    if (i > 0) CHECK(g.gate != p.gate_schedule[i - 1].gate);
    const int len = g.end_s - g.start_s;
    CHECK(len >= 60);
    if (g.end_s != end_s) CHECK(len <= 180);
    t = g.end_s;
  }
  CHECK(t == end_s);
}

}  // namespace

TEST_CASE("RefBoxMode: protocol numbers, names, config default and YAML") {
  CHECK(static_cast<int>(RefBoxMode::kStandalone) == 0);
  CHECK(static_cast<int>(RefBoxMode::kMaster) == 1);
  CHECK(static_cast<int>(RefBoxMode::kSlave) == 2);
  CHECK(to_string(RefBoxMode::kSlave) == "SLAVE");
  CHECK(refbox_mode_from_string("MASTER") == RefBoxMode::kMaster);
  CHECK_FALSE(refbox_mode_from_string("master?").has_value());
  RefboxConfig c;
  CHECK(c.mode == RefBoxMode::kStandalone);
  CHECK_FALSE(c.synchronised());
  CHECK(c.overtime_duration == SimTime::from_sec(300));
  Game g(c);
  CHECK(g.rb.mode() == RefBoxMode::kStandalone);

  const RefboxConfig y =
      load_refbox_config(core::ConfigNode::parse("mode: slave\novertime_s: 120\n", "t.yaml"));
  CHECK(y.mode == RefBoxMode::kSlave);
  CHECK(y.synchronised());
  CHECK(y.overtime_duration == SimTime::from_sec(120));
  CHECK_THROWS_WITH_AS(load_refbox_config(core::ConfigNode::parse("mode: boss\n", "t.yaml")),
                       doctest::Contains("mode"), core::ConfigError);
  CHECK_THROWS_WITH_AS(load_refbox_config(core::ConfigNode::parse("overtime_s: 301\n", "t.yaml")),
                       doctest::Contains("overtime_s"), core::ConfigError);
  // A synchronised config's explicit plan must cover 1200 s.
  RefboxConfig m = test_config();
  m.mode = RefBoxMode::kMaster;
  CHECK_THROWS_WITH_AS(m.validate(), doctest::Contains("1200"), core::ConfigError);
  m.params = test_params_synchronised();
  CHECK_NOTHROW(m.validate());
}

TEST_CASE("gate schedule: 900 s standalone (unchanged draws), 1200 s in synchronised mode") {
  const RulesVariant v = make_rules_variant(kRulesRefbox061);
  for (std::uint64_t seed = 1; seed <= 100; ++seed) {
    core::RandomStream a = core::Rng(seed).stream("refbox");
    core::RandomStream b = core::Rng(seed).stream("refbox");
    core::RandomStream c = core::Rng(seed).stream("refbox");
    const GameParams standalone = draw_game_params(a, v);
    CHECK(standalone == draw_game_params(b, v, kPlanProductionS));
    check_schedule(standalone, 900);
    const GameParams sync = draw_game_params(c, v, kPlanSynchronisedS);
    check_schedule(sync, 1200);
    CHECK_NOTHROW(validate_game_params(sync, "p", kPlanSynchronisedS));
    // Everything but the gate schedule is the same plan; the schedule shares its first periods.
    GameParams x = sync;
    x.gate_schedule = standalone.gate_schedule;
    CHECK(x == standalone);
    for (std::size_t i = 0; i < standalone.gate_schedule.size(); ++i) {
      if (standalone.gate_schedule[i].end_s > 840) break;
      CHECK(sync.gate_schedule[i] == standalone.gate_schedule[i]);
    }
    if (seed <= 20) {
      CHECK_THROWS_WITH_AS(validate_game_params(standalone, "p", kPlanSynchronisedS),
                           doctest::Contains("1200"), core::ConfigError);
    }
  }
  // Games draw accordingly.
  for (RefBoxMode mode : {RefBoxMode::kStandalone, RefBoxMode::kMaster, RefBoxMode::kSlave}) {
    Game g(mode_config(mode, true), 3);
    g.command(command::SetGameState{GameState::kRunning});
    g.step();
    REQUIRE(g.rb.params().has_value());
    check_schedule(*g.rb.params(), mode == RefBoxMode::kStandalone ? 900 : 1200);
  }
}

TEST_CASE("slave: plays the master's plan, whatever its own seed") {
  for (std::uint64_t slave_seed : {std::uint64_t{1}, std::uint64_t{99}}) {
    Game master(mode_config(RefBoxMode::kMaster, true), 1);
    Game slave(mode_config(RefBoxMode::kSlave, true), slave_seed);
    CHECK(master.rb.mode() == RefBoxMode::kMaster);
    CHECK(slave.rb.mode() == RefBoxMode::kSlave);
    const GameParams sent = master.rb.sync_params();  // SyncInfo content
    const SyncResult r = slave.rb.sync_from(sent);
    CHECK(r.ok());
    CHECK(r.status == SyncResult::Status::kApplied);
    // Both start; both play the same plan.
    for (Game* g : {&master, &slave}) {
      g->command(command::SetGameState{GameState::kRunning});
      g->step();
      REQUIRE(g->rb.params().has_value());
    }
    CHECK(*master.rb.params() == sent);
    CHECK(*slave.rb.params() == sent);
    check_schedule(sent, 1200);
    // The master's early sync_params() is the plan it would have drawn anyway.
    Game unsynced(mode_config(RefBoxMode::kMaster, true), 1);
    unsynced.command(command::SetGameState{GameState::kRunning});
    unsynced.step();
    CHECK(*unsynced.rb.params() == sent);
    // The same machine types, orders, light codes in play.
    for (Game* g : {&master, &slave}) {
      g->command(command::SetGamePhase{GamePhase::kProduction});
      g->step();
    }
    for (int i = 0; i < kDeviceCount; ++i) {
      CHECK(master.rb.machine(DeviceId(i)).type == slave.rb.machine(DeviceId(i)).type);
    }
    REQUIRE(master.rb.orders().size() == slave.rb.orders().size());
    for (std::size_t i = 0; i < master.rb.orders().size(); ++i) {
      const Order& a = master.rb.orders()[i];
      const Order& b = slave.rb.orders()[i];
      CHECK(a.product == b.product);
      CHECK(a.quantity_requested == b.quantity_requested);
      CHECK(a.window_begin_s == b.window_begin_s);
      CHECK(a.window_end_s == b.window_end_s);
    }
    for (std::size_t t = 0; t < 5; ++t) {
      CHECK(master.rb.exploration_signals()[t].lights == slave.rb.exploration_signals()[t].lights);
    }
  }
}

TEST_CASE("sync_from: only a SLAVE, only before the plan is fixed, only a valid plan") {
  Game standalone(mode_config(RefBoxMode::kStandalone, true));
  CHECK(standalone.rb.sync_from(test_params()).status == SyncResult::Status::kNotSlave);
  Game master(mode_config(RefBoxMode::kMaster, true));
  CHECK(master.rb.sync_from(test_params_synchronised()).status == SyncResult::Status::kNotSlave);

  // A plan whose gate schedule ends at 900 s does not fit a synchronised game.
  Game slave(mode_config(RefBoxMode::kSlave, true), 5);
  const SyncResult bad = slave.rb.sync_from(test_params());
  CHECK(bad.status == SyncResult::Status::kInvalid);
  CHECK(bad.reason.find("gate_schedule") != std::string::npos);
  GameParams broken = test_params_synchronised();
  broken.proc_time_s[2] = 0;
  CHECK(slave.rb.sync_from(broken).status == SyncResult::Status::kInvalid);
  // A later valid plan replaces nothing yet fixed: it is taken.
  CHECK(slave.rb.sync_from(test_params_synchronised()).ok());
  slave.command(command::SetGameState{GameState::kRunning});
  slave.step();
  CHECK(*slave.rb.params() == test_params_synchronised());
  // Too late once the game left PRE_GAME.
  GameParams other = test_params_synchronised();
  other.proc_time_s[0] = 7;
  CHECK(slave.rb.sync_from(other).status == SyncResult::Status::kAlreadyParameterised);
  CHECK(*slave.rb.params() == test_params_synchronised());

  // A slave that starts without a master's plan draws its own and says so.
  Game lonely(mode_config(RefBoxMode::kSlave, true), 5);
  lonely.command(command::SetGameState{GameState::kRunning});
  lonely.step();
  CHECK(lonely.attention_contains("no plan from its master"));
  check_schedule(*lonely.rb.params(), 1200);
}

TEST_CASE("standalone: the game ends at 900 s whatever a peer reports") {
  Game g(mode_config(RefBoxMode::kStandalone, false));
  play_to_regular_end(g, true);
  CHECK(g.rb.phase() == GamePhase::kPostGame);
  CHECK(g.rb.game_time() == SimTime::from_sec(900));
  g.peer(GamePhase::kProduction, GameState::kPaused, 900, g.rb.points());
  g.step();
  CHECK(g.rb.phase() == GamePhase::kPostGame);
  CHECK_FALSE(g.rb.overtime());
}

TEST_CASE("synchronised: pause at 900 s, overtime on equal non-zero points, to 1200 s") {
  Game g(mode_config(RefBoxMode::kMaster, false));
  play_to_regular_end(g, true);
  CHECK(g.rb.points() == 4);
  CHECK(g.rb.phase() == GamePhase::kProduction);
  CHECK(g.rb.state() == GameState::kPaused);
  CHECK(g.rb.game_time() == SimTime::from_sec(900));
  CHECK(g.rb.awaiting_overtime_decision());
  CHECK(g.attention_contains("Waiting for the synchronised game to end"));

  // The controller cannot resume, time stands still.
  g.command(command::SetGameState{GameState::kRunning});
  g.run_s(5);
  CHECK(g.rb.state() == GameState::kPaused);
  CHECK(g.rb.game_time() == SimTime::from_sec(900));
  // The other field still plays its regular time: nothing happens.
  g.peer(GamePhase::kProduction, GameState::kRunning, 899.5, 4);
  g.step();
  CHECK(g.rb.awaiting_overtime_decision());
  g.peer(GamePhase::kProduction, GameState::kPaused, 400, 4);  // a pause mid-game
  g.step();
  CHECK(g.rb.awaiting_overtime_decision());

  // It pauses at its regular end with the same points: overtime.
  g.peer(GamePhase::kProduction, GameState::kPaused, 900, 4);
  g.step();
  CHECK(g.rb.overtime());
  CHECK_FALSE(g.rb.awaiting_overtime_decision());
  CHECK(g.rb.state() == GameState::kRunning);
  CHECK(g.rb.phase() == GamePhase::kProduction);
  CHECK(g.rb.phase_duration(GamePhase::kProduction) == SimTime::from_sec(1200));
  CHECK(g.attention_contains("Entering overtime"));

  // The gate schedule goes on in overtime.
  while (g.rb.game_time() < SimTime::from_sec(1000)) g.step(SimTime::from_sec(1));
  CHECK(g.rb.active_gate() == DeviceId(kD1));
  CHECK(g.rb.machine(DeviceId(kD1)).lights == L(kOff, kOff, kOn));
  CHECK(g.rb.machine(DeviceId(kD3)).lights == L(kOn, kOff, kOff));
  while (g.rb.phase() == GamePhase::kProduction) g.step();
  CHECK(g.rb.phase() == GamePhase::kPostGame);
  CHECK(g.rb.state() == GameState::kPaused);
  CHECK(g.rb.game_time() == SimTime::from_sec(1200));
  CHECK(g.now - SimTime::from_sec(1080) < SimTime::from_sec(310));
  const GameReport r = g.rb.report();
  CHECK(r.mode == RefBoxMode::kMaster);
  CHECK(r.overtime);
  CHECK(to_json(r).find("\"overtime\": true") != std::string::npos);
}

TEST_CASE("synchronised: no overtime on different or zero points") {
  SUBCASE("different points -> POST_GAME at 900 s") {
    Game g(mode_config(RefBoxMode::kSlave, false));
    play_to_regular_end(g, true);
    REQUIRE(g.rb.awaiting_overtime_decision());
    g.peer(GamePhase::kProduction, GameState::kPaused, 900, 5);
    g.step();
    CHECK_FALSE(g.rb.overtime());
    CHECK(g.rb.phase() == GamePhase::kPostGame);
    CHECK(g.rb.game_time() == SimTime::from_sec(900));
  }
  SUBCASE("both 0 points -> POST_GAME") {
    Game g(mode_config(RefBoxMode::kMaster, false));
    play_to_regular_end(g, false);
    REQUIRE(g.rb.points() == 0);
    REQUIRE(g.rb.awaiting_overtime_decision());
    g.peer(GamePhase::kProduction, GameState::kPaused, 900.04, 0);
    g.step();
    CHECK_FALSE(g.rb.overtime());
    CHECK(g.rb.phase() == GamePhase::kPostGame);
  }
  SUBCASE("the other field already went to POST_GAME with other points") {
    Game g(mode_config(RefBoxMode::kMaster, false));
    play_to_regular_end(g, true);
    g.peer(GamePhase::kPostGame, GameState::kPaused, 900, 12);
    g.step();
    CHECK(g.rb.phase() == GamePhase::kPostGame);
  }
  SUBCASE("the other field already plays overtime -> overtime here too") {
    Game g(mode_config(RefBoxMode::kMaster, false));
    play_to_regular_end(g, true);
    g.peer(GamePhase::kProduction, GameState::kRunning, 901, 6);
    g.step();
    CHECK(g.rb.overtime());
    CHECK(g.rb.state() == GameState::kRunning);
  }
}

TEST_CASE("synchronised: re-entering PRODUCTION clears the overtime") {
  Game g(mode_config(RefBoxMode::kMaster, false));
  play_to_regular_end(g, true);
  g.peer(GamePhase::kProduction, GameState::kPaused, 900, 4);
  g.step();
  REQUIRE(g.rb.overtime());
  g.command(command::SetGamePhase{GamePhase::kProduction});
  g.step();
  CHECK_FALSE(g.rb.overtime());
  CHECK(g.rb.game_time() == SimTime());
}
