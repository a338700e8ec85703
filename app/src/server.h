// SPDX-License-Identifier: MIT
// The browser viewer's HTTP/WebSocket server (`llsfsim serve`, `llsfsim run --serve`): the
// viewer's static files, the statistics store and recordings as JSON, and a live game's
// recording lines over a WebSocket (docs/llsfsim.md, "llsfsim serve").
#pragma once

#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace llsf::app {

/// The recording lines of a live game, kept from the first line on (a client that connects late
/// is sent every line so far). Thread-safe: one thread publishes, the server reads.
class LiveFeed {
 public:
  LiveFeed() = default;
  LiveFeed(const LiveFeed&) = delete;
  LiveFeed& operator=(const LiveFeed&) = delete;

  /// Appends one recording line (a trailing '\n' is dropped) and wakes the listener.
  void publish(std::string_view line);
  /// The game ended: no more lines will come.
  void finish();
  /// Whether finish() was called.
  bool finished() const;
  /// Lines published so far.
  std::int64_t size() const;
  /// Bytes of the lines from index `from` to the end (what a client at `from` still lacks).
  std::int64_t bytes_after(std::int64_t from) const;
  /// Appends the lines from index `from` on to `out`, each followed by '\n', stopping after
  /// the line that makes `out` reach `max_bytes`; returns the index after the last line taken.
  std::int64_t read(std::int64_t from, std::int64_t max_bytes, std::string& out) const;
  /// Called after every publish() and finish(), on the publishing thread; one listener
  /// (nullptr removes it; returns only when no call of the old one is running).
  void set_listener(std::function<void()> listener);

 private:
  void notify();

  mutable std::mutex mutex_;
  std::vector<std::string> lines_;
  std::vector<std::int64_t> ends_;  ///< bytes of lines_[0..i] with their '\n'
  bool finished_ = false;
  std::mutex listener_mutex_;
  std::function<void()> listener_;
};

/// A request handed to ServerOptions::routes.
struct HttpRequest {
  std::string method;             ///< "GET", "POST", ...
  std::vector<std::string> path;  ///< the target's decoded path segments ("/" gives none)
  std::string query;              ///< the target after '?', as sent
  std::string content_type;
  std::string body;
  std::string peer;  ///< "address:port"
};

/// An answer of ServerOptions::routes.
struct HttpAnswer {
  int status = 200;
  std::string content_type = "application/json";
  std::string body;
};

/// Where the server listens and what it serves.
struct ServerOptions {
  std::string bind = "127.0.0.1";  ///< IPv4 or IPv6 address
  int port = 8080;                 ///< 0: any free port
  /// The statistics store (opened when it exists; "" = none: no batches).
  std::string db = "llsfsim.db";
  std::string recordings;  ///< recordings below /api/recordings/ ("" = default_recordings_dir(db))
  std::string viewer;      ///< the built front end ("" = study::viewer_dir())
  /// A WebSocket client further behind the live game than this is dropped (logged): the bytes
  /// it still lacks are its send queue.
  std::int64_t max_client_backlog_bytes = std::int64_t{64} << 20;
  /// HTTP connections open at once (WebSocket clients not counted); one more is accepted and
  /// closed at once (logged).
  int max_connections = 64;
  /// WebSocket clients of /api/live at once; one more gets 503 (logged).
  int max_websocket_clients = 32;
  /// Largest request header (start line and fields) and body; larger requests get 400.
  std::int64_t max_header_bytes = 16 * 1024;
  std::int64_t max_body_bytes = 64 * 1024;
  /// A request must arrive in full within this (a keep-alive connection's wait for the next
  /// request too); otherwise the connection is closed.
  std::chrono::milliseconds request_timeout{15000};
  /// Where refusals, drops and accept errors are logged (one line, no newline; called on the
  /// server's thread). Empty: "llsfsim serve: <line>" on standard error.
  std::function<void(const std::string&)> log;
  /// Routes tried before the built-in ones (empty: none), called on the server's thread (keep
  /// them short): an answer, or nullopt for the built-in routes. Only with routes does the
  /// server accept other methods than GET (which the routes must answer).
  std::function<std::optional<HttpAnswer>(const HttpRequest&)> routes;
};

struct ServerImpl;

/// The HTTP/WebSocket server: one io thread, every connection asynchronous and independent.
class Server {
 public:
  /// Binds and listens. `feed` (borrowed, may be null: no live game) must outlive the server.
  /// Throws std::runtime_error naming the address if it cannot listen.
  explicit Server(ServerOptions options, LiveFeed* feed = nullptr);
  /// Stops serving (stop()).
  ~Server();
  Server(const Server&) = delete;
  Server& operator=(const Server&) = delete;

  /// The port listened on (the chosen one for port 0).
  int port() const;
  /// "http://ADDR:PORT/".
  std::string url() const;
  /// Serves on a background thread (which blocks SIGINT and SIGTERM).
  void start();
  /// Stops serving, joins the thread and closes the listening socket (the port is free again);
  /// open connections are dropped. Idempotent.
  void stop();

 private:
  std::unique_ptr<ServerImpl> impl_;
};

/// Blocks until SIGINT or SIGTERM arrives (the signals are blocked in the calling thread while
/// it waits); returns the signal.
int wait_for_stop_signal();

}  // namespace llsf::app
