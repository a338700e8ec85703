// SPDX-License-Identifier: MIT
// Hostile peers on 127.0.0.1 (issue #21, docs/comm.md "Network limits"): a malformed datagram
// must not redirect a peer's traffic, loop configs are refused, and the TCP stream server caps
// its connections, closes connections that leave a frame incomplete and bounds each send queue.
// Ports are chosen by the OS; every wait is bounded by a wall-clock deadline.
#include <doctest/doctest.h>
#include <llsf_agent_msgs/LockMessage.pb.h>

#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/ip/udp.hpp>
#include <boost/asio/write.hpp>
#include <chrono>
#include <string>
#include <vector>

#include "comm/loopback.h"
#include "llsf/comm/socket_config.h"
#include "llsf/comm/stream.h"
#include "llsf/comm/udp_hub.h"
#include "llsf/core/error.h"

using namespace llsf::comm;
using namespace llsf::comm::test;
namespace asio = boost::asio;
using asio::ip::tcp;
using asio::ip::udp;
using Clock = std::chrono::steady_clock;
using std::chrono::milliseconds;

namespace {

std::string socket_config_error(const std::string& yaml) {
  try {
    load_socket_config(llsf::core::ConfigNode::parse(yaml, "sock.yaml"));
  } catch (const llsf::core::ConfigError& e) {
    return e.what();
  }
  return "(no error)";
}

/// True once the peer has closed `s` (read returns EOF or an error), waiting up to `wait`
/// while `pump` drives the server.
template <typename Pump>
bool closed_by_peer(tcp::socket& s, Pump pump, milliseconds wait) {
  s.non_blocking(true);
  const auto deadline = Clock::now() + wait;
  while (Clock::now() < deadline) {
    pump();
    std::array<std::uint8_t, 256> buf{};
    boost::system::error_code ec;
    s.read_some(asio::buffer(buf), ec);
    if (ec && ec != asio::error::would_block) return true;
  }
  return false;
}

}  // namespace

TEST_CASE("UDP: a malformed datagram from another port does not steal a peer's return address") {
  const MessageRegistry reg = registry();
  asio::io_context io;
  Endpoint robot(io), refbox(io), attacker(io);
  HubConfig cfg;
  cfg.delay.fixed = SimTime::from_ms(0);
  UdpHub hub(cfg, reg, llsf::core::Rng(1));
  const PeerId pr = hub.add_peer({"robot1", "team", 0, 0});
  const PeerId pb = hub.add_peer({"refbox", "*", 0, 0});
  const auto deadline = Clock::now() + std::chrono::seconds(5);
  const auto& to_robot = hub.hub().link_counters(pb, pr);

  // Both peers speak once: their addresses are learnt.
  robot.send(reg.encode(lock(1)), hub.listen_port(pr));
  refbox.send(reg.encode(lock(2)), hub.listen_port(pb));
  while (to_robot.delivered < 1 && Clock::now() < deadline) hub.run_for(milliseconds(2));
  REQUIRE(to_robot.delivered == 1);
  CHECK(static_cast<int>(robot.drain().size()) == 1);

  // The attacker sends 3 bytes (and a frame of an unknown type) to the robot's hub port.
  attacker.send({1, 2, 3}, hub.listen_port(pr));
  auto unknown = reg.encode(lock(3));
  unknown[3] = 99;
  attacker.send(unknown, hub.listen_port(pr));
  while (hub.hub().peer_counters(pr).malformed_by(FrameError::kShortHeader) < 1 &&
         Clock::now() < deadline) {
    hub.run_for(milliseconds(2));
  }
  // The refbox's next frame still goes to the robot, not to the attacker.
  refbox.send(reg.encode(lock(4)), hub.listen_port(pb));
  int at_robot = 0;
  while (at_robot == 0 && Clock::now() < deadline) {
    hub.run_for(milliseconds(2));
    at_robot += static_cast<int>(robot.drain().size());
  }
  CHECK(at_robot == 1);
  CHECK(static_cast<int>(attacker.drain().size()) == 0);
  CHECK(to_robot.delivered == 2);
}

