// SPDX-License-Identifier: MIT
// The viewer's server (app/src/server.h) in-process on a free port: the store's batches, runs,
// reports and recordings as JSON, static files, bad requests (traversal, unknown ids, corrupt
// recordings, garbage) answered without stopping the server, and the live feed over WebSocket.
#include "server.h"

#include <doctest/doctest.h>
#include <fcntl.h>
#include <sys/resource.h>
#include <time.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <boost/asio/connect.hpp>
#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/write.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/websocket.hpp>
#include <chrono>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <functional>
#include <memory>
#include <mutex>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "app/cli_fixture.h"
#include "llsf/study/batch.h"
#include "llsf/study/scenario.h"
#include "llsf/study/stats_store.h"
#include "support/temp_dir.h"

namespace {

namespace fs = std::filesystem;
namespace asio = boost::asio;
namespace beast = boost::beast;
namespace http = beast::http;
namespace websocket = beast::websocket;
using tcp = asio::ip::tcp;
using json = nlohmann::json;

using llsf::test::TempDir;

void write(const std::string& path, const std::string& text) {
  fs::create_directories(fs::path(path).parent_path());
  std::ofstream(path, std::ios::binary) << text;
}

/// A store with one batch of two short recorded games (seeds 3 and 4) and a viewer directory.
struct Fixture {
  TempDir dir;
  std::string db = dir.file("stats.db");
  std::string recordings = dir.file("stats-recordings");
  std::string viewer = dir.file("dist");
  std::vector<llsf::study::StoredRun> runs;

  Fixture() {
    const std::string agents = std::string(LLSF_SOURCE_DIR) + "/clips/agents";
    const std::string scenario = dir.file("tiny.yaml");
    write(scenario,
          "name: tiny\nseeds: [3, 4]\nstart: production\nduration_s: 20\nrobots:\n"
          "  count: 1\n  agent: [" +
              agents + "/common, " + agents + "/llsf2013]\n  config:\n    roles: [P3]\n");
    llsf::study::StatsStore store(db);
    llsf::study::BatchOptions options;
    options.jobs = 1;
    options.recordings_dir = recordings;
    const llsf::study::ScenarioFile file = llsf::study::load_scenario(scenario);
    llsf::study::run_batch(file, llsf::study::batch_identity_hash(scenario, file), store, options);
    runs = store.runs(1);
    write(viewer + "/index.html", "<!doctype html><title>viewer</title>");
    write(viewer + "/viewer.js", "console.log(1);");
  }
  llsf::app::ServerOptions options() const {
    llsf::app::ServerOptions o;
    o.port = 0;
    o.db = db;
    o.recordings = recordings;
    o.viewer = viewer;
    return o;
  }
};

struct Reply {
  int status = 0;
  std::string content_type;
  std::string body;
};

/// One request on a fresh connection (the target is sent as given, unnormalized).
Reply request(int port, const std::string& target, http::verb verb = http::verb::get) {
  asio::io_context ioc;
  tcp::socket socket(ioc);
  socket.connect(
      tcp::endpoint(asio::ip::make_address("127.0.0.1"), static_cast<unsigned short>(port)));
  http::request<http::empty_body> req{verb, target, 11};
  req.set(http::field::host, "127.0.0.1");
  http::write(socket, req);
  beast::flat_buffer buffer;
  http::response_parser<http::string_body> parser;
  parser.body_limit(64 << 20);
  http::read(socket, buffer, parser);
  const auto& res = parser.get();
  return {static_cast<int>(res.result_int()), std::string(res[http::field::content_type]),
          res.body()};
}

std::string error_of(const Reply& r) {
  const json j = json::parse(r.body, nullptr, false);
  return j.is_object() && j.contains("error") ? j["error"].get<std::string>() : "";
}

std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream in(text);
  for (std::string l; std::getline(in, l);) out.push_back(l);
  return out;
}

