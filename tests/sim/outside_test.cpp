// SPDX-License-Identifier: MIT
// The game's interface to the outside world (a socket bridge such as `llsfsim run
// --refbox-sockets` calls it between ticks): external radio peers and stream clients, without
// sockets.
#include <doctest/doctest.h>
#include <llsf_msgs/BeaconSignal.pb.h>
#include <llsf_msgs/GameInfo.pb.h>
#include <llsf_msgs/GameState.pb.h>
#include <llsf_msgs/VersionInfo.pb.h>

#include <algorithm>
#include <string>
#include <vector>

#include "llsf/core/error.h"
#include "llsf/sim/game.h"

using namespace llsf;
using namespace llsf::sim;

namespace {

GameConfig with_peers(std::vector<ExternalPeerConfig> peers) {
  GameConfig c;
  c.external_peers = std::move(peers);
  return c;
}

llsf_msgs::BeaconSignal beacon(const std::string& name) {
  llsf_msgs::BeaconSignal b;
  b.mutable_time()->set_sec(0);
  b.mutable_time()->set_nsec(0);
  b.set_seq(1);
  b.set_team_name("T");
  b.set_peer_name(name);
  b.set_number(9);
  return b;
}

const refbox::Robot* robot_named(const Game& g, const std::string& name) {
  const auto& rs = g.refbox().robots();
  const auto it =
      std::find_if(rs.begin(), rs.end(), [&](const refbox::Robot& r) { return r.name == name; });
  return it == rs.end() ? nullptr : &*it;
}

/// Type names of what the hub delivered (beacons with their peer name: "...BeaconSignal:robot1") to
/// `peer` over the next `ticks` ticks.
std::vector<std::string> heard(Game& g, comm::PeerId peer, int ticks) {
  std::vector<std::string> out;
  for (int i = 0; i < ticks; ++i) {
    g.step();
    for (const comm::Delivery& d : g.hub().received(peer)) {
      std::string name = g.registry().name_at(d.type_index);
      if (name == "llsf_msgs.BeaconSignal") {
        name += ":" + static_cast<const llsf_msgs::BeaconSignal&>(*g.hub().decode(d)).peer_name();
      }
      out.push_back(name);
    }
  }
  return out;
}

bool contains(const std::vector<std::string>& v, const std::string& s) {
  return std::find(v.begin(), v.end(), s) != v.end();
}

}  // namespace

TEST_CASE("game outside: external peer names are unique among the radio's peers") {
  CHECK_THROWS_WITH_AS(Game(with_peers({{"robot2", "team"}})),
                       "game.external_peers[0].name: 'robot2' is the name of another radio peer",
                       core::ConfigError);
  CHECK_THROWS_WITH_AS(Game(with_peers({{"a", "team"}, {"refbox", "team"}})),
                       "game.external_peers[1].name: 'refbox' is the name of another radio peer",
                       core::ConfigError);
  CHECK_THROWS_WITH_AS(Game(with_peers({{"a", "team"}, {"a", "public"}})),
                       "game.external_peers[1].name: 'a' is the name of another radio peer",
                       core::ConfigError);
  CHECK_THROWS_WITH_AS(Game(with_peers({{"", "team"}})),
                       "game.external_peers[0].name: must not be empty", core::ConfigError);
  // The hub's links may name an external peer, as any other peer.
  GameConfig c = with_peers({{"ext1", "team"}});
  c.hub.loss_model = comm::LossModel::kPerLink;
  c.hub.links.push_back({"refbox", "ext1", true, 1.0, {}, {}});
  const Game g(c);
  CHECK(g.hub().peer_name(g.external_peer(0)) == "ext1");
  CHECK(g.external_peer(0).value() == 1 + g.robot_count());  // after the refbox and the robots
}

