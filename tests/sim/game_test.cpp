// SPDX-License-Identifier: MIT
// Whole games through the game loop: a robot producing an S1 through its RobotApi only, the
// refbox's lights on the world's devices, referee actions, beacons over the radio, determinism.
#include <doctest/doctest.h>

#include <llsf_agent_msgs/LockMessage.pb.h>
#include <llsf_msgs/BeaconSignal.pb.h>

#include <algorithm>
#include <cmath>
#include <optional>
#include <vector>

#include "fixture.h"
#include "llsf/sim/game.h"

using namespace llsf;
using namespace llsf::sim;
using test::StepBrain;

namespace {

kinematic::SignalLights to_world(const refbox::Lights& l) {
  auto lamp = [](refbox::LightState s) { return static_cast<kinematic::LampState>(s); };
  return {lamp(l.red), lamp(l.yellow), lamp(l.green)};
}

/// A tick hook that checks that every device of the world shows the refbox's lamps.
struct LightsMirror {
  int ticks = 0;
  int mismatches = 0;
  void operator()(const Game& g) {
    ++ticks;
    for (int i = 0; i < kinematic::kDeviceCount; ++i) {
      const core::DeviceId d(i);
      if (!(g.world().lights(d) == to_world(g.refbox().machine(d).lights))) ++mismatches;
    }
  }
};

bool run_until(Game& g, double max_s, const std::function<bool()>& done) {
  const SimTime end = g.time() + SimTime::from_seconds(max_s);
  while (g.time() < end) {
    g.step();
    if (done()) return true;
  }
  return false;
}

constexpr double kHeldPuckOffset = 0.2225;  // robot centre to a held puck's centre

/// One robot, through its RobotApi only: storage -> an S0 -> a T1's input place; the refbox
/// makes it an S1 and the world's lamps of the machine show processing, then the output.
void produce_s1(std::uint64_t seed) {
  CAPTURE(seed);
  GameConfig config = test::small_game(1, seed);
  Game g(config);
  test::start_phase(g, refbox::GamePhase::kProduction);
  g.step();
  REQUIRE(g.refbox().phase() == refbox::GamePhase::kProduction);
  REQUIRE(g.refbox().state() == refbox::GameState::kRunning);
  const std::optional<int> t1 = test::machine_of_type(g.refbox(), refbox::MachineType::kT1, 120);
  REQUIRE(t1.has_value());
  const std::string machine(kinematic::device_name(core::DeviceId(*t1)));

  bool held_after_pickup = false;
  std::string light_device;
  StepBrain brain({
      // Look at the storage from 0.95 m.
      [](lua::RobotApi& r) {
        r.goto_pose({0.95, 2.85, core::kPi}, false);
        return true;
      },
      [](lua::RobotApi& r) { return r.navigator().status != lua::NavStatus::kRunning; },
      // Pick the puck straight ahead in the front column (puck detection, robot frame) and
      // drive onto it, holder first.
      [](lua::RobotApi& r) {
        REQUIRE(r.navigator().status == lua::NavStatus::kArrived);
        const auto seen = r.pucks();
        const lua::PuckSighting* best = nullptr;
        for (const auto& s : seen) {
          if (std::abs(s.position.y()) > 0.05 || s.position.x() <= 0.0) continue;
          if (best == nullptr || s.position.x() < best->position.x()) best = &s;
        }
        REQUIRE(best != nullptr);
        const core::Pose2D me = r.pose().pose;
        const core::Vec2 puck = me.to_parent(best->position);
        const core::Vec2 stand = puck - kHeldPuckOffset * core::unit(me.theta);
        r.goto_pose({stand.x(), stand.y(), me.theta}, true);
        return true;
      },
      [](lua::RobotApi& r) { return r.navigator().status != lua::NavStatus::kRunning; },
      // The navigator stops within its tolerance; creep on until the IR sensor reads the puck
      // at the body (the holder keeps it from there), at most 4 cm.
      [creep_from = std::optional<core::Vec2>()](lua::RobotApi& r) mutable {
        if (!creep_from) creep_from = r.pose().pose.position();
        if (r.ir_distance_m() > 0.005 && (r.pose().pose.position() - *creep_from).norm() < 0.04) {
          r.set_velocity(0.05, 0.0, 0.0);
          return false;
        }
        r.stop();
        return true;
      },
      [&](lua::RobotApi& r) {
        held_after_pickup = r.puck_in_holder();
        r.goto_place(machine, true);  // the bare name is the input place
        return true;
      },
      [](lua::RobotApi& r) { return r.navigator().status != lua::NavStatus::kRunning; },
      [&](lua::RobotApi& r) {
        CHECK(r.navigator().status == lua::NavStatus::kArrived);
        light_device = r.light().device;
        return true;
      },
  });
  g.set_brain(0, &brain);

  // Record the lamps of the machine as the world shows them.
  std::vector<kinematic::SignalLights> seen;
  LightsMirror mirror;
  g.set_tick_hook([&](const Game& game) {
    mirror(game);
    const kinematic::SignalLights l = game.world().lights(core::DeviceId(*t1));
    if (seen.empty() || !(seen.back() == l)) seen.push_back(l);
  });

  REQUIRE(run_until(g, 90.0, [&] { return brain.done(); }));
  CHECK(held_after_pickup);
  CHECK(light_device == machine);
  const core::PuckId puck = g.refbox().machine(core::DeviceId(*t1)).puck_under_rfid;
  REQUIRE(puck.valid());
  // T1 processing takes 3..8 s.
  REQUIRE(run_until(g, 12.0, [&] {
    return g.refbox().puck_state(puck) == refbox::PuckState::kS1 &&
           g.world().lights(core::DeviceId(*t1)).yellow == kinematic::LampState::kOff;
  }));
  using LS = kinematic::LampState;
  const kinematic::SignalLights processing{LS::kOff, LS::kOn, LS::kOn};
  const kinematic::SignalLights ready{LS::kOff, LS::kOff, LS::kOn};
  const auto p = std::find(seen.begin(), seen.end(), processing);
  REQUIRE(p != seen.end());
  CHECK(std::find(p, seen.end(), ready) != seen.end());
  CHECK(g.world().lights(core::DeviceId(*t1)) == ready);
  CHECK(mirror.mismatches == 0);
  // Every refbox message fitted into a 2013 frame (MachineInfo, OrderInfo, ...).
  CHECK(g.hub().peer_counters(g.refbox_peer()).malformed_total() == 0);
  CHECK(g.hub().peer_counters(g.refbox_peer()).broadcasts > 50);
  CHECK(g.summary().collisions_robot_device == 0);
  CHECK(g.summary().collisions_robot_wall == 0);
}

/// The referee's hand: puck 16 under the T5's reader becomes a P3 (20..40 s, plus a down time),
/// then lies in the active gate's zone. Returns the gate.
core::DeviceId deliver_p3(Game& g, const GameConfig& config, core::PuckId puck) {
  test::start_phase(g, refbox::GamePhase::kProduction);
  g.step();
  const auto& params = *g.refbox().params();
  int t5 = -1;
  for (int i = 0; i < refbox::kProductionMachineCount; ++i) {
    if (params.machine_types[static_cast<std::size_t>(i)] == refbox::MachineType::kT5) t5 = i;
  }
  REQUIRE(t5 >= 0);
  g.world().teleport_puck(puck, config.world.devices[static_cast<std::size_t>(t5)].rfid_center());
  REQUIRE(
      run_until(g, 200.0, [&] { return g.refbox().puck_state(puck) == refbox::PuckState::kP3; }));
  const std::optional<core::DeviceId> gate = g.refbox().active_gate();
  REQUIRE(gate.has_value());
  g.world().teleport_puck(
      puck, config.world.devices[static_cast<std::size_t>(gate->value())].rfid_center());
  return *gate;
}

}  // namespace

