// SPDX-License-Identifier: MIT
// `llsfsim run --refbox-sockets`: the simulated refbox served on real sockets, as the 2013 refbox
// serves itself (docs/refbox-protocol.md, "Attaching 2013 tools"): TCP controllers get the
// refbox's stream messages on its schedule and their commands reach the game; UDP peers are hub
// peers of the game (the hub's loss, delay and outages apply) whose frames enter the radio and
// who receive what the radio delivers to them. All socket I/O happens between ticks, when the
// caller asks for it; times on the wire are Unix time (refbox::WireClock).
#pragma once

#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/udp.hpp>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "llsf/comm/registry.h"
#include "llsf/comm/socket_config.h"
#include "llsf/comm/stream.h"
#include "llsf/refbox/wire_time.h"
#include "llsf/sim/game.h"
#include "llsf/sim/game_config.h"

namespace llsf::app {

/// The served sockets of one game. Single-threaded (the game's thread); not copyable.
class RefboxSockets {
 public:
  /// Binds the controllers' TCP server (unless `config.stream_enabled` is false) and one UDP
  /// socket per entry of `config.udp_peers` (config validated first). Throws core::UserError
  /// naming the address and port that cannot be bound. `lock_messages` is the numbering of the
  /// lock messages on the wire: the game's (its radio's `lock_messages`), so that a 2013 peer
  /// sends and receives them as (2000, 1337/1338). `log` receives the transports' lines.
  RefboxSockets(comm::SocketConfig config, comm::LockNumbering lock_messages,
                comm::LogSink log = comm::log_to_stderr);
  ~RefboxSockets();
  RefboxSockets(const RefboxSockets&) = delete;
  RefboxSockets& operator=(const RefboxSockets&) = delete;

  /// The UDP peers as GameConfig::external_peers (same order, names and channels).
  std::vector<sim::ExternalPeerConfig> external_peers() const;
  /// Serves `game` (borrowed until destruction; built with external_peers() and the lock
  /// numbering given at construction) from now on: its start is mapped to the wall clock now.
  /// Call before the first tick.
  void attach(sim::Game& game);

  /// After a tick: the refbox's messages of that tick for stream clients go to the TCP
  /// controllers, what the radio delivered to each UDP peer goes to its socket (times turned
  /// into wire time), and the writes are started.
  void send_tick();
  /// Between ticks: reads what arrived and hands it to the game: connections, disconnections
  /// and commands of controllers (checked with the 2013 channel rules, applied at the next
  /// tick), UDP frames into the radio from their peer (at the game's current time).
  void receive();

  /// The TCP port the controllers connect to (-1 without a stream server).
  int stream_port() const;
  /// The UDP port the game listens on for udp_peers[index]'s frames.
  int udp_port(int index) const;
  /// One line per socket for the user: "controllers: tcp 127.0.0.1:4444", "udp peer NAME
  /// (channel CH): listens on ADDR:PORT, sends to ...".
  std::vector<std::string> describe() const;
  /// The wire clock (valid after attach()).
  const refbox::WireClock& wire_clock() const { return clock_; }

 private:
  struct Peer;
  struct Datagram {
    int peer = 0;
    std::vector<std::uint8_t> bytes;
    boost::asio::ip::udp::endpoint source;
  };
  void start_receive(int peer);
  void take_datagram(const Datagram& d);
  bool is_own_endpoint(const boost::asio::ip::udp::endpoint& ep) const;

  comm::SocketConfig config_;
  comm::LockNumbering lock_messages_;
  comm::MessageRegistry registry_;  // before server_: borrowed by it
  std::unique_ptr<comm::StreamServer> server_;
  boost::asio::io_context io_;  // before the peers' sockets
  boost::asio::ip::address address_;
  std::vector<std::unique_ptr<Peer>> peers_;  // by udp_peers index
  std::vector<Datagram> arrived_;
  sim::Game* game_ = nullptr;
  refbox::WireClock clock_;
  std::vector<std::uint8_t> frame_;  // encoding scratch
  /// The stream server's log lines (dropped frames) since the last receive(): they go to the
  /// controllers as LogMessages too (RefboxProtocol::log_transport).
  std::vector<std::string> transport_log_;
};

}  // namespace llsf::app
