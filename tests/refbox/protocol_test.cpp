// SPDX-License-Identifier: MIT
// The protocol adapter (spec §9.6, §9.7): message schedules over simulated time, contents
// against the engine's snapshot, channel rules, bad input, and a game driven only by messages.
#include <doctest/doctest.h>

#include <google/protobuf/dynamic_message.h>
#include <llsf_log_msgs/LogMessage.pb.h>
#include <llsf_msgs/AttentionMessage.pb.h>
#include <llsf_msgs/BeaconSignal.pb.h>
#include <llsf_msgs/ExplorationInfo.pb.h>
#include <llsf_msgs/GameInfo.pb.h>
#include <llsf_msgs/GameState.pb.h>
#include <llsf_msgs/MachineCommands.pb.h>
#include <llsf_msgs/MachineInfo.pb.h>
#include <llsf_msgs/MachineReport.pb.h>
#include <llsf_msgs/OrderInfo.pb.h>
#include <llsf_msgs/PuckInfo.pb.h>
#include <llsf_msgs/RobotCommands.pb.h>
#include <llsf_msgs/RobotInfo.pb.h>
#include <llsf_msgs/Sync.pb.h>
#include <llsf_msgs/VersionInfo.pb.h>

#include <cmath>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "fixture.h"
#include "llsf/refbox/protocol.h"

using namespace llsf;
using namespace llsf::refbox;
using namespace llsf::refbox::test;
using google::protobuf::Message;
using Kind = Destination::Kind;

namespace {

/// One message as it went out, with the time of its step.
struct Sent {
  SimTime t;
  Destination to;
  std::shared_ptr<const Message> msg;
};

/// Drives a RefboxProtocol at 10 ms steps from t = 0 and records every outgoing message.
class Harness {
 public:
  explicit Harness(RefboxConfig cfg = test_config(), ProtocolConfig pc = {}, SimTime dt = kStep)
      : p(std::move(cfg), core::Rng(1), std::move(pc)), dt_(dt) {}

  /// One step at `next`.
  void step() {
    last = next;
    for (const Outgoing& o : p.step(next, world)) sent.push_back({next, o.to, o.message});
    next += dt_;
  }
  void run_s(double s) {
    const SimTime end = next + SimTime::from_seconds(s);
    while (next < end) step();
  }
  /// Steps until `pred()` holds (at most `max_s` seconds).
  template <class F>
  void run_until(F pred, double max_s = 2000) {
    const SimTime end = next + SimTime::from_seconds(max_s);
    while (!pred() && next < end) step();
    REQUIRE(pred());
  }

  ReceiveResult tcp(const Message& m, int client = 1) {
    return p.receive(m, Origin::stream(client));
  }
  ReceiveResult udp(const Message& m, const char* host = "172.26.1.1", int port = 4444) {
    return p.receive(m, Origin::peer(host, port));
  }

  /// Messages of type T to destinations of `kind` sent in [from, to).
  template <class T>
  std::vector<const T*> msgs(Kind kind, double from_s = 0, double to_s = 1e9) const {
    std::vector<const T*> r;
    for (const Sent& s : sent) {
      if (s.to.kind != kind || s.t < SimTime::from_seconds(from_s) ||
          s.t >= SimTime::from_seconds(to_s)) {
        continue;
      }
      if (const auto* m = dynamic_cast<const T*>(s.msg.get())) r.push_back(m);
    }
    return r;
  }
  /// Times (s) at which messages of type T went to `kind`.
  template <class T>
  std::vector<double> times(Kind kind, double from_s = 0, double to_s = 1e9) const {
    std::vector<double> r;
    for (const Sent& s : sent) {
      if (s.to.kind == kind && dynamic_cast<const T*>(s.msg.get()) &&
          s.t >= SimTime::from_seconds(from_s) && s.t < SimTime::from_seconds(to_s)) {
        r.push_back(s.t.seconds());
      }
    }
    return r;
  }
  /// The last message of type T to `kind`, or null.
  template <class T>
  const T* last_msg(Kind kind) const {
    const auto v = msgs<T>(kind);
    return v.empty() ? nullptr : v.back();
  }
  /// Messages of type T in the last step's output, to `kind`.
  template <class T>
  std::vector<const T*> now_msgs(Kind kind) const {
    std::vector<const T*> r;
    for (const Outgoing& o : p.outgoing()) {
      if (o.to.kind != kind) continue;
      if (const auto* m = dynamic_cast<const T*>(o.message.get())) r.push_back(m);
    }
    return r;
  }

  RefboxProtocol p;
  WorldInputs world;
  SimTime next;
  SimTime last;
  std::vector<Sent> sent;

 private:
  SimTime dt_;
};

llsf_msgs::SetGameState set_state(llsf_msgs::GameState::State s) {
  llsf_msgs::SetGameState m;
  m.set_state(s);
  return m;
}
llsf_msgs::SetGamePhase set_phase(llsf_msgs::GameState::Phase ph) {
  llsf_msgs::SetGamePhase m;
  m.set_phase(ph);
  return m;
}
template <class T>
T puck_cmd(const char* machine, std::uint32_t puck_id) {
  T m;
  m.set_machine_name(machine);
  m.set_puck_id(puck_id);
  return m;
}
llsf_msgs::BeaconSignal robot_beacon(SimTime t, const char* name, std::uint32_t number,
                                     const char* team = "Carologistics") {
  llsf_msgs::BeaconSignal b;
  b.mutable_time()->set_sec(t.ns() / 1000000000);
  b.mutable_time()->set_nsec(t.ns() % 1000000000);
  b.set_seq(1);
  b.set_team_name(team);
  b.set_peer_name(name);
  b.set_number(number);
  auto* pose = b.mutable_pose();
  pose->mutable_timestamp()->set_sec(0);
  pose->mutable_timestamp()->set_nsec(0);
  pose->set_x(1.5f);
  pose->set_y(2.5f);
  pose->set_ori(0.25f);
  return b;
}
llsf_msgs::MachineReport report(std::initializer_list<std::pair<const char*, const char*>> e) {
  llsf_msgs::MachineReport r;
  for (const auto& [name, type] : e) {
    auto* x = r.add_machines();
    x->set_name(name);
    x->set_type(type);
  }
  return r;
}

/// Starts the game in `phase`, RUNNING, by controller messages.
void start_in(Harness& h, llsf_msgs::GameState::Phase phase) {
  REQUIRE(h.tcp(set_phase(phase)).status == ReceiveStatus::kAccepted);
  REQUIRE(h.tcp(set_state(llsf_msgs::GameState::RUNNING)).status == ReceiveStatus::kAccepted);
  h.step();
}

/// Time from (sec, nsec).
double secs(const llsf_msgs::Time& t) { return double(t.sec()) + double(t.nsec()) * 1e-9; }

std::vector<double> expected_series(double start, double step, int n) {
  std::vector<double> r;
  for (int i = 0; i < n; ++i) r.push_back(start + step * i);
  return r;
}
void check_times(const std::vector<double>& got, const std::vector<double>& want) {
  REQUIRE(got.size() == want.size());
  for (std::size_t i = 0; i < got.size(); ++i) CHECK(got[i] == doctest::Approx(want[i]));
}

}  // namespace