TEST_CASE("a robot takes an S0 from the storage to a T1 through its RobotApi; it becomes S1") {
  // Four seeds: four plans, with the T1 at M1, M3, M2 and M1 (different routes).
  for (const std::uint64_t seed : {7, 8, 9, 10}) produce_s1(seed);
}

TEST_CASE("the refbox's lamps are on the world's devices in every phase") {
  GameConfig config = test::small_game(1);
  config.refbox.team = "Carologistics";
  Game g(config);
  LightsMirror mirror;
  g.set_tick_hook([&](const Game& game) { mirror(game); });
  g.run_until(SimTime::from_sec(1));
  // PRE_GAME: everything lit.
  CHECK(g.world().lights(core::DeviceId(3)) == kinematic::SignalLights{kinematic::LampState::kOn,
                                                                       kinematic::LampState::kOn,
                                                                       kinematic::LampState::kOn});
  llsf_msgs::SetGameState run;
  run.set_state(llsf_msgs::GameState::RUNNING);
  REQUIRE(g.controller_command(run).status == refbox::ReceiveStatus::kAccepted);
  g.run_until(SimTime::from_ms(3500));
  REQUIRE(g.refbox().phase() == refbox::GamePhase::kSetup);
  // SETUP: the dark spot, exactly one production machine dark.
  int dark = 0;
  for (int i = 0; i < refbox::kProductionMachineCount; ++i) {
    dark += g.world().lights(core::DeviceId(i)) == kinematic::SignalLights{} ? 1 : 0;
  }
  CHECK(dark == 1);
  for (const auto phase : {refbox::GamePhase::kExploration, refbox::GamePhase::kProduction,
                           refbox::GamePhase::kPostGame}) {
    test::start_phase(g, phase);
    g.run_until(g.time() + SimTime::from_sec(2));
    CHECK(g.refbox().phase() == phase);
  }
  // POST_GAME: red blinking everywhere.
  CHECK(g.world().lights(core::DeviceId(0)).red == kinematic::LampState::kBlink);
  CHECK(mirror.ticks == g.ticks());
  CHECK(mirror.mismatches == 0);
}

