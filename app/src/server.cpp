// SPDX-License-Identifier: MIT
// The viewer's server: Boost.Beast on one io_context thread. Every connection is its own
// asynchronous session; a request is answered from the statistics store, a recording file or the
// viewer directory, and bad requests get a JSON error without disturbing other connections.
#include "server.h"

#include <fmt/format.h>
#include <pthread.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/post.hpp>
#include <boost/asio/steady_timer.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/websocket.hpp>
#include <cerrno>
#include <charconv>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <optional>
#include <stdexcept>
#include <thread>
#include <utility>

#include "commands.h"
#include "llsf/core/error.h"
#include "llsf/study/recording.h"
#include "llsf/study/report.h"
#include "llsf/study/stats_store.h"

namespace llsf::app {

// ---------------------------------------------------------------------------------------------
// LiveFeed

void LiveFeed::publish(std::string_view line) {
  if (!line.empty() && line.back() == '\n') line.remove_suffix(1);
  {
    const std::lock_guard lock(mutex_);
    const std::int64_t before = ends_.empty() ? 0 : ends_.back();
    lines_.emplace_back(line);
    ends_.push_back(before + static_cast<std::int64_t>(line.size()) + 1);
  }
  notify();
}

void LiveFeed::finish() {
  {
    const std::lock_guard lock(mutex_);
    finished_ = true;
  }
  notify();
}

bool LiveFeed::finished() const {
  const std::lock_guard lock(mutex_);
  return finished_;
}

std::int64_t LiveFeed::size() const {
  const std::lock_guard lock(mutex_);
  return static_cast<std::int64_t>(lines_.size());
}

std::int64_t LiveFeed::bytes_after(std::int64_t from) const {
  const std::lock_guard lock(mutex_);
  const auto n = static_cast<std::int64_t>(ends_.size());
  if (from >= n) return 0;
  const std::int64_t start = from <= 0 ? 0 : ends_[static_cast<std::size_t>(from - 1)];
  return ends_.back() - start;
}

std::int64_t LiveFeed::read(std::int64_t from, std::int64_t max_bytes, std::string& out) const {
  const std::lock_guard lock(mutex_);
  std::int64_t i = std::max<std::int64_t>(from, 0);
  const auto n = static_cast<std::int64_t>(lines_.size());
  const std::size_t start = out.size();
  while (i < n && static_cast<std::int64_t>(out.size() - start) < max_bytes) {
    out += lines_[static_cast<std::size_t>(i)];
    out += '\n';
    ++i;
  }
  return i;
}

void LiveFeed::set_listener(std::function<void()> listener) {
  const std::lock_guard lock(listener_mutex_);
  listener_ = std::move(listener);
}

void LiveFeed::notify() {
  const std::lock_guard lock(listener_mutex_);
  if (listener_) listener_();
}

// ---------------------------------------------------------------------------------------------
// Requests

namespace {

namespace asio = boost::asio;
namespace beast = boost::beast;
namespace http = beast::http;
namespace websocket = beast::websocket;
namespace fs = std::filesystem;
using tcp = asio::ip::tcp;
using json = nlohmann::json;

constexpr std::int64_t kWsChunkBytes = 256 * 1024;        // one WebSocket message at most (about)
constexpr auto kWriteTimeout = std::chrono::seconds(60);  // to write one response
constexpr auto kAcceptRetry = std::chrono::milliseconds(100);  // after a failed accept (EMFILE)

/// An answer before it becomes an HTTP response.
struct Reply {
  http::status status = http::status::ok;
  std::string content_type = "application/json";
  std::string body;
  bool api = true;  ///< not cached (static files are revalidated instead)
};

/// JSON text; invalid UTF-8 (a file name, a parse error quoting a broken line) becomes U+FFFD
/// instead of an exception.
std::string dump(const json& j) { return j.dump(-1, ' ', false, json::error_handler_t::replace); }

Reply error_reply(http::status status, const std::string& message) {
  return {status, "application/json", dump(json{{"error", message}}) + "\n", true};
}

Reply json_reply(const json& j) { return {http::status::ok, "application/json", dump(j), true}; }

/// The request target's path as decoded segments; nullopt with `error` set for a target that
/// is not a plain path below the root (traversal, encoded or not, backslashes, NUL, bad
/// percent-encoding). "/" gives no segments; a trailing '/' is ignored.
std::optional<std::vector<std::string>> split_target(std::string_view target, std::string& error) {
  if (target.empty() || target.front() != '/') {
    error = "the request target must be a path starting with '/'";
    return std::nullopt;
  }
  target = target.substr(0, target.find_first_of("?#"));
  std::string path;
  path.reserve(target.size());
  for (std::size_t i = 0; i < target.size(); ++i) {
    if (target[i] != '%') {
      path += target[i];
      continue;
    }
    int value = 0;
    const char* begin = target.data() + i + 1;
    if (i + 2 >= target.size() || std::from_chars(begin, begin + 2, value, 16).ptr != begin + 2) {
      error = "bad percent-encoding in the path";
      return std::nullopt;
    }
    path += static_cast<char>(value);
    i += 2;
  }
  if (path.find('\0') != std::string::npos) {
    error = "NUL in the path";
    return std::nullopt;
  }
  if (path.find('\\') != std::string::npos) {
    error = "backslash in the path";
    return std::nullopt;
  }
  std::vector<std::string> segments;
  std::size_t pos = 1;
  while (pos <= path.size()) {
    const std::size_t slash = std::min(path.find('/', pos), path.size());
    std::string segment = path.substr(pos, slash - pos);
    const bool last = slash == path.size();
    if (segment.empty() && !last) {
      error = "empty path segment (absolute path?)";
      return std::nullopt;
    }
    if (segment == "." || segment == "..") {
      error = "path traversal ('" + segment + "') is not allowed";
      return std::nullopt;
    }
    if (!segment.empty()) segments.push_back(std::move(segment));
    pos = slash + 1;
  }
  return segments;
}

/// Whether `file`, with every symbolic link resolved, lies inside `root` (also resolved); false
/// if either does not exist. A link inside a served folder that points out of it is refused.
bool inside_root(const fs::path& root, const fs::path& file) {
  std::error_code ec;
  const fs::path r = fs::canonical(root, ec);
  if (ec) return false;
  const fs::path f = fs::canonical(file, ec);
  if (ec) return false;
  const auto [ri, fi] = std::mismatch(r.begin(), r.end(), f.begin(), f.end());
  return ri == r.end();
}

/// "address:port" of a socket's peer, for log lines.
std::string peer_of(const tcp::socket& socket) {
  beast::error_code ec;
  const tcp::endpoint ep = socket.remote_endpoint(ec);
  return ec ? std::string("?") : ep.address().to_string() + ":" + std::to_string(ep.port());
}

/// Logs the 1st, 2nd, 4th, 8th, ... event of a kind, so that a flood cannot flood the log.
bool log_this_one(std::int64_t count) { return count > 0 && (count & (count - 1)) == 0; }

/// A positive integer id, or nullopt.
std::optional<std::int64_t> parse_id(const std::string& s) {
  std::int64_t v = 0;
  const auto [ptr, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  if (ec != std::errc() || ptr != s.data() + s.size() || v <= 0) return std::nullopt;
  return v;
}

std::string_view content_type_of(const fs::path& p) {
  const std::string ext = p.extension().string();
  if (ext == ".html" || ext == ".htm") return "text/html; charset=utf-8";
  if (ext == ".js" || ext == ".mjs") return "text/javascript; charset=utf-8";
  if (ext == ".css") return "text/css; charset=utf-8";
  if (ext == ".json" || ext == ".map") return "application/json";
  if (ext == ".png") return "image/png";
  if (ext == ".svg") return "image/svg+xml";
  if (ext == ".ico") return "image/x-icon";
  if (ext == ".txt") return "text/plain; charset=utf-8";
  if (ext == ".wasm") return "application/wasm";
  return "application/octet-stream";
}

std::optional<std::string> read_file(const fs::path& p) {
  std::ifstream f(p, std::ios::binary);
  if (!f) return std::nullopt;
  std::string s{std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>()};
  if (f.bad()) return std::nullopt;
  return s;
}

/// A recording file as JSON lines: 404 if missing, 422 if it does not read.
Reply recording_reply(const fs::path& path, const std::string& shown_as) {
  std::error_code ec;
  if (!fs::is_regular_file(path, ec))
    return error_reply(http::status::not_found, "no recording " + shown_as);
  std::vector<study::RecordingLine> lines;
  try {
    lines = study::read_recording(path.string());
  } catch (const std::runtime_error& e) {
    return error_reply(http::status::unprocessable_entity, e.what());
  }
  Reply r{http::status::ok, "application/x-ndjson", {}, true};
  std::size_t bytes = 0;
  for (const study::RecordingLine& l : lines) bytes += l.json.size() + 1;
  r.body.reserve(bytes);
  for (const study::RecordingLine& l : lines) {
    r.body += l.json;
    r.body += '\n';
  }
  return r;
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// The server's state (everything below runs on the io thread unless said otherwise)

class WsSession;

struct ServerImpl {
  ServerOptions options;
  LiveFeed* feed = nullptr;
  std::optional<study::StatsStore> store;
  // Counted by the sessions' constructors and destructors; declared before ioc, whose
  // destruction destroys the sessions still pending.
  int http_connections = 0;
  int ws_clients = 0;
  std::int64_t refused_connections = 0;
  std::int64_t refused_ws_clients = 0;
  std::int64_t dropped_ws_clients = 0;
  bool accept_failing = false;  ///< since the last successful accept (logged once)
  asio::io_context ioc{1};
  tcp::acceptor acceptor{ioc};
  int port = 0;  // the port listened on (also after stop())
  asio::steady_timer accept_retry{ioc};
  std::vector<std::weak_ptr<WsSession>> ws_sessions;
  std::atomic<bool> fan_out_pending{false};
  std::thread thread;
  std::string host;  ///< as written in the URL

  void accept();
  void on_accept_error(const beast::error_code& ec);
  void refuse(tcp::socket& socket);
  void log(const std::string& line) const;
  void fan_out();
  Reply handle(const std::vector<std::string>& path);
  Reply handle_api(const std::vector<std::string>& path);
  Reply serve_static(const std::vector<std::string>& path);
  /// The statistics store, opened on first use if its file exists (nullptr if it does not); a
  /// database server's store is opened by the constructor.
  study::StatsStore* stats();
};

void ServerImpl::log(const std::string& line) const {
  if (options.log) {
    options.log(line);
  } else {
    std::fprintf(stderr, "llsfsim serve: %s\n", line.c_str());
  }
}

study::StatsStore* ServerImpl::stats() {
  if (store) return &*store;
  std::error_code ec;
  if (options.db.empty() || study::is_database_url(options.db) ||
      !fs::is_regular_file(options.db, ec)) {
    return nullptr;
  }
  store.emplace(options.db);  // StatsError reaches handle(): 500
  return &*store;
}

Reply ServerImpl::handle(const std::vector<std::string>& path) {
  try {
    if (!path.empty() && path.front() == "api") return handle_api(path);
    return serve_static(path);
  } catch (const std::exception& e) {
    return error_reply(http::status::internal_server_error, e.what());
  }
}

Reply ServerImpl::serve_static(const std::vector<std::string>& path) {
  fs::path file(options.viewer);
  if (path.empty()) {
    file /= "index.html";
  } else {
    for (const std::string& s : path) file /= s;
  }
  std::error_code ec;
  if (!fs::is_regular_file(file, ec)) {
    if (path.empty()) {
      return error_reply(http::status::not_found, "the viewer is not built (run `make viewer`): " +
                                                      file.string() + " is missing");
    }
    return error_reply(http::status::not_found, "not found");
  }
  if (!inside_root(options.viewer, file)) {
    return error_reply(http::status::forbidden, "the path leads out of the viewer folder");
  }
  std::optional<std::string> body = read_file(file);
  if (!body) return error_reply(http::status::internal_server_error, "cannot read the file");
  return {http::status::ok, std::string(content_type_of(file)), std::move(*body), false};
}

Reply ServerImpl::handle_api(const std::vector<std::string>& path) {
  const std::size_t n = path.size();
  auto at = [&](std::size_t i) -> const std::string& { return path[i]; };
  // GET /api/batches
  if (n == 2 && at(1) == "batches") {
    json a = json::array();
    if (study::StatsStore* s = stats()) {
      for (const study::StoredBatch& b : s->batches()) {
        a.push_back({{"id", b.id},
                     {"kind", b.kind},
                     {"scenario_name", b.scenario_name},
                     {"scenario_file", b.scenario_file},
                     {"variants", b.variants},
                     {"runs_per_variant", b.runs_per_variant},
                     {"finished", !b.finished.empty()}});
      }
    }
    return json_reply(a);
  }
  // GET /api/batches/{id}/runs, /api/batches/{id}/report
  if (n == 4 && at(1) == "batches" && (at(3) == "runs" || at(3) == "report")) {
    const std::optional<std::int64_t> id = parse_id(at(2));
    if (!id) return error_reply(http::status::bad_request, "bad batch id '" + at(2) + "'");
    study::StatsStore* s = stats();
    if (s == nullptr || !s->batch(*id)) {
      return error_reply(http::status::not_found, fmt::format("no batch {}", *id));
    }
    if (at(3) == "report") {
      Reply r{http::status::ok, "application/json",
              study::to_json(study::make_report(*s, *id), study::run_values(*s, *id)), true};
      return r;
    }
    json a = json::array();
    for (const study::StoredRun& r : s->runs(*id)) {
      a.push_back({{"id", r.id},
                   {"variant", r.variant},
                   {"seed", r.seed},
                   {"points", r.points},
                   {"passed", r.passed},
                   {"result_hash", fmt::format("{:016x}", r.result_hash)},
                   {"recording", !r.recording.empty()}});
    }
    return json_reply(a);
  }
  // GET /api/runs/{id}/recording
  if (n == 4 && at(1) == "runs" && at(3) == "recording") {
    const std::optional<std::int64_t> id = parse_id(at(2));
    if (!id) return error_reply(http::status::bad_request, "bad run id '" + at(2) + "'");
    if (study::StatsStore* s = stats()) {
      if (const std::optional<study::StoredRun> r = s->run(*id)) {
        if (r->recording.empty()) {
          return error_reply(http::status::not_found, fmt::format("run {} has no recording", *id));
        }
        return recording_reply(r->recording, r->recording);
      }
    }
    return error_reply(http::status::not_found, fmt::format("no run {}", *id));
  }
  // GET /api/recordings/{relative path}
  if (n >= 3 && at(1) == "recordings") {
    fs::path file(options.recordings);
    std::string shown;
    for (std::size_t i = 2; i < n; ++i) {
      file /= at(i);
      shown += (i > 2 ? "/" : "") + at(i);
    }
    std::error_code ec;
    if (fs::exists(file, ec) && !inside_root(options.recordings, file)) {
      return error_reply(http::status::forbidden,
                         "the path leads out of the recordings folder: " + shown);
    }
    return recording_reply(file, shown);
  }
  // GET /api/live/status
  if (n == 3 && at(1) == "live" && at(2) == "status") {
    const bool live = feed != nullptr;
    return json_reply({{"live", live},
                       {"running", live && !feed->finished()},
                       {"lines", live ? feed->size() : 0}});
  }
  if (n == 2 && at(1) == "live") {
    if (feed == nullptr) return error_reply(http::status::not_found, "no live game");
    return error_reply(http::status::upgrade_required, "/api/live is a WebSocket");
  }
  return error_reply(http::status::not_found, "no such API route");
}

// ---------------------------------------------------------------------------------------------
// WebSocket sessions: the live feed, pulled from the feed at the client's own pace

class WsSession : public std::enable_shared_from_this<WsSession> {
 public:
  WsSession(tcp::socket&& socket, ServerImpl& server)
      : ws_(std::move(socket)), server_(server), peer_(peer_of(ws_.next_layer().socket())) {
    ++server_.ws_clients;
  }
  ~WsSession() { --server_.ws_clients; }
  WsSession(const WsSession&) = delete;
  WsSession& operator=(const WsSession&) = delete;

  void accept(http::request<http::string_body> req) {
    websocket::stream_base::timeout t =
        websocket::stream_base::timeout::suggested(beast::role_type::server);
    t.keep_alive_pings = true;  // a vanished client is noticed even when no line comes
    ws_.set_option(t);
    ws_.read_message_max(64 * 1024);
    ws_.async_accept(req, [self = shared_from_this()](beast::error_code ec) {
      if (ec) return;
      // Drop the entries of clients gone since (after the game no fan_out() prunes them).
      std::erase_if(self->server_.ws_sessions,
                    [](const std::weak_ptr<WsSession>& w) { return w.expired(); });
      self->server_.ws_sessions.push_back(self);
      self->read();
      self->pump();
    });
  }

  /// Sends what the client lacks, if no write is under way; drops a client too far behind.
  void pump() {
    if (closed_) return;
    LiveFeed& feed = *server_.feed;
    if (const std::int64_t behind = feed.bytes_after(next_);
        behind > server_.options.max_client_backlog_bytes) {
      closed_ = true;
      if (log_this_one(++server_.dropped_ws_clients)) {
        server_.log(fmt::format(
            "dropped WebSocket client {}: {} bytes behind the live game (max_client_backlog_bytes "
            "{}); {} dropped so far",
            peer_, behind, server_.options.max_client_backlog_bytes, server_.dropped_ws_clients));
      }
      beast::error_code ignored;
      beast::get_lowest_layer(ws_).socket().close(ignored);
      return;
    }
    if (writing_) return;
    out_.clear();
    next_ = feed.read(next_, kWsChunkBytes, out_);
    if (out_.empty()) return;
    out_.pop_back();  // lines are separated by '\n' within a message
    writing_ = true;
    ws_.text(true);
    ws_.async_write(asio::buffer(out_),
                    [self = shared_from_this()](beast::error_code ec, std::size_t) {
                      self->writing_ = false;
                      if (ec) {
                        self->closed_ = true;
                        return;
                      }
                      self->pump();
                    });
  }

 private:
  // Reads (and ignores) what the client sends, to see pings and the close.
  void read() {
    ws_.async_read(in_, [self = shared_from_this()](beast::error_code ec, std::size_t) {
      if (ec) {
        self->closed_ = true;
        return;
      }
      self->in_.consume(self->in_.size());
      self->read();
    });
  }

  websocket::stream<beast::tcp_stream> ws_;
  ServerImpl& server_;
  std::string peer_;
  beast::flat_buffer in_;
  std::string out_;
  std::int64_t next_ = 0;  ///< the next feed line to send
  bool writing_ = false;
  bool closed_ = false;
};

void ServerImpl::fan_out() {
  fan_out_pending = false;
  std::erase_if(ws_sessions, [](const std::weak_ptr<WsSession>& w) { return w.expired(); });
  for (const std::weak_ptr<WsSession>& w : ws_sessions) {
    if (std::shared_ptr<WsSession> s = w.lock()) s->pump();
  }
}

// ---------------------------------------------------------------------------------------------
// HTTP sessions

namespace {

class HttpSession : public std::enable_shared_from_this<HttpSession> {
 public:
  HttpSession(tcp::socket&& socket, ServerImpl& server)
      : stream_(std::move(socket)), server_(server) {
    ++server_.http_connections;
  }
  ~HttpSession() { --server_.http_connections; }
  HttpSession(const HttpSession&) = delete;
  HttpSession& operator=(const HttpSession&) = delete;

  void read() {
    parser_.emplace();
    parser_->header_limit(static_cast<std::uint32_t>(server_.options.max_header_bytes));
    parser_->body_limit(static_cast<std::uint64_t>(server_.options.max_body_bytes));
    stream_.expires_after(server_.options.request_timeout);
    http::async_read(
        stream_, buffer_, *parser_,
        [self = shared_from_this()](beast::error_code ec, std::size_t) { self->on_read(ec); });
  }

 private:
  void on_read(beast::error_code ec) {
    if (ec == http::error::end_of_stream) {
      stream_.socket().shutdown(tcp::socket::shutdown_send, ec);
      return;
    }
    if (ec) {
      // A malformed request gets a 400 and the connection is closed; I/O errors just close.
      if (ec == http::error::body_limit && server_.options.routes) {  // an upload too large
        send(http::request<http::string_body>{},
             error_reply(http::status::payload_too_large,
                         fmt::format("the request body is larger than {} bytes",
                                     server_.options.max_body_bytes)),
             /*close=*/true, /*drain=*/true);
        return;
      }
      if (ec.category() == http::make_error_code(http::error::bad_target).category()) {
        send(http::request<http::string_body>{},
             error_reply(http::status::bad_request, "bad request: " + ec.message()),
             /*close=*/true);
      }
      return;
    }
    http::request<http::string_body> req = parser_->release();
    std::string error;
    const std::optional<std::vector<std::string>> path =
        split_target(std::string_view(req.target().data(), req.target().size()), error);
    if (!path) {
      send(req, error_reply(http::status::bad_request, error));
      return;
    }
    if (server_.options.routes) {
      HttpRequest r;
      r.method = std::string(req.method_string());
      r.path = *path;
      const std::string_view target(req.target().data(), req.target().size());
      if (const std::size_t q = target.find('?'); q != std::string_view::npos) {
        r.query = std::string(target.substr(q + 1));
      }
      r.content_type = std::string(req[http::field::content_type]);
      r.body = std::move(req.body());
      r.peer = peer_of(stream_.socket());
      std::optional<HttpAnswer> answer;
      try {
        answer = server_.options.routes(r);
      } catch (const std::exception& e) {
        answer = HttpAnswer{500, "application/json", dump(json{{"error", e.what()}}) + "\n"};
      }
      if (answer) {
        send(req, {static_cast<http::status>(answer->status), std::move(answer->content_type),
                   std::move(answer->body), true});
        return;
      }
    }
    if (req.method() != http::verb::get) {
      send(req, error_reply(http::status::method_not_allowed, "only GET is served"));
      return;
    }
    const bool live_route = path->size() == 2 && (*path)[0] == "api" && (*path)[1] == "live";
    if (live_route && server_.feed != nullptr && websocket::is_upgrade(req)) {
      if (server_.ws_clients >= server_.options.max_websocket_clients) {
        if (log_this_one(++server_.refused_ws_clients)) {
          server_.log(fmt::format(
              "refused a WebSocket client {}: {} open (max_websocket_clients); {} refused so far",
              peer_of(stream_.socket()), server_.ws_clients, server_.refused_ws_clients));
        }
        send(req,
             error_reply(http::status::service_unavailable,
                         fmt::format("too many live clients ({} at most)",
                                     server_.options.max_websocket_clients)),
             /*close=*/true);
        return;
      }
      stream_.expires_never();
      std::make_shared<WsSession>(stream_.release_socket(), server_)->accept(std::move(req));
      return;
    }
    send(req, server_.handle(*path));
  }

  // After refusing an upload: reads (and drops) what the client still sends, at most `left`
  // bytes within the request timeout, so that closing does not reset the connection before the
  // client read the refusal (its write would fail with "Broken pipe" and the 413 be lost).
  void drain(std::uint64_t left) {
    if (left == 0) return;
    auto scratch = std::make_shared<std::array<char, 16384>>();
    stream_.expires_after(server_.options.request_timeout);
    stream_.async_read_some(asio::buffer(*scratch), [self = shared_from_this(), scratch, left](
                                                        beast::error_code ec, std::size_t n) {
      if (ec) return;  // the client closed (or the time is up): done
      self->drain(n >= left ? 0 : left - n);
    });
  }

  void send(const http::request<http::string_body>& req, Reply reply, bool close = false,
            bool drain_after = false) {
    auto res = std::make_shared<http::response<http::string_body>>(
        reply.status, req.version() ? req.version() : 11);
    res->set(http::field::server, "llsfsim");
    res->set(http::field::content_type, reply.content_type);
    res->set(http::field::cache_control, reply.api ? "no-store" : "no-cache");
    if (reply.status == http::status::method_not_allowed) {
      res->set(http::field::allow, server_.options.routes ? "GET, POST" : "GET");
    }
    res->keep_alive(!close && req.keep_alive());
    res->body() = std::move(reply.body);
    res->prepare_payload();
    stream_.expires_after(kWriteTimeout);
    http::async_write(
        stream_, *res,
        [self = shared_from_this(), res, drain_after](beast::error_code ec, std::size_t) {
          if (ec) return;
          if (!res->keep_alive()) {
            self->stream_.socket().shutdown(tcp::socket::shutdown_send, ec);
            if (drain_after) {
              self->drain(64 * static_cast<std::uint64_t>(self->server_.options.max_body_bytes) +
                          (1U << 20));
            }
            return;
          }
          self->read();
        });
  }

  beast::tcp_stream stream_;
  ServerImpl& server_;
  beast::flat_buffer buffer_;
  std::optional<http::request_parser<http::string_body>> parser_;
};

}  // namespace

void ServerImpl::accept() {
  acceptor.async_accept([this](beast::error_code ec, tcp::socket socket) {
    if (!acceptor.is_open()) return;
    if (ec) {
      on_accept_error(ec);
      return;
    }
    accept_failing = false;
    if (http_connections >= options.max_connections) {
      refuse(socket);
    } else {
      std::make_shared<HttpSession>(std::move(socket), *this)->read();
    }
    accept();
  });
}

void ServerImpl::on_accept_error(const beast::error_code& ec) {
  // Out of file descriptors (EMFILE, ENFILE) or memory, the connection stays in the listen
  // backlog and accepting again fails at once: retry after a pause instead of spinning.
  if (!accept_failing) {
    accept_failing = true;
    log(fmt::format("cannot accept a connection: {}; retrying every {} ms until it works",
                    ec.message(), kAcceptRetry.count()));
  }
  accept_retry.expires_after(kAcceptRetry);
  accept_retry.async_wait([this](beast::error_code e) {
    if (e || !acceptor.is_open()) return;
    accept();
  });
}

void ServerImpl::refuse(tcp::socket& socket) {
  ++refused_connections;
  if (log_this_one(refused_connections)) {
    log(fmt::format("refused a connection from {}: {} open (max_connections); {} refused so far",
                    peer_of(socket), http_connections, refused_connections));
  }
  beast::error_code ignored;
  socket.close(ignored);
}

// ---------------------------------------------------------------------------------------------
// Server

Server::Server(ServerOptions options, LiveFeed* feed) : impl_(std::make_unique<ServerImpl>()) {
  ServerImpl& m = *impl_;
  if (options.recordings.empty()) options.recordings = default_recordings_dir(options.db);
  if (options.viewer.empty()) options.viewer = study::viewer_dir();
  m.options = std::move(options);
  m.feed = feed;
  // A database server's store at once: an unreachable server or a bad URL is an error of the
  // command (StatsError is a UserError: exit 2), not a 500 of every batch page later.
  if (study::is_database_url(m.options.db)) m.store.emplace(m.options.db);
  const std::string& bind = m.options.bind;
  if (m.options.port < 0 || m.options.port > 65535) {
    throw core::UserError(fmt::format("bad port {}", m.options.port));
  }
  if (m.options.max_connections < 1 || m.options.max_websocket_clients < 0 ||
      m.options.max_header_bytes < 1 || m.options.max_header_bytes > 0xffffffff ||
      m.options.max_body_bytes < 0 || m.options.request_timeout.count() <= 0) {
    throw core::UserError(
        "bad server limits (max_connections >= 1, max_websocket_clients >= 0, header and body "
        "sizes, request timeout > 0)");
  }
  beast::error_code ec;
  const asio::ip::address address = asio::ip::make_address(bind, ec);
  if (ec) throw core::UserError("bad address to bind: '" + bind + "'");
  const tcp::endpoint endpoint(address, static_cast<unsigned short>(m.options.port));
  const auto fail = [&](const char* what) {
    throw core::UserError(
        fmt::format("cannot {} {}:{}: {}", what, bind, m.options.port, ec.message()));
  };
  if (m.acceptor.open(endpoint.protocol(), ec)) fail("open a socket for");
  if (m.acceptor.set_option(asio::socket_base::reuse_address(true), ec)) fail("configure");
  if (m.acceptor.bind(endpoint, ec)) fail("listen on");
  if (m.acceptor.listen(asio::socket_base::max_listen_connections, ec)) fail("listen on");
  m.host = address.is_v6() ? "[" + bind + "]" : bind;
  m.port = m.acceptor.local_endpoint().port();
  if (feed != nullptr) {
    feed->set_listener([&m] {
      if (!m.fan_out_pending.exchange(true)) asio::post(m.ioc, [&m] { m.fan_out(); });
    });
  }
  m.accept();
}

Server::~Server() {
  if (impl_->feed != nullptr) impl_->feed->set_listener(nullptr);
  stop();
}

int Server::port() const { return impl_->port; }

std::string Server::url() const { return fmt::format("http://{}:{}/", impl_->host, port()); }

void Server::start() {
  if (impl_->thread.joinable()) return;
  // The io thread leaves SIGINT and SIGTERM to the thread that waits for them.
  sigset_t block;
  sigset_t old;
  sigemptyset(&block);
  sigaddset(&block, SIGINT);
  sigaddset(&block, SIGTERM);
  pthread_sigmask(SIG_BLOCK, &block, &old);
  impl_->thread = std::thread([m = impl_.get()] {
    for (;;) {
      try {
        m->ioc.run();
        return;
      } catch (const std::exception&) {
        // A handler threw (out of memory, ...): that connection is gone, the others go on.
      }
    }
  });
  pthread_sigmask(SIG_SETMASK, &old, nullptr);
}

void Server::stop() {
  impl_->ioc.stop();
  if (impl_->thread.joinable()) impl_->thread.join();
  // The port is free again once stopped (not only when the server is destroyed).
  beast::error_code ec;
  impl_->acceptor.close(ec);
}

int wait_for_stop_signal() {
  sigset_t set;
  sigset_t old;
  sigemptyset(&set);
  sigaddset(&set, SIGINT);
  sigaddset(&set, SIGTERM);
  pthread_sigmask(SIG_BLOCK, &set, &old);
  int sig = 0;
  while (sigwait(&set, &sig) != 0) {
  }
  pthread_sigmask(SIG_SETMASK, &old, nullptr);
  return sig;
}

}  // namespace llsf::app
