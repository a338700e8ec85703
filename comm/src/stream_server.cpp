// SPDX-License-Identifier: MIT
// StreamServer: accepts controller connections on loopback and speaks the 2013 stream framing.
#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/steady_timer.hpp>
#include <deque>
#include <map>
#include <stdexcept>

#include "llsf/comm/stream.h"
#include "stream_connection.h"

namespace llsf::comm {

namespace asio = boost::asio;
using asio::ip::tcp;
using detail::StreamConnection;

/// Pause before accepting again after a failed accept (out of file descriptors: EMFILE).
constexpr std::chrono::milliseconds kAcceptRetry{100};

struct StreamServer::Impl {
  asio::io_context io;  // first: destroyed last
  tcp::acceptor acceptor{io};
  asio::steady_timer accept_retry{io};
  bool accept_failing = false;  ///< an accept failed and none worked since (logged once)
  const MessageRegistry* registry;
  StreamServerOptions options;
  std::int64_t refused = 0;
  std::map<int, std::shared_ptr<StreamConnection>> open;  ///< by client id
  std::deque<StreamCounters> counters;                    ///< by client id; stable addresses
  std::vector<StreamEvent> events;

  Impl(const MessageRegistry& reg, const StreamServerOptions& o) : registry(&reg), options(o) {
    if (o.max_payload < 0 || o.max_connections < 1 || o.max_send_queue_bytes < 1) {
      throw std::runtime_error(
          "StreamServer: max_payload must be >= 0, max_connections and max_send_queue_bytes >= 1");
    }
    boost::system::error_code ec;
    const auto address = asio::ip::make_address(o.address, ec);
    if (ec) throw std::runtime_error("StreamServer: bad address '" + o.address + "'");
    if (o.port < 0 || o.port > 65535) throw std::runtime_error("StreamServer: bad port");
    const tcp::endpoint ep(address, static_cast<unsigned short>(o.port));
    acceptor.open(ep.protocol(), ec);
    if (!ec) acceptor.set_option(tcp::acceptor::reuse_address(true), ec);
    if (!ec) acceptor.bind(ep, ec);
    if (!ec) acceptor.listen(asio::socket_base::max_listen_connections, ec);
    if (ec) {
      throw std::runtime_error("StreamServer: cannot listen on " + o.address + ":" +
                               std::to_string(o.port) + ": " + ec.message());
    }
    accept();
  }

  void accept() {
    acceptor.async_accept([this](const boost::system::error_code& ec, tcp::socket socket) {
      if (ec == asio::error::operation_aborted || !acceptor.is_open()) return;
      if (ec) {
        on_accept_error(ec);
        return;
      }
      accept_failing = false;
      if (static_cast<int>(open.size()) >= options.max_connections) {
        refuse(std::move(socket));
      } else {
        const int id = static_cast<int>(counters.size());
        counters.emplace_back();
        auto conn = std::make_shared<StreamConnection>(
            std::move(socket), *registry,
            StreamConnection::Limits{options.max_payload, options.partial_frame_timeout,
                                     options.max_send_queue_bytes, options.log},
            ClientId(id), &counters.back(), [this](StreamEvent&& e) {
              if (e.kind == StreamEvent::Kind::kDisconnected) open.erase(e.client.value());
              events.push_back(std::move(e));
            });
        open.emplace(id, conn);
        StreamEvent e;
        e.kind = StreamEvent::Kind::kConnected;
        e.client = ClientId(id);
        events.push_back(std::move(e));
        conn->start();
      }
      accept();
    });
  }

  /// Out of file descriptors (EMFILE, ENFILE) or memory, the connection stays in the listen
  /// backlog and accepting again fails at once: retry after a pause instead of spinning.
  void on_accept_error(const boost::system::error_code& ec) {
    if (!accept_failing && options.log) {
      options.log("stream server: cannot accept a connection: " + ec.message() +
                  "; retrying every " + std::to_string(kAcceptRetry.count()) +
                  " ms until it works");
    }
    accept_failing = true;
    accept_retry.expires_after(kAcceptRetry);
    accept_retry.async_wait([this](const boost::system::error_code& e) {
      if (e || !acceptor.is_open()) return;
      accept();
    });
  }

  /// Closes a connection beyond max_connections at once. Logs the 1st, 2nd, 4th, 8th, ...
  /// refusal, so that a flood of connections cannot flood the log.
  void refuse(tcp::socket socket) {
    ++refused;
    boost::system::error_code ec;
    const auto ep = socket.remote_endpoint(ec);
    socket.close(ec);
    if ((refused & (refused - 1)) == 0 && options.log) {
      options.log("stream server: refused a connection from " +
                  (ep.port() ? ep.address().to_string() + ":" + std::to_string(ep.port())
                             : std::string("?")) +
                  ": " + std::to_string(options.max_connections) +
                  " connections open (max_connections); " + std::to_string(refused) +
                  " refused so far");
    }
  }
};

StreamServer::StreamServer(const MessageRegistry& registry, StreamServerOptions options)
    : impl_(std::make_unique<Impl>(registry, options)) {}

StreamServer::~StreamServer() {
  boost::system::error_code ec;
  impl_->acceptor.close(ec);
  impl_->accept_retry.cancel();
  // Closing emits events into impl_; take a copy of the list first.
  const auto open = impl_->open;
  for (const auto& [id, conn] : open) conn->close();
}

int StreamServer::port() const {
  boost::system::error_code ec;
  const auto ep = impl_->acceptor.local_endpoint(ec);
  return ec ? -1 : ep.port();
}

void StreamServer::poll() {
  impl_->io.restart();
  impl_->io.poll();
}

void StreamServer::run_for(std::chrono::milliseconds duration) {
  impl_->io.restart();
  impl_->io.run_for(duration);
}

std::vector<StreamEvent> StreamServer::take_events() {
  std::vector<StreamEvent> out;
  out.swap(impl_->events);
  return out;
}

bool StreamServer::send(ClientId client, const google::protobuf::Message& message) {
  const auto it = impl_->open.find(client.value());
  if (it == impl_->open.end()) return false;
  const auto conn = it->second;  // a full send queue closes it, which erases it from the map
  return conn->send(message);
}

int StreamServer::broadcast(const google::protobuf::Message& message) {
  // A send may close its connection (send queue full), which erases it from `open`: iterate
  // over a copy.
  std::vector<std::shared_ptr<StreamConnection>> conns;
  conns.reserve(impl_->open.size());
  for (const auto& [id, conn] : impl_->open) conns.push_back(conn);
  int n = 0;
  for (const auto& conn : conns) n += conn->send(message) ? 1 : 0;
  return n;
}

void StreamServer::disconnect(ClientId client) {
  const auto it = impl_->open.find(client.value());
  if (it == impl_->open.end()) return;
  const auto conn = it->second;  // keep alive while it erases itself from the map
  conn->close();
}

int StreamServer::client_count() const { return static_cast<int>(impl_->open.size()); }

std::int64_t StreamServer::refused_count() const { return impl_->refused; }

const StreamCounters& StreamServer::counters(ClientId client) const {
  return impl_->counters.at(static_cast<std::size_t>(client.value()));
}

}  // namespace llsf::comm