TEST_CASE("referee_remove_delay: a delivered puck lies at the gate, all lamps on, until then") {
  GameConfig config = test::small_game(1, 5);
  config.referee_remove_delay = SimTime::from_sec(4);
  Game g(config);
  const core::PuckId puck(16);
  const core::DeviceId gate = deliver_p3(g, config, puck);
  REQUIRE(run_until(g, 10.0,
                    [&] { return g.refbox().puck_state(puck) == refbox::PuckState::kFinished; }));
  const SimTime finished = g.time();
  // Still there, the gate's three lamps on, until the referee comes.
  REQUIRE(run_until(g, 3.5, [&] { return false; }) == false);
  CHECK(g.world().has_puck(puck));
  const kinematic::SignalLights l = g.world().lights(gate);
  CHECK(l.red == kinematic::LampState::kOn);
  CHECK(l.yellow == kinematic::LampState::kOn);
  CHECK(l.green == kinematic::LampState::kOn);
  REQUIRE(run_until(g, 1.0, [&] { return !g.world().has_puck(puck); }));
  CHECK(g.time() - finished >= SimTime::from_sec(4));
  CHECK(g.time() - finished <= SimTime::from_ms(4020));
}

TEST_CASE("referee actions: a delivered puck leaves the world, late-order pucks arrive") {
  GameConfig config = test::small_game(1, 5);
  Game g(config);
  // ... delivered at the active gate, and the refbox has it taken away.
  const core::PuckId puck(16);
  deliver_p3(g, config, puck);
  REQUIRE(run_until(g, 10.0, [&] { return !g.world().has_puck(puck); }));
  CHECK(g.refbox().puck_state(puck) == refbox::PuckState::kFinished);

  // Late orders: the first S0 goes to the free insertion slot, the second (slot occupied by the
  // first) into the input storage.
  auto count = [&g] {
    return std::count_if(g.world().pucks().begin(), g.world().pucks().end(),
                         [&g](core::PuckId q) { return g.world().has_puck(q); });
  };
  const auto n0 = count();
  REQUIRE(run_until(g, 500.0, [&] { return count() > n0; }));
  const core::PuckId first = g.world().pucks().back();
  CHECK(first.value() == 21);
  CHECK((g.world().puck_position(first) - config.world.field.late_order_slot).norm() < 0.01);
  REQUIRE(run_until(g, 500.0, [&] { return count() > n0 + 1; }));
  const core::PuckId second = g.world().pucks().back();
  CHECK(second.value() == 22);
  const core::Vec2 p = g.world().puck_position(second);
  CHECK(config.world.field.input_storage.contains(p));
  for (const core::PuckId q : g.world().pucks()) {
    if (q != second && g.world().has_puck(q)) {
      CHECK((g.world().puck_position(q) - p).norm() >= 2 * config.world.puck.radius_m);
    }
  }
  CHECK(g.refbox().puck_state(first) == refbox::PuckState::kS0);
  CHECK(g.refbox().puck_state(second) == refbox::PuckState::kS0);
}

