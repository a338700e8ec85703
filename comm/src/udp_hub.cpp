// SPDX-License-Identifier: MIT
// UdpHub: one listening UDP socket per peer, forwarding through a Hub paced by the wall clock.
#include "llsf/comm/udp_hub.h"

#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/udp.hpp>
#include <boost/asio/steady_timer.hpp>
#include <stdexcept>

namespace llsf::comm {

namespace asio = boost::asio;
using asio::ip::udp;

namespace {
/// Receive buffer per peer: larger than any legal frame, so that an oversized datagram is seen
/// whole and counted as oversized instead of being truncated into a size mismatch.
constexpr std::size_t kReceiveBuffer = 65536;
}  // namespace

struct UdpHub::Impl {
  struct Socket {
    explicit Socket(asio::io_context& io) : socket(io) {}
    udp::socket socket;
    udp::endpoint source;       ///< of the datagram being received
    udp::endpoint destination;  ///< where frames for this peer go
    bool destination_known = false;
    bool learn_destination = false;
    int bound_port = 0;  ///< where the hub listens for this peer
    std::vector<std::uint8_t> buffer = std::vector<std::uint8_t>(kReceiveBuffer);
  };

  // io first: destroyed last, after the sockets and the timer that use it.
  asio::io_context io;
  Hub hub;
  asio::ip::address address;
  std::chrono::steady_clock::time_point start = std::chrono::steady_clock::now();
  std::vector<std::unique_ptr<Socket>> sockets;  ///< by peer index
  asio::steady_timer timer{io};
  bool timer_armed = false;
  SimTime timer_due;

  Impl(HubConfig config, const MessageRegistry& registry, const core::Rng& rng,
       const UdpHubOptions& options)
      : hub(std::move(config), registry, rng, "comm/udp") {
    boost::system::error_code ec;
    address = asio::ip::make_address(options.address, ec);
    if (ec) throw std::runtime_error("UdpHub: bad address '" + options.address + "'");
  }

  /// The hub's clock: wall time since construction (monotonic).
  SimTime now() const {
    const auto d = std::chrono::steady_clock::now() - start;
    return std::max(
        hub.now(),
        SimTime::from_ns(std::chrono::duration_cast<std::chrono::nanoseconds>(d).count()));
  }

  void receive(int peer) {
    Socket& s = *sockets[static_cast<std::size_t>(peer)];
    s.socket.async_receive_from(asio::buffer(s.buffer), s.source,
                                [this, peer](const boost::system::error_code& ec, std::size_t n) {
                                  if (ec == asio::error::operation_aborted) return;
                                  if (!ec) on_datagram(peer, n);
                                  receive(peer);
                                });
  }

  void on_datagram(int peer, std::size_t n) {
    Socket& s = *sockets[static_cast<std::size_t>(peer)];
    const FrameError e =
        hub.broadcast_frame(PeerId(peer), std::span<const std::uint8_t>(s.buffer.data(), n), now());
    // The return address is learnt only from a frame the hub accepted (a malformed datagram from
    // any local port must not redirect the peer's traffic), and never as one of the hub's own
    // listening sockets (a frame would circulate for ever).
    if (s.learn_destination && e == FrameError::kNone && !is_own_endpoint(s.source)) {
      s.destination = s.source;
      s.destination_known = true;
    }
    pump();
  }

  /// Whether `ep` is one of the hub's listening sockets.
  bool is_own_endpoint(const udp::endpoint& ep) const {
    for (const auto& other : sockets) {
      if (other->bound_port == ep.port() &&
          (ep.address() == address || address.is_unspecified() || ep.address().is_loopback())) {
        return true;
      }
    }
    return false;
  }

  /// Delivers what is due and re-arms the timer for the next due copy.
  void pump() {
    hub.step(now());
    for (int p = 0; p < hub.peer_count(); ++p) {
      Socket& s = *sockets[static_cast<std::size_t>(p)];
      for (const Delivery& d : hub.received(PeerId(p))) {
        if (!s.destination_known) {
          hub.mark_undeliverable(d);
          continue;
        }
        boost::system::error_code ec;
        s.socket.send_to(asio::buffer(d.frame.data(), d.frame.size()), s.destination, 0, ec);
        if (ec) hub.mark_undeliverable(d);
      }
    }
    arm_timer();
  }