/// A WebSocket client of /api/live whose reads give up after 5 s.
struct WsClient {
  asio::io_context ioc;
  websocket::stream<beast::tcp_stream> ws{ioc};
  explicit WsClient(int port) {
    beast::get_lowest_layer(ws).connect(
        tcp::endpoint(asio::ip::make_address("127.0.0.1"), static_cast<unsigned short>(port)));
    ws.set_option(
        websocket::stream_base::timeout{std::chrono::seconds(5), std::chrono::seconds(5), false});
    ws.handshake("127.0.0.1", "/api/live");
  }
  /// Lines received until `n` have come (fewer if the connection fails or is idle for 5 s).
  std::vector<std::string> read_lines(std::size_t n) {
    std::vector<std::string> lines;
    while (lines.size() < n) {
      beast::flat_buffer buffer;
      beast::error_code error;
      bool done = false;
      ws.async_read(buffer, [&](beast::error_code ec, std::size_t) {
        error = ec;
        done = true;
      });
      ioc.restart();
      while (!done && ioc.run_one() > 0) {
      }
      if (!done || error) break;
      for (std::string& l : lines_of(beast::buffers_to_string(buffer.data()))) {
        lines.push_back(std::move(l));
      }
    }
    return lines;
  }
};

}  // namespace

TEST_CASE("server: batches, runs, reports, recordings and static files") {
  const Fixture f;
  REQUIRE(f.runs.size() == 2);
  REQUIRE(!f.runs[0].recording.empty());
  llsf::app::Server server(f.options());
  server.start();
  const int port = server.port();
  CHECK(port > 0);
  CHECK(server.url() == "http://127.0.0.1:" + std::to_string(port) + "/");

  Reply r = request(port, "/api/batches");
  CHECK(r.status == 200);
  CHECK(r.content_type == "application/json");
  json j = json::parse(r.body);
  REQUIRE(j.size() == 1);
  CHECK(j[0]["id"] == 1);
  CHECK(j[0]["kind"] == "batch");
  CHECK(j[0]["scenario_name"] == "tiny");
  CHECK(j[0]["variants"] == 1);
  CHECK(j[0]["runs_per_variant"] == 2);
  CHECK(j[0]["finished"] == true);

  r = request(port, "/api/batches/1/runs");
  CHECK(r.status == 200);
  j = json::parse(r.body);
  REQUIRE(j.size() == 2);
  CHECK(j[0]["id"] == f.runs[0].id);
  CHECK(j[0]["seed"] == 3);
  CHECK(j[0]["recording"] == true);
  CHECK(j[0]["result_hash"].get<std::string>().size() == 16);
  CHECK(j[0].contains("points"));
  CHECK(j[0].contains("passed"));

  r = request(port, "/api/batches/1/report");
  CHECK(r.status == 200);
  j = json::parse(r.body);
  CHECK(j["format"] == "llsfsim-report");
  CHECK(j["runs"].size() == 2);

  // A run's recording: the header line first, then frames and events.
  r = request(port, "/api/runs/" + std::to_string(f.runs[0].id) + "/recording");
  CHECK(r.status == 200);
  CHECK(r.content_type == "application/x-ndjson");
  std::vector<std::string> lines = lines_of(r.body);
  REQUIRE(lines.size() > 10);
  CHECK(json::parse(lines[0])["format"] == "llsfsim-recording");
  CHECK(json::parse(lines[1]).contains("t"));

  // The same file below --recordings.
  const std::string rel = fs::relative(f.runs[0].recording, f.recordings).string();
  CHECK(rel.rfind("batch1/", 0) == 0);
  Reply same = request(port, "/api/recordings/" + rel);
  CHECK(same.status == 200);
  CHECK(same.body == r.body);

  r = request(port, "/");
  CHECK(r.status == 200);
  CHECK(r.content_type == "text/html; charset=utf-8");
  CHECK(r.body == "<!doctype html><title>viewer</title>");
  r = request(port, "/viewer.js");
  CHECK(r.status == 200);
  CHECK(r.content_type == "text/javascript; charset=utf-8");
  CHECK(request(port, "/missing.js").status == 404);

  r = request(port, "/api/live/status");
  CHECK(r.status == 200);
  CHECK(json::parse(r.body)["live"] == false);
}

