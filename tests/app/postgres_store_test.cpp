// SPDX-License-Identifier: MIT
// The commands on a PostgreSQL statistics store (a throwaway cluster, tests/support/pg_cluster.h):
// a bad URL or an unreachable server is exit 2 before any game; `batch` (and its resume), `run`,
// `report` and `serve` end to end, with the same results and the same report as a SQLite file.
#include <doctest/doctest.h>

#include <boost/asio/connect.hpp>
#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <tuple>
#include <vector>

#include "app/cli_fixture.h"
#include "llsf/study/stats_store.h"
#include "server.h"
#include "support/pg_cluster.h"
#include "support/temp_dir.h"

namespace {

namespace fs = std::filesystem;
namespace asio = boost::asio;
namespace beast = boost::beast;
namespace http = beast::http;
using tcp = asio::ip::tcp;
using json = nlohmann::json;

using llsf::test::has;
using llsf::test::llsfsim;
using llsf::test::PgCluster;
using llsf::test::Run;
using llsf::test::TempDir;

/// Two variants x two seeds of 20 s games with one robot.
std::string write_tiny(const TempDir& dir) {
  const std::string agents = std::string(LLSF_SOURCE_DIR) + "/clips/agents";
  const std::string path = dir.file("tiny.yaml");
  std::ofstream(path) << "name: tiny\nseeds: [3, 4]\nstart: production\nduration_s: 20\n"
                         "robots:\n  count: 1\n  agent: ["
                      << agents << "/common, " << agents
                      << "/llsf2013]\n  config:\n    roles: [P3]\n"
                         "matrix:\n  config:\n    P3: {}\n    P1P2: {robots.config.roles: [P1P2]}\n"
                         "tests:\n  - no_agent_errors: true\n";
  return path;
}

/// (variant, seed) -> result hash of every run of the store's batches of kind `batch`.
std::map<std::pair<std::string, std::uint64_t>, std::uint64_t> hashes(const std::string& db) {
  const llsf::study::StatsStore store(db);
  std::map<std::pair<std::string, std::uint64_t>, std::uint64_t> out;
  for (const auto& b : store.batches()) {
    if (b.kind != "batch") continue;
    for (const auto& r : store.runs(b.id)) out[{r.variant, r.seed}] = r.result_hash;
  }
  return out;
}

/// GET `target` from 127.0.0.1:`port`: status and body.
std::pair<int, std::string> get(int port, const std::string& target) {
  asio::io_context ioc;
  tcp::socket socket(ioc);
  socket.connect(
      tcp::endpoint(asio::ip::make_address("127.0.0.1"), static_cast<unsigned short>(port)));
  http::request<http::empty_body> req{http::verb::get, target, 11};
  req.set(http::field::host, "127.0.0.1");
  http::write(socket, req);
  beast::flat_buffer buffer;
  http::response<http::string_body> res;
  http::read(socket, buffer, res);
  return {static_cast<int>(res.result_int()), res.body()};
}

}  // namespace

TEST_CASE("--db URL: a bad URL or an unreachable server is exit 2 before any game") {
  const TempDir dir;
  const std::string scenario = write_tiny(dir);
  const int closed = PgCluster::shared().port() == 1 ? 2 : 1;  // nothing listens there
  const std::string unreachable =
      "postgresql://llsf:hunter2@127.0.0.1:" + std::to_string(closed) + "/study";
  const std::string bad = "postgresql://llsf:hunter2@127.0.0.1/study?bogus=1";
  for (const std::string& url : {unreachable, bad}) {
    CAPTURE(url);
    const std::string why = url == bad ? "not a valid PostgreSQL URL" : "cannot connect";
    const std::string rec = dir.file("rec");
    const Run batch = llsfsim({"batch", scenario, "--db", url, "--recordings", rec, "--jobs", "1"});
    CHECK(batch.code == 2);
    CHECK(has(batch.err, why));
    CHECK(has(batch.err, "llsf:***@127.0.0.1"));
    CHECK_FALSE(has(batch.err + batch.out, "hunter2"));
    CHECK(batch.out.empty());             // no summary: no game was played
    CHECK_FALSE(has(batch.err, "seed"));  // no progress line of a stored run
    CHECK_FALSE(fs::exists(rec));
    const Run run = llsfsim({"run", scenario, "--db", url, "--no-record", "--json"});
    CHECK(run.code == 2);
    CHECK(has(run.err, why));
    CHECK(run.out.empty());
    CHECK_FALSE(has(run.err + run.out, "hunter2"));
    const Run report = llsfsim({"report", "--db", url});
    CHECK(report.code == 2);
    CHECK(has(report.err, why));
    CHECK_FALSE(has(report.err, "hunter2"));
    const Run serve = llsfsim({"serve", "--db", url, "--port", "0", "--viewer", dir.file("none")});
    CHECK(serve.code == 2);
    CHECK(has(serve.err, why));
    CHECK_FALSE(has(serve.err, "hunter2"));
  }
}