TEST_CASE("beacons reach the refbox through the hub; skills and agents run at their rates") {
  GameConfig config = test::small_game(3);
  Game g(config);
  std::vector<StepBrain> brains(3, StepBrain({}));
  for (int i = 0; i < 3; ++i) g.set_brain(i, &brains[static_cast<std::size_t>(i)]);
  g.run_until(SimTime::from_ms(3500));
  const auto& robots = g.refbox().robots();
  REQUIRE(robots.size() == 3);
  for (int i = 0; i < 3; ++i) {
    const auto it = std::find_if(robots.begin(), robots.end(),
                                 [&](const refbox::Robot& r) { return r.number == i + 1; });
    REQUIRE(it != robots.end());
    CHECK(it->name == "robot" + std::to_string(i + 1));
    REQUIRE(it->pose.has_value());
    CHECK(it->pose->distance_to(g.world().robot_pose(core::RobotId(i))) < 1e-4);
    const auto& link = g.hub().link_counters(g.robot_peer(i), g.refbox_peer());
    CHECK(link.delivered >= 3);
  }
  CHECK(g.summary().refbox_accepted >= 9);
  CHECK(g.summary().refbox_rejected == 0);
  for (const StepBrain& b : brains) {
    CHECK(b.skill_cycles == doctest::Approx(3.5 * 30).epsilon(0.02));
    CHECK(b.agent_cycles == 35);
    CHECK(b.messages > 3);  // the refbox's beacons and GameStates, the others' beacons
  }
}

TEST_CASE("with 100 % loss nothing reaches the refbox or the robots") {
  GameConfig config = test::small_game(3);
  config.hub.loss_model = comm::LossModel::kGlobal;
  config.hub.loss_probability = 1.0;
  Game g(config);
  std::vector<StepBrain> brains(3, StepBrain({}));
  for (int i = 0; i < 3; ++i) g.set_brain(i, &brains[static_cast<std::size_t>(i)]);
  g.run_until(SimTime::from_sec(4));
  CHECK(g.refbox().robots().empty());
  const GameSummary s = g.summary();
  CHECK(s.refbox_accepted == 0);
  CHECK(s.comm.sent > 0);
  CHECK(s.comm.delivered == 0);
  CHECK(s.comm.dropped_by(comm::DropCause::kLoss) == s.comm.sent);
  for (const StepBrain& b : brains) CHECK(b.messages == 0);
}

