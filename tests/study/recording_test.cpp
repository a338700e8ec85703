// SPDX-License-Identifier: MIT
// Recordings: a full game is recorded compactly (poses at 10 Hz, events), read back, and bad
// files are reported with file and line.
#include <doctest/doctest.h>
#include <unistd.h>
#include <zlib.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <string>

#include "llsf/study/recording.h"
#include "llsf/study/runner.h"
#include "llsf/study/scenario.h"
#include "support/temp_dir.h"

using namespace llsf;
using namespace llsf::sim;
using namespace llsf::study;
using Json = nlohmann::json;

namespace {

// One directory for the binary's run, removed at exit.
std::filesystem::path temp_dir() {
  static const llsf::test::TempDir dir("llsf_recording_test");
  return dir.path;
}

}  // namespace

TEST_CASE("a full game is recorded: 10 Hz frames, events, well under 5 MB, readable") {
  const ScenarioFile f = load_scenario(LLSF_SOURCE_DIR "/scenarios/default.yaml");
  const std::string path = (temp_dir() / "default.jsonl.gz").string();
  RunHooks hooks;
  hooks.record_path = path;
  const RunResult r = run_game(f.variants[0], 3, hooks);
  const auto bytes = std::filesystem::file_size(path);
  MESSAGE("recording of a 1080 s game: ", bytes, " bytes");
  CHECK(bytes < 5u * 1024u * 1024u);
  const std::vector<RecordingLine> lines = read_recording(path);
  REQUIRE(lines.size() > 10000);
  CHECK(lines[0].kind == "header");
  CHECK(Json::parse(lines[0].json)["robots"] == Json{"robot1", "robot2", "robot3"});
  std::map<std::string, int> kinds;
  double last_t = 0.0;
  bool ordered = true;
  for (std::size_t i = 1; i < lines.size(); ++i) {
    ++kinds[lines[i].kind];
    ordered = ordered && lines[i].t + 1e-9 >= last_t;
    last_t = lines[i].t;
  }
  CHECK(ordered);
  // 10 Hz over 1080 s (+ the frame at t = 0.01).
  CHECK(kinds["frame"] >= 10800);
  CHECK(kinds["frame"] <= 10802);
  CHECK(kinds["game"] >= 2);  // EXPLORATION, PRODUCTION (POST_GAME comes after the last tick)
  CHECK(kinds["plan"] == 1);
  CHECK(kinds["lights"] > 16);
  CHECK(kinds["rfid"] > 0);
  CHECK(kinds["skill"] > 0);
  CHECK(kinds["puck"] > 20);
  CHECK(kinds["order"] > 0);
  CHECK(kinds["path"] > 10);  // planned paths as they change
  int award_points = 0;
  for (const RecordingLine& l : lines) {
    if (l.kind != "award") continue;
    award_points += Json::parse(l.json).at("points").get<int>();
  }
  CHECK(award_points == r.exploration_points + r.production_points);
  CHECK(r.recording == path);

  // The agents' decisions and the lock protocol (default.yaml has locks on): every grant and
  // refusal of the run's statistics is a lock line.
  CHECK(kinds["agent"] > 10);
  int grants = 0, refusals = 0;
  for (const RecordingLine& l : lines) {
    if (l.kind != "lock") continue;
    const Json j = Json::parse(l.json);
    CHECK(j.at("robot").get<std::string>().rfind("robot", 0) == 0);
    if (j.at("to") == "ACCEPTED") ++grants;
    if (j.at("from") == "REQUESTED" && j.at("to") == "REFUSED") ++refusals;
  }
  MESSAGE("locks: ", r.lock_grants, " grants, ", r.lock_refusals, " refusals, ", r.lock_waits,
          " waits, ", r.lock_wait_s, " s, longest ", r.lock_wait_max_s, " s");
  CHECK(r.lock_grants > 10);
  CHECK(grants == r.lock_grants);
  CHECK(refusals == r.lock_refusals);
  CHECK(r.lock_wait_s > 0.0);
  CHECK(r.lock_wait_max_s <= r.lock_wait_s);
  CHECK(r.lock_wait_max_s <= r.game_time_s);
}