TEST_CASE("protocol: enum conversions cover every §9.4 value") {
  const std::vector<std::pair<GamePhase, int>> phases = {{GamePhase::kPreGame, 0},
                                                         {GamePhase::kSetup, 10},
                                                         {GamePhase::kExploration, 20},
                                                         {GamePhase::kProduction, 30},
                                                         {GamePhase::kPostGame, 40},
                                                         {GamePhase::kOpenChallenge, 1000},
                                                         {GamePhase::kNavigationChallenge, 1001},
                                                         {GamePhase::kWhackAMoleChallenge, 1002}};
  for (const auto& [ph, n] : phases) {
    CHECK(int(to_msg_phase(ph)) == n);
    CHECK(from_msg_phase(n) == ph);
  }
  CHECK_FALSE(from_msg_phase(1).has_value());  // a 0.5.x value
  CHECK_FALSE(from_msg_phase(-1).has_value());
  for (int s = 0; s < 4; ++s) {
    REQUIRE(from_msg_state(s).has_value());
    CHECK(int(to_msg_state(*from_msg_state(s))) == s);
  }
  CHECK_FALSE(from_msg_state(4).has_value());
}

TEST_CASE("protocol: BeaconSignal and GameState every 1 s; GameState follows the snapshot") {
  Harness h;
  h.p.client_connected(1);
  h.run_s(10);
  // Beacons: 0, 1, ..., 9 s, seq 1..10, the refbox's identity, no pose.
  check_times(h.times<llsf_msgs::BeaconSignal>(Kind::kAllPeers), expected_series(0, 1, 10));
  const auto beacons = h.msgs<llsf_msgs::BeaconSignal>(Kind::kAllPeers);
  for (std::size_t i = 0; i < beacons.size(); ++i) {
    CHECK(beacons[i]->seq() == i + 1);
    CHECK(beacons[i]->team_name() == "LLSF");
    CHECK(beacons[i]->peer_name() == "RefBox");
    CHECK(beacons[i]->number() == 0);
    CHECK_FALSE(beacons[i]->has_pose());
    CHECK(secs(beacons[i]->time()) == doctest::Approx(double(i)));
  }
  CHECK(h.msgs<llsf_msgs::BeaconSignal>(Kind::kAllClients).empty());
  // GameState to peers and to stream clients, 1 Hz; refbox_mode only in the stream copy.
  check_times(h.times<llsf_msgs::GameState>(Kind::kAllPeers), expected_series(0, 1, 10));
  check_times(h.times<llsf_msgs::GameState>(Kind::kAllClients), expected_series(0, 1, 10));
  for (const auto* g : h.msgs<llsf_msgs::GameState>(Kind::kAllPeers)) {
    CHECK_FALSE(g->has_refbox_mode());
    CHECK(g->state() == llsf_msgs::GameState::WAIT_START);
    CHECK(g->phase() == llsf_msgs::GameState::PRE_GAME);
    CHECK(g->team() == "Carologistics");
    CHECK(g->points() == 0);
  }
  for (const auto* g : h.msgs<llsf_msgs::GameState>(Kind::kAllClients)) {
    CHECK(g->has_refbox_mode());
    CHECK(g->refbox_mode() == llsf_msgs::GameState::STANDALONE);
  }

  // Running through SETUP into EXPLORATION with points: every GameState equals the snapshot of
  // its step.
  RefboxConfig cfg = test_config();
  cfg.setup_duration = SimTime::from_sec(3);
  Harness g(cfg);
  g.p.client_connected(1);
  g.step();
  REQUIRE(g.tcp(set_state(llsf_msgs::GameState::RUNNING)).status == ReceiveStatus::kAccepted);
  int checked = 0;
  bool reported = false;
  while (g.next < SimTime::from_sec(8)) {
    g.step();
    if (!reported && g.p.refbox().phase() == GamePhase::kExploration) {
      reported = true;
      REQUIRE(g.udp(report({{"M1", "T1"}, {"M3", "T3"}})).status == ReceiveStatus::kAccepted);
    }
    for (const auto* m : g.now_msgs<llsf_msgs::GameState>(Kind::kAllPeers)) {
      const Refbox& rb = g.p.refbox();
      CHECK(secs(m->game_time()) == doctest::Approx(rb.game_time().seconds()));
      CHECK(m->state() == int(rb.state()));
      CHECK(m->phase() == int(rb.phase()));
      CHECK(m->points() == std::uint32_t(rb.points()));
      CHECK(m->team() == rb.team());
      ++checked;
    }
  }
  CHECK(checked == 7);  // 1 s .. 7 s
  const auto* last = g.last_msg<llsf_msgs::GameState>(Kind::kAllPeers);
  REQUIRE(last != nullptr);
  CHECK(last->phase() == llsf_msgs::GameState::EXPLORATION);
  CHECK(last->points() == 8);
  CHECK(secs(last->game_time()) > 3.0);  // phase-relative: 7 s since start - 3 s setup
  CHECK(secs(last->game_time()) < 5.0);
}

TEST_CASE("protocol: a connecting client gets VersionInfo, GameInfo, and the reset messages") {
  ProtocolConfig pc;
  pc.known_teams = {"Carologistics", "BavarianBendingBots"};
  Harness h(test_config(), pc);
  h.run_s(0.6);
  // Nothing for stream clients while there are none.
  for (const Sent& s : h.sent) CHECK(s.to.kind == Kind::kAllPeers);
  h.p.client_connected(7);
  h.step();  // t = 0.6
  const auto out = h.p.outgoing();
  REQUIRE(out.size() >= 2);
  CHECK(out[0].to == Destination{Kind::kClient, 7});
  const auto* v = dynamic_cast<const llsf_msgs::VersionInfo*>(out[0].message.get());
  REQUIRE(v != nullptr);
  CHECK(v->version_major() == 0);
  CHECK(v->version_minor() == 6);
  CHECK(v->version_micro() == 1);
  CHECK(v->version_string() == "0.6.1");
  CHECK(out[1].to == Destination{Kind::kClient, 7});
  const auto* gi = dynamic_cast<const llsf_msgs::GameInfo*>(out[1].message.get());
  REQUIRE(gi != nullptr);
  REQUIRE(gi->known_teams_size() == 2);
  CHECK(gi->known_teams(1) == "BavarianBendingBots");
  // The timers of GameState, RobotInfo, MachineInfo and PuckInfo were reset: all at once.
  CHECK(h.now_msgs<llsf_msgs::GameState>(Kind::kAllClients).size() == 1);
  CHECK(h.now_msgs<llsf_msgs::GameState>(Kind::kAllPeers).size() == 1);
  CHECK(h.now_msgs<llsf_msgs::RobotInfo>(Kind::kAllClients).size() == 1);
  CHECK(h.now_msgs<llsf_msgs::MachineInfo>(Kind::kAllClients).size() == 1);
  CHECK(h.now_msgs<llsf_msgs::PuckInfo>(Kind::kAllClients).size() == 1);
  // ... and continue from there.
  h.run_s(2.0);
  check_times(h.times<llsf_msgs::GameState>(Kind::kAllClients), {0.6, 1.6, 2.6});
  check_times(h.times<llsf_msgs::PuckInfo>(Kind::kAllClients), {0.6, 1.6, 2.6});
  CHECK(h.times<llsf_msgs::VersionInfo>(Kind::kClient).size() == 1);
  // The PuckInfo lists every puck.
  const auto* pi = h.last_msg<llsf_msgs::PuckInfo>(Kind::kAllClients);
  REQUIRE(pi->pucks_size() == 20);
  CHECK(pi->pucks(19).id() == 20);
  CHECK(pi->pucks(19).state() == llsf_msgs::S0);
  // After a disconnect nothing goes to stream clients.
  h.p.client_disconnected(7);
  const std::size_t before = h.msgs<llsf_msgs::GameState>(Kind::kAllClients).size();
  h.run_s(3);
  CHECK(h.msgs<llsf_msgs::GameState>(Kind::kAllClients).size() == before);
  CHECK(h.p.clients().empty());
}