TEST_CASE("socket config: a recv_port where the hub listens (a forwarding loop) is refused") {
  CHECK(socket_config_error("udp_peers:\n"
                            "  - {name: a, send_port: 5000, recv_port: 5001}\n"
                            "  - {name: b, send_port: 5002, recv_port: 5000}\n") ==
        "sock.yaml:3:43: udp_peers[1].recv_port: 5000 is where the hub listens for 'a' "
        "(udp_peers[0].send_port): frames would be forwarded in a loop");
  CHECK(socket_config_error("udp_peers:\n  - {name: a, send_port: 5000, recv_port: 5000}\n") ==
        "sock.yaml:2:43: udp_peers[0].recv_port: 5000 is where the hub listens for this peer "
        "(its own send_port): frames would be forwarded in a loop");
  CHECK(socket_config_error("udp_peers:\n  - {name: a, send_port: 5000, recv_port: 5001}\n"
                            "  - {name: b, send_port: 5002, recv_port: 5003}\n") == "(no error)");
}

TEST_CASE("UDP: ports chosen at bind time cannot form a loop either") {
  const MessageRegistry reg = registry();
  UdpHub hub(HubConfig{}, reg, llsf::core::Rng(1));
  const PeerId a = hub.add_peer({"a", "team", 0, 0});
  // b's frames would go to the socket where the hub listens for a.
  CHECK_THROWS_WITH_AS(hub.add_peer({"b", "team", 0, hub.listen_port(a)}),
                       doctest::Contains("forwarding loop"), std::runtime_error);
  CHECK(hub.hub().peer_count() == 1);
}

TEST_CASE("TCP: connections beyond max_connections are closed at once and logged") {
  const MessageRegistry reg = registry();
  std::vector<std::string> log;
  StreamServerOptions o{"127.0.0.1", 0};
  o.max_connections = 2;
  o.log = [&](std::string_view line) { log.emplace_back(line); };
  StreamServer server(reg, o);
  asio::io_context io;
  const tcp::endpoint ep(kLoopback, static_cast<unsigned short>(server.port()));
  const auto pump = [&] { server.run_for(milliseconds(2)); };
  std::vector<tcp::socket> s;
  for (int i = 0; i < 3; ++i) {
    s.emplace_back(io).connect(ep);
    const auto deadline = Clock::now() + std::chrono::seconds(5);
    while (server.client_count() + server.refused_count() < i + 1 && Clock::now() < deadline) {
      pump();
    }
  }
  CHECK(server.client_count() == 2);
  CHECK(server.refused_count() == 1);
  CHECK(closed_by_peer(s[2], pump, milliseconds(3000)));
  CHECK_FALSE(closed_by_peer(s[0], pump, milliseconds(50)));
  REQUIRE(log.size() == 1);
  CHECK(log[0].find("refused a connection") != std::string::npos);
  CHECK(log[0].find("max_connections") != std::string::npos);
  // A slot that frees up is taken again.
  s[0].close();
  const auto deadline = Clock::now() + std::chrono::seconds(5);
  while (server.client_count() > 1 && Clock::now() < deadline) pump();
  tcp::socket again(io);
  again.connect(ep);
  while (server.client_count() < 2 && Clock::now() < deadline) pump();
  CHECK(server.client_count() == 2);
  CHECK(server.refused_count() == 1);
}

TEST_CASE("TCP: a frame left incomplete is closed after partial_frame_timeout; idle is fine") {
  const MessageRegistry reg = registry();
  std::vector<std::string> log;
  StreamServerOptions o{"127.0.0.1", 0};
  o.partial_frame_timeout = milliseconds(200);
  o.log = [&](std::string_view line) { log.emplace_back(line); };
  StreamServer server(reg, o);
  asio::io_context io;
  const tcp::endpoint ep(kLoopback, static_cast<unsigned short>(server.port()));
  const auto pump = [&] {
    server.run_for(milliseconds(2));
    server.take_events();
  };
  tcp::socket idle(io), slow(io);
  idle.connect(ep);
  slow.connect(ep);
  // The idle one sends whole frames, then nothing; the slow one half a header, then one byte
  // now and then (which must not extend its deadline).
  asio::write(idle, asio::buffer(reg.encode(lock(1))));
  const auto frame = reg.encode(lock(2));
  asio::write(slow, asio::buffer(frame.data(), 4));
  const auto deadline = Clock::now() + std::chrono::seconds(5);
  std::size_t sent = 4;
  slow.non_blocking(true);
  bool slow_closed = false;
  while (!slow_closed && Clock::now() < deadline) {
    for (int i = 0; i < 25; ++i) pump();
    boost::system::error_code ec;
    if (sent < frame.size() - 1) asio::write(slow, asio::buffer(&frame[sent++], 1), ec);
    std::array<std::uint8_t, 16> buf{};
    slow.read_some(asio::buffer(buf), ec);
    slow_closed = ec && ec != asio::error::would_block;
  }
  CHECK(slow_closed);
  CHECK(server.counters(ClientId(1)).closed_for == "partial_frame_timeout");
  CHECK(server.counters(ClientId(0)).closed_for.empty());
  CHECK(server.counters(ClientId(0)).frames_in == 1);
  CHECK_FALSE(closed_by_peer(idle, pump, milliseconds(400)));
  CHECK(server.client_count() == 1);
  REQUIRE(log.size() == 1);
  CHECK(log[0].find("partial_frame_timeout") != std::string::npos);
}

