// SPDX-License-Identifier: MIT
// The 2013 TCP stream protocol on loopback: a server for refbox controllers (default port 4444)
// and a client. Frames follow each other in the byte stream (llsf2013-rules.md §9.2); partial
// reads are reassembled by StreamDecoder. Malformed frames are counted per connection: a frame of
// an unknown type or with a garbage payload is skipped, an oversized one closes the connection
// (the stream cannot be resynchronised). Single-threaded: the caller drives the event loop with
// poll() or run_for(); not thread-safe. Wall-clock paced, not deterministic.
#pragma once

#include <google/protobuf/message.h>

#include <array>
#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "llsf/comm/frame.h"
#include "llsf/comm/registry.h"
#include "llsf/core/ids.h"

namespace llsf::comm {

struct ClientTag {};
/// A connection accepted by a StreamServer (never reused while the server lives).
using ClientId = core::Id<ClientTag>;

/// Counters of one stream connection.
struct StreamCounters {
  std::int64_t frames_in = 0;  ///< well-formed frames received
  std::int64_t bytes_in = 0;
  std::int64_t frames_out = 0;
  std::int64_t bytes_out = 0;
  /// Refused frames by FrameError (kUnknownType, kBadPayload, kOversized).
  std::array<std::int64_t, kFrameErrorCount> malformed{};
  /// Why the connection was closed by this side for a limit ("" while open or for other causes):
  /// "oversized", "partial_frame_timeout", "send_queue_full".
  std::string closed_for;
  std::int64_t malformed_by(FrameError e) const { return malformed[static_cast<std::size_t>(e)]; }
};

/// What happened on a stream since the last take_events().
struct StreamEvent {
  enum class Kind { kConnected, kMessage, kDisconnected };
  Kind kind = Kind::kMessage;
  ClientId client;                                     ///< server side; invalid on the client side
  MessageKey key;                                      ///< kMessage
  std::unique_ptr<google::protobuf::Message> message;  ///< kMessage
};

/// Receives the transports' log lines (one line, no trailing newline).
using LogSink = std::function<void(std::string_view line)>;
/// The default LogSink: "llsf comm: <line>" on standard error.
void log_to_stderr(std::string_view line);

/// Defaults of the stream server's limits (docs/comm.md, "Network limits").
inline constexpr int kDefaultMaxStreamConnections = 16;
inline constexpr std::int64_t kDefaultMaxSendQueueBytes = std::int64_t{1} << 20;
inline constexpr std::chrono::milliseconds kDefaultPartialFrameTimeout{10000};

struct StreamServerOptions {
  std::string address = "127.0.0.1";  ///< loopback unless told otherwise
  int port = 4444;                    ///< 0: any free port (see StreamServer::port)
  /// Largest payload a frame may announce; a larger size field closes the connection before
  /// anything is allocated for it.
  std::int64_t max_payload = kDefaultMaxStreamPayload;
  /// Connections open at once; one more is accepted and closed at once (logged).
  int max_connections = kDefaultMaxStreamConnections;
  /// A connection whose frame stays incomplete this long (counted from the frame's first byte)
  /// is closed (logged). Wall-clock I/O only: game logic never depends on it.
  std::chrono::milliseconds partial_frame_timeout = kDefaultPartialFrameTimeout;
  /// Encoded bytes queued to one connection and not yet written; a send() beyond it closes the
  /// connection (a client that does not read; logged).
  std::int64_t max_send_queue_bytes = kDefaultMaxSendQueueBytes;
  /// Where refusals and closes for a limit are logged.
  LogSink log = log_to_stderr;
};

/// The refbox's controller server.
class StreamServer {
 public:
  /// Binds and listens; throws std::runtime_error if it cannot. `registry` is borrowed.
  explicit StreamServer(const MessageRegistry& registry, StreamServerOptions options = {});
  StreamServer(const StreamServer&) = delete;
  StreamServer& operator=(const StreamServer&) = delete;
  ~StreamServer();

  /// The port the server listens on.
  int port() const;
  void poll();
  void run_for(std::chrono::milliseconds duration);

  /// Events (connections, messages, disconnections) in arrival order since the last call.
  std::vector<StreamEvent> take_events();
  /// Queues `message` to one client; false if it is not connected or cannot be encoded.
  bool send(ClientId client, const google::protobuf::Message& message);
  /// Queues `message` to every connected client; returns how many.
  int broadcast(const google::protobuf::Message& message);
  /// Closes one connection.
  void disconnect(ClientId client);
  int client_count() const;
  /// Connections refused because max_connections were open.
  std::int64_t refused_count() const;
  /// Counters of a connection (also after it closed).
  const StreamCounters& counters(ClientId client) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// A controller's side of the stream protocol.
class StreamClient {
 public:
  explicit StreamClient(const MessageRegistry& registry,
                        std::int64_t max_payload = kDefaultMaxStreamPayload);
  StreamClient(const StreamClient&) = delete;
  StreamClient& operator=(const StreamClient&) = delete;
  ~StreamClient();

  /// Connects (blocking up to `timeout`); false on failure.
  bool connect(const std::string& address, int port,
               std::chrono::milliseconds timeout = std::chrono::milliseconds(2000));
  bool connected() const;
  /// Queues `message`; false if not connected or it cannot be encoded.
  bool send(const google::protobuf::Message& message);
  void poll();
  void run_for(std::chrono::milliseconds duration);
  /// Messages (and a final kDisconnected) since the last call.
  std::vector<StreamEvent> take_events();
  const StreamCounters& counters() const;
  void close();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace llsf::comm