TEST_CASE("noisy localization differs from the truth but stays bounded") {
  GameConfig config = test::small_game(1, 21);
  config.levels.localization.level = LocalizationLevel::kNoisy;
  Game g(config);
  StepBrain brain(
      {test::go("M2_look"), test::go("M7_look"), test::go("D2_look"), test::go("INS_3")});
  g.set_brain(0, &brain);
  double max_err = 0.0;
  double sum_err = 0.0;
  double max_heading = 0.0;
  int n = 0;
  g.set_tick_hook([&](const Game& game) {
    const core::Pose2D est = game.robot(0).pose().pose;
    const core::Pose2D truth = game.world().robot_pose(core::RobotId(0));
    const double e = est.distance_to(truth);
    max_err = std::max(max_err, e);
    max_heading = std::max(max_heading, std::abs(core::angle_diff(est.theta, truth.theta)));
    sum_err += e;
    ++n;
  });
  REQUIRE(run_until(g, 120.0, [&] { return brain.done(); }));
  const double mean = sum_err / n;
  INFO("mean ", mean, " max ", max_err, " heading ", max_heading);
  CHECK(mean > 0.005);
  CHECK(max_err < 0.15);
  CHECK(max_heading < 0.15);
}

TEST_CASE("a robot driven into a wall: the collision is counted") {
  Game g(test::small_game(1));
  g.robot(0).set_velocity(0.0, -0.4, 0.0);  // robot1 starts 0.215 m from the bottom wall
  g.run_until(SimTime::from_sec(2));
  CHECK(g.summary().collisions_robot_wall >= 1);
  g.robot(0).stop();
  CHECK(g.robot(0).navigator().status == lua::NavStatus::kIdle);
}

TEST_CASE("same seed, same game: refbox report, world hash and radio counters") {
  auto play = [](std::uint64_t seed) {
    GameConfig config = test::small_game(3, seed);
    config.levels.localization.level = LocalizationLevel::kNoisy;
    config.levels.light.level = DetectionLevel::kVision;
    config.levels.puck.level = DetectionLevel::kVision;
    config.hub.loss_model = comm::LossModel::kPerLink;
    config.hub.loss_probability = 0.2;
    auto g = std::make_unique<Game>(config);
    test::start_phase(*g, refbox::GamePhase::kProduction);
    std::vector<StepBrain> brains;
    brains.emplace_back(std::vector<StepBrain::Step>{test::go("M3_look", false, false),
                                                     test::go("D1_look", false, false)});
    brains.emplace_back(std::vector<StepBrain::Step>{test::go("M8_look", false, false),
                                                     test::go("R1_look", false, false)});
    brains.emplace_back(std::vector<StepBrain::Step>{test::go("M5_look", false, false),
                                                     test::go("TST_look", false, false)});
    for (int i = 0; i < 3; ++i) g->set_brain(i, &brains[static_cast<std::size_t>(i)]);
    g->run_until(SimTime::from_sec(25));
    for (int i = 0; i < 3; ++i) g->set_brain(i, nullptr);
    struct Out {
      GameSummary s;
      std::string report;
    };
    return Out{g->summary(), refbox::to_json(g->refbox().report())};
  };
  const auto a = play(99);
  const auto b = play(99);
  const auto c = play(100);
  CHECK(a.s.world_hash == b.s.world_hash);
  CHECK(a.s.refbox_hash == b.s.refbox_hash);
  CHECK(a.report == b.report);
  CHECK(a.s.comm.delivered == b.s.comm.delivered);
  CHECK(a.s.comm.dropped_total() == b.s.comm.dropped_total());
  CHECK(a.s.ticks == 2500);
  CHECK(a.s.world_hash != c.s.world_hash);
}

