// SPDX-License-Identifier: MIT
// `llsfsim skill`: status lines with time stamps, exit codes, help, bad input.
#include <doctest/doctest.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "app/cli_fixture.h"
#include "llsf/app/cli.h"
#include "llsf/study/recording.h"

namespace {

using llsf::test::has;
using llsf::test::llsfsim;
using llsf::test::Run;

}  // namespace

TEST_CASE("llsfsim skill runs strings in turn and prints status changes with game time") {
  const Run r = llsfsim({"skill", "--seed", "7", "get_s0{}", "finish_puck_at{place=\"M10\"}"});
  INFO(r.out, r.err);
  CHECK(r.code == llsf::app::kExitOk);
  CHECK(has(r.out, "s] robot1 RUNNING  get_s0{}"));
  CHECK(has(r.out, "s] robot1 FINAL  get_s0{}"));
  CHECK(has(r.out, "FINAL  finish_puck_at{place=\"M10\"}  -> "));
  CHECK(has(r.out, "s] end: "));
  // Same seed, same output.
  CHECK(llsfsim({"skill", "--seed", "7", "get_s0{}", "finish_puck_at{place=\"M10\"}"}).out ==
        r.out);
}

TEST_CASE("llsfsim skill --skills DIR takes one directory; the skill strings follow") {
  const std::string examples = std::string(LLSF_SOURCE_DIR) + "/lua/skills/examples";
  const Run r = llsfsim(
      {"skill", "--skills", examples, "say_hello{who=\"tour\"}", "goto_place{place=\"M5\"}"});
  INFO(r.out, r.err);
  CHECK(r.code == 0);
  CHECK(has(r.out, "robot1 FINAL  say_hello{who=\"tour\"}"));
  CHECK(has(r.out, "robot1 FINAL  goto_place{place=\"M5\"}"));
}

TEST_CASE("llsfsim skill: a failing skill exits 1 with its reason; bad input exits 2") {
  Run r = llsfsim({"skill", "drive_to{place=\"M11\"}"});
  CHECK(r.code == llsf::app::kExitFailed);
  CHECK(has(r.out, "FAILED  drive_to{place=\"M11\"}"));
  CHECK(has(r.out, "unknown place 'M11'"));

  r = llsfsim({"skill", "drive_to{place="});
  CHECK(r.code == llsf::app::kExitBadInput);
  CHECK(has(r.err, "skill string:1:"));

  r = llsfsim({"skill", "--level", "magic", "park{}"});
  CHECK(r.code == llsf::app::kExitBadInput);
  CHECK(has(r.err, "--level"));

  r = llsfsim({"skill"});
  CHECK(r.code == llsf::app::kExitBadInput);
  CHECK(has(r.err, "give a skill string"));

  r = llsfsim({"frobnicate"});
  CHECK(r.code == llsf::app::kExitBadInput);
}

TEST_CASE("llsfsim skill: a skill file that does not load exits 2; an exhausted budget exits 1") {
  const auto dir = std::filesystem::temp_directory_path() /
                   ("llsf_skill_cmd_" +
                    std::to_string(std::chrono::steady_clock::now().time_since_epoch().count()));
  std::filesystem::create_directories(dir);
  std::ofstream(dir / "broken.lua") << "name = 'broken'\ndocumentation = 'x'\nfunction execute(\n";
  Run r = llsfsim({"skill", "--skills", dir.string(), "get_s0{}"});
  INFO(r.out, r.err);
  CHECK(r.code == llsf::app::kExitBadInput);
  CHECK(has(r.err, "broken.lua:4:"));
  CHECK(has(r.err, "1 skill file(s) do not load"));
  r = llsfsim({"skill", "--skills", dir.string(), "--list"});
  CHECK(r.code == llsf::app::kExitOk);
  CHECK(has(r.out, "LOAD ERROR"));

  std::filesystem::remove(dir / "broken.lua");
  std::ofstream(dir / "bomb.lua") << "name = 'bomb'\ndocumentation = 'x'\n"
                                     "function execute() table.move({}, 1, 2^50, 2) end\n";
  r = llsfsim({"skill", "--skills", dir.string(), "bomb{}"});
  CHECK(r.code == llsf::app::kExitFailed);
  CHECK(has(r.out, "bomb.lua:3: instruction budget exhausted"));
  std::filesystem::remove_all(dir);
}

TEST_CASE("llsfsim --help, skill --help and skill --list") {
  Run r = llsfsim({"--help"});
  CHECK(r.code == 0);
  CHECK(has(r.out, "skill"));
  r = llsfsim({"skill", "--help"});
  CHECK(r.code == 0);
  CHECK(has(r.out, "--level"));
  CHECK(has(r.out, "--trace"));
  r = llsfsim({"skill", "--list"});
  CHECK(r.code == 0);
  for (const char* s : {"drive_to", "motor_move", "get_s0", "get_consumed", "finish_puck_at",
                        "deliver", "recycle", "explore_machine", "leave_puck", "park"}) {
    CHECK(has(r.out, std::string(s) + "  ("));
  }
  CHECK_FALSE(has(r.out, "LOAD ERROR"));
}

