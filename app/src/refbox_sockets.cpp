// SPDX-License-Identifier: MIT
// RefboxSockets: the game's refbox and radio on TCP and UDP sockets, between ticks.
#include "refbox_sockets.h"

#include <chrono>
#include <stdexcept>
#include <utility>

#include "llsf/core/assert.h"
#include "llsf/core/error.h"

namespace llsf::app {

namespace asio = boost::asio;
using asio::ip::udp;

namespace {
/// Receive buffer per UDP peer: larger than any legal frame, so that an oversized datagram is
/// seen whole and counted as oversized (as UdpHub does).
constexpr std::size_t kReceiveBuffer = 65536;
/// Datagrams read between two receive() calls. When that many are waiting the sockets are not
/// read again until the next receive(): a flood stays in (and overflows) the kernel's buffer
/// instead of keeping the game's thread in io_context::poll().
constexpr std::size_t kMaxArrived = 4096;

/// A copy of `m` with its times in wire time.
std::unique_ptr<google::protobuf::Message> wire_copy(const google::protobuf::Message& m,
                                                     const refbox::WireClock& clock) {
  std::unique_ptr<google::protobuf::Message> c(m.New());
  c->CopyFrom(m);
  refbox::to_wire_time(*c, clock);
  return c;
}
}  // namespace

struct RefboxSockets::Peer {
  explicit Peer(asio::io_context& io) : socket(io) {}
  udp::socket socket;
  udp::endpoint source;       ///< of the datagram being received
  udp::endpoint destination;  ///< where the radio's frames for this peer go
  bool destination_known = false;
  bool learn_destination = false;
  bool reading = false;  ///< a receive is pending (none while kMaxArrived datagrams wait)
  int bound_port = 0;
  std::vector<std::uint8_t> buffer = std::vector<std::uint8_t>(kReceiveBuffer);
};

RefboxSockets::RefboxSockets(comm::SocketConfig config, comm::LockNumbering lock_messages,
                             comm::LogSink log)
    : config_(std::move(config)), lock_messages_(lock_messages) {
  config_.validate();
  // The game's registry (sim::Game): frames are decoded and encoded here as the radio does.
  sim::add_refbox_messages(registry_);
  comm::add_agent_messages(registry_, lock_messages_);
  address_ = asio::ip::make_address(config_.address);
  if (config_.stream_enabled) {
    comm::StreamServerOptions o;
    o.address = config_.address;
    o.port = config_.stream_port;
    o.log = [this, log = std::move(log)](std::string_view line) {
      if (log) log(line);
      if (transport_log_.size() < 100) transport_log_.emplace_back(line);
    };
    try {
      server_ = std::make_unique<comm::StreamServer>(registry_, o);
    } catch (const std::runtime_error& e) {
      throw core::UserError("cannot listen for controllers on " + config_.address + ":" +
                            std::to_string(config_.stream_port) + ": " + e.what());
    }
  }
  for (std::size_t i = 0; i < config_.udp_peers.size(); ++i) {
    const comm::UdpPeerConfig& c = config_.udp_peers[i];
    auto p = std::make_unique<Peer>(io_);
    boost::system::error_code ec;
    const udp::endpoint local(address_, static_cast<unsigned short>(c.send_port));
    p->socket.open(local.protocol(), ec);
    if (!ec) p->socket.bind(local, ec);
    if (ec) {
      throw core::UserError("udp peer '" + c.name + "': cannot bind " + config_.address + ":" +
                            std::to_string(c.send_port) + ": " + ec.message());
    }
    p->bound_port = p->socket.local_endpoint(ec).port();
    // A port chosen at bind time (send_port 0) may be another peer's recv_port: a frame would
    // then go round for ever (load_socket_config() refuses the fixed ports already).
    for (std::size_t j = 0; j < config_.udp_peers.size(); ++j) {
      if (config_.udp_peers[j].recv_port == p->bound_port) {
        throw core::UserError("udp peer '" + c.name + "': listening port " +
                              std::to_string(p->bound_port) + " is the recv_port of '" +
                              config_.udp_peers[j].name + "' (a forwarding loop)");
      }
    }
    if (c.recv_port > 0) {
      p->destination = udp::endpoint(address_, static_cast<unsigned short>(c.recv_port));
      p->destination_known = true;
    } else {
      p->learn_destination = true;
    }
    peers_.push_back(std::move(p));
  }
}

RefboxSockets::~RefboxSockets() {
  boost::system::error_code ec;
  for (auto& p : peers_) p->socket.close(ec);
}

std::vector<sim::ExternalPeerConfig> RefboxSockets::external_peers() const {
  std::vector<sim::ExternalPeerConfig> out;
  for (const comm::UdpPeerConfig& c : config_.udp_peers) out.push_back({c.name, c.channel});
  return out;
}

void RefboxSockets::attach(sim::Game& game) {
  LLSF_DEMAND(static_cast<std::size_t>(game.config().external_peers.size()) == peers_.size());
  LLSF_DEMAND(game.config().hub.lock_messages == lock_messages_);
  game_ = &game;
  // The 2013 time base: the game's start (its time now) is the wall clock now.
  const auto wall = std::chrono::duration_cast<std::chrono::nanoseconds>(
                        std::chrono::system_clock::now().time_since_epoch())
                        .count();
  clock_.offset_ns = wall - game.time().ns();
  for (std::size_t i = 0; i < peers_.size(); ++i) start_receive(static_cast<int>(i));
}

void RefboxSockets::start_receive(int peer) {
  Peer& p = *peers_[static_cast<std::size_t>(peer)];
  p.reading = true;
  p.socket.async_receive_from(
      asio::buffer(p.buffer), p.source,
      [this, peer](const boost::system::error_code& ec, std::size_t n) {
        if (ec == asio::error::operation_aborted) return;
        Peer& q = *peers_[static_cast<std::size_t>(peer)];
        q.reading = false;
        if (!ec && arrived_.size() < kMaxArrived) {
          arrived_.push_back(
              {peer,
               std::vector<std::uint8_t>(q.buffer.begin(),
                                         q.buffer.begin() + static_cast<std::ptrdiff_t>(n)),
               q.source});
        }
        if (arrived_.size() < kMaxArrived) start_receive(peer);
      });
}

bool RefboxSockets::is_own_endpoint(const udp::endpoint& ep) const {
  for (const auto& p : peers_) {
    if (p->bound_port == ep.port() &&
        (ep.address() == address_ || address_.is_unspecified() || ep.address().is_loopback())) {
      return true;
    }
  }
  return false;
}

void RefboxSockets::send_tick() {
  LLSF_DEMAND(game_ != nullptr);
  sim::Game& g = *game_;
  // The refbox's messages for controllers (the peers' ones went into the radio in the tick).
  if (server_) {
    for (const refbox::Outgoing& o : g.refbox_outgoing()) {
      if (o.to.kind == refbox::Destination::Kind::kAllClients) {
        server_->broadcast(*wire_copy(*o.message, clock_));
      } else if (o.to.kind == refbox::Destination::Kind::kClient && o.to.client >= 1) {
        server_->send(comm::ClientId(o.to.client - 1), *wire_copy(*o.message, clock_));
      }
    }
    server_->poll();
  }
  // What the radio delivered to each UDP peer in this tick.
  comm::Hub& hub = g.hub();
  for (std::size_t i = 0; i < peers_.size(); ++i) {
    Peer& p = *peers_[i];
    for (const comm::Delivery& d : hub.received(g.external_peer(static_cast<int>(i)))) {
      if (!p.destination_known) {
        hub.mark_undeliverable(d);  // the peer has not sent a valid frame yet
        continue;
      }
      std::span<const std::uint8_t> bytes = d.frame;
      if (auto msg = hub.decode(d)) {
        refbox::to_wire_time(*msg, clock_);
        if (registry_.encode(*msg, frame_)) bytes = frame_;
      }
      boost::system::error_code ec;
      p.socket.send_to(asio::buffer(bytes.data(), bytes.size()), p.destination, 0, ec);
      if (ec) hub.mark_undeliverable(d);
    }
  }
}

void RefboxSockets::receive() {
  LLSF_DEMAND(game_ != nullptr);
  sim::Game& g = *game_;
  // Controllers: connections, commands and disconnections in arrival order. Client ids are the
  // server's + 1 (0 is the game's own start command).
  if (server_) {
    server_->poll();
    for (comm::StreamEvent& e : server_->take_events()) {
      const int client = e.client.value() + 1;
      switch (e.kind) {
        case comm::StreamEvent::Kind::kConnected:
          g.controller_connected(client);
          break;
        case comm::StreamEvent::Kind::kMessage:
          refbox::from_wire_time(*e.message, clock_);
          // A refusal is logged by the protocol and sent to the controllers as a LogMessage.
          g.controller_command(*e.message, client, config_.address, 0);
          break;
        case comm::StreamEvent::Kind::kDisconnected:
          g.controller_disconnected(client);
          break;
      }
    }
    // Frames dropped as malformed: told to the controllers as the 0.6.1 refbox did.
    for (std::string& line : transport_log_) {
      g.refbox_protocol().log_transport(refbox::ProtocolLogLine::Level::kWarn, std::move(line));
    }
    transport_log_.clear();
  }
  // UDP peers: every datagram read since the last call goes into the radio.
  io_.restart();
  io_.poll();
  std::vector<Datagram> arrived;
  arrived.swap(arrived_);
  for (const Datagram& d : arrived) take_datagram(d);
  // Peers whose reading stopped at kMaxArrived read again from the next poll on.
  for (std::size_t i = 0; i < peers_.size(); ++i) {
    if (!peers_[i]->reading) start_receive(static_cast<int>(i));
  }
}

void RefboxSockets::take_datagram(const Datagram& d) {
  sim::Game& g = *game_;
  comm::Hub& hub = g.hub();
  const comm::PeerId peer = g.external_peer(d.peer);
  Peer& p = *peers_[static_cast<std::size_t>(d.peer)];
  comm::MessageRegistry::Decoded m =
      registry_.decode_datagram(d.bytes, hub.config().max_frame_bytes);
  comm::FrameError e = comm::FrameError::kNone;
  if (m.error == comm::FrameError::kNone) {
    refbox::from_wire_time(*m.message, clock_);
    e = hub.broadcast(peer, *m.message, g.time());
  } else {
    // Malformed, or of a type this build does not know: the hub counts it as the peer's refused
    // frame (or relays it unparsed with forward_unregistered).
    e = hub.broadcast_frame(peer, d.bytes, g.time());
  }
  if (e != comm::FrameError::kNone) return;
  // Only an accepted frame teaches the peer's address (as UdpHub: a malformed datagram from any
  // local port must not redirect the peer's traffic), never one of the game's own sockets.
  if (is_own_endpoint(d.source)) return;
  if (p.learn_destination) {
    p.destination = d.source;
    p.destination_known = true;
  }
  g.set_external_origin(d.peer, d.source.address().to_string(), d.source.port());
}

int RefboxSockets::stream_port() const { return server_ ? server_->port() : -1; }

int RefboxSockets::udp_port(int index) const {
  return peers_.at(static_cast<std::size_t>(index))->bound_port;
}

std::vector<std::string> RefboxSockets::describe() const {
  std::vector<std::string> lines;
  if (server_) {
    lines.push_back("controllers: tcp " + config_.address + ":" + std::to_string(stream_port()));
  }
  for (std::size_t i = 0; i < peers_.size(); ++i) {
    const comm::UdpPeerConfig& c = config_.udp_peers[i];
    std::string l = "udp peer " + c.name + " (channel " + c.channel + "): send to " +
                    config_.address + ":" + std::to_string(peers_[i]->bound_port) + ", receive on ";
    l += c.recv_port > 0 ? config_.address + ":" + std::to_string(c.recv_port)
                         : std::string("the port it sends from");
    lines.push_back(l);
  }
  return lines;
}

}  // namespace llsf::app