TEST_CASE("protocol: periods of the controller view, RobotInfo and PuckInfo") {
  Harness h;
  h.p.client_connected(1);
  h.run_s(5);
  CHECK(h.times<llsf_msgs::MachineInfo>(Kind::kAllClients).size() == 20);  // 4 Hz
  CHECK(h.times<llsf_msgs::RobotInfo>(Kind::kAllClients).size() == 20);    // 4 Hz
  check_times(h.times<llsf_msgs::RobotInfo>(Kind::kAllPeers), {0.0, 2.5});
  CHECK(h.times<llsf_msgs::PuckInfo>(Kind::kAllClients).size() == 5);
  CHECK(h.times<llsf_msgs::MachineInfo>(Kind::kAllPeers).empty());  // robot view: PRODUCTION
  CHECK(h.times<llsf_msgs::OrderInfo>(Kind::kAllPeers).empty());
  CHECK(h.times<llsf_msgs::ExplorationInfo>(Kind::kAllPeers).empty());
}

TEST_CASE("protocol: beacons register robots by (host, port); VersionInfo burst per new source") {
  Harness h;
  h.p.client_connected(1);
  h.step();
  // Beacons every second from one robot: one burst of 10 VersionInfo at 0.5 s.
  for (int i = 0; i < 12; ++i) {
    const auto r = h.udp(robot_beacon(h.next, "R-1", 1), "172.26.1.1", 4444);
    CHECK(r.status == ReceiveStatus::kAccepted);
    h.run_s(1);
  }
  check_times(h.times<llsf_msgs::VersionInfo>(Kind::kAllPeers), expected_series(0.01, 0.5, 10));
  REQUIRE(h.p.refbox().robots().size() == 1);
  const Robot& r = h.p.refbox().robots()[0];
  CHECK(r.host == "172.26.1.1");
  CHECK(r.port == 4444);
  CHECK(r.name == "R-1");
  CHECK(r.number == 1);
  REQUIRE(r.pose.has_value());
  CHECK(r.pose->x == doctest::Approx(1.5));
  CHECK(r.pose->y == doctest::Approx(2.5));
  CHECK(r.pose->theta == doctest::Approx(0.25));
  // RobotInfo: poses and maintenance to stream clients, no poses to peers.
  const auto* rs = h.last_msg<llsf_msgs::RobotInfo>(Kind::kAllClients);
  REQUIRE(rs->robots_size() == 1);
  CHECK(rs->robots(0).name() == "R-1");
  CHECK(rs->robots(0).team() == "Carologistics");
  CHECK(rs->robots(0).host() == "172.26.1.1");
  CHECK(rs->robots(0).number() == 1);
  CHECK(rs->robots(0).state() == llsf_msgs::ACTIVE);
  CHECK(rs->robots(0).has_maintenance_cycles());
  REQUIRE(rs->robots(0).has_pose());
  CHECK(rs->robots(0).pose().x() == doctest::Approx(1.5f));
  CHECK(secs(rs->robots(0).last_seen()) == doctest::Approx(r.last_seen.seconds()));
  const auto* rp = h.last_msg<llsf_msgs::RobotInfo>(Kind::kAllPeers);
  REQUIRE(rp->robots_size() == 1);
  CHECK_FALSE(rp->robots(0).has_pose());
  CHECK(rp->robots(0).number() == 1);

  // The same host with another port is a new source: a new burst; another refbox is not.
  const double t0 = h.next.seconds();
  h.udp(robot_beacon(h.next, "R-2", 2), "172.26.1.1", 4445);
  auto other_refbox = robot_beacon(h.next, "RefBox", 0, "LLSF");
  h.udp(other_refbox, "172.26.1.9", 4444);
  h.run_s(6);
  CHECK(h.times<llsf_msgs::VersionInfo>(Kind::kAllPeers, t0).size() == 10);
  CHECK(h.p.refbox().robots().size() == 2);
  // The engine's warning about the other refbox reaches the controller.
  bool warned = false;
  for (const auto* a : h.msgs<llsf_msgs::AttentionMessage>(Kind::kAllClients)) {
    warned = warned || a->message().find("Another refbox") != std::string::npos;
  }
  CHECK(warned);

  // Maintenance through the controller shows in RobotInfo.
  llsf_msgs::SetRobotMaintenance sm;
  sm.set_robot_number(2);
  sm.set_maintenance(true);
  CHECK(h.tcp(sm).status == ReceiveStatus::kAccepted);
  h.run_s(0.5);
  const auto* rm = h.last_msg<llsf_msgs::RobotInfo>(Kind::kAllClients);
  bool found = false;
  for (const auto& x : rm->robots()) {
    if (x.number() != 2) continue;
    found = true;
    CHECK(x.state() == llsf_msgs::MAINTENANCE);
    CHECK(x.maintenance_cycles() == 1);
    CHECK(x.maintenance_time_remaining() > 0.0f);
  }
  CHECK(found);
}

