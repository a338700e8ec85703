// SPDX-License-Identifier: MIT
// One TCP connection speaking the 2013 stream framing, shared by StreamServer and StreamClient.
#pragma once

#include <boost/asio/ip/tcp.hpp>
#include <deque>
#include <functional>
#include <memory>

#include "llsf/comm/stream.h"

namespace llsf::comm::detail {

/// Reads frames into events and writes queued frames. Owned through shared_ptr: pending
/// handlers keep it alive. Emits exactly one kDisconnected, when it closes for any reason.
class StreamConnection : public std::enable_shared_from_this<StreamConnection> {
 public:
  using Sink = std::function<void(StreamEvent&&)>;

  /// `counters` must outlive the connection.
  StreamConnection(boost::asio::ip::tcp::socket socket, const MessageRegistry& registry,
                   std::int64_t max_payload, ClientId id, StreamCounters* counters, Sink sink);

  /// Starts the read loop.
  void start();
  /// Queues an encoded frame.
  bool send(const google::protobuf::Message& message);
  void close();
  bool open() const { return open_; }
  ClientId id() const { return id_; }

 private:
  void read();
  void on_bytes(std::size_t n);
  void write_next();

  boost::asio::ip::tcp::socket socket_;
  const MessageRegistry* registry_;
  StreamDecoder decoder_;
  ClientId id_;
  StreamCounters* counters_;
  Sink sink_;
  std::array<std::uint8_t, 4096> read_buffer_{};
  std::deque<std::vector<std::uint8_t>> write_queue_;
  bool writing_ = false;
  bool open_ = true;
};

}  // namespace llsf::comm::detail
