// SPDX-License-Identifier: MIT
// The socket transports on 127.0.0.1: a UDP round trip through the hub with 50 % loss, address
// learning, malformed datagrams; the TCP stream server with a client that sends one byte at a
// time. Ports are chosen by the OS (bind to port 0). Every wait is bounded by count and by a
// wall-clock deadline; no test asserts on timing.
#include <doctest/doctest.h>
#include <llsf_agent_msgs/LockMessage.pb.h>

#include <algorithm>
#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/ip/udp.hpp>
#include <boost/asio/write.hpp>
#include <chrono>
#include <cmath>
#include <set>
#include <string>
#include <string_view>
#include <vector>

#include "comm/loopback.h"
#include "llsf/comm/stream.h"
#include "llsf/comm/udp_hub.h"

using namespace llsf::comm;
using namespace llsf::comm::test;
namespace asio = boost::asio;
using asio::ip::tcp;
using asio::ip::udp;
using Clock = std::chrono::steady_clock;
using std::chrono::milliseconds;

TEST_CASE("UDP: round trip through the hub on 127.0.0.1 with 50 % loss") {
  const MessageRegistry reg = registry();
  asio::io_context io;
  Endpoint a(io), b(io);
  HubConfig cfg;
  cfg.loss_model = LossModel::kPerLink;
  cfg.loss_probability = 0.5;
  cfg.delay.fixed = SimTime::from_ms(0);
  UdpHub hub(cfg, reg, llsf::core::Rng(3));
  const PeerId pa = hub.add_peer({"robot1", "team", 0, a.port()});
  const PeerId pb = hub.add_peer({"robot2", "team", 0, b.port()});
  REQUIRE(hub.listen_port(pa) > 0);
  REQUIRE(hub.listen_port(pb) != hub.listen_port(pa));

  // Paced in small batches so that no socket buffer overflows: send, let the hub forward, read.
  constexpr int kFrames = 400;
  std::vector<int> got;
  const auto deadline = Clock::now() + std::chrono::seconds(10);
  const auto& link = hub.hub().link_counters(pa, pb);
  for (int i = 0; i < kFrames; ++i) {
    a.send(reg.encode(lock(i)), hub.listen_port(pa));
    // Wait until the hub has taken this frame (bounded).
    while (link.sent < i + 1 && Clock::now() < deadline) hub.run_for(milliseconds(1));
    for (const auto& d : b.drain()) {
      const auto m = reg.decode_datagram(d);
      REQUIRE(m.error == FrameError::kNone);
      got.push_back(std::stoi(
          dynamic_cast<const llsf_agent_msgs::LockMessage&>(*m.message).resource().substr(1)));
    }
  }
  while (static_cast<std::int64_t>(got.size()) < link.delivered && Clock::now() < deadline) {
    hub.run_for(milliseconds(2));
    for (const auto& d : b.drain()) {
      const auto m = reg.decode_datagram(d);
      REQUIRE(m.error == FrameError::kNone);
      got.push_back(std::stoi(
          dynamic_cast<const llsf_agent_msgs::LockMessage&>(*m.message).resource().substr(1)));
    }
  }
  REQUIRE(link.sent == kFrames);
  CHECK(link.delivered + link.dropped_by(DropCause::kLoss) == kFrames);
  CHECK(static_cast<std::int64_t>(got.size()) == link.delivered);
  // 400 draws of p = 0.5: sd 10 frames; allow 60 (6 sigma).
  CHECK(std::abs(static_cast<double>(got.size()) - 200.0) < 60.0);
  // No delay, no reordering on loopback: received in send order, each at most once.
  CHECK(std::is_sorted(got.begin(), got.end()));
  CHECK(std::set<int>(got.begin(), got.end()).size() == got.size());
  // Nothing went back to the sender.
  CHECK(a.drain().empty());
}