TEST_CASE("TCP: a client that does not read is closed when its send queue is full") {
  const MessageRegistry reg = registry();
  std::vector<std::string> log;
  StreamServerOptions o{"127.0.0.1", 0};
  o.max_send_queue_bytes = 4096;
  o.log = [&](std::string_view line) { log.emplace_back(line); };
  StreamServer server(reg, o);
  asio::io_context io;
  tcp::socket reader(io);
  reader.connect(tcp::endpoint(kLoopback, static_cast<unsigned short>(server.port())));
  const auto deadline = Clock::now() + std::chrono::seconds(5);
  while (server.client_count() < 1 && Clock::now() < deadline) server.run_for(milliseconds(2));
  REQUIRE(server.client_count() == 1);
  const ClientId c(0);
  // Without running the event loop nothing is written: the queue fills up.
  int accepted = 0;
  while (accepted < 100000 && server.send(c, lock(accepted))) ++accepted;
  CHECK(accepted > 10);
  CHECK(accepted < 4096 / 8);
  CHECK(server.counters(c).closed_for == "send_queue_full");
  CHECK(server.client_count() == 0);
  REQUIRE(log.size() == 1);
  CHECK(log[0].find("send_queue_full") != std::string::npos);
}

TEST_CASE("TCP: broadcast to clients that do not read closes each at its send-queue bound") {
  const MessageRegistry reg = registry();
  StreamServerOptions o{"127.0.0.1", 0};
  o.max_send_queue_bytes = 2048;
  o.log = [](std::string_view) {};
  StreamServer server(reg, o);
  asio::io_context io;
  std::vector<tcp::socket> readers;
  for (int i = 0; i < 3; ++i) {
    readers.emplace_back(io).connect(
        tcp::endpoint(kLoopback, static_cast<unsigned short>(server.port())));
  }
  const auto deadline = Clock::now() + std::chrono::seconds(5);
  while (server.client_count() < 3 && Clock::now() < deadline) server.run_for(milliseconds(2));
  REQUIRE(server.client_count() == 3);
  // Without running the event loop nothing is written: every queue fills up, and the broadcast
  // that overflows them closes all three (each erased from the server while it iterates).
  int rounds = 0;
  while (server.client_count() > 0 && rounds < 100000) {
    server.broadcast(lock(rounds));
    ++rounds;
  }
  CHECK(rounds < 2048 / 8);
  CHECK(server.client_count() == 0);
  for (int c = 0; c < 3; ++c) CHECK(server.counters(ClientId(c)).closed_for == "send_queue_full");
}

TEST_CASE("TCP: a busy client whose reads always end mid-frame is not timed out") {
  const MessageRegistry reg = registry();
  StreamServerOptions o{"127.0.0.1", 0};
  o.partial_frame_timeout = milliseconds(200);
  o.log = [](std::string_view) {};
  StreamServer server(reg, o);
  asio::io_context io;
  tcp::socket busy(io);
  busy.connect(tcp::endpoint(kLoopback, static_cast<unsigned short>(server.port())));
  busy.set_option(tcp::no_delay(true));
  // Frames back to back, written so that every write ends in the middle of a frame, for three
  // times the timeout: each frame completes well within it.
  std::vector<std::uint8_t> bytes;
  for (int i = 0; i < 200; ++i) {
    const auto f = reg.encode(lock(i));
    bytes.insert(bytes.end(), f.begin(), f.end());
  }
  const std::size_t frame = reg.encode(lock(0)).size();
  std::size_t sent = 0;
  const auto until = Clock::now() + milliseconds(600);
  std::int64_t messages = 0;
  while (Clock::now() < until && sent + frame < bytes.size()) {
    const std::size_t n = frame + frame / 2;
    asio::write(busy, asio::buffer(bytes.data() + sent, std::min(n, bytes.size() - sent)));
    sent += n;
    server.run_for(milliseconds(25));
    for (const auto& e : server.take_events()) messages += e.kind == StreamEvent::Kind::kMessage;
  }
  CHECK(Clock::now() >= until);
  CHECK(server.client_count() == 1);
  CHECK(server.counters(ClientId(0)).closed_for.empty());
  CHECK(messages > 10);
}