TEST_CASE("server: bad requests get JSON errors and the server keeps serving") {
  Fixture f;
  llsf::app::Server server(f.options());
  server.start();
  const int port = server.port();

  // Path traversal, plain and encoded, backslashes, NUL, absolute paths.
  for (const char* target :
       {"/../CMakeLists.txt", "/%2e%2e/x", "/%2E%2E/%2e%2e/etc/passwd",
        "/api/recordings/../../etc/passwd", "/api/recordings/%2e%2e/%2e%2e/etc/passwd",
        "/api/recordings/batch1/..%2f..%2fx", "/..\\..\\x", "/a%5c..%5cx", "/index.html%00.js",
        "//etc/passwd", "/./index.html", "/%zz", "/%2"}) {
    INFO(target);
    const Reply r = request(port, target);
    CHECK(r.status == 400);
    CHECK(r.content_type == "application/json");
    CHECK(!error_of(r).empty());
  }

  // Unknown ids and routes, non-numeric ids, other methods.
  CHECK(request(port, "/api/runs/999/recording").status == 404);
  CHECK(request(port, "/api/runs/abc/recording").status == 400);
  CHECK(request(port, "/api/runs/-1/recording").status == 400);
  CHECK(request(port, "/api/batches/7/runs").status == 404);
  CHECK(request(port, "/api/batches/7/report").status == 404);
  CHECK(request(port, "/api/batches/x1/report").status == 400);
  CHECK(request(port, "/api/nothing").status == 404);
  CHECK(request(port, "/api/recordings/batch1/none.jsonl.gz").status == 404);
  CHECK(request(port, "/api/live").status == 404);  // no live game
  const Reply post = request(port, "/api/batches", http::verb::post);
  CHECK(post.status == 405);
  CHECK(!error_of(post).empty());

  // A corrupt recording: 422 naming the file; a missing one: 404.
  const llsf::study::StoredRun& run = f.runs[1];
  write(run.recording, "this is not gzip\n");
  Reply r = request(port, "/api/runs/" + std::to_string(run.id) + "/recording");
  CHECK(r.status == 422);
  CHECK(error_of(r).find(run.recording) != std::string::npos);
  const std::string rel = fs::relative(run.recording, f.recordings).string();
  CHECK(request(port, "/api/recordings/" + rel).status == 422);
  fs::remove(run.recording);
  CHECK(request(port, "/api/runs/" + std::to_string(run.id) + "/recording").status == 404);

  // Garbage and half requests on raw connections.
  for (const std::string& garbage :
       {std::string("\x16\x03\x01\x02\x00garbage\r\n\r\n"), std::string("GET\r\n\r\n"),
        std::string("GET / HTTP/1.1\r\nHost: x\r\nContent-Length: 99999999999\r\n\r\n"),
        std::string("GET /api/batches HTTP/1.1\r\nHost")}) {
    asio::io_context ioc;
    tcp::socket socket(ioc);
    socket.connect(
        tcp::endpoint(asio::ip::make_address("127.0.0.1"), static_cast<unsigned short>(port)));
    asio::write(socket, asio::buffer(garbage));
    socket.shutdown(tcp::socket::shutdown_send);
    beast::error_code ec;
    std::string answer(4096, '\0');
    answer.resize(socket.read_some(asio::buffer(answer), ec));
    CHECK((answer.empty() || answer.rfind("HTTP/1.1 400", 0) == 0));
  }

  r = request(port, "/api/batches");
  CHECK(r.status == 200);
  CHECK(json::parse(r.body).size() == 1);
}

TEST_CASE("server: stop() frees the port") {
  Fixture f;
  llsf::app::Server server(f.options());
  server.start();
  const int port = server.port();
  CHECK(request(port, "/api/nothing").status == 404);
  server.stop();
  CHECK(server.port() == port);
  boost::asio::io_context ioc;
  boost::asio::ip::tcp::socket s(ioc);
  boost::system::error_code ec;
  s.connect({boost::asio::ip::make_address("127.0.0.1"), static_cast<unsigned short>(port)}, ec);
  CHECK(ec == boost::asio::error::connection_refused);
  server.stop();  // (idempotent)
}

