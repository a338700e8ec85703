// SPDX-License-Identifier: MIT
// The hackathon leaderboard (app/src/hackathon.*, sandbox.*, study SubmissionStore): ranking,
// bad submissions, the store across restarts, the sandbox's limits, the real llsfsim as worker.
#include <doctest/doctest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <chrono>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <thread>

#include "cli_fixture.h"
#include "hackathon.h"
#include "llsf/study/stats_store.h"
#include "llsf/study/submission_store.h"
#include "sandbox.h"

namespace {

namespace fs = std::filesystem;
using llsf::app::HackathonOptions;
using llsf::app::HackathonServer;
using llsf::app::HttpAnswer;
using llsf::app::HttpRequest;
using llsf::app::SandboxLimits;
using llsf::app::SandboxResult;
using llsf::study::Submission;
using llsf::study::SubmissionStatus;
using llsf::study::SubmissionStore;
using json = nlohmann::json;

/// A fresh temporary directory, removed afterwards.
struct TempDir {
  TempDir() {
    std::string t = (fs::temp_directory_path() / "llsf-hackathon-test-XXXXXX").string();
    REQUIRE(::mkdtemp(t.data()) != nullptr);
    path = t;
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  std::string file(const std::string& name) const { return (fs::path(path) / name).string(); }
  std::string path;
};

std::string read(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>()};
}

const std::string kSource = LLSF_SOURCE_DIR;
const std::string kReference01 = kSource + "/tests/app/exercises/01-drive-to-point.lua";
const std::string kSkeleton01 = kSource + "/exercises/01-drive-to-point/skill.lua";

HackathonOptions options(const TempDir& tmp) {
  HackathonOptions o;
  o.port = 0;
  o.db = tmp.file("board.db");
  o.exercises = kSource + "/exercises";
  o.viewer = tmp.path;
  o.seeds = "1001-1002";
  o.workers = 2;
  o.worker_program = LLSF_LLSFSIM;
  o.log = [](const std::string&) {};
  return o;
}

HttpRequest post(const json& body) {
  HttpRequest r;
  r.method = "POST";
  r.path = {"api", "hackathon", "submit"};
  r.content_type = "application/json";
  r.body = body.dump();
  return r;
}

json submission(const std::string& team, const std::string& exercise, const std::string& file) {
  return {{"team", team}, {"exercise", exercise}, {"file_name", "my.lua"}, {"skill", read(file)}};
}

/// Waits (up to 120 s) until submission `id` is no longer queued or running.
Submission wait_done(SubmissionStore& store, std::int64_t id) {
  const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(120);
  for (;;) {
    const std::optional<Submission> s = store.get(id);
    REQUIRE(s.has_value());
    if (s->status != SubmissionStatus::kQueued && s->status != SubmissionStatus::kRunning) {
      return *s;
    }
    REQUIRE(std::chrono::steady_clock::now() < until);
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
}

Submission done_row(std::int64_t id, const std::string& team, int passed, std::optional<double> v,
                    std::int64_t received_ms, const std::string& better = "lower") {
  Submission s;
  s.id = id;
  s.team = team;
  s.status = SubmissionStatus::kDone;
  s.passed = passed;
  s.total = 5;
  s.value = v;
  s.received_ms = received_ms;
  s.better = better;
  return s;
}

}  // namespace

TEST_CASE("sha256 and UTF-8: the standard's vectors, broken sequences refused") {
  CHECK(llsf::study::sha256_hex("") ==
        "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855");
  CHECK(llsf::study::sha256_hex("abc") ==
        "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
  CHECK(llsf::study::sha256_hex("abcdbcdecdefdefgefghfghighijhijkijkljklmklmnlmnomnopnopq") ==
        "248d6a61d20638b8e5c026930c3e6039a33ce45964ff2167f6ecedd419db06c1");
  CHECK(llsf::study::is_valid_utf8("plain -- ü € 𝄞"));
  CHECK_FALSE(llsf::study::is_valid_utf8("\xff"));
  CHECK_FALSE(llsf::study::is_valid_utf8("a\xc3"));             // truncated
  CHECK_FALSE(llsf::study::is_valid_utf8("\xc0\xaf"));          // overlong '/'
  CHECK_FALSE(llsf::study::is_valid_utf8("\xed\xa0\x80"));      // a surrogate
  CHECK_FALSE(llsf::study::is_valid_utf8("\xf4\x90\x80\x80"));  // above U+10FFFF
}

TEST_CASE("rank_board: a team's best counts; passed seeds, then the value, then the earlier") {
  const std::vector<Submission> done = {
      done_row(1, "a", 3, 0.5, 100),          // a's first try
      done_row(2, "b", 5, 0.9, 200),          // all passed, far
      done_row(3, "c", 5, 0.1, 300),          // all passed, close: first
      done_row(4, "a", 5, 0.9, 400),          // a's best: ties b's value, later than b
      done_row(5, "d", 5, std::nullopt, 50),  // no value: after every value of 5 passed
      done_row(6, "e", 0, 0.0, 10),
  };
  const auto board = llsf::study::rank_board(done);
  REQUIRE(board.size() == 5);
  CHECK(board[0].best.team == "c");
  CHECK(board[1].best.team == "b");
  CHECK(board[2].best.team == "a");
  CHECK(board[2].best.id == 4);
  CHECK(board[2].submissions == 2);
  CHECK(board[3].best.team == "d");
  CHECK(board[4].best.team == "e");
  CHECK(board[4].rank == 5);
  // Points: higher is better.
  const auto points = llsf::study::rank_board(
      {done_row(1, "x", 5, 40.0, 1, "higher"), done_row(2, "y", 5, 70.0, 2, "higher")});
  CHECK(points[0].best.team == "y");
}

TEST_CASE("SubmissionStore: versioned tables beside the statistics store, kept, re-queued") {
  const TempDir tmp;
  const std::string db = tmp.file("s.db");
  std::int64_t id = 0;
  {
    SubmissionStore store(db);
    id = store.add("team", "01-drive-to-point", "f.lua", "-- skill", "1-5", 1000);
    CHECK(store.claim_next()->id == id);
    CHECK_FALSE(store.claim_next().has_value());  // running, not queued
  }
  // The statistics store still opens the file; the hackathon tables are migrated once.
  CHECK_NOTHROW(llsf::study::StatsStore{db});
  SubmissionStore again(db);
  CHECK(again.get(id)->status == SubmissionStatus::kRunning);
  CHECK(again.get(id)->sha256 == llsf::study::sha256_hex("-- skill"));
  CHECK(again.requeue_running() == 1);
  CHECK(again.get(id)->status == SubmissionStatus::kQueued);
  CHECK(again.count_since("team", 1000) == 1);
  CHECK(again.count_since("team", 1001) == 0);
  CHECK_THROWS_WITH_AS(SubmissionStore("postgresql://u@127.0.0.1/x"),
                       doctest::Contains("SQLite file"), llsf::study::StatsError);
}

TEST_CASE("hackathon: bad submissions get a 4xx with a clear message, nothing is stored") {
  const TempDir tmp;
  HackathonOptions o = options(tmp);
  o.max_per_minute = 2;
  o.max_skill_bytes = 1000;
  HackathonServer server(o);  // not started: submissions stay queued
  auto expect = [&](const HttpRequest& r, int status, const std::string& part) {
    const std::optional<HttpAnswer> a = server.route(r);
    REQUIRE(a.has_value());
    CHECK(a->status == status);
    const json j = json::parse(a->body);
    CHECK_MESSAGE(j.value("error", std::string()).find(part) != std::string::npos, a->body);
  };
  const std::string small = "-- a skill\n";
  expect(post({{"exercise", "01"}, {"skill", small}}), 400, "give a team name");
  expect(post({{"team", "  "}, {"exercise", "01"}, {"skill", small}}), 400, "give a team name");
  expect(post({{"team", "t"}, {"exercise", "09"}, {"skill", small}}), 400,
         "unknown exercise '09'; the exercises: 01-drive-to-point");
  expect(post({{"team", "t"}, {"exercise", "0"}, {"skill", small}}), 400, "names several");
  expect(post({{"team", "t"}, {"exercise", "01"}, {"skill", ""}}), 400, "empty");
  expect(post({{"team", "t"}, {"exercise", "01"}, {"skill", std::string(1001, 'x')}}), 413,
         "1001 bytes; at most 1000");
  expect(post({{"team", 7}, {"exercise", "01"}, {"skill", small}}), 400, "must be strings");
  HttpRequest not_utf8 = post({});
  not_utf8.body = "{\"team\": \"t\", \"exercise\": \"01\", \"skill\": \"\xff\xfe\"}";
  expect(not_utf8, 400, "not UTF-8");
  HttpRequest not_json = post({});
  not_json.body = "team=t&exercise=01";
  expect(not_json, 400, "JSON object");
  HttpRequest get_submit = post({});
  get_submit.method = "GET";
  expect(get_submit, 405, "POST");
  HttpRequest bad_id;
  bad_id.method = "GET";
  bad_id.path = {"api", "hackathon", "submissions", "12x"};
  expect(bad_id, 400, "bad submission id");
  bad_id.path = {"api", "hackathon", "board", "nope"};
  expect(bad_id, 404, "unknown exercise");
  CHECK(server.store().list("", 100).empty());
  // The rate limit: two a minute, the third refused.
  CHECK(server.route(post({{"team", "t"}, {"exercise", "01"}, {"skill", small}}))->status == 202);
  CHECK(server.route(post({{"team", "t"}, {"exercise", "01"}, {"skill", small}}))->status == 202);
  expect(post({{"team", "t"}, {"exercise", "01"}, {"skill", small}}), 429, "at most 2 a minute");
  CHECK(server.route(post({{"team", "u"}, {"exercise", "01"}, {"skill", small}}))->status == 202);
  CHECK(server.store().list("", 100).size() == 3);
}

TEST_CASE("hackathon: workers play submissions on hidden seeds; ranked; seeds never shown") {
  const TempDir tmp;
  std::int64_t weak = 0;
  std::int64_t good = 0;
  {
    HackathonServer server(options(tmp));
    server.start();
    weak = json::parse(server.route(post(submission("weak", "01", kSkeleton01)))->body)["id"];
    good = json::parse(server.route(post(submission("good", "01", kReference01)))->body)["id"];
    CHECK(wait_done(server.store(), weak).passed == 0);
    const Submission g = wait_done(server.store(), good);
    CHECK(g.status == SubmissionStatus::kDone);
    CHECK(g.passed == 2);
    CHECK(g.total == 2);
    CHECK(g.verdict == "PASS");
    CHECK(g.seeds == "1001-1002");
    HttpRequest r;
    r.method = "GET";
    r.path = {"api", "hackathon", "board", "01"};
    const json board = json::parse(server.route(r)->body);
    REQUIRE(board["entries"].size() == 2);
    CHECK(board["entries"][0]["team"] == "good");
    CHECK(board["entries"][1]["team"] == "weak");
    // The page shows why a played submission failed: its first run not passed, no seed.
    for (const json& s : board["recent"]) {
      CAPTURE(s.dump());
      if (s["team"] == "weak") {
        REQUIRE(s.contains("reason"));
        CHECK(s["reason"].get<std::string>().starts_with("run 1 of 2: "));
        CHECK(s["reason"].get<std::string>().find("not solved yet") != std::string::npos);
        CHECK(s["reason"].get<std::string>().find("1001") == std::string::npos);
      } else {
        CHECK_FALSE(s.contains("reason"));
      }
    }
    r.path = {"api", "hackathon", "submissions", std::to_string(good)};
    const std::string shown = server.route(r)->body;
    CHECK(shown.find("1001") == std::string::npos);
    CHECK(shown.find("\"seed\"") == std::string::npos);
    CHECK(json::parse(shown)["result"]["runs"].size() == 2);
    server.stop();
  }
  // A restart keeps the board.
  HackathonServer again(options(tmp));
  HttpRequest r;
  r.method = "GET";
  r.path = {"api", "hackathon", "board", "01-drive-to-point"};
  CHECK(json::parse(again.route(r)->body)["entries"].size() == 2);
}

TEST_CASE("hackathon: a skill that loops or allocates is cut off by the Lua budgets") {
  const TempDir tmp;
  HackathonServer server(options(tmp));
  server.start();
  std::string ref = read(kReference01);
  const std::string anchor = "function DRIVE:init()\n";
  REQUIRE(ref.find(anchor) != std::string::npos);
  std::string loop = ref;
  loop.insert(loop.find(anchor) + anchor.size(), "   while true do end\n");
  std::string alloc = ref;
  alloc.insert(alloc.find(anchor) + anchor.size(),
               "   local t = {} for i = 1, 1e9 do t[i] = string.rep('x', 1000) .. i end\n");
  auto submit = [&](const std::string& team, const std::string& text) -> std::int64_t {
    return json::parse(
        server.route(post({{"team", team}, {"exercise", "01"}, {"skill", text}}))->body)["id"];
  };
  const Submission l = wait_done(server.store(), submit("loops", loop));
  CHECK(l.status == SubmissionStatus::kDone);
  CHECK(l.passed == 0);
  CHECK(l.result.find("instruction budget exhausted") != std::string::npos);
  const Submission a = wait_done(server.store(), submit("allocates", alloc));
  CHECK(a.status == SubmissionStatus::kDone);
  CHECK(a.passed == 0);
  CHECK(a.result.find("not enough memory") != std::string::npos);
}

TEST_CASE("hackathon: a worker over the wall-clock limit is killed and marked timeout") {
  const TempDir tmp;
  HackathonOptions o = options(tmp);
  o.limits.wall_s = 0.05;  // a 300 s game of exercise 04 takes longer than that
  o.seeds = "1-3";
  HackathonServer server(o);
  server.start();
  const json body = submission("slow", "04", kSource + "/tests/app/exercises/rescue.lua");
  const std::int64_t id = json::parse(server.route(post(body))->body)["id"];
  const Submission s = wait_done(server.store(), id);
  CHECK(s.status == SubmissionStatus::kTimeout);
  CHECK(s.error.find("wall-clock limit of 0.05 s") != std::string::npos);
}

TEST_CASE("sandbox: wall limit kills the whole group, CPU limit, output cap, exec failure") {
  const TempDir tmp;
  SandboxLimits l;
  l.wall_s = 0.3;
  // A grandchild holding the pipe open is killed with the group: the call returns.
  const auto t0 = std::chrono::steady_clock::now();
  SandboxResult r = llsf::app::run_sandboxed({"/bin/sh", "-c", "sleep 30 & sleep 30"}, tmp.path, l);
  CHECK(r.timed_out);
  CHECK(r.signal == SIGKILL);
  CHECK(std::chrono::steady_clock::now() - t0 < std::chrono::seconds(20));
  CHECK(llsf::app::outcome_of(r, l).status == SubmissionStatus::kTimeout);

  // CPU seconds: SIGXCPU at the soft limit.
  l.wall_s = 30;
  l.cpu_s = 1;
  r = llsf::app::run_sandboxed({"/bin/sh", "-c", "while :; do :; done"}, tmp.path, l);
  CHECK_FALSE(r.timed_out);
  CHECK((r.signal == SIGXCPU || r.signal == SIGKILL));
  const auto o = llsf::app::outcome_of(r, l);
  CHECK(o.status == SubmissionStatus::kFailed);
  CHECK(o.error.find("CPU limit of 1 s") != std::string::npos);

  // Output beyond the cap is read and dropped; no file larger than RLIMIT_FSIZE.
  l.cpu_s = 10;
  l.max_output_bytes = 1000;
  l.file_size_bytes = 4096;
  r = llsf::app::run_sandboxed(
      {"/bin/sh", "-c", "head -c 3000000 /dev/zero; head -c 100000 /dev/zero > big; echo $? >&2"},
      tmp.path, l);
  CHECK(r.exit_code == 0);
  CHECK(r.out.size() == 1000);
  CHECK(r.out_truncated);
  CHECK(fs::file_size(tmp.file("big")) <= 4096);
  CHECK(r.err != "0\n");  // head failed: file too large

  // A worker that prints no result: failed, with its standard error.
  r = llsf::app::run_sandboxed({"/bin/sh", "-c", "echo broken >&2; exit 3"}, tmp.path, l);
  const auto f = llsf::app::outcome_of(r, l);
  CHECK(f.status == SubmissionStatus::kFailed);
  CHECK(f.error.find("exited with code 3 without a result") != std::string::npos);
  CHECK(f.error.find("broken") != std::string::npos);

  r = llsf::app::run_sandboxed({tmp.file("no-such-program")}, tmp.path, l);
  CHECK_FALSE(r.started);
  CHECK(r.error.find("No such file") != std::string::npos);
}

TEST_CASE("exercise --submit: queued over HTTP; refusals, bad URLs and a closed port exit 2") {
  const TempDir tmp;
  HackathonOptions o = options(tmp);
  o.max_skill_bytes = 2000;
  HackathonServer server(o);
  server.start();
  const std::string url = server.url();
  llsf::test::Run r = llsf::test::llsfsim(
      {"exercise", "01", "--skill", kReference01, "--submit", url, "--team", "cli team"});
  CHECK(r.code == 0);
  CHECK(llsf::test::has(r.out, "for 01-drive-to-point as team 'cli team': submission 1, queued"));
  CHECK(llsf::test::has(r.out, "#01-drive-to-point"));
  CHECK(wait_done(server.store(), 1).passed == 2);

  r = llsf::test::llsfsim({"exercise", "01", "--skill", kReference01, "--submit", url});
  CHECK(r.code == 2);
  CHECK(llsf::test::has(r.err, "--team NAME"));
  r = llsf::test::llsfsim(
      {"exercise", "7", "--skill", kReference01, "--submit", url, "--team", "t"});
  CHECK(r.code == 2);
  CHECK(llsf::test::has(r.err, "refused the submission (HTTP 400): unknown exercise '7'"));
  const std::string big = tmp.file("big.lua");
  std::ofstream(big) << std::string(3000, '-');
  r = llsf::test::llsfsim({"exercise", "01", "--skill", big, "--submit", url, "--team", "t"});
  CHECK(r.code == 2);
  CHECK(llsf::test::has(r.err, "(HTTP 413): the skill file is 3000 bytes; at most 2000 bytes"));
  // Over the server's request body limit: its 413 is read, not "Broken pipe".
  const std::string huge = tmp.file("huge.lua");
  std::ofstream(huge) << std::string(4 << 20, '-');
  r = llsf::test::llsfsim({"exercise", "01", "--skill", huge, "--submit", url, "--team", "t"});
  CHECK(r.code == 2);
  CHECK(llsf::test::has(r.err, "refused the submission (HTTP 413): the request body is larger"));
  CHECK_FALSE(llsf::test::has(r.err, "cannot reach"));
  const std::string latin1 = tmp.file("latin1.lua");
  std::ofstream(latin1) << "-- gr\xfc\xdf\n";
  r = llsf::test::llsfsim({"exercise", "01", "--skill", latin1, "--submit", url, "--team", "t"});
  CHECK(r.code == 2);
  CHECK(llsf::test::has(r.err, "is not UTF-8 text"));
  r = llsf::test::llsfsim(
      {"exercise", "01", "--skill", kReference01, "--submit", "https://x/", "--team", "t"});
  CHECK(r.code == 2);
  CHECK(llsf::test::has(r.err, "is not an http://HOST:PORT/ address"));
  server.stop();
  // A closed port: a port the kernel gave a socket that is closed again.
  int port = 0;
  {
    boost::asio::io_context ioc;
    boost::asio::ip::tcp::acceptor a(
        ioc, boost::asio::ip::tcp::endpoint(boost::asio::ip::make_address("127.0.0.1"), 0));
    port = a.local_endpoint().port();
  }
  r = llsf::test::llsfsim({"exercise", "01", "--skill", kReference01, "--submit",
                           "http://127.0.0.1:" + std::to_string(port) + "/", "--team", "t"});
  CHECK(r.code == 2);
  CHECK(llsf::test::has(r.err, "cannot reach the leaderboard at http://127.0.0.1:"));
}