TEST_CASE("--db URL: batch, resume, run, report and serve on PostgreSQL") {
  PgCluster& pg = PgCluster::shared();
  const std::string url = pg.create_database();
  const TempDir dir;
  const std::string scenario = write_tiny(dir);
  const std::string rec = dir.file("rec");

  const Run first = llsfsim({"batch", scenario, "--db", url, "--jobs", "2", "--recordings", rec});
  REQUIRE(first.code == 0);
  CHECK(has(first.out, "4 runs, 4 played, 0 stored before"));
  CHECK(has(first.out, "in " + url));
  // Resumed: everything is stored, nothing is played.
  const Run again = llsfsim({"batch", scenario, "--db", url, "--jobs", "2", "--no-record"});
  REQUIRE(again.code == 0);
  CHECK(has(again.out, "4 runs, 0 played, 4 stored before"));

  // The same batch into a SQLite file: the same games, the same report.
  const std::string file = dir.file("stats.db");
  REQUIRE(llsfsim({"batch", scenario, "--db", file, "--jobs", "1", "--no-record"}).code == 0);
  const auto pg_hashes = hashes(url);
  CHECK(pg_hashes.size() == 4);
  CHECK(pg_hashes == hashes(file));
  const Run pg_report = llsfsim({"report", "--db", url});
  const Run file_report = llsfsim({"report", "--db", file});
  REQUIRE(pg_report.code == 0);
  REQUIRE(file_report.code == 0);
  CHECK(pg_report.out == file_report.out);
  CHECK(has(pg_report.out, "P1P2"));
  const std::string csv = dir.file("r.csv");
  REQUIRE(llsfsim({"report", "--db", url, "--csv", csv}).code == 0);
  CHECK(fs::file_size(csv) > 100);

  // Recordings: absolute paths in the store, the files where the batch wrote them.
  const llsf::study::StatsStore store(url);
  const auto runs = store.runs(store.batches().front().id);
  REQUIRE(runs.size() == 4);
  for (const auto& r : runs) {
    CHECK(fs::path(r.recording).is_absolute());
    CHECK(r.recording.starts_with(rec + "/batch1/"));
    CHECK(fs::exists(r.recording));
  }

  // `run`: its game stored in a batch of kind run, replaced when played again.
  for (int i = 0; i < 2; ++i) {
    const Run one = llsfsim({"run", scenario, "--db", url, "--no-record", "--seed", "3", "-q"});
    CHECK(one.code == 0);
  }
  const auto batches = store.batches();
  REQUIRE(batches.size() == 2);
  CHECK(batches[1].kind == "run");
  CHECK(store.runs(batches[1].id).size() == 1);

  // `serve`: the batch pages and a recording from the store on the server.
  llsf::app::ServerOptions o;
  o.port = 0;
  o.db = url;
  o.recordings = rec;
  o.viewer = dir.file("viewer");
  llsf::app::Server server(o);
  server.start();
  const int port = server.port();
  const auto [status, body] = get(port, "/api/batches");
  CHECK(status == 200);
  const json list = json::parse(body);
  REQUIRE(list.size() == 2);
  CHECK(list[0]["scenario_name"] == "tiny");
  const auto [runs_status, runs_body] = get(port, "/api/batches/1/runs");
  CHECK(runs_status == 200);
  CHECK(json::parse(runs_body).size() == 4);
  CHECK(get(port, "/api/batches/1/report").first == 200);
  CHECK(get(port, "/api/runs/" + std::to_string(runs[0].id) + "/recording").first == 200);
  server.stop();
}