TEST_CASE("UDP: an external peer's address is learnt from its first datagram; bad ones count") {
  const MessageRegistry reg = registry();
  asio::io_context io;
  Endpoint a(io), b(io);
  HubConfig cfg;
  cfg.delay.fixed = SimTime::from_ms(1);
  UdpHub hub(cfg, reg, llsf::core::Rng(3));
  const PeerId pa = hub.add_peer({"robot1", "team", 0, 0});
  const PeerId pb = hub.add_peer({"refbox", "*", 0, 0});
  const auto& ab = hub.hub().link_counters(pa, pb);
  const auto& ba = hub.hub().link_counters(pb, pa);
  const auto deadline = Clock::now() + std::chrono::seconds(5);

  // robot1 speaks first: the refbox has not sent anything yet, so its copy cannot be delivered.
  a.send(reg.encode(lock(1)), hub.listen_port(pa));
  while (ab.dropped_by(DropCause::kTransport) < 1 && Clock::now() < deadline) {
    hub.run_for(milliseconds(2));
  }
  CHECK(ab.dropped_by(DropCause::kTransport) == 1);

  // Malformed datagrams from the refbox are counted and dropped; a valid one then flows.
  b.send({1, 2, 3}, hub.listen_port(pb));
  b.send(std::vector<std::uint8_t>(1500, 0), hub.listen_port(pb));
  auto bad = reg.encode(lock(2));
  bad[3] = 99;
  b.send(bad, hub.listen_port(pb));
  b.send(reg.encode(lock(3)), hub.listen_port(pb));
  std::vector<std::vector<std::uint8_t>> at_a;
  while (at_a.empty() && Clock::now() < deadline) {
    hub.run_for(milliseconds(2));
    at_a = a.drain();
  }
  REQUIRE(at_a.size() == 1);
  CHECK(reg.decode_datagram(at_a[0]).error == FrameError::kNone);
  const PeerCounters& pc = hub.hub().peer_counters(pb);
  CHECK(pc.malformed_by(FrameError::kShortHeader) == 1);
  CHECK(pc.malformed_by(FrameError::kOversized) == 1);
  CHECK(pc.malformed_by(FrameError::kUnknownType) == 1);
  CHECK(ba.delivered == 1);

  // Now both addresses are known.
  a.send(reg.encode(lock(4)), hub.listen_port(pa));
  std::vector<std::vector<std::uint8_t>> at_b;
  while (at_b.empty() && Clock::now() < deadline) {
    hub.run_for(milliseconds(2));
    at_b = b.drain();
  }
  REQUIRE(at_b.size() == 1);
  CHECK(ab.delivered == 1);

  // An in-process peer's broadcast reaches the socket peers too.
  CHECK(hub.broadcast(pb, lock(5)) == FrameError::kNone);
  at_a.clear();
  while (at_a.empty() && Clock::now() < deadline) {
    hub.run_for(milliseconds(2));
    at_a = a.drain();
  }
  CHECK(at_a.size() == 1);
}

TEST_CASE("UDP: a port that is taken is refused with a clear error") {
  const MessageRegistry reg = registry();
  asio::io_context io;
  Endpoint taken(io);
  UdpHub hub(HubConfig{}, reg, llsf::core::Rng(1));
  CHECK_THROWS_AS(hub.add_peer({"robot1", "team", taken.port(), 0}), std::runtime_error);
  CHECK_THROWS_AS(UdpHub(HubConfig{}, reg, llsf::core::Rng(1), UdpHubOptions{"not-an-ip"}),
                  std::runtime_error);
}

TEST_CASE("TCP: a client that sends a frame one byte at a time; server -> client") {
  const MessageRegistry reg = registry();
  std::vector<std::string> logged;
  StreamServerOptions options{"127.0.0.1", 0};
  options.log = [&logged](std::string_view line) { logged.emplace_back(line); };
  StreamServer server(reg, options);
  REQUIRE(server.port() > 0);

  asio::io_context io;
  tcp::socket raw(io);
  raw.connect(tcp::endpoint(kLoopback, static_cast<unsigned short>(server.port())));
  raw.set_option(tcp::no_delay(true));
  const auto deadline = Clock::now() + std::chrono::seconds(5);

  std::vector<StreamEvent> events;
  const auto pump_until = [&](auto done) {
    while (!done() && Clock::now() < deadline) {
      server.run_for(milliseconds(2));
      for (auto& e : server.take_events()) events.push_back(std::move(e));
    }
  };
  pump_until([&] { return !events.empty(); });
  REQUIRE(events.size() == 1);
  CHECK(events[0].kind == StreamEvent::Kind::kConnected);
  const ClientId client = events[0].client;
  events.clear();

  const auto frame = reg.encode(lock(42));
  for (std::size_t i = 0; i < frame.size(); ++i) {
    asio::write(raw, asio::buffer(&frame[i], 1));
    server.run_for(milliseconds(1));
    for (auto& e : server.take_events()) events.push_back(std::move(e));
    if (i + 1 < frame.size()) REQUIRE(events.empty());  // nothing before the last byte
  }
  pump_until([&] { return !events.empty(); });
  REQUIRE(events.size() == 1);
  CHECK(events[0].kind == StreamEvent::Kind::kMessage);
  CHECK(events[0].client == client);
  CHECK(events[0].key == MessageKey{2100, 1});
  CHECK(dynamic_cast<const llsf_agent_msgs::LockMessage&>(*events[0].message).resource() == "M42");
  events.clear();

  // Two frames and a garbage one (unknown type) in one write: the bad one is skipped and counted.
  auto unknown = reg.encode(lock(0));
  unknown[3] = 77;
  std::vector<std::uint8_t> burst = reg.encode(lock(1));
  burst.insert(burst.end(), unknown.begin(), unknown.end());
  const auto third = reg.encode(lock(3));
  burst.insert(burst.end(), third.begin(), third.end());
  asio::write(raw, asio::buffer(burst));
  pump_until([&] { return events.size() >= 2; });
  REQUIRE(events.size() == 2);
  CHECK(dynamic_cast<const llsf_agent_msgs::LockMessage&>(*events[1].message).resource() == "M3");
  CHECK(server.counters(client).malformed_by(FrameError::kUnknownType) == 1);
  CHECK(server.counters(client).frames_in == 3);
  // ... and logged with its numbers and why.
  REQUIRE(logged.size() == 1);
  CHECK(logged[0].find(": dropped a frame (component 2100, type 77, ") != std::string::npos);
  CHECK(logged[0].find("unknown_type: no message type is registered under these numbers") !=
        std::string::npos);
  events.clear();

  // A flood of bad frames: the first 10 are logged, then one line says the rest are not.
  std::vector<std::uint8_t> flood;
  for (int i = 0; i < 20; ++i) flood.insert(flood.end(), unknown.begin(), unknown.end());
  flood.insert(flood.end(), third.begin(), third.end());
  asio::write(raw, asio::buffer(flood));
  pump_until([&] { return !events.empty(); });
  REQUIRE(events.size() == 1);
  CHECK(server.counters(client).malformed_by(FrameError::kUnknownType) == 21);
  REQUIRE(logged.size() == 11);
  CHECK(logged[10].find("more frames dropped; they are counted, not logged") != std::string::npos);
  events.clear();

  // Server -> raw client.
  CHECK(server.send(client, lock(7)));
  std::vector<std::uint8_t> in;
  StreamDecoder dec;
  raw.non_blocking(true);
  std::optional<std::string> resource;
  while (!resource && Clock::now() < deadline) {
    server.run_for(milliseconds(2));
    std::array<std::uint8_t, 256> buf{};
    boost::system::error_code ec;
    const std::size_t n = raw.read_some(asio::buffer(buf), ec);
    if (!ec) dec.feed(std::span(buf.data(), n));
    const auto next = dec.next();
    if (next.status == StreamDecoder::Next::Status::kFrame) {
      const auto d = reg.decode(next.frame);
      REQUIRE(d.error == FrameError::kNone);
      resource = dynamic_cast<const llsf_agent_msgs::LockMessage&>(*d.message).resource();
    }
  }
  CHECK(resource == "M7");

  // An oversized header closes the connection.
  const std::vector<std::uint8_t> huge{0x08, 0x34, 0x00, 0x01, 0x7f, 0xff, 0xff, 0xff};
  asio::write(raw, asio::buffer(huge));
  pump_until([&] { return !events.empty(); });
  REQUIRE(events.size() == 1);
  CHECK(events[0].kind == StreamEvent::Kind::kDisconnected);
  CHECK(server.counters(client).malformed_by(FrameError::kOversized) == 1);
  CHECK(server.client_count() == 0);
}