TEST_CASE("protocol: ExplorationInfo and MachineReportInfo in EXPLORATION, also paused") {
  Harness h;
  h.p.client_connected(1);
  h.step();
  CHECK(h.times<llsf_msgs::ExplorationInfo>(Kind::kAllPeers).empty());
  // Controller view before PRODUCTION: "?" for M1..M10, fixed types for the others.
  const auto* pre = h.last_msg<llsf_msgs::MachineInfo>(Kind::kAllClients);
  REQUIRE(pre->machines_size() == 16);
  for (int i = 0; i < 16; ++i) {
    const auto& m = pre->machines(i);
    CHECK(m.name() == kDeviceNames[std::size_t(i)]);
    if (i < 10) {
      CHECK(m.type() == "?");
    } else if (i < 12) {
      CHECK(m.type() == "RECYCLE");
    } else if (i == 12) {
      CHECK(m.type() == "TEST");
    } else {
      CHECK(m.type() == "DELIVER");
    }
    CHECK(m.lights_size() == 3);
    CHECK(m.inputs_size() == 0);
  }
  const double t0 = h.next.seconds();
  start_in(h, llsf_msgs::GameState::EXPLORATION);
  h.run_s(3);
  // Paused: still sent (quirk 6).
  CHECK(h.tcp(set_state(llsf_msgs::GameState::PAUSED)).status == ReceiveStatus::kAccepted);
  h.run_s(2);
  check_times(h.times<llsf_msgs::ExplorationInfo>(Kind::kAllPeers), expected_series(t0, 1, 6));
  check_times(h.times<llsf_msgs::MachineReportInfo>(Kind::kAllPeers), expected_series(t0, 1, 6));
  CHECK(h.times<llsf_msgs::ExplorationInfo>(Kind::kAllClients).empty());

  const auto* ei = h.last_msg<llsf_msgs::ExplorationInfo>(Kind::kAllPeers);
  const GameParams& params = *h.p.refbox().params();
  REQUIRE(ei->signals_size() == 5);
  for (int t = 0; t < 5; ++t) {
    const auto& s = ei->signals(t);
    CHECK(s.type() == "T" + std::to_string(t + 1));
    REQUIRE(s.lights_size() == 3);
    CHECK(s.lights(0).color() == llsf_msgs::RED);
    CHECK(s.lights(1).color() == llsf_msgs::YELLOW);
    CHECK(s.lights(2).color() == llsf_msgs::GREEN);
    const Lights& code = params.light_codes[std::size_t(t)];
    CHECK(s.lights(0).state() == int(code.red));
    CHECK(s.lights(1).state() == int(code.yellow));
    CHECK(s.lights(2).state() == int(code.green));
  }
  REQUIRE(ei->machines_size() == 10);
  const auto& poses = h.p.refbox().config().device_poses;
  for (int i = 0; i < 10; ++i) {
    CHECK(ei->machines(i).name() == "M" + std::to_string(i + 1));
    CHECK(ei->machines(i).pose().x() == doctest::Approx(poses[std::size_t(i)].x));
    CHECK(ei->machines(i).pose().y() == doctest::Approx(poses[std::size_t(i)].y));
    CHECK(ei->machines(i).pose().ori() == doctest::Approx(poses[std::size_t(i)].theta));
  }
  CHECK(ei->machines(0).pose().x() == doctest::Approx(3.92));  // spec §1: M1 (3.92, 1.68)

  // A report (paused is still EXPLORATION) scores; MachineReportInfo and the controller view
  // acknowledge it. M1 is T1 (right), M2 is T2 (reported wrong).
  CHECK(h.udp(report({{"M1", "T1"}, {"M2", "T5"}})).status == ReceiveStatus::kAccepted);
  h.run_s(1.5);
  CHECK(h.p.refbox().phase_points(GamePhase::kExploration) == 1);
  const auto* ri = h.last_msg<llsf_msgs::MachineReportInfo>(Kind::kAllPeers);
  REQUIRE(ri->reported_machines_size() == 2);
  CHECK(ri->reported_machines(0) == "M1");
  CHECK(ri->reported_machines(1) == "M2");
  const auto* mi = h.last_msg<llsf_msgs::MachineInfo>(Kind::kAllClients);
  CHECK(mi->machines(0).correctly_reported());
  REQUIRE(mi->machines(1).has_correctly_reported());
  CHECK_FALSE(mi->machines(1).correctly_reported());
  CHECK_FALSE(mi->machines(2).has_correctly_reported());
  CHECK(mi->machines(0).type() == "?");

  // Nothing of exploration in PRODUCTION.
  const double t1 = h.next.seconds();
  start_in(h, llsf_msgs::GameState::PRODUCTION);
  h.run_s(3);
  CHECK(h.times<llsf_msgs::ExplorationInfo>(Kind::kAllPeers, t1).empty());
  CHECK(h.times<llsf_msgs::MachineReportInfo>(Kind::kAllPeers, t1).empty());
}

TEST_CASE("protocol: PRODUCTION: robot-view MachineInfo and OrderInfo bursts, contents") {
  Harness h;
  h.p.client_connected(1);
  h.run_s(1);
  const double t0 = h.next.seconds();
  start_in(h, llsf_msgs::GameState::PRODUCTION);
  h.run_s(30);
  // Robot view: 30 at 0.5 s, then every 2 s.
  std::vector<double> robot = expected_series(t0, 0.5, 30);
  for (double t = t0 + 14.5 + 2; t < t0 + 30 - 1e-6; t += 2) robot.push_back(t);
  check_times(h.times<llsf_msgs::MachineInfo>(Kind::kAllPeers), robot);
  // OrderInfo: 10 at 0.5 s, then every 5 s, to peers and stream clients (the same message).
  std::vector<double> orders = expected_series(t0, 0.5, 10);
  for (double t = t0 + 4.5 + 5; t < t0 + 30 - 1e-6; t += 5) orders.push_back(t);
  check_times(h.times<llsf_msgs::OrderInfo>(Kind::kAllPeers), orders);
  check_times(h.times<llsf_msgs::OrderInfo>(Kind::kAllClients), orders);
  CHECK(h.msgs<llsf_msgs::OrderInfo>(Kind::kAllPeers).back() ==
        h.msgs<llsf_msgs::OrderInfo>(Kind::kAllClients).back());

  // OrderInfo: the active orders, sorted by id, as in the snapshot.
  const auto* oi = h.last_msg<llsf_msgs::OrderInfo>(Kind::kAllPeers);
  REQUIRE(oi->orders_size() == 9);
  for (int i = 0; i < 9; ++i) {
    const Order& o = h.p.refbox().orders()[std::size_t(i)];
    const auto& x = oi->orders(i);
    CHECK(x.id() == std::uint32_t(i + 1));
    CHECK(x.product() == (i % 3) + 1);
    CHECK(x.quantity_requested() == std::uint32_t(o.quantity_requested));
    CHECK(x.quantity_delivered() == 0);
    CHECK(x.delivery_period_begin() == std::uint32_t(o.window_begin_s));
    CHECK(x.delivery_period_end() == std::uint32_t(o.window_end_s));
    CHECK(x.delivery_gate() == llsf_msgs::Order::ANY);
  }

  // Robot view: true types, inputs, output, pose; no lights. Controller view: lights, real types.
  const auto* rv = h.last_msg<llsf_msgs::MachineInfo>(Kind::kAllPeers);
  const auto* cv = h.last_msg<llsf_msgs::MachineInfo>(Kind::kAllClients);
  REQUIRE(rv->machines_size() == 16);
  REQUIRE(cv->machines_size() == 16);
  for (int i = 0; i < 16; ++i) {
    const Machine& m = h.p.refbox().machines()[std::size_t(i)];
    const auto& r = rv->machines(i);
    const auto& c = cv->machines(i);
    CHECK(r.name() == kDeviceNames[std::size_t(i)]);
    CHECK(r.type() == to_string(m.type));
    CHECK(c.type() == to_string(m.type));
    CHECK(r.lights_size() == 0);
    CHECK(c.lights_size() == 3);
    CHECK(r.has_pose());
    CHECK(c.has_pose());
    const TypeInputs in = inputs_of(m.type);
    REQUIRE(r.inputs_size() == in.count);
    for (int k = 0; k < in.count; ++k) CHECK(r.inputs(k) == int(in.states[std::size_t(k)]));
    CHECK(r.has_output() == output_of(m.type).has_value());
    CHECK(c.inputs_size() == 0);
  }
  // Test plan: M3 is T3 (S0 + S1 + S2 -> P1); D1 is the active gate (green) at the start.
  CHECK(rv->machines(2).type() == "T3");
  CHECK(rv->machines(2).output() == llsf_msgs::P1);
  CHECK(cv->machines(kD1).lights(2).state() == llsf_msgs::ON);
  CHECK(cv->machines(kD2).lights(0).state() == llsf_msgs::ON);
}

