// SPDX-License-Identifier: MIT
// `llsfsim run --refbox-sockets` (app/src/refbox_sockets.cpp): a game served on 127.0.0.1 to a
// TCP controller (comm::StreamClient) and a UDP peer (an external program's socket), the 2013
// time base on the wire (refbox::to_wire_time), and bad socket configs.
#include <doctest/doctest.h>
#include <llsf_log_msgs/LogMessage.pb.h>
#include <llsf_msgs/BeaconSignal.pb.h>
#include <llsf_msgs/GameState.pb.h>
#include <llsf_msgs/MachineInfo.pb.h>
#include <llsf_msgs/MachineReport.pb.h>
#include <llsf_msgs/OrderInfo.pb.h>
#include <llsf_msgs/RobotInfo.pb.h>
#include <llsf_msgs/VersionInfo.pb.h>

#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/write.hpp>
#include <chrono>
#include <cstdint>
#include <ctime>
#include <functional>
#include <limits>
#include <string>
#include <thread>
#include <vector>

#include "app/cli_fixture.h"
#include "comm/loopback.h"
#include "llsf/comm/stream.h"
#include "llsf/refbox/wire_time.h"
#include "llsf/sim/driver.h"
#include "llsf/study/runner.h"
#include "llsf/study/scenario.h"
#include "refbox_sockets.h"
#include "support/temp_dir.h"

namespace {

using llsf::test::has;
using llsf::test::llsfsim;
using llsf::test::Run;
using Clock = std::chrono::steady_clock;

/// A TCP port that was free a moment ago (bound to port 0, then released).
int free_tcp_port() {
  boost::asio::io_context io;
  boost::asio::ip::tcp::acceptor a(io, {llsf::comm::test::kLoopback, 0});
  return a.local_endpoint().port();
}

/// A UDP port that was free a moment ago.
int free_udp_port() {
  boost::asio::io_context io;
  boost::asio::ip::udp::socket s(io, {llsf::comm::test::kLoopback, 0});
  return s.local_endpoint().port();
}

std::int64_t unix_now_s() { return static_cast<std::int64_t>(std::time(nullptr)); }

/// True if `sec` is Unix time near now (a generous hour: the game runs ahead of the wall clock
/// at --speed, and a loaded machine may be slow).
bool near_now(std::int64_t sec) { return sec > unix_now_s() - 3600 && sec < unix_now_s() + 3600; }

llsf::comm::MessageRegistry refbox_registry() {
  llsf::comm::MessageRegistry r;
  llsf::sim::add_refbox_messages(r);
  llsf::comm::add_agent_messages(r);
  return r;
}

/// The game's thread: `llsfsim run ...`, joined on destruction (also when a check throws).
struct Served {
  explicit Served(std::vector<std::string> args)
      : thread([this, a = std::move(args)] { result = llsfsim(a); }) {}
  ~Served() {
    if (thread.joinable()) thread.join();
  }
  Served(const Served&) = delete;
  Served& operator=(const Served&) = delete;
  Run result;
  std::thread thread;
};

/// What the test's controller and UDP peer have seen so far.
struct Seen {
  std::vector<llsf_msgs::GameState> game_states;
  std::vector<llsf_msgs::RobotInfo> robot_infos;
  std::vector<llsf_msgs::OrderInfo> order_infos;
  int machine_infos = 0;
  int version_infos = 0;
  bool disconnected = false;
  std::vector<llsf_msgs::BeaconSignal> udp_beacons;  // what the UDP peer received
  int udp_game_states = 0;
};

}  // namespace