  void arm_timer() {
    const auto due = hub.next_due();
    if (!due || (timer_armed && timer_due <= *due)) return;
    timer_armed = true;
    timer_due = *due;
    timer.expires_at(start + std::chrono::nanoseconds(due->ns()));
    timer.async_wait([this](const boost::system::error_code& ec) {
      if (ec == asio::error::operation_aborted) return;  // re-armed earlier, or shutting down
      timer_armed = false;
      pump();
    });
  }
};

UdpHub::UdpHub(HubConfig config, const MessageRegistry& registry, const core::Rng& rng,
               UdpHubOptions options)
    : impl_(std::make_unique<Impl>(std::move(config), registry, rng, options)) {}

UdpHub::~UdpHub() {
  boost::system::error_code ec;
  impl_->timer.cancel();
  for (auto& s : impl_->sockets) s->socket.close(ec);
}

PeerId UdpHub::add_peer(const UdpPeerConfig& peer) {
  if (peer.send_port < 0 || peer.send_port > 65535 || peer.recv_port < 0 ||
      peer.recv_port > 65535) {
    throw std::runtime_error("UdpHub: peer '" + peer.name + "': ports must be in [0, 65535]");
  }
  auto s = std::make_unique<Impl::Socket>(impl_->io);
  boost::system::error_code ec;
  const udp::endpoint local(impl_->address, static_cast<unsigned short>(peer.send_port));
  s->socket.open(local.protocol(), ec);
  if (!ec) s->socket.bind(local, ec);
  if (ec) {
    throw std::runtime_error("UdpHub: peer '" + peer.name + "': cannot bind " +
                             impl_->address.to_string() + ":" + std::to_string(peer.send_port) +
                             ": " + ec.message());
  }
  // A peer's receive port must not be one of the hub's listening ports (its own or another
  // peer's), and a new listening port must not be an earlier peer's receive port: either way a
  // frame would be forwarded back into the hub for ever.
  const int bound = s->socket.local_endpoint(ec).port();
  s->bound_port = bound;
  for (std::size_t i = 0; i < impl_->sockets.size(); ++i) {
    const Impl::Socket& other = *impl_->sockets[i];
    const std::string& other_name = impl_->hub.peer_name(PeerId(static_cast<int>(i)));
    if (peer.recv_port > 0 && other.bound_port == peer.recv_port) {
      throw std::runtime_error("UdpHub: peer '" + peer.name + "': recv_port " +
                               std::to_string(peer.recv_port) + " is where the hub listens for '" +
                               other_name + "' (a forwarding loop)");
    }
    if (other.destination_known && other.destination.port() == bound) {
      throw std::runtime_error("UdpHub: peer '" + peer.name + "': listening port " +
                               std::to_string(bound) + " is the recv_port of '" + other_name +
                               "' (a forwarding loop)");
    }
  }
  if (peer.recv_port > 0 && peer.recv_port == bound) {
    throw std::runtime_error("UdpHub: peer '" + peer.name + "': recv_port " +
                             std::to_string(peer.recv_port) +
                             " is its own send_port (a forwarding loop)");
  }
  if (peer.recv_port > 0) {
    s->destination = udp::endpoint(impl_->address, static_cast<unsigned short>(peer.recv_port));
    s->destination_known = true;
  } else {
    s->learn_destination = true;
  }
  const PeerId id = impl_->hub.add_peer(peer.name, peer.channel);
  impl_->sockets.push_back(std::move(s));
  impl_->receive(id.value());
  return id;
}

int UdpHub::listen_port(PeerId peer) const {
  boost::system::error_code ec;
  const auto ep =
      impl_->sockets.at(static_cast<std::size_t>(peer.value()))->socket.local_endpoint(ec);
  return ec ? -1 : ep.port();
}

FrameError UdpHub::broadcast(PeerId from, const google::protobuf::Message& message) {
  const FrameError e = impl_->hub.broadcast(from, message, impl_->now());
  impl_->pump();
  return e;
}

void UdpHub::poll() {
  impl_->io.restart();
  impl_->io.poll();
}

void UdpHub::run_for(std::chrono::milliseconds duration) {
  impl_->io.restart();
  impl_->io.run_for(duration);
}

const Hub& UdpHub::hub() const { return impl_->hub; }
Hub& UdpHub::hub() { return impl_->hub; }

}  // namespace llsf::comm