TEST_CASE("bad configs are refused before anything is built") {
  GameConfig config = test::small_game(1);
  config.hub.links.push_back({"robot9", "refbox"});
  CHECK_THROWS_AS(Game{config}, core::ConfigError);
  config = test::small_game(1);
  config.levels.puck.merge_distance_m = -1.0;
  CHECK_THROWS_WITH_AS(Game{config}, doctest::Contains("game.levels.puck.merge_distance_m"),
                       core::ConfigError);
}

namespace {

/// An agent that sends one LockMessage per agent cycle and counts those it receives.
class LockAgent : public sim::RobotBrain {
 public:
  void on_agent_cycle(lua::RobotApi& robot, RobotRadio& radio) override {
    for (const auto& m : radio.inbox()) {
      if (dynamic_cast<const llsf_agent_msgs::LockMessage*>(m.get()) != nullptr) {
        ++locks_received;
        CHECK(m.from != std::string(robot.name()));
        CHECK((m.from == "refbox" || m.from_id > 0));
      }
    }
    llsf_agent_msgs::LockMessage lock;
    lock.set_type(llsf_agent_msgs::LockMessage::GET);
    lock.set_agent(std::string(robot.name()));
    lock.set_resource("M1");
    CHECK(radio.broadcast(lock) == comm::FrameError::kNone);
    ++locks_sent;
  }
  int locks_sent = 0;
  int locks_received = 0;
};

}  // namespace

TEST_CASE("agents talk over the radio; the refbox ignores their messages") {
  // Also under the 2013 numbering (radio `lock_messages: 2013`), where the lock messages share
  // the refbox's component 2000 on the wire.
  GameConfig config = test::small_game(2);
  SUBCASE("llsfsim numbering") { config.hub.lock_messages = comm::LockNumbering::kLlsfsim; }
  SUBCASE("2013 numbering") { config.hub.lock_messages = comm::LockNumbering::k2013; }
  Game g(config);
  CHECK(g.registry().key_of(llsf_agent_msgs::LockMessage::default_instance())->component_id ==
        (config.hub.lock_messages == comm::LockNumbering::k2013 ? comm::kRefboxComponentId
                                                                : comm::kAgentComponentId));
  LockAgent a;
  LockAgent b;
  g.set_brain(0, &a);
  g.set_brain(1, &b);
  g.run_until(SimTime::from_sec(2));
  CHECK(a.locks_sent == 20);
  // Each hears the other's (2 ms delay: all but the last cycle's arrive before its next cycle).
  CHECK(a.locks_received == 19);
  CHECK(b.locks_received == 19);
  const GameSummary s = g.summary();
  CHECK(s.refbox_rejected == 0);
  CHECK(g.refbox().robots().size() == 2);
}

TEST_CASE("RobotApi navigator: unknown places, goal ids, motor commands abort a navigation") {
  Game g(test::small_game(1));
  RobotStack& r = g.robot(0);
  CHECK(r.name() == "robot1");
  CHECK(r.navigator().status == lua::NavStatus::kIdle);
  r.goto_place("NOWHERE", false);
  g.step();
  lua::NavState s = r.navigator();
  CHECK(s.status == lua::NavStatus::kInvalidGoal);
  CHECK(s.error.find("NOWHERE") != std::string::npos);
  CHECK(s.goal_id == 1);
  r.goto_place("M8_look", false);
  g.run_until(SimTime::from_sec(1));
  CHECK(r.navigator().status == lua::NavStatus::kRunning);
  CHECK(r.navigator().goal_id == 2);
  const core::Pose2D before = g.world().robot_pose(core::RobotId(0));
  r.set_velocity(0.0, 0.0, 1.0);  // turn on the spot
  CHECK(r.navigator().status == lua::NavStatus::kAborted);
  g.run_until(SimTime::from_sec(3));
  const core::Pose2D after = g.world().robot_pose(core::RobotId(0));
  CHECK(std::abs(core::angle_diff(after.theta, before.theta)) > 0.5);
  CHECK(r.pose().valid);
  CHECK(r.now() == g.time());
}