TEST_CASE("protocol: a late order restarts the OrderInfo burst") {
  // 40 ms steps (the 2013 loop) to keep the long run short; late order 10 activates at 195 s.
  Harness h(test_config(), {}, SimTime::from_ms(40));
  start_in(h, llsf_msgs::GameState::PRODUCTION);
  h.run_until([&] { return h.p.refbox().game_time() >= SimTime::from_sec(200); });
  double activated = -1;
  for (const auto* m : h.msgs<llsf_msgs::OrderInfo>(Kind::kAllPeers)) {
    if (m->orders_size() == 10) {
      CHECK(m->orders(9).id() == 10);
      CHECK(m->orders(9).product() == llsf_msgs::Order::P3);
      CHECK(m->orders(9).quantity_requested() == 1);
      CHECK(m->orders(9).delivery_period_begin() == 200);
      CHECK(m->orders(9).delivery_period_end() == 320);
      if (activated < 0) activated = 1;
    }
  }
  CHECK(activated > 0);
  // Find the activation (195 s of game time = 195.04 s after the start step at 0).
  const auto first_with_10 = [&] {
    for (const Sent& s : h.sent) {
      const auto* m = dynamic_cast<const llsf_msgs::OrderInfo*>(s.msg.get());
      if (m && m->orders_size() == 10) return s.t.seconds();
    }
    return -1.0;
  }();
  REQUIRE(first_with_10 > 190);
  const auto burst =
      h.times<llsf_msgs::OrderInfo>(Kind::kAllPeers, first_with_10, first_with_10 + 4.6);
  CHECK(burst.size() == 10);
  // Before it, the regular 5 s rhythm.
  const auto before =
      h.times<llsf_msgs::OrderInfo>(Kind::kAllPeers, first_with_10 - 20, first_with_10 - 1e-6);
  CHECK(before.size() == 4);
}

TEST_CASE("protocol: §9.7 channel rules for every controller message") {
  Harness h;
  h.p.client_connected(1);
  h.step();

  // SetGameState: stream only; a UDP copy is dropped and logged as illegal.
  auto r = h.udp(set_state(llsf_msgs::GameState::RUNNING));
  CHECK(r.status == ReceiveStatus::kRejected);
  CHECK(r.reason.find("Illegal SetGameState") != std::string::npos);
  h.step();
  CHECK(h.p.refbox().state() == GameState::kWaitStart);
  REQUIRE(h.p.log().size() == 1);
  CHECK(h.p.log()[0].level == ProtocolLogLine::Level::kWarn);
  const auto logs = h.now_msgs<llsf_log_msgs::LogMessage>(Kind::kAllClients);
  REQUIRE(logs.size() == 1);
  CHECK(logs[0]->log_level() == llsf_log_msgs::LogMessage::LL_WARN);
  CHECK(logs[0]->message().find("Illegal SetGameState") != std::string::npos);

  // SetTeamName and SetRobotMaintenance: stream only.
  llsf_msgs::SetTeamName tn;
  tn.set_team_name("Solidus");
  CHECK(h.udp(tn).status == ReceiveStatus::kRejected);
  h.step();
  CHECK(h.p.refbox().team() == "Carologistics");
  CHECK(h.tcp(tn).status == ReceiveStatus::kAccepted);
  h.step();
  CHECK(h.p.refbox().team() == "Solidus");
  llsf_msgs::SetRobotMaintenance sm;
  sm.set_robot_number(1);
  sm.set_maintenance(true);
  CHECK(h.udp(sm).status == ReceiveStatus::kRejected);
  CHECK(h.tcp(sm).status == ReceiveStatus::kAccepted);

  // SetGamePhase: a UDP copy is logged as illegal but applied (0.6.1).
  r = h.udp(set_phase(llsf_msgs::GameState::PRODUCTION));
  CHECK(r.status == ReceiveStatus::kAcceptedIllegal);
  CHECK(r.reason.find("Illegal SetGamePhase") != std::string::npos);
  h.step();
  CHECK(h.p.refbox().phase() == GamePhase::kProduction);
  REQUIRE(h.p.log().size() == 2);  // SetRobotMaintenance and SetGamePhase via UDP
  CHECK(h.p.log()[1].text.find("Illegal SetGamePhase") != std::string::npos);
  CHECK(h.tcp(set_state(llsf_msgs::GameState::RUNNING)).status == ReceiveStatus::kAccepted);
  h.step();
  CHECK(h.p.refbox().state() == GameState::kRunning);

  // PlacePuckUnderMachine and LoadPuckInMachine: stream only.
  const auto place = puck_cmd<llsf_msgs::PlacePuckUnderMachine>("M1", 3);
  CHECK(h.udp(place).status == ReceiveStatus::kRejected);
  h.step();
  CHECK_FALSE(h.p.refbox().machine(M(1)).puck_under_rfid.valid());
  CHECK(h.tcp(place).status == ReceiveStatus::kAccepted);
  h.step();
  CHECK(h.p.refbox().machine(M(1)).puck_under_rfid == PuckId(3));
  CHECK(h.p.refbox().machine(M(1)).state == MachineState::kProcessing);
  // RemovePuckFromMachine: a UDP copy is logged as illegal but applied.
  r = h.udp(puck_cmd<llsf_msgs::RemovePuckFromMachine>("M1", 3));
  CHECK(r.status == ReceiveStatus::kAcceptedIllegal);
  h.step();
  CHECK_FALSE(h.p.refbox().machine(M(1)).puck_under_rfid.valid());
  CHECK(h.tcp(puck_cmd<llsf_msgs::RemovePuckFromMachine>("M1", 3)).status ==
        ReceiveStatus::kAccepted);
  // LoadPuckInMachine: M2 is T2; an S0 loaded from the stream joins its loaded list.
  const auto load = puck_cmd<llsf_msgs::LoadPuckInMachine>("M2", 4);
  CHECK(h.udp(load).status == ReceiveStatus::kRejected);
  h.step();
  CHECK(h.p.refbox().machine(M(2)).loaded_count == 0);
  CHECK(h.tcp(load).status == ReceiveStatus::kAccepted);
  h.step();
  REQUIRE(h.p.refbox().machine(M(2)).loaded_count == 1);
  h.run_s(0.3);
  const auto* cv = h.last_msg<llsf_msgs::MachineInfo>(Kind::kAllClients);
  REQUIRE(cv->machines(1).loaded_with_size() == 1);
  CHECK(cv->machines(1).loaded_with(0).id() == 4);
  CHECK(cv->machines(1).loaded_with(0).state() == llsf_msgs::S0);

  // SetPucks and MachineReport: any channel.
  llsf_msgs::SetPucks sp;
  for (std::uint32_t id : {31u, 32u, 33u}) sp.add_ids(id);
  CHECK(h.udp(sp).status == ReceiveStatus::kAccepted);
  h.step();
  REQUIRE(h.p.refbox().pucks().size() == 3);
  CHECK(h.p.refbox().pucks()[0].id == PuckId(31));
  CHECK(h.tcp(sp).status == ReceiveStatus::kAccepted);
  // BeaconSignal only via UDP.
  CHECK(h.tcp(robot_beacon(h.next, "R-1", 1)).status == ReceiveStatus::kRejected);
  CHECK(h.udp(robot_beacon(h.next, "R-1", 1)).status == ReceiveStatus::kAccepted);
  // Sync messages and refbox output messages are not accepted.
  CHECK(h.tcp(llsf_msgs::InitiateSync()).status == ReceiveStatus::kRejected);
  llsf_msgs::AttentionMessage am;
  am.set_message("hi");
  r = h.udp(am);
  CHECK(r.status == ReceiveStatus::kRejected);
  CHECK(r.reason.find("llsf_msgs.AttentionMessage") != std::string::npos);
}

