// SPDX-License-Identifier: MIT
// One TCP connection speaking the 2013 stream framing, shared by StreamServer and StreamClient.
#pragma once

#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/steady_timer.hpp>
#include <chrono>
#include <deque>
#include <functional>
#include <memory>
#include <string>

#include "llsf/comm/stream.h"

namespace llsf::comm::detail {

/// Reads frames into events and writes queued frames. Owned through shared_ptr: pending
/// handlers keep it alive. Emits exactly one kDisconnected, when it closes for any reason.
class StreamConnection : public std::enable_shared_from_this<StreamConnection> {
 public:
  using Sink = std::function<void(StreamEvent&&)>;

  /// The connection's bounds (StreamServerOptions documents them).
  struct Limits {
    std::int64_t max_payload = kDefaultMaxStreamPayload;
    std::chrono::milliseconds partial_frame_timeout{0};  ///< 0: none
    std::int64_t max_send_queue_bytes = kDefaultMaxSendQueueBytes;
    LogSink log;  ///< empty: no log lines
  };

  /// `counters` must outlive the connection.
  StreamConnection(boost::asio::ip::tcp::socket socket, const MessageRegistry& registry,
                   Limits limits, ClientId id, StreamCounters* counters, Sink sink);

  /// Starts the read loop.
  void start();
  /// Queues an encoded frame; false (and the connection is closed) if the send queue would
  /// exceed max_send_queue_bytes.
  bool send(const google::protobuf::Message& message);
  void close();
  bool open() const { return open_; }
  ClientId id() const { return id_; }

 private:
  void read();
  void on_bytes(std::size_t n);
  /// Starts writing the next queued frame unless a write is under way.
  void write_next();
  /// The completion of the write of in_flight_.
  void on_written(const boost::system::error_code& ec);
  /// Arms the partial-frame timer when a frame is incomplete (again when a new frame started
  /// after `frame_done`), disarms it when none is.
  void watch_partial_frame(bool frame_done);
  // Logs a frame dropped for `error` (the first kMaxDroppedLogged of the connection).
  void log_dropped(const FrameView& frame, FrameError error);
  /// Closes for a limit: logs "stream <peer>: <reason>: <detail>" and records the reason.
  void close_for(const char* reason, const std::string& detail);

  boost::asio::ip::tcp::socket socket_;
  boost::asio::steady_timer partial_timer_;
  const MessageRegistry* registry_;
  Limits limits_;
  StreamDecoder decoder_;
  ClientId id_;
  StreamCounters* counters_;
  Sink sink_;
  std::string peer_;  ///< "address:port" for log lines
  std::array<std::uint8_t, 4096> read_buffer_{};
  std::deque<std::vector<std::uint8_t>> write_queue_;  ///< frames not yet started
  /// The frame async_write is writing (empty when none): Asio reads it until the completion
  /// runs, even after close(), so only on_written() releases it.
  std::vector<std::uint8_t> in_flight_;
  std::int64_t queued_bytes_ = 0;               ///< in write_queue_ and in_flight_
  std::int64_t partial_generation_ = 0;         ///< bumped whenever the partial-frame watch changes
  static constexpr int kMaxDroppedLogged = 10;  ///< dropped frames logged per connection
  int dropped_logged_ = 0;
  bool partial_watched_ = false;
  bool writing_ = false;  ///< an async_write of in_flight_ is under way
  bool open_ = true;
};

}  // namespace llsf::comm::detail