TEST_CASE("server: the live feed over WebSocket, catch-up first, several clients") {
  Fixture f;
  llsf::app::LiveFeed feed;
  llsf::app::Server server(f.options(), &feed);
  server.start();
  const int port = server.port();
  for (int i = 0; i < 3; ++i) feed.publish("{\"t\": " + std::to_string(i) + "}");

  const Reply status = request(port, "/api/live/status");
  CHECK(json::parse(status.body)["live"] == true);
  CHECK(json::parse(status.body)["running"] == true);

  WsClient a(port);
  std::vector<std::string> got = a.read_lines(3);
  REQUIRE(got.size() == 3);
  CHECK(got[0] == "{\"t\": 0}");
  CHECK(got[2] == "{\"t\": 2}");

  for (int i = 3; i < 500; ++i) feed.publish("{\"t\": " + std::to_string(i) + "}\n");
  WsClient b(port);
  const std::vector<std::string> rest = a.read_lines(497);
  got.insert(got.end(), rest.begin(), rest.end());
  const std::vector<std::string> all = b.read_lines(500);
  REQUIRE(got.size() == 500);
  REQUIRE(all.size() == 500);
  for (int i = 0; i < 500; ++i) {
    const std::string want = "{\"t\": " + std::to_string(i) + "}";
    CHECK(got[static_cast<std::size_t>(i)] == want);
    CHECK(all[static_cast<std::size_t>(i)] == want);
  }
  feed.finish();
  CHECK(json::parse(request(port, "/api/live/status").body)["running"] == false);
  CHECK(request(port, "/api/batches").status == 200);
}

TEST_CASE("server: a client too far behind the live game is dropped") {
  Fixture f;
  llsf::app::LiveFeed feed;
  llsf::app::ServerOptions o = f.options();
  o.max_client_backlog_bytes = 1 << 20;
  llsf::app::Server server(o, &feed);
  server.start();
  WsClient a(server.port());
  // 32 MB while the client reads nothing: more than the sockets' buffers can take, so the
  // client falls more than 1 MB behind and is dropped; the game never waits for it.
  const std::string line = "\"" + std::string(16 * 1024, 'x') + "\"";
  const int n = 2048;
  for (int i = 0; i < n; ++i) feed.publish(line);
  CHECK(a.read_lines(n).size() < static_cast<std::size_t>(n));
  CHECK(request(server.port(), "/api/batches").status == 200);
}

TEST_CASE("llsfsim run --serve prints the URL first and --serve-exit ends with the game") {
  const TempDir dir;
  const std::string agents = std::string(LLSF_SOURCE_DIR) + "/clips/agents";
  const std::string scenario = dir.file("tiny.yaml");
  write(scenario,
        "name: tiny\nseeds: [3]\nstart: production\nduration_s: 10\nrobots:\n"
        "  count: 1\n  agent: [" +
            agents + "/common, " + agents + "/llsf2013]\n");
  const llsf::test::Run r = llsf::test::llsfsim(
      {"run", scenario, "--serve", "--port", "0", "--serve-exit", "--db", dir.file("s.db")});
  INFO(r.out, r.err);
  CHECK(r.code == llsf::app::kExitOk);
  CHECK(r.out.rfind("llsfsim serve: http://127.0.0.1:", 0) == 0);
  CHECK(!llsf::test::has(r.out, "game over"));
  CHECK(llsf::test::llsfsim({"run", scenario, "--port", "1"}).code == llsf::app::kExitBadInput);
}

// ---------------------------------------------------------------------------------------------
// Hostile clients (issue #21; docs/llsfsim.md "Limits")