TEST_CASE("protocol: MachineReport via either channel, scored only in EXPLORATION") {
  Harness h;
  h.p.client_connected(1);
  h.step();
  auto r = h.udp(report({{"M1", "T1"}}));
  CHECK(r.status == ReceiveStatus::kRejected);
  CHECK(r.reason.find("EXPLORATION") != std::string::npos);
  start_in(h, llsf_msgs::GameState::EXPLORATION);
  CHECK(h.udp(report({{"M1", "T1"}})).status == ReceiveStatus::kAccepted);
  CHECK(h.tcp(report({{"M3", "T3"}})).status == ReceiveStatus::kAccepted);
  h.step();
  CHECK(h.p.refbox().points() == 8);
  // Unknown names are dropped with a reason; the rest counts.
  r = h.udp(report({{"M11", "T1"}, {"D1", "DELIVER"}, {"M4", "T4"}}));
  CHECK(r.status == ReceiveStatus::kAccepted);
  CHECK(r.reason.find("'M11'") != std::string::npos);
  CHECK(r.reason.find("'D1'") != std::string::npos);
  h.step();
  CHECK(h.p.refbox().points() == 12);
  r = h.udp(report({{"X", "T1"}}));
  CHECK(r.status == ReceiveStatus::kRejected);
  CHECK(r.reason.find("'X'") != std::string::npos);
  CHECK(h.udp(llsf_msgs::MachineReport()).status == ReceiveStatus::kRejected);
}

TEST_CASE("protocol: bad input is rejected with a reason, never a crash") {
  Harness h;
  h.p.client_connected(1);
  start_in(h, llsf_msgs::GameState::PRODUCTION);

  // Missing required fields.
  llsf_msgs::PlacePuckUnderMachine no_id;
  no_id.set_machine_name("M1");
  auto r = h.tcp(no_id);
  CHECK(r.status == ReceiveStatus::kRejected);
  CHECK(r.reason.find("puck_id") != std::string::npos);
  llsf_msgs::BeaconSignal no_time;
  no_time.set_seq(1);
  no_time.set_team_name("T");
  no_time.set_peer_name("P");
  no_time.set_number(1);
  CHECK(h.udp(no_time).status == ReceiveStatus::kRejected);
  CHECK(h.tcp(llsf_msgs::SetGameState()).status == ReceiveStatus::kRejected);

  // Unknown machine names, bad puck ids, wrong machine kinds.
  r = h.tcp(puck_cmd<llsf_msgs::PlacePuckUnderMachine>("M11", 1));
  CHECK(r.status == ReceiveStatus::kRejected);
  CHECK(r.reason.find("unknown machine 'M11'") != std::string::npos);
  CHECK(h.tcp(puck_cmd<llsf_msgs::RemovePuckFromMachine>("m1", 1)).status ==
        ReceiveStatus::kRejected);
  CHECK(h.tcp(puck_cmd<llsf_msgs::PlacePuckUnderMachine>("M1", 0)).status ==
        ReceiveStatus::kRejected);
  CHECK(h.tcp(puck_cmd<llsf_msgs::PlacePuckUnderMachine>("M1", 0xFFFFFFFFu)).status ==
        ReceiveStatus::kRejected);
  r = h.tcp(puck_cmd<llsf_msgs::LoadPuckInMachine>("D1", 1));
  CHECK(r.status == ReceiveStatus::kRejected);
  CHECK(r.reason.find("no production machine") != std::string::npos);
  llsf_msgs::SetPucks dup;
  dup.add_ids(1);
  dup.add_ids(1);
  CHECK(h.tcp(dup).status == ReceiveStatus::kRejected);
  llsf_msgs::SetRobotMaintenance big;
  big.set_robot_number(0xFFFFFFFFu);
  big.set_maintenance(true);
  CHECK(h.tcp(big).status == ReceiveStatus::kRejected);

  // Beacons: absurd time and number rejected; a non-finite pose is dropped, the beacon kept.
  auto b = robot_beacon(h.next, "R-1", 1);
  b.mutable_time()->set_sec(std::numeric_limits<std::int64_t>::max());
  CHECK(h.udp(b).status == ReceiveStatus::kRejected);
  b = robot_beacon(h.next, "R-1", 1);
  b.mutable_time()->set_nsec(-5);
  CHECK(h.udp(b).status == ReceiveStatus::kRejected);
  b = robot_beacon(h.next, "R-1", 0x80000000u);
  CHECK(h.udp(b).status == ReceiveStatus::kRejected);
  b = robot_beacon(h.next, "R-1", 1);
  b.mutable_pose()->set_x(std::numeric_limits<float>::quiet_NaN());
  r = h.udp(b, "10.0.0.5", 4444);
  CHECK(r.status == ReceiveStatus::kAccepted);
  CHECK(r.reason.find("not finite") != std::string::npos);
  // Outside PRODUCTION / RUNNING: the puck commands are refused with the phase in the reason.
  CHECK(h.tcp(set_state(llsf_msgs::GameState::PAUSED)).status == ReceiveStatus::kAccepted);
  h.step();
  r = h.tcp(puck_cmd<llsf_msgs::PlacePuckUnderMachine>("M1", 1));
  CHECK(r.status == ReceiveStatus::kRejected);
  CHECK(r.reason.find("RUNNING") != std::string::npos);
  h.run_s(1);
  REQUIRE(h.p.refbox().robots().size() == 1);
  CHECK_FALSE(h.p.refbox().robots()[0].pose.has_value());
  CHECK_FALSE(h.p.refbox().machine(M(1)).puck_under_rfid.valid());
  // Every rejection was logged.
  CHECK(h.msgs<llsf_log_msgs::LogMessage>(Kind::kAllClients).size() >= 14);
}

TEST_CASE("protocol: a message built by reflection (DynamicMessage) is understood") {
  Harness h;
  h.p.client_connected(1);
  h.step();
  google::protobuf::DynamicMessageFactory factory;
  const auto* desc = llsf_msgs::SetGameState::descriptor();
  std::unique_ptr<Message> m(factory.GetPrototype(desc)->New());
  m->GetReflection()->SetEnumValue(m.get(), desc->FindFieldByName("state"),
                                   llsf_msgs::GameState::RUNNING);
  CHECK(h.tcp(*m).status == ReceiveStatus::kAccepted);
  h.step();
  CHECK(h.p.refbox().state() == GameState::kRunning);
  CHECK(h.p.refbox().phase() == GamePhase::kSetup);
}