TEST_CASE("wire time: absolute times in Unix time, the game time phase-relative") {
  const llsf::refbox::WireClock clock{1'700'000'000'250'000'000};  // + 1.7e9 s + 0.25 s
  llsf_msgs::RobotInfo ri;
  llsf_msgs::Robot* r = ri.add_robots();
  r->set_name("R1");
  r->set_team("T");
  r->set_host("h");
  r->set_number(1);
  r->mutable_last_seen()->set_sec(12);
  r->mutable_last_seen()->set_nsec(900'000'000);
  r->mutable_pose()->mutable_timestamp()->set_sec(3);
  r->mutable_pose()->mutable_timestamp()->set_nsec(0);
  r->mutable_pose()->set_x(1);
  r->mutable_pose()->set_y(2);
  r->mutable_pose()->set_ori(0);
  llsf_msgs::RobotInfo wire = ri;
  llsf::refbox::to_wire_time(wire, clock);
  CHECK(wire.robots(0).last_seen().sec() == 1'700'000'013);  // 12.9 + 0.25: a carry
  CHECK(wire.robots(0).last_seen().nsec() == 150'000'000);
  CHECK(wire.robots(0).pose().timestamp().sec() == 1'700'000'003);
  CHECK(wire.robots(0).pose().timestamp().nsec() == 250'000'000);
  llsf::refbox::from_wire_time(wire, clock);
  CHECK(wire.SerializeAsString() == ri.SerializeAsString());

  llsf_msgs::GameState gs;
  gs.mutable_game_time()->set_sec(42);
  gs.mutable_game_time()->set_nsec(0);
  gs.set_state(llsf_msgs::GameState::RUNNING);
  gs.set_phase(llsf_msgs::GameState::EXPLORATION);
  llsf::refbox::to_wire_time(gs, clock);
  CHECK(gs.game_time().sec() == 42);

  llsf_log_msgs::LogMessage log;
  log.set_ts_sec(5);
  log.set_ts_nsec(0);
  log.set_log_level(llsf_log_msgs::LogMessage::LL_WARN);
  log.set_component("refbox");
  log.set_message("m");
  llsf::refbox::to_wire_time(log, clock);
  CHECK(log.ts_sec() == 1'700'000'005);
  CHECK(log.ts_nsec() == 250'000'000);

  // A peer's absurd clock saturates instead of overflowing.
  llsf_msgs::BeaconSignal b;
  b.mutable_time()->set_sec(std::numeric_limits<std::int64_t>::min() + 1);
  b.mutable_time()->set_nsec(0);
  llsf::refbox::from_wire_time(b, clock);
  CHECK(b.time().sec() == std::numeric_limits<std::int64_t>::min());
  CHECK(b.time().nsec() == 750'000'000);
}

TEST_CASE("run --refbox-sockets: bad socket configs are refused before the game") {
  const llsf::test::TempDir dir("llsf_app_sockets_bad");
  dir.write("s.yaml", "name: s\nduration_s: 5\nrobots: {count: 2}\n");
  const std::string scenario = dir.file("s.yaml");
  const std::vector<std::string> base = {"run", scenario, "--no-db", "--no-record"};
  auto run_with = [&](const std::string& yaml) {
    dir.write("sockets.yaml", yaml);
    std::vector<std::string> args = base;
    args.insert(args.end(), {"--refbox-sockets", dir.file("sockets.yaml"), "--speed", "1000"});
    return llsfsim(args);
  };
  SUBCASE("a missing file") {
    std::vector<std::string> args = base;
    args.insert(args.end(), {"--refbox-sockets", dir.file("nothing.yaml")});
    const Run r = llsfsim(args);
    CHECK(r.code == llsf::app::kExitBadInput);
    CHECK(has(r.err, "nothing.yaml"));
  }
  SUBCASE("argument order: the optional value takes what follows") {
    // Without a sockets file before the scenario: the scenario became the sockets file.
    const Run r = llsfsim({"run", "--refbox-sockets", scenario, "--no-db", "--no-record"});
    CHECK(r.code == llsf::app::kExitBadInput);
    CHECK(has(r.err, "scenario is required"));
    CHECK(has(r.err, "hint: --refbox-sockets took '" + scenario +
                         "' as its sockets file (its value is optional): put it after the "
                         "scenario"));
    // With a sockets file, before the scenario works (docs/llsfsim.md).
    dir.write("sockets.yaml", "stream: {port: 0}\n");
    const Run ok = llsfsim({"run", "--refbox-sockets", dir.file("sockets.yaml"), scenario,
                            "--no-db", "--no-record", "--speed", "1000", "-q"});
    CHECK(ok.code == 0);
  }
  SUBCASE("an unknown key, named with its line") {
    const Run r = run_with("stream: {port: 0}\nudp_peer: []\n");
    CHECK(r.code == llsf::app::kExitBadInput);
    CHECK(has(r.err, "sockets.yaml:2:"));
    CHECK(has(r.err, "udp_peer"));
  }
  SUBCASE("a peer named like a robot") {
    const Run r = run_with("stream: {port: 0}\nudp_peers:\n  - {name: robot1}\n");
    CHECK(r.code == llsf::app::kExitBadInput);
    CHECK(has(r.err, "udp_peers[0].name: 'robot1' is the name of another radio peer"));
  }
  SUBCASE("a port that is taken") {
    boost::asio::io_context io;
    boost::asio::ip::tcp::acceptor taken(io, {llsf::comm::test::kLoopback, 0});
    const int port = taken.local_endpoint().port();
    const Run r = run_with("stream: {port: " + std::to_string(port) + "}\n");
    CHECK(r.code == llsf::app::kExitBadInput);
    CHECK(has(r.err, "llsfsim run: --refbox-sockets " + dir.file("sockets.yaml") +
                         ": cannot listen for controllers on 127.0.0.1:" + std::to_string(port)));
    CHECK(!has(r.err, "--refbox-sockets: --refbox-sockets"));  // the prefix once
  }
}

TEST_CASE("run --refbox-sockets: a controller and a UDP peer play a served game") {
  const llsf::test::TempDir dir("llsf_app_sockets");
  // Two robots without agents (they stand still and send beacons), exploration at once; 90 s of
  // game at 30x: about 3 s of wall time.
  dir.write("s.yaml",
            "name: served\nseed: 3\nstart: exploration\nduration_s: 90\nrobots: {count: 2}\n");
  const std::string scenario = dir.file("s.yaml");
  const int tcp_port = free_tcp_port();
  const int udp_port = free_udp_port();
  dir.write("sockets.yaml", "stream: {port: " + std::to_string(tcp_port) +
                                "}\nudp_peers:\n  - {name: ext1, channel: team, send_port: " +
                                std::to_string(udp_port) + "}\n");
  // The truth the UDP peer reports: M1's type in this game (the layout comes from the seed).
  const llsf::study::ScenarioFile file = llsf::study::load_scenario(scenario);
  llsf::sim::GameConfig truth_config = file.variants.front().game;
  truth_config.seed = 3;
  const llsf::sim::GameDriver truth(truth_config);
  const std::string m1_type(
      llsf::refbox::to_string(truth.game().refbox().machine(llsf::core::DeviceId(0)).type));

  const llsf::comm::MessageRegistry registry = refbox_registry();
  boost::asio::io_context io;
  llsf::comm::test::Endpoint peer(io);
  llsf::comm::StreamClient controller(registry);
  Seen seen;

  Served served({"run", scenario, "--seed", "3", "--no-db", "--no-record", "--refbox-sockets",
                 dir.file("sockets.yaml"), "--speed", "30"});

  // Connect (the sockets are bound before the game starts; retry until then).
  const auto connect_deadline = Clock::now() + std::chrono::seconds(20);
  while (!controller.connect("127.0.0.1", tcp_port, std::chrono::milliseconds(200)) &&
         Clock::now() < connect_deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  REQUIRE(controller.connected());

  // Reads what arrived on both sockets until `done` or 20 s (a generous bound).
  auto pump_until = [&](const std::function<bool()>& done) {
    const auto deadline = Clock::now() + std::chrono::seconds(20);
    while (Clock::now() < deadline) {
      controller.run_for(std::chrono::milliseconds(10));
      for (llsf::comm::StreamEvent& e : controller.take_events()) {
        if (e.kind == llsf::comm::StreamEvent::Kind::kDisconnected) seen.disconnected = true;
        if (e.kind != llsf::comm::StreamEvent::Kind::kMessage) continue;
        const std::string type = e.message->GetTypeName();
        if (type == "llsf_msgs.GameState") {
          seen.game_states.push_back(static_cast<const llsf_msgs::GameState&>(*e.message));
        } else if (type == "llsf_msgs.RobotInfo") {
          seen.robot_infos.push_back(static_cast<const llsf_msgs::RobotInfo&>(*e.message));
        } else if (type == "llsf_msgs.OrderInfo") {
          seen.order_infos.push_back(static_cast<const llsf_msgs::OrderInfo&>(*e.message));
        } else if (type == "llsf_msgs.MachineInfo") {
          ++seen.machine_infos;
        } else if (type == "llsf_msgs.VersionInfo") {
          ++seen.version_infos;
        }
      }
      for (const std::vector<std::uint8_t>& d : peer.drain()) {
        const auto m = registry.decode_datagram(d);
        if (m.error != llsf::comm::FrameError::kNone) continue;
        if (m.message->GetTypeName() == "llsf_msgs.BeaconSignal") {
          seen.udp_beacons.push_back(static_cast<const llsf_msgs::BeaconSignal&>(*m.message));
        } else if (m.message->GetTypeName() == "llsf_msgs.GameState") {
          ++seen.udp_game_states;
        }
      }
      if (done()) return true;
      if (seen.disconnected) return false;
    }
    return false;
  };
  auto send_udp = [&](const google::protobuf::Message& m) {
    peer.send(registry.encode(m), udp_port);
  };
  auto beacon = [&](std::uint64_t seq) {
    llsf_msgs::BeaconSignal b;
    b.mutable_time()->set_sec(unix_now_s());
    b.mutable_time()->set_nsec(0);
    b.set_seq(seq);
    b.set_team_name("Carologistics");
    b.set_peer_name("ext1");
    b.set_number(7);
    return b;
  };

  // 1. The controller is greeted and gets the refbox's stream messages, times in 2013 form.
  REQUIRE(pump_until([&] {
    return seen.version_infos > 0 && !seen.game_states.empty() && seen.machine_infos > 0 &&
           !seen.robot_infos.empty() && seen.robot_infos.back().robots_size() >= 2;
  }));
  {
    const llsf_msgs::GameState& g = seen.game_states.back();
    CHECK(g.phase() == llsf_msgs::GameState::EXPLORATION);
    CHECK(g.state() == llsf_msgs::GameState::RUNNING);
    CHECK(g.game_time().sec() < 100);  // phase-relative, as in 2013
    for (const llsf_msgs::Robot& r : seen.robot_infos.back().robots()) {
      INFO(r.name() << " last seen " << r.last_seen().sec());
      CHECK(near_now(r.last_seen().sec()));  // Unix time, not simulated seconds
    }
  }

  // 2. A UDP peer's BeaconSignal: it appears in RobotInfo; it hears the radio (the robots' and
  //    the refbox's beacons, GameState) with Unix times.
  std::uint64_t seq = 0;
  REQUIRE(pump_until([&] {
    send_udp(beacon(++seq));
    for (const llsf_msgs::Robot& r : seen.robot_infos.back().robots()) {
      if (r.name() == "ext1") return true;
    }
    return false;
  }));
  for (const llsf_msgs::Robot& r : seen.robot_infos.back().robots()) {
    if (r.name() != "ext1") continue;
    CHECK(r.team() == "Carologistics");
    CHECK(r.number() == 7);
    CHECK(r.host() == "127.0.0.1");
    CHECK(near_now(r.last_seen().sec()));
  }
  REQUIRE(pump_until([&] { return !seen.udp_beacons.empty() && seen.udp_game_states > 0; }));
  for (const llsf_msgs::BeaconSignal& b : seen.udp_beacons) CHECK(near_now(b.time().sec()));

  // 3. Its MachineReport in EXPLORATION is scored.
  CHECK(seen.game_states.back().points() == 0);
  llsf_msgs::MachineReport report;
  llsf_msgs::MachineReportEntry* entry = report.add_machines();
  entry->set_name("M1");
  entry->set_type(m1_type);
  send_udp(report);
  REQUIRE(pump_until([&] { return seen.game_states.back().points() > 0; }));

  // 4. The controller pauses the game: the game clock stops.
  llsf_msgs::SetGameState pause;
  pause.set_state(llsf_msgs::GameState::PAUSED);
  REQUIRE(controller.send(pause));
  REQUIRE(
      pump_until([&] { return seen.game_states.back().state() == llsf_msgs::GameState::PAUSED; }));
  const std::size_t paused_at = seen.game_states.size();
  const llsf_msgs::Time stopped = seen.game_states.back().game_time();
  REQUIRE(pump_until([&] { return seen.game_states.size() >= paused_at + 4; }));  // 4 s of game
  for (std::size_t i = paused_at; i < seen.game_states.size(); ++i) {
    CHECK(seen.game_states[i].state() == llsf_msgs::GameState::PAUSED);
    CHECK(seen.game_states[i].game_time().sec() == stopped.sec());
    CHECK(seen.game_states[i].game_time().nsec() == stopped.nsec());
  }

  // 5. PRODUCTION and RUNNING: OrderInfo follows, the clock runs again.
  llsf_msgs::SetGamePhase production;
  production.set_phase(llsf_msgs::GameState::PRODUCTION);
  REQUIRE(controller.send(production));
  llsf_msgs::SetGameState run;
  run.set_state(llsf_msgs::GameState::RUNNING);
  REQUIRE(controller.send(run));
  REQUIRE(pump_until([&] {
    const llsf_msgs::GameState& g = seen.game_states.back();
    return !seen.order_infos.empty() && g.phase() == llsf_msgs::GameState::PRODUCTION &&
           g.state() == llsf_msgs::GameState::RUNNING && g.game_time().sec() >= 2;
  }));
  CHECK(seen.order_infos.back().orders_size() > 0);
  CHECK(seen.game_states.back().points() > 0);  // the exploration points are kept

  // The game plays to its end; the controller stays connected (and reading) until then.
  REQUIRE(pump_until([&] { return seen.disconnected; }));
  served.thread.join();
  INFO(served.result.err);
  CHECK(served.result.code == llsf::app::kExitOk);
  CHECK(has(served.result.out,
            "refbox sockets: controllers: tcp 127.0.0.1:" + std::to_string(tcp_port)));
  CHECK(has(served.result.out, "udp peer ext1 (channel team)"));
}

TEST_CASE("refbox sockets with radio lock_messages 2013: the peers' lock messages in 2013 form") {
  const llsf::test::TempDir dir("llsf_app_sockets_2013");
  // One robot with the lock protocol (it announces its master every 0.5 s) and an agent that
  // does nothing else; 3 s of game, unpaced.
  dir.write("agent.clp", "(defrule idle (time $?) (not (idle)) => (assert (idle)))\n");
  dir.write("s.yaml",
            "name: locks2013\nstart: production\nduration_s: 3\nradio: {lock_messages: 2013}\n"
            "robots: {count: 1, locks: true, agent: [" +
                dir.file("agent.clp") + "]}\n");
  boost::asio::io_context io;
  llsf::comm::test::Endpoint peer(io);
  llsf::comm::SocketConfig sc;
  sc.stream_enabled = false;
  llsf::comm::UdpPeerConfig p;
  p.name = "ext1";
  p.channel = "team";
  p.send_port = 0;
  p.recv_port = peer.port();
  sc.udp_peers.push_back(p);
  llsf::study::Scenario scenario = llsf::study::load_scenario(dir.file("s.yaml")).variants.at(0);
  llsf::app::RefboxSockets sockets(sc, scenario.game.hub.lock_messages, [](std::string_view) {});
  scenario.game.external_peers = sockets.external_peers();
  // The 2013 tools' registry: LockMessage (2000, 1337), LockMasterAnnounce (2000, 1338).
  llsf::comm::MessageRegistry tools;
  llsf::sim::add_refbox_messages(tools);
  llsf::comm::add_agent_messages(tools, llsf::comm::LockNumbering::k2013);
  // What the peer says: a 2013 LockMessage, sent before the first tick.
  peer.send(tools.encode(llsf::comm::test::lock(1)), sockets.udp_port(0));
  llsf::comm::PeerCounters from_peer;
  llsf::study::RunHooks hooks;
  hooks.attach = [&sockets](llsf::sim::Game& g) { sockets.attach(g); };
  hooks.tick = [&](const llsf::sim::Game& g) {
    sockets.send_tick();
    sockets.receive();
    from_peer = g.hub().peer_counters(g.external_peer(0));
  };
  (void)llsf::study::run_game(scenario, 1, hooks);
  // It was taken as a lock message, not refused as an unknown type.
  CHECK(from_peer.broadcasts == 1);
  CHECK(from_peer.malformed_total() == 0);
  // The robot's master announcements reach the peer as (2000, 1338).
  int announces = 0;
  for (const std::vector<std::uint8_t>& d : peer.drain()) {
    const auto m = tools.decode_datagram(d);
    if (m.error == llsf::comm::FrameError::kNone &&
        m.message->GetTypeName() == "llsf_agent_msgs.LockMasterAnnounce") {
      ++announces;
    }
  }
  CHECK(announces >= 1);
}

TEST_CASE("refbox sockets: a controller's malformed frame is logged and sent as a LogMessage") {
  const llsf::test::TempDir dir("llsf_app_sockets_log");
  dir.write("s.yaml", "name: lm\nstart: exploration\nduration_s: 3\nrobots: {count: 1}\n");
  llsf::comm::SocketConfig sc;
  sc.stream_port = 0;
  std::vector<std::string> logged;
  llsf::study::Scenario scenario = llsf::study::load_scenario(dir.file("s.yaml")).variants.at(0);
  llsf::app::RefboxSockets sockets(sc, scenario.game.hub.lock_messages,
                                   [&logged](std::string_view l) { logged.emplace_back(l); });
  REQUIRE(sockets.stream_port() > 0);
  const llsf::comm::MessageRegistry registry = refbox_registry();
  // One controller listens; a second one sends a frame of a type nobody registered.
  llsf::comm::StreamClient listener(registry);
  REQUIRE(listener.connect("127.0.0.1", sockets.stream_port(), std::chrono::seconds(5)));
  boost::asio::io_context io;
  boost::asio::ip::tcp::socket raw(io);
  raw.connect(boost::asio::ip::tcp::endpoint(boost::asio::ip::make_address("127.0.0.1"),
                                             static_cast<unsigned short>(sockets.stream_port())));
  llsf_msgs::BeaconSignal beacon;
  beacon.mutable_time()->set_sec(0);
  beacon.mutable_time()->set_nsec(0);
  beacon.set_seq(1);
  beacon.set_team_name("Carologistics");
  beacon.set_peer_name("ext1");
  beacon.set_number(7);
  std::vector<std::uint8_t> bad = registry.encode(beacon);
  bad[3] = 77;  // the message type's low byte: no such type
  boost::asio::write(raw, boost::asio::buffer(bad));
  std::vector<std::string> told;
  llsf::study::RunHooks hooks;
  hooks.attach = [&sockets](llsf::sim::Game& g) { sockets.attach(g); };
  hooks.tick = [&](const llsf::sim::Game&) {
    sockets.send_tick();
    sockets.receive();
    listener.run_for(std::chrono::milliseconds(1));
    for (llsf::comm::StreamEvent& e : listener.take_events()) {
      if (e.kind != llsf::comm::StreamEvent::Kind::kMessage ||
          e.message->GetTypeName() != "llsf_log_msgs.LogMessage") {
        continue;
      }
      told.push_back(static_cast<const llsf_log_msgs::LogMessage&>(*e.message).message());
    }
  };
  (void)llsf::study::run_game(scenario, 1, hooks);
  // The user's log line ...
  REQUIRE(logged.size() == 1);
  CHECK(logged[0].find("dropped a frame (component 2000, type 77") != std::string::npos);
  // ... and the controllers' LogMessage with the same text (as refbox 0.6.1's network logger).
  bool found = false;
  for (const std::string& t : told) found = found || t.find(logged[0]) != std::string::npos;
  CHECK(found);
}
