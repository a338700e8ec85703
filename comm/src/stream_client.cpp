// SPDX-License-Identifier: MIT
// StreamClient: a controller's connection to a StreamServer (or to a real 2013 refbox).
#include <boost/asio/connect.hpp>
#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/tcp.hpp>

#include "llsf/comm/stream.h"
#include "stream_connection.h"

namespace llsf::comm {

namespace asio = boost::asio;
using asio::ip::tcp;
using detail::StreamConnection;

struct StreamClient::Impl {
  asio::io_context io;  // first: destroyed last
  const MessageRegistry* registry;
  std::int64_t max_payload;
  StreamCounters counters;
  std::shared_ptr<StreamConnection> conn;
  std::vector<StreamEvent> events;
};

StreamClient::StreamClient(const MessageRegistry& registry, std::int64_t max_payload)
    : impl_(std::make_unique<Impl>()) {
  impl_->registry = &registry;
  impl_->max_payload = max_payload;
}

StreamClient::~StreamClient() { close(); }

bool StreamClient::connect(const std::string& address, int port,
                           std::chrono::milliseconds timeout) {
  close();
  boost::system::error_code ec;
  const auto addr = asio::ip::make_address(address, ec);
  if (ec || port <= 0 || port > 65535) return false;
  // The handler owns its state, so that a timed-out connect can finish after we return.
  struct State {
    explicit State(asio::io_context& io) : socket(io) {}
    tcp::socket socket;
    bool done = false;
    boost::system::error_code result;
  };
  auto st = std::make_shared<State>(impl_->io);
  st->socket.async_connect(tcp::endpoint(addr, static_cast<unsigned short>(port)),
                           [st](const boost::system::error_code& e) {
                             st->done = true;
                             st->result = e;
                           });
  impl_->io.restart();
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  while (!st->done && std::chrono::steady_clock::now() < deadline) {
    impl_->io.run_one_until(deadline);
  }
  if (!st->done || st->result) {
    st->socket.close(ec);
    impl_->io.restart();
    impl_->io.poll();  // runs the aborted handler
    return false;
  }
  impl_->conn = std::make_shared<StreamConnection>(
      std::move(st->socket), *impl_->registry,
      StreamConnection::Limits{impl_->max_payload, std::chrono::milliseconds(0),
                               kDefaultMaxSendQueueBytes, log_to_stderr},
      ClientId(), &impl_->counters,
      [impl = impl_.get()](StreamEvent&& e) { impl->events.push_back(std::move(e)); });
  impl_->conn->start();
  return true;
}

bool StreamClient::connected() const { return impl_->conn && impl_->conn->open(); }

bool StreamClient::send(const google::protobuf::Message& message) {
  return impl_->conn && impl_->conn->send(message);
}

void StreamClient::poll() {
  impl_->io.restart();
  impl_->io.poll();
}

void StreamClient::run_for(std::chrono::milliseconds duration) {
  impl_->io.restart();
  impl_->io.run_for(duration);
}

std::vector<StreamEvent> StreamClient::take_events() {
  std::vector<StreamEvent> out;
  out.swap(impl_->events);
  return out;
}

const StreamCounters& StreamClient::counters() const { return impl_->counters; }

void StreamClient::close() {
  if (impl_->conn) {
    impl_->conn->close();
    impl_->conn.reset();
  }
}

}  // namespace llsf::comm