TEST_CASE("game outside: an external peer is heard by the refbox once its origin is known") {
  Game g(with_peers({{"ext1", "team"}, {"logger", "public"}}));
  const comm::PeerId ext = g.external_peer(0);
  const comm::PeerId logger = g.external_peer(1);
  g.start(refbox::GamePhase::kExploration);
  // Without an origin its beacon goes over the radio (the robots' channel) but not to the refbox.
  REQUIRE(g.hub().broadcast(ext, beacon("ext1"), g.time()) == comm::FrameError::kNone);
  for (int i = 0; i < 10; ++i) g.step();
  CHECK(robot_named(g, "ext1") == nullptr);
  g.set_external_origin(0, "127.0.0.1", 5000);
  REQUIRE(g.hub().broadcast(ext, beacon("ext1"), g.time()) == comm::FrameError::kNone);
  for (int i = 0; i < 10; ++i) g.step();
  const refbox::Robot* r = robot_named(g, "ext1");
  REQUIRE(r != nullptr);
  CHECK(r->host == "127.0.0.1");
  CHECK(r->port == 5000);
  CHECK(r->number == 9);
  // Channel "team" hears the robots' beacons and the refbox; another channel only the refbox.
  const std::vector<std::string> team = heard(g, ext, 150);
  CHECK(contains(team, "llsf_msgs.GameState"));
  CHECK(contains(team, "llsf_msgs.BeaconSignal:RefBox"));
  CHECK(contains(team, "llsf_msgs.BeaconSignal:robot1"));
  REQUIRE(g.hub().broadcast(ext, beacon("ext1"), g.time()) == comm::FrameError::kNone);
  const std::vector<std::string> pub = heard(g, logger, 150);
  CHECK(contains(pub, "llsf_msgs.GameState"));
  CHECK(contains(pub, "llsf_msgs.BeaconSignal:RefBox"));
  CHECK_FALSE(contains(pub, "llsf_msgs.BeaconSignal:robot1"));
  CHECK_FALSE(contains(pub, "llsf_msgs.BeaconSignal:ext1"));
}

TEST_CASE("game outside: stream clients are greeted and their commands take effect") {
  Game g{GameConfig{}};
  g.start(refbox::GamePhase::kExploration);
  g.step();
  // Before a client: nothing for clients is built.
  for (const refbox::Outgoing& o : g.refbox_outgoing()) {
    CHECK(o.to.kind != refbox::Destination::Kind::kClient);
    CHECK(o.to.kind != refbox::Destination::Kind::kAllClients);
  }
  g.controller_connected(3);
  g.step();
  std::vector<std::string> to_client;
  bool all_clients = false;
  for (const refbox::Outgoing& o : g.refbox_outgoing()) {
    if (o.to.kind == refbox::Destination::Kind::kClient && o.to.client == 3) {
      to_client.push_back(o.message->GetTypeName());
    }
    all_clients = all_clients || o.to.kind == refbox::Destination::Kind::kAllClients;
  }
  CHECK(to_client == std::vector<std::string>{"llsf_msgs.VersionInfo", "llsf_msgs.GameInfo"});
  CHECK(all_clients);  // GameState, MachineInfo, RobotInfo, PuckInfo at once
  // A controller pauses the game; a beacon over the stream is refused (2013 channel rules).
  llsf_msgs::SetGameState pause;
  pause.set_state(llsf_msgs::GameState::PAUSED);
  CHECK(g.controller_command(pause, 3, "127.0.0.1", 40000).status ==
        refbox::ReceiveStatus::kAccepted);
  CHECK(g.controller_command(beacon("x"), 3, "127.0.0.1", 40000).status ==
        refbox::ReceiveStatus::kRejected);
  g.step();
  CHECK(g.refbox().state() == refbox::GameState::kPaused);
  const SimTime stopped = g.refbox().game_time();
  for (int i = 0; i < 100; ++i) g.step();
  CHECK(g.refbox().game_time() == stopped);
  CHECK(g.summary().controller_rejected == 1);
  g.controller_disconnected(3);
  g.step();
  for (const refbox::Outgoing& o : g.refbox_outgoing()) {
    CHECK(o.to.kind != refbox::Destination::Kind::kAllClients);
  }
}