TEST_CASE("a line sink gets every recorded line, with or without a file") {
  ScenarioFile f = load_scenario(LLSF_SOURCE_DIR "/scenarios/default.yaml");
  Scenario s = f.variants[0];
  s.duration = core::SimTime::from_sec(40);
  const std::string path = (temp_dir() / "sink.jsonl.gz").string();
  std::vector<std::string> sunk;
  RunHooks hooks;
  hooks.record_path = path;
  hooks.record_sink = [&](std::string_view line) { sunk.emplace_back(line); };
  const RunResult r = run_game(s, 2, hooks);
  const std::vector<RecordingLine> lines = read_recording(path);
  REQUIRE(lines.size() == sunk.size());
  for (std::size_t i = 0; i < lines.size(); ++i) CHECK(lines[i].json == sunk[i]);
  bool path_seen = false;
  for (const std::string& l : sunk) {
    const Json j = Json::parse(l);
    if (j.value("e", "") == "path" && j.at("robot").get<std::string>().rfind("robot", 0) == 0 &&
        !j.at("points").empty() && j.at("points")[0].size() == 2)
      path_seen = true;
  }
  CHECK(path_seen);

  // Without a file: the same lines, the same game.
  std::vector<std::string> only;
  RunHooks sink_only;
  sink_only.record_sink = [&](std::string_view line) { only.emplace_back(line); };
  const RunResult r2 = run_game(s, 2, sink_only);
  CHECK(only == sunk);
  CHECK(r2.result_hash == r.result_hash);
  CHECK(r2.recording.empty());
}

TEST_CASE("radio drops are recorded per frame and per sender robot") {
  const ScenarioFile f = load_scenario(LLSF_SOURCE_DIR "/scenarios/packet-loss.yaml");
  Scenario s = f.variants.at(2);  // 20 % per-link loss
  REQUIRE(s.variant == "loss=20");
  s.duration = core::SimTime::from_sec(30);
  std::vector<std::string> lines;
  RunHooks hooks;
  hooks.record_sink = [&](std::string_view line) { lines.emplace_back(line); };
  const RunResult r = run_game(s, 1, hooks);
  REQUIRE(r.messages_dropped > 0);
  // Every frame's drops_from sums to at most its drops (the refbox's drops are not a robot's).
  long drops = 0, by_robots = 0;
  for (const std::string& l : lines) {
    const Json j = Json::parse(l);
    if (!j.contains("drops")) continue;
    const long frame_drops = j.at("drops").get<long>();
    drops += frame_drops;
    long frame_by = 0;
    const Json by = j.value("drops_from", Json::object());
    for (const auto& [robot, n] : by.items()) {
      CHECK(robot.rfind("robot", 0) == 0);
      frame_by += n.get<long>();
    }
    CHECK(frame_by <= frame_drops);
    by_robots += frame_by;
  }
  CHECK(drops == r.messages_dropped);
  CHECK(by_robots > 0);
}

TEST_CASE("bad recordings: missing, corrupt, wrong version, not JSON") {
  const auto dir = temp_dir();
  CHECK_THROWS_WITH(read_recording((dir / "missing.gz").string()),
                    doctest::Contains("cannot open"));
  {
    std::ofstream((dir / "v9.jsonl").string())
        << "{\"format\": \"llsfsim-recording\", \"version\": 9}\n";
  }
  CHECK_THROWS_WITH(read_recording((dir / "v9.jsonl").string()),
                    doctest::Contains("v9.jsonl:1: recording version 9"));
  {
    std::ofstream((dir / "garbage.jsonl").string())
        << "{\"format\": \"llsfsim-recording\", \"version\": 1}\nhello\n";
  }
  CHECK_THROWS_WITH(read_recording((dir / "garbage.jsonl").string()),
                    doctest::Contains("garbage.jsonl:2: not a JSON object"));
  {
    // A gzip stream cut in the middle.
    const std::string good = (dir / "good.gz").string();
    gzFile g = gzopen(good.c_str(), "wb");
    std::string body = "{\"format\": \"llsfsim-recording\", \"version\": 1}\n";
    for (int i = 0; i < 2000; ++i)
      body += "{\"t\": " + std::to_string(i) + ".00, \"f\": 1, \"r\": []}\n";
    gzwrite(g, body.data(), static_cast<unsigned>(body.size()));
    gzclose(g);
    std::ifstream in(good, std::ios::binary);
    std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    std::ofstream((dir / "cut.gz").string(), std::ios::binary) << bytes.substr(0, bytes.size() / 2);
  }
  CHECK_THROWS_WITH(read_recording((dir / "cut.gz").string()), doctest::Contains("cut.gz:"));
}
