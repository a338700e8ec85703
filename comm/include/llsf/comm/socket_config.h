// SPDX-License-Identifier: MIT
// SocketConfig: where the socket transports listen (docs/comm.md, section "sockets"). Loopback
// unless told otherwise.
#pragma once

#include <string>
#include <vector>

#include "llsf/core/config.h"

namespace llsf::comm {

/// One peer of the UDP transport: the hub listens on `send_port` for the peer's frames and
/// forwards the other peers' frames to `recv_port` (the Fawkes hub's port pair).
struct UdpPeerConfig {
  std::string name;
  std::string channel = "team";
  /// Port the hub listens on for this peer's frames; 0: any free port (see UdpHub::listen_port).
  int send_port = 0;
  /// Port (on the hub's address) the hub sends the other peers' frames to; 0: the source port of
  /// the peer's most recent datagram (until the peer has sent one, frames for it are dropped with
  /// cause `transport`).
  int recv_port = 0;
};

/// The socket side of the radio, for peers in other processes.
struct SocketConfig {
  /// Address both transports bind to (and the UDP hub sends to).
  std::string address = "127.0.0.1";
  bool stream_enabled = true;
  int stream_port = 4444;  ///< TCP stream server for refbox controllers; 0: any free port
  std::vector<UdpPeerConfig> udp_peers;

  /// Throws core::ConfigError naming the first bad field ("udp_peers[1].send_port: ...").
  void validate() const;
};

/// Reads a socket config from YAML on top of `base`; errors name file, line and field.
SocketConfig load_socket_config(const core::ConfigNode& node, SocketConfig base = {});

}  // namespace llsf::comm