TEST_CASE("llsfsim skill --trace shows the FSM states; symbolic level works the same") {
  const Run r = llsfsim({"skill", "--trace", "--level", "symbolic", "--phase", "exploration",
                         "explore_machine{place=\"M5\"}"});
  INFO(r.out, r.err);
  CHECK(r.code == 0);
  CHECK(has(r.out, "explore_machine: GOTO"));
  CHECK(has(r.out, "explore_machine: READ"));
  CHECK(has(r.out, "-> M5 red="));
}

TEST_CASE("llsfsim run --record writes a readable recording; an unwritable path exits 2") {
  const std::string rec = std::filesystem::temp_directory_path() / "llsf_app_test_run.jsonl.gz";
  const std::string scenario = std::filesystem::temp_directory_path() / "llsf_app_test_run.yaml";
  {
    std::ofstream(scenario) << "name: rec\nstart: production\nduration_s: 30\nrobots:\n  count: 1\n"
                               "  agent: [" LLSF_SOURCE_DIR "/clips/agents/common, " LLSF_SOURCE_DIR
                               "/clips/agents/llsf2013]\n";
  }
  Run r = llsfsim({"run", scenario, "--no-db", "--record", rec, "-q"});
  INFO(r.err);
  CHECK(r.code == 0);
  CHECK(llsf::study::read_recording(rec).size() > 300);
  r = llsfsim({"run", scenario, "--no-db", "--record", "/no/such/dir/x.jsonl.gz", "-q"});
  CHECK(r.code == llsf::app::kExitBadInput);
  CHECK(has(r.err, "cannot create the recording"));
}

TEST_CASE("llsfsim skill --record writes the game with the skill's states; bad path exits 2") {
  const std::string rec = std::filesystem::temp_directory_path() / "llsf_app_test_skill.jsonl.gz";
  Run r = llsfsim({"skill", "--seed", "7", "get_s0{}", "--record", rec, "-q"});
  INFO(r.out, r.err);
  CHECK(r.code == llsf::app::kExitOk);
  const auto lines = llsf::study::read_recording(rec);
  CHECK(lines.size() > 50);  // the header and about 80 frames of 8 s at 10 Hz
  std::string all;
  for (const auto& l : lines) all += l.json + "\n";
  CHECK(has(all, "\"scenario\":\"skill\""));
  CHECK(has(all, "\"e\":\"skill_state\",\"robot\":\"robot1\",\"skill\":\"get_s0\""));
  CHECK(has(all, "\"e\":\"skill\""));
  // The game is the same with and without the recording.
  CHECK(llsfsim({"skill", "--seed", "7", "get_s0{}", "-q"}).out == r.out);
  r = llsfsim({"skill", "get_s0{}", "--record", "/no/such/dir/x.jsonl.gz", "-q"});
  CHECK(r.code == llsf::app::kExitBadInput);
  CHECK(has(r.err, "cannot create the recording"));
}

TEST_CASE("llsfsim run --speed paces the game and gives the same result as unpaced") {
  const std::string scenario = std::filesystem::temp_directory_path() / "llsf_app_test_speed.yaml";
  {
    std::ofstream(scenario)
        << "name: speed\nstart: production\nduration_s: 10\nrobots:\n  count: 1\n"
           "  agent: [" LLSF_SOURCE_DIR "/clips/agents/common, " LLSF_SOURCE_DIR
           "/clips/agents/llsf2013]\n";
  }
  const auto t0 = std::chrono::steady_clock::now();
  const Run paced = llsfsim({"run", scenario, "--no-db", "--no-record", "--json", "--speed", "40"});
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  CHECK(paced.code == 0);
  CHECK(wall >= 0.24);  // 10 s of game at 40x: at least 0.25 s (minus a tick)
  const Run fast = llsfsim({"run", scenario, "--no-db", "--no-record", "--json"});
  auto hash = [](const std::string& json) {
    const auto p = json.find("\"result_hash\"");
    return json.substr(p, 40);
  };
  CHECK(hash(paced.out) == hash(fast.out));
  CHECK(llsfsim({"run", scenario, "--no-db", "--no-record", "--speed", "0"}).code ==
        llsf::app::kExitBadInput);
}

TEST_CASE("llsfsim report: an empty store has no batch (exit 2); --list works; help") {
  const std::string db = std::filesystem::temp_directory_path() / "llsf_app_test_report.db";
  std::filesystem::remove(db);
  Run r = llsfsim({"report", "--db", db});
  CHECK(r.code == llsf::app::kExitBadInput);
  CHECK(has(r.err, "holds no batch"));
  r = llsfsim({"report", "--db", db, "--list"});
  CHECK(r.code == 0);
  r = llsfsim({"report", "--help"});
  CHECK(r.code == 0);
  CHECK(has(r.out, "--csv"));
  std::filesystem::remove(db);
}