TEST_CASE("protocol: a short game driven only by messages") {
  RefboxConfig cfg = test_config();
  cfg.team = "";
  cfg.setup_duration = SimTime::from_sec(5);
  cfg.exploration_duration = SimTime::from_sec(10);
  cfg.production_duration = SimTime::from_sec(60);
  Harness h(cfg);
  h.p.client_connected(1);
  h.step();
  llsf_msgs::SetTeamName tn;
  tn.set_team_name("Carologistics");
  CHECK(h.tcp(tn).status == ReceiveStatus::kAccepted);
  CHECK(h.tcp(set_state(llsf_msgs::GameState::RUNNING)).status == ReceiveStatus::kAccepted);
  h.step();
  CHECK(h.p.refbox().phase() == GamePhase::kSetup);
  // A robot announces itself during setup and reports in exploration.
  CHECK(h.udp(robot_beacon(h.next, "R-1", 1)).status == ReceiveStatus::kAccepted);
  h.run_until([&] { return h.p.refbox().phase() == GamePhase::kExploration; });
  CHECK(h.udp(report({{"M1", "T1"}, {"M2", "T2"}, {"M3", "T1"}})).status ==
        ReceiveStatus::kAccepted);
  h.run_until([&] { return h.p.refbox().phase() == GamePhase::kProduction; });
  CHECK(h.p.refbox().phase_points(GamePhase::kExploration) == 5);
  // Production by the controller: S0 under M1 (T1, 4 s) -> S1; an S0 loaded into M2 (T2) waits
  // for an S1; the S1 under M2 completes the T2 (20 s): S2, +4.
  CHECK(h.tcp(puck_cmd<llsf_msgs::PlacePuckUnderMachine>("M1", 1)).status ==
        ReceiveStatus::kAccepted);
  CHECK(h.tcp(puck_cmd<llsf_msgs::LoadPuckInMachine>("M2", 2)).status == ReceiveStatus::kAccepted);
  h.run_s(4.5);
  CHECK(h.p.refbox().puck_state(PuckId(1)) == PuckState::kS1);
  CHECK(h.p.refbox().machine(M(2)).state == MachineState::kWaiting);
  CHECK(h.tcp(puck_cmd<llsf_msgs::RemovePuckFromMachine>("M1", 1)).status ==
        ReceiveStatus::kAccepted);
  h.step();
  CHECK_FALSE(h.p.refbox().machine(M(1)).puck_under_rfid.valid());
  CHECK(h.tcp(puck_cmd<llsf_msgs::PlacePuckUnderMachine>("M2", 1)).status ==
        ReceiveStatus::kAccepted);
  h.run_s(21);
  CHECK(h.p.refbox().puck_state(PuckId(1)) == PuckState::kS2);
  CHECK(h.p.refbox().puck_state(PuckId(2)) == PuckState::kConsumed);
  // The controller sees the result in PuckInfo and MachineInfo.
  const auto* pi = h.last_msg<llsf_msgs::PuckInfo>(Kind::kAllClients);
  CHECK(pi->pucks(0).state() == llsf_msgs::S2);
  CHECK(pi->pucks(1).state() == llsf_msgs::CONSUMED);
  const auto* cv = h.last_msg<llsf_msgs::MachineInfo>(Kind::kAllClients);
  CHECK(cv->machines(1).puck_under_rfid().id() == 1);
  CHECK(cv->machines(1).lights(2).state() == llsf_msgs::ON);  // idle: green
  // Phase switches were announced to the controller.
  std::vector<std::string> switches;
  for (const auto* a : h.msgs<llsf_msgs::AttentionMessage>(Kind::kAllClients)) {
    if (a->message().rfind("Switching to ", 0) == 0) switches.push_back(a->message());
  }
  CHECK(switches == std::vector<std::string>{"Switching to SETUP", "Switching to EXPLORATION",
                                             "Switching to PRODUCTION"});
  // To the end of the game.
  h.run_until([&] { return h.p.refbox().phase() == GamePhase::kPostGame; });
  h.run_s(1.1);
  const auto* gs = h.last_msg<llsf_msgs::GameState>(Kind::kAllPeers);
  CHECK(gs->phase() == llsf_msgs::GameState::POST_GAME);
  CHECK(gs->state() == llsf_msgs::GameState::PAUSED);
  CHECK(gs->points() == 9);
  CHECK(gs->team() == "Carologistics");
  CHECK(h.p.refbox().points() == 9);
  // No robot view or OrderInfo after production.
  const double end = h.last.seconds();
  h.run_s(5);
  CHECK(h.times<llsf_msgs::OrderInfo>(Kind::kAllPeers, end + 0.001).empty());
  CHECK(h.times<llsf_msgs::MachineInfo>(Kind::kAllPeers, end + 0.001).empty());
}

TEST_CASE("protocol: messages are reused once nobody holds them") {
  RefboxProtocol p(test_config(), core::Rng(1));
  p.client_connected(1);
  const auto puck_info = [&]() -> const Message* {
    for (const Outgoing& o : p.outgoing()) {
      if (dynamic_cast<const llsf_msgs::PuckInfo*>(o.message.get())) return o.message.get();
    }
    return nullptr;
  };
  p.step(SimTime(), {});
  const Message* first = puck_info();
  REQUIRE(first != nullptr);
  p.step(SimTime::from_sec(1), {});
  CHECK(puck_info() == first);
  // Held by a receiver beyond the step: the next one is another object, the held one unchanged.
  std::shared_ptr<const Message> held;
  for (const Outgoing& o : p.outgoing()) {
    if (o.message.get() == first) held = o.message;
  }
  p.step(SimTime::from_sec(2), {});
  CHECK(puck_info() != nullptr);
  CHECK(puck_info() != first);
  CHECK(dynamic_cast<const llsf_msgs::PuckInfo*>(held.get())->pucks_size() == 20);
}

TEST_CASE("protocol: bad ProtocolConfig is refused at construction") {
  ProtocolConfig pc;
  pc.order_info_period = SimTime();
  CHECK_THROWS_WITH_AS(RefboxProtocol(test_config(), core::Rng(1), pc),
                       "protocol.order_info_period: must be > 0", core::ConfigError);
}

TEST_CASE(
    "protocol: GameState.refbox_mode follows the engine's mode; vision poses reach RobotInfo") {
  RefboxConfig cfg = test_config();
  cfg.mode = RefBoxMode::kMaster;
  cfg.params.reset();  // a synchronised plan covers the overtime; let the engine draw one
  Harness h(cfg);
  h.p.client_connected(1);
  h.udp(robot_beacon(SimTime(), "R-1", 1));
  const std::vector<RobotPose> seen = {{1, core::Pose2D{3.0, 4.0, 1.0}}};
  h.step();
  h.world.robot_poses = seen;
  h.step();
  h.world.robot_poses = {};
  h.run_s(1.1);
  CHECK(int(to_msg_mode(RefBoxMode::kSlave)) == 2);
  const auto* gs = h.last_msg<llsf_msgs::GameState>(Kind::kAllClients);
  CHECK(gs->refbox_mode() == llsf_msgs::GameState::MASTER);
  CHECK_FALSE(h.last_msg<llsf_msgs::GameState>(Kind::kAllPeers)->has_refbox_mode());
  REQUIRE(h.p.refbox().robots().size() == 1);
  REQUIRE(h.p.refbox().robots()[0].vision_pose.has_value());
  const auto* ri = h.last_msg<llsf_msgs::RobotInfo>(Kind::kAllClients);
  REQUIRE(ri->robots(0).has_vision_pose());
  CHECK(ri->robots(0).vision_pose().x() == doctest::Approx(3.0f));
  CHECK_FALSE(h.last_msg<llsf_msgs::RobotInfo>(Kind::kAllPeers)->robots(0).has_vision_pose());
}

