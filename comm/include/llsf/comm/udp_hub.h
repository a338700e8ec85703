// SPDX-License-Identifier: MIT
// UdpHub: the hub on real UDP sockets, for peers in other processes (real LLSF tools, agents).
//
// Like the Fawkes comm hub, it opens one port pair per peer: the hub listens on the peer's
// `send_port` (where the peer sends its frames) and forwards the other peers' frames to the
// peer's `recv_port`. A Hub inside applies the same loss, delay and outage models and keeps the
// same counters; its simulated time is the wall time since the UdpHub was created, so socket mode
// is paced by real time and NOT deterministic (arrival order and timing depend on the OS).
// Sockets bind to 127.0.0.1 unless told otherwise. Single-threaded: the caller drives the event
// loop with poll() or run_for(); not thread-safe.
#pragma once

#include <chrono>
#include <memory>
#include <string>

#include "llsf/comm/hub.h"
#include "llsf/comm/socket_config.h"

namespace llsf::comm {

struct UdpHubOptions {
  /// Address the hub binds to and sends to; loopback unless told otherwise.
  std::string address = "127.0.0.1";
};

class UdpHub {
 public:
  /// Throws core::ConfigError for a bad config, std::runtime_error for a bad address.
  UdpHub(HubConfig config, const MessageRegistry& registry, const core::Rng& rng,
         UdpHubOptions options = {});
  UdpHub(const UdpHub&) = delete;
  UdpHub& operator=(const UdpHub&) = delete;
  ~UdpHub();

  /// Adds a peer and binds its listening socket; throws std::runtime_error if the port is taken.
  PeerId add_peer(const UdpPeerConfig& peer);
  /// The port the hub listens on for `peer`'s frames (the bound port when send_port was 0).
  int listen_port(PeerId peer) const;

  /// Broadcasts `message` on behalf of `from` (e.g. an in-process refbox) at the current time,
  /// through the same models; returns as Hub::broadcast().
  FrameError broadcast(PeerId from, const google::protobuf::Message& message);

  /// Handles every ready event (received datagrams, due deliveries) without blocking.
  void poll();
  /// Runs the event loop for `duration` of wall time, then returns.
  void run_for(std::chrono::milliseconds duration);

  /// The hub inside: counters, trace, peer names. Send through UdpHub::broadcast(), not
  /// through the hub, so that deliveries get scheduled.
  const Hub& hub() const;
  Hub& hub();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace llsf::comm