TEST_CASE("TCP: StreamClient and StreamServer talk both ways") {
  const MessageRegistry reg = registry();
  StreamServer server(reg, StreamServerOptions{"127.0.0.1", 0});
  StreamClient client(reg);
  REQUIRE(client.connect("127.0.0.1", server.port()));
  CHECK(client.connected());
  const auto deadline = Clock::now() + std::chrono::seconds(5);
  std::vector<StreamEvent> at_server;
  CHECK(client.send(lock(1)));
  while (at_server.size() < 2 && Clock::now() < deadline) {
    client.run_for(milliseconds(1));
    server.run_for(milliseconds(1));
    for (auto& e : server.take_events()) at_server.push_back(std::move(e));
  }
  REQUIRE(at_server.size() == 2);
  CHECK(at_server[0].kind == StreamEvent::Kind::kConnected);
  CHECK(at_server[1].kind == StreamEvent::Kind::kMessage);
  CHECK(server.broadcast(lock(2)) == 1);
  std::vector<StreamEvent> at_client;
  while (at_client.empty() && Clock::now() < deadline) {
    server.run_for(milliseconds(1));
    client.run_for(milliseconds(1));
    for (auto& e : client.take_events()) at_client.push_back(std::move(e));
  }
  REQUIRE(at_client.size() == 1);
  CHECK(dynamic_cast<const llsf_agent_msgs::LockMessage&>(*at_client[0].message).resource() ==
        "M2");
  // The server closes: the client sees it.
  server.disconnect(at_server[0].client);
  at_client.clear();
  while (at_client.empty() && Clock::now() < deadline) {
    server.run_for(milliseconds(1));
    client.run_for(milliseconds(1));
    for (auto& e : client.take_events()) at_client.push_back(std::move(e));
  }
  REQUIRE(at_client.size() == 1);
  CHECK(at_client[0].kind == StreamEvent::Kind::kDisconnected);
  CHECK_FALSE(client.connected());
  // Connecting where nothing listens any more fails, within the timeout.
  int dead_port = 0;
  {
    StreamServer gone(reg, StreamServerOptions{"127.0.0.1", 0});
    dead_port = gone.port();
  }
  StreamClient other(reg);
  CHECK_FALSE(other.connect("127.0.0.1", dead_port, milliseconds(1000)));
  CHECK_FALSE(other.connected());
  CHECK_FALSE(other.connect("not-an-ip", server.port()));
  CHECK(other.connect("127.0.0.1", server.port()));
}