namespace {

/// Log lines from the server's thread.
struct LogLines {
  std::mutex mutex;
  std::vector<std::string> lines;
  std::function<void(const std::string&)> sink() {
    return [this](const std::string& l) {
      const std::lock_guard lock(mutex);
      lines.push_back(l);
    };
  }
  int count(const std::string& part) {
    const std::lock_guard lock(mutex);
    return static_cast<int>(std::count_if(lines.begin(), lines.end(), [&](const std::string& l) {
      return l.find(part) != std::string::npos;
    }));
  }
};

/// True once the server has closed `s` (EOF or an error), within `wait`.
bool closed_by_server(tcp::socket& s, std::chrono::milliseconds wait) {
  s.non_blocking(true);
  const auto deadline = std::chrono::steady_clock::now() + wait;
  while (std::chrono::steady_clock::now() < deadline) {
    std::array<char, 4096> buf{};
    beast::error_code ec;
    s.read_some(asio::buffer(buf), ec);
    if (ec && ec != asio::error::would_block) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  return false;
}

tcp::socket connect_raw(asio::io_context& ioc, int port) {
  tcp::socket s(ioc);
  s.connect(tcp::endpoint(asio::ip::make_address("127.0.0.1"), static_cast<unsigned short>(port)));
  return s;
}

/// CPU time of this process (all threads).
std::chrono::nanoseconds process_cpu_time() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return std::chrono::seconds(ts.tv_sec) + std::chrono::nanoseconds(ts.tv_nsec);
}

}  // namespace

TEST_CASE("server: symbolic links that lead out of the served folders are refused") {
  Fixture f;
  const std::string outside = f.dir.file("outside");
  write(outside + "/secret.txt", "secret");
  fs::create_symlink(outside + "/secret.txt", f.viewer + "/link.txt");
  fs::create_directory_symlink(outside, f.viewer + "/sub");
  fs::copy_file(f.runs[0].recording, outside + "/game.jsonl.gz");
  fs::create_symlink(outside + "/game.jsonl.gz", f.recordings + "/escape.jsonl.gz");
  // A link that stays inside its folder is fine.
  fs::create_symlink(f.viewer + "/viewer.js", f.viewer + "/alias.js");
  llsf::app::Server server(f.options());
  server.start();
  const int port = server.port();

  Reply r = request(port, "/link.txt");
  CHECK(r.status == 403);
  CHECK(r.body.find("secret") == std::string::npos);
  CHECK(error_of(r) == "the path leads out of the viewer folder");
  CHECK(request(port, "/sub/secret.txt").status == 403);
  r = request(port, "/api/recordings/escape.jsonl.gz");
  CHECK(r.status == 403);
  CHECK(error_of(r) == "the path leads out of the recordings folder: escape.jsonl.gz");
  r = request(port, "/alias.js");
  CHECK(r.status == 200);
  CHECK(r.body == "console.log(1);");
}

TEST_CASE(
    "server: connections beyond max_connections are closed at once; slow requests time "
    "out; header limit") {
  Fixture f;
  LogLines log;
  llsf::app::ServerOptions o = f.options();
  o.max_connections = 2;
  o.request_timeout = std::chrono::milliseconds(300);
  o.max_header_bytes = 1024;
  o.log = log.sink();
  llsf::app::Server server(o);
  server.start();
  const int port = server.port();
  asio::io_context ioc;

  // Two slow clients (half a request line, then nothing) take both slots.
  tcp::socket a = connect_raw(ioc, port);
  tcp::socket b = connect_raw(ioc, port);
  asio::write(a, asio::buffer(std::string("GET / HTTP/1.1\r\nHost: x\r\n")));
  asio::write(b, asio::buffer(std::string("GET /vi")));
  std::this_thread::sleep_for(std::chrono::milliseconds(50));
  tcp::socket c = connect_raw(ioc, port);
  CHECK(closed_by_server(c, std::chrono::milliseconds(200)));
  CHECK(log.count("max_connections") == 1);
  // The slow ones are closed after the request timeout; then the server answers again.
  CHECK(closed_by_server(a, std::chrono::seconds(3)));
  CHECK(closed_by_server(b, std::chrono::seconds(3)));
  CHECK(request(port, "/api/batches").status == 200);
  // A header larger than max_header_bytes: 400.
  tcp::socket d = connect_raw(ioc, port);
  asio::write(d, asio::buffer("GET / HTTP/1.1\r\nHost: x\r\nX-Big: " + std::string(2000, 'a') +
                              "\r\n\r\n"));
  std::string answer(4096, '\0');
  beast::error_code ec;
  answer.resize(d.read_some(asio::buffer(answer), ec));
  CHECK(answer.rfind("HTTP/1.1 400", 0) == 0);
}