TEST_CASE("protocol: SyncInfo round trip and bad SyncInfo") {
  const GameParams p = test_params();
  llsf_msgs::SyncInfo si;
  to_sync_info(p, si);
  CHECK(si.IsInitialized());
  CHECK(si.machines_size() == 10);
  CHECK(si.orders_size() == 11);
  CHECK(si.orders(9).late_order());
  CHECK(si.delivery_gates_size() == 3);
  CHECK(si.proc_times_size() == 5);
  REQUIRE(si.exploration_lights_size() == 5);
  CHECK(si.exploration_lights(0).lights_size() == 3);
  std::string error;
  const auto back = from_sync_info(si, error);
  REQUIRE(back.has_value());
  CHECK(*back == p);
  CHECK(error.empty());

  llsf_msgs::SyncInfo missing = si;
  missing.mutable_machines()->RemoveLast();
  CHECK_FALSE(from_sync_info(missing, error).has_value());
  CHECK(error == "no type for M10");
  llsf_msgs::SyncInfo bad_type = si;
  bad_type.mutable_machines(0)->set_type("RECYCLE");
  CHECK_FALSE(from_sync_info(bad_type, error).has_value());
  CHECK(error.find("unknown type 'RECYCLE'") != std::string::npos);
  llsf_msgs::SyncInfo bad_time = si;
  bad_time.mutable_delivery_gates(0)->set_gt_to(std::numeric_limits<float>::infinity());
  CHECK_FALSE(from_sync_info(bad_time, error).has_value());
  llsf_msgs::SyncInfo no_order = si;
  no_order.mutable_orders()->RemoveLast();
  CHECK_FALSE(from_sync_info(no_order, error).has_value());
  CHECK(error == "order 11 missing");
}

TEST_CASE("protocol: master/slave: InitiateSync, SyncInfo, GameState between the refboxes") {
  RefboxConfig mc = test_config();
  mc.mode = RefBoxMode::kMaster;
  mc.params.reset();
  mc.production_duration = SimTime::from_sec(10);
  RefboxConfig sc = mc;
  sc.mode = RefBoxMode::kSlave;
  RefboxProtocol master(mc, core::Rng(1));
  RefboxProtocol slave(sc, core::Rng(2));
  master.client_connected(5);  // the slave's connection to the master's stream server
  slave.master_connected();
  int initiate = 0, sync_info = 0, slave_states = 0, master_states = 0;
  SimTime t;
  const auto relay = [&] {
    for (const Outgoing& o : slave.step(t, {})) {
      if (o.to.kind != Kind::kMaster) continue;
      const auto r = master.receive(*o.message, Origin::stream(5));
      CHECK(r.status == ReceiveStatus::kAccepted);
      if (dynamic_cast<const llsf_msgs::InitiateSync*>(o.message.get())) ++initiate;
      if (const auto* g = dynamic_cast<const llsf_msgs::GameState*>(o.message.get())) {
        CHECK(g->refbox_mode() == llsf_msgs::GameState::SLAVE);
        ++slave_states;
      }
    }
    for (const Outgoing& o : master.step(t, {})) {
      const bool to_slave = o.to.kind == Kind::kAllClients || o.to == Destination{Kind::kClient, 5};
      const bool sync = dynamic_cast<const llsf_msgs::SyncInfo*>(o.message.get()) ||
                        dynamic_cast<const llsf_msgs::GameState*>(o.message.get());
      if (!to_slave || !sync) continue;
      const auto r = slave.receive(*o.message, Origin::master());
      CHECK(r.status == ReceiveStatus::kAccepted);
      if (dynamic_cast<const llsf_msgs::SyncInfo*>(o.message.get())) ++sync_info;
      if (dynamic_cast<const llsf_msgs::GameState*>(o.message.get())) ++master_states;
    }
    t += kStep;
  };
  for (int i = 0; i < 300; ++i) relay();
  CHECK(initiate == 1);
  CHECK(sync_info == 1);
  CHECK(slave_states == 3);
  CHECK(master_states == 3);
  // Both start; the slave plays the master's plan.
  for (RefboxProtocol* p : {&master, &slave}) {
    p->receive(set_phase(llsf_msgs::GameState::PRODUCTION), Origin::stream(1));
    p->receive(set_state(llsf_msgs::GameState::RUNNING), Origin::stream(1));
  }
  relay();
  REQUIRE(master.refbox().params().has_value());
  REQUIRE(slave.refbox().params().has_value());
  CHECK(*slave.refbox().params() == *master.refbox().params());
  // At the regular end both pause; each one's GameState tells the other that the game is over
  // with 0 : 0 points, so no overtime: POST_GAME.
  while (t < SimTime::from_sec(3 + 13)) relay();
  CHECK(master.refbox().phase() == GamePhase::kPostGame);
  CHECK(slave.refbox().phase() == GamePhase::kPostGame);
  // Without the other's GameState a master keeps waiting.
  RefboxProtocol lone(mc, core::Rng(1));
  lone.receive(set_phase(llsf_msgs::GameState::PRODUCTION), Origin::stream(1));
  lone.receive(set_state(llsf_msgs::GameState::RUNNING), Origin::stream(1));
  for (SimTime u; u < SimTime::from_sec(13); u += kStep) lone.step(u, {});
  CHECK(lone.refbox().phase() == GamePhase::kProduction);
  CHECK(lone.refbox().awaiting_overtime_decision());
  // Once the game left PRE_GAME, a SyncInfo is refused with the engine's reason.
  llsf_msgs::SyncInfo again;
  to_sync_info(*master.refbox().params(), again);
  const auto r = slave.receive(again, Origin::master());
  CHECK(r.status == ReceiveStatus::kRejected);
  CHECK(r.reason.find("already") != std::string::npos);
  // Sync messages where they do not belong.
  RefboxProtocol standalone(test_config(), core::Rng(1));
  CHECK(standalone.receive(llsf_msgs::InitiateSync(), Origin::stream(1)).status ==
        ReceiveStatus::kRejected);
  CHECK(standalone.receive(again, Origin::master()).status == ReceiveStatus::kRejected);
  llsf_msgs::GameState gs;
  gs.mutable_game_time()->set_sec(1);
  gs.mutable_game_time()->set_nsec(0);
  gs.set_state(llsf_msgs::GameState::RUNNING);
  gs.set_phase(llsf_msgs::GameState::PRODUCTION);
  CHECK(standalone.receive(gs, Origin::stream(1)).status == ReceiveStatus::kRejected);
  CHECK(slave.receive(gs, Origin::stream(1)).status == ReceiveStatus::kRejected);
  CHECK(master.receive(gs, Origin::peer("10.0.0.1", 4444)).status == ReceiveStatus::kRejected);
  CHECK(slave.receive(robot_beacon(t, "R", 1), Origin::master()).status ==
        ReceiveStatus::kRejected);
}

TEST_CASE("protocol: a controller connecting keeps the peers' RobotInfo and MachineInfo rhythm") {
  Harness h;
  start_in(h, llsf_msgs::GameState::PRODUCTION);
  h.run_s(1.0);
  const auto peers_robot_info = h.times<llsf_msgs::RobotInfo>(Kind::kAllPeers);
  const auto peers_machine_info = h.times<llsf_msgs::MachineInfo>(Kind::kAllPeers);
  REQUIRE(!peers_robot_info.empty());
  // A controller reconnecting in a loop, every 0.2 s, for 1 s (the peers' RobotInfo is due at
  // 2.5 s).
  for (int i = 0; i < 5; ++i) {
    h.p.client_connected(i + 1);
    h.run_s(0.2);
    h.p.client_disconnected(i + 1);
  }
  // No RobotInfo to the peers since (next due 2.5 s after the first), and the MachineInfo burst
  // (0.5 s) went on at its own pace: one per 0.5 s, not one per connection.
  CHECK(h.times<llsf_msgs::RobotInfo>(Kind::kAllPeers) == peers_robot_info);
  CHECK(h.times<llsf_msgs::MachineInfo>(Kind::kAllPeers).size() <= peers_machine_info.size() + 2);
  // The controllers' own messages did restart for each connection.
  CHECK(h.times<llsf_msgs::RobotInfo>(Kind::kAllClients).size() >= 5);
}