TEST_CASE("server: WebSocket clients beyond max_websocket_clients get 503; a slow one is logged") {
  Fixture f;
  LogLines log;
  llsf::app::LiveFeed feed;
  llsf::app::ServerOptions o = f.options();
  o.max_websocket_clients = 1;
  o.max_client_backlog_bytes = 1 << 20;
  o.log = log.sink();
  llsf::app::Server server(o, &feed);
  server.start();
  feed.publish("{\"t\": 0}");
  auto first = std::make_unique<WsClient>(server.port());
  CHECK(first->read_lines(1).size() == 1);
  CHECK_THROWS(WsClient(server.port()));
  CHECK(log.count("max_websocket_clients") == 1);
  // The first client stops reading and falls behind: it is dropped and logged, which frees its
  // slot.
  const std::string line = "\"" + std::string(16 * 1024, 'x') + "\"";
  for (int i = 0; i < 2048; ++i) feed.publish(line);
  CHECK(first->read_lines(2049).size() < 2049);
  CHECK(log.count("dropped WebSocket client") == 1);
  first.reset();
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(5);
  std::unique_ptr<WsClient> second;
  while (!second && std::chrono::steady_clock::now() < deadline) {
    try {
      second = std::make_unique<WsClient>(server.port());
    } catch (const std::exception&) {
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
  }
  CHECK(second != nullptr);
}

TEST_CASE("server: out of file descriptors, accept backs off instead of spinning") {
  Fixture f;
  LogLines log;
  llsf::app::ServerOptions o = f.options();
  o.log = log.sink();
  llsf::app::Server server(o);
  server.start();
  const int port = server.port();
  REQUIRE(request(port, "/api/batches").status == 200);
  // Let the server close that connection, so that no descriptor comes free during the test.
  std::this_thread::sleep_for(std::chrono::milliseconds(200));

  rlimit old{};
  REQUIRE(getrlimit(RLIMIT_NOFILE, &old) == 0);
  int open_now = 0;
  for ([[maybe_unused]] const auto& e : fs::directory_iterator("/proc/self/fd")) ++open_now;
  rlimit low = old;
  low.rlim_cur = static_cast<rlim_t>(open_now + 64);
  REQUIRE(setrlimit(RLIMIT_NOFILE, &low) == 0);
  asio::io_context ioc;
  tcp::socket client(ioc);
  client.open(tcp::v4());
  std::vector<int> hoard;  // every descriptor left: none for the server's accept
  for (int fd; (fd = ::open("/dev/null", O_RDONLY)) >= 0;) hoard.push_back(fd);
  // Completes in the listen backlog.
  client.connect(
      tcp::endpoint(asio::ip::make_address("127.0.0.1"), static_cast<unsigned short>(port)));

  std::this_thread::sleep_for(std::chrono::milliseconds(100));
  const auto cpu_before = process_cpu_time();
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
  const auto cpu = process_cpu_time() - cpu_before;
  const int logged = log.count("cannot accept a connection");
  for (const int fd : hoard) ::close(fd);
  setrlimit(RLIMIT_NOFILE, &old);
  // A spinning accept loop burns the whole 500 ms; backing off every 100 ms takes almost none.
  CHECK(cpu < std::chrono::milliseconds(150));
  CHECK(logged == 1);  // once, not per retry

  // With descriptors back, the waiting connection is served.
  http::request<http::empty_body> req{http::verb::get, "/api/batches", 11};
  req.set(http::field::host, "127.0.0.1");
  http::write(client, req);
  beast::flat_buffer buffer;
  http::response<http::string_body> res;
  http::read(client, buffer, res);
  CHECK(res.result_int() == 200);
}
