// SPDX-License-Identifier: MIT
// `llsfsim exercise --seeds LIST [--jobs N] [--json]`: a sweep gives the same table whatever the
// number of threads, FAIL lists the seeds not passed, --json holds the contract's fields
// (docs/exercises.md) and parses, and a bad --seeds names the token. In the batch tests' binary
// (label `batch`): the games run on threads, so the tsan preset runs these too.
#include <doctest/doctest.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "app/cli_fixture.h"
#include "batch_progress.h"
#include "llsf/app/cli.h"

namespace {

using llsf::test::has;
using llsf::test::llsfsim;
using llsf::test::Run;
using Json = nlohmann::json;

const std::string kExercise = LLSF_SOURCE_DIR "/exercises/01-drive-to-point";
const std::string kReference = LLSF_SOURCE_DIR "/tests/app/exercises/01-drive-to-point.lua";

std::string read(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

std::string write_temp(const std::string& name, const std::string& text) {
  const auto path = std::filesystem::temp_directory_path() / name;
  std::ofstream(path) << text;
  return path.string();
}

/// The reference solution of 01, failing with a Lua error when the target is east of x = 4 (the
/// seeds 1 and 6 of 1..6 draw such a target; 2..5 do not).
std::string east_fails() {
  std::string text = read(kReference);
  const std::string init = "function DRIVE:init()\n";
  const std::size_t at = text.find(init);
  REQUIRE(at != std::string::npos);
  text.insert(at + init.size(), "   if self.fsm.vars.x > 4 then error(\"too far east\") end\n");
  return write_temp("llsfex_sweep_east.lua", text);
}

}  // namespace

TEST_CASE("exercise --seeds: the same table with --jobs 1 and --jobs 2, PASS n/n, exit 0") {
  const Run one =
      llsfsim({"exercise", kExercise, "--skill", kReference, "--seeds", "1-5", "--jobs", "1"});
  const Run two =
      llsfsim({"exercise", kExercise, "--skill", kReference, "--seeds", "1-5", "--jobs", "2"});
  INFO(one.out, one.err, "\n---\n", two.out, two.err);
  CHECK(one.code == llsf::app::kExitOk);
  CHECK(two.code == llsf::app::kExitOk);
  CHECK(one.out == two.out);
  CHECK(has(one.out, "verdict  PASS 5/5\n"));
  CHECK(has(one.out, "seed  result   score"));
  for (int seed = 1; seed <= 5; ++seed) {
    CHECK(has(one.out, "\n   " + std::to_string(seed) + "  PASS     "));
  }
  // The seeds' rows come in seed order, and the progress (not on a terminal: one line per seed)
  // goes to stderr.
  CHECK(one.out.find("\n   1  PASS") < one.out.find("\n   5  PASS"));
  CHECK(has(two.err, "[5/5] seed "));
  CHECK_FALSE(has(two.out, "[5/5]"));
  // -q: no progress.
  const Run quiet = llsfsim({"exercise", kExercise, "--skill", kReference, "--seeds", "2", "-q"});
  CHECK(quiet.code == llsf::app::kExitOk);
  CHECK(quiet.err.empty());
  CHECK(has(quiet.out, "verdict  PASS 1/1\n"));
}

TEST_CASE("exercise --seeds: a skill failing on some seeds gives FAIL with those seeds, exit 1") {
  const std::string path = east_fails();
  const Run one =
      llsfsim({"exercise", kExercise, "--skill", path, "--seeds", "1-6", "--jobs", "1"});
  const Run two =
      llsfsim({"exercise", kExercise, "--skill", path, "--seeds", "1-6", "--jobs", "2"});
  INFO(one.out, one.err, "\n---\n", two.out);
  CHECK(one.code == llsf::app::kExitFailed);
  CHECK(two.code == llsf::app::kExitFailed);
  CHECK(one.out == two.out);
  CHECK(has(one.out, "verdict  FAIL 4/6 passed, 2 failed: seed(s) 1, 6\n"));
  CHECK(has(one.out, "details  llsfsim exercise 01-drive-to-point --skill " + path + " --seed 1"));
  // The failed rows carry the error's first line with the participant's path.
  CHECK(has(one.out, "   1  FAIL"));
  CHECK(has(one.out, "   6  FAIL"));
  CHECK(has(one.out, path + ":24: too far east"));
  CHECK_FALSE(has(one.out, "llsfex-"));
  CHECK(has(one.out, "   2  PASS"));
}

TEST_CASE("exercise --json: one object with the contract's fields") {
  const std::string path = east_fails();
  const Run r = llsfsim({"exercise", kExercise, "--skill", path, "--seeds", "5,6", "--json"});
  INFO(r.out, r.err);
  CHECK(r.code == llsf::app::kExitFailed);
  CHECK(r.err.empty());               // no progress with --json
  const Json j = Json::parse(r.out);  // the whole of stdout is one JSON value
  REQUIRE(j.is_object());
  CHECK(j.at("exercise") == "01-drive-to-point");
  CHECK(j.at("skill") == "drive_to_point");
  CHECK(j.at("skill_file") == path);
  CHECK(j.at("goal") == "reach");
  CHECK(j.at("better") == "lower");
  CHECK(j.at("passed") == 1);
  CHECK(j.at("total") == 2);
  CHECK(j.at("verdict") == "FAIL");
  const Json& runs = j.at("runs");
  REQUIRE(runs.size() == 2);
  for (const Json& run : runs) {
    for (const char* key :
         {"seed", "result", "value", "score", "why", "error", "hint", "warnings", "game_time_s"}) {
      CHECK_MESSAGE(run.contains(key), key);
    }
    CHECK(run.at("value").is_number());
    CHECK(run.at("game_time_s").is_number());
    CHECK(run.at("game_time_s").get<double>() > 0.0);
  }
  CHECK(runs[0].at("seed") == 5);
  CHECK(runs[0].at("result") == "PASS");
  CHECK(runs[0].at("value").get<double>() <= 0.2);
  CHECK(runs[0].at("error") == "");
  CHECK(runs[1].at("seed") == 6);
  CHECK(runs[1].at("result") == "FAIL");
  CHECK(runs[1].at("error") == path + ":24: too far east");
  CHECK_FALSE(runs[1].at("hint").get<std::string>().empty());
  CHECK(runs[0].at("warnings") == Json::array());

  // --seed N --json: one run, the same as that seed's run in the sweep.
  const Run single = llsfsim({"exercise", kExercise, "--skill", path, "--seed", "5", "--json"});
  CHECK(single.code == llsf::app::kExitOk);
  const Json s = Json::parse(single.out);
  CHECK(s.at("verdict") == "PASS");
  REQUIRE(s.at("runs").size() == 1);
  CHECK(s.at("runs")[0] == runs[0]);
}

TEST_CASE("exercise --seeds/--json: the skill's warnings, once each with their seeds") {
  // Two states bouncing with cond=true: the engine warns (exercise_hints_test.cpp).
  const std::string bounce = LLSF_SOURCE_DIR "/tests/app/exercises/mistakes/bounce.lua";
  const Run r = llsfsim({"exercise", kExercise, "--skill", bounce, "--seeds", "1-2", "-q"});
  INFO(r.out, r.err);
  CHECK(r.code == llsf::app::kExitFailed);
  CHECK(has(r.out, "warning  " + bounce +
                       ":14: drive_to_point: states PLAN -> CHECK -> PLAN keep "
                       "switching without waiting"));
  CHECK(has(r.out, "(seed(s) 1, 2)\nverdict  FAIL"));
  const Run j = llsfsim({"exercise", kExercise, "--skill", bounce, "--seeds", "1-2", "--json"});
  const Json o = Json::parse(j.out);
  for (const Json& run : o.at("runs")) {
    REQUIRE(run.at("warnings").size() == 1);
    CHECK(has(run.at("warnings")[0].get<std::string>(), "keep switching without waiting"));
  }
}

TEST_CASE("exercise --json: a long path (Lua shortens those over 59 characters) is shown whole") {
  const auto dir = std::filesystem::temp_directory_path() /
                   "llsfex_sweep_a_rather_long_directory/of_a_participant/with_skills";
  std::filesystem::create_directories(dir);
  const std::string path = (dir / "my_drive_to_point.lua").string();
  REQUIRE(path.size() > 60);
  std::filesystem::copy_file(east_fails(), path, std::filesystem::copy_options::overwrite_existing);
  const Run r = llsfsim({"exercise", kExercise, "--skill", path, "--seeds", "1", "--json"});
  INFO(r.out, r.err);
  CHECK(r.code == llsf::app::kExitFailed);
  CHECK(Json::parse(r.out).at("runs")[0].at("error") == path + ":24: too far east");
  std::filesystem::remove_all(std::filesystem::temp_directory_path() /
                              "llsfex_sweep_a_rather_long_directory");
}

TEST_CASE("exercise --seeds/--json: a file that does not load is NOT RUN, exit 2") {
  const std::string path =
      write_temp("llsfex_sweep_syntax.lua", "name = \"drive_to_point\"\nfsm = (\n");
  const Run t = llsfsim({"exercise", kExercise, "--skill", path, "--seeds", "1-3"});
  INFO(t.out, t.err);
  CHECK(t.code == llsf::app::kExitBadInput);
  CHECK(has(t.out, "error    " + path + ":3:"));
  CHECK(has(t.out, "verdict  NOT RUN"));
  const Run j = llsfsim({"exercise", kExercise, "--skill", path, "--seeds", "1-3", "--json"});
  CHECK(j.code == llsf::app::kExitBadInput);
  const Json o = Json::parse(j.out);
  CHECK(o.at("verdict") == "NOT RUN");
  CHECK(o.at("passed") == 0);
  REQUIRE(o.at("runs").size() == 3);
  CHECK(o.at("runs")[0].at("result") == "NOT RUN");
  CHECK(o.at("runs")[0].at("value").is_null());
  CHECK(has(o.at("runs")[0].at("error").get<std::string>(), path + ":3:"));
}

extern "C" void sweep_ignore_sigint(int) {}

TEST_CASE("exercise --seeds: Ctrl-C ends the sweep after the running games, exit 130") {
  // A private temporary directory: the skill directories (llsfex-*) must all be gone after.
  const std::filesystem::path tmp =
      std::filesystem::temp_directory_path() / ("llsf_sweep_sigint_" + std::to_string(::getpid()));
  std::filesystem::create_directories(tmp);
  const char* old_tmpdir = std::getenv("TMPDIR");
  const std::string saved = old_tmpdir != nullptr ? old_tmpdir : "";
  ::setenv("TMPDIR", tmp.c_str(), 1);
  // Should the signal come after the command restored the handler, it must not end the tests.
  const auto old = std::signal(SIGINT, sweep_ignore_sigint);
  std::atomic<bool> done{false};
  std::thread ctrl_c([&] {
    while (!done) {  // as soon as a game has its skill directory, Ctrl-C
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
      std::error_code ec;
      if (std::filesystem::directory_iterator(tmp, ec) == std::filesystem::directory_iterator())
        continue;
      std::raise(SIGINT);  // to this thread; the handler sets the command's flag
      return;
    }
  });
  const std::string exercise = LLSF_SOURCE_DIR "/exercises/04-rescue-5-minutes";
  const std::string skill = LLSF_SOURCE_DIR "/tests/app/exercises/rescue.lua";
  const Run r =
      llsfsim({"exercise", exercise, "--skill", skill, "--seeds", "1-200", "--jobs", "1", "-q"});
  done = true;
  ctrl_c.join();
  std::signal(SIGINT, old);
  if (old_tmpdir != nullptr) {
    ::setenv("TMPDIR", saved.c_str(), 1);
  } else {
    ::unsetenv("TMPDIR");
  }
  INFO(r.out, r.err);
  CHECK(r.code == llsf::app::kExitInterrupted);
  CHECK(has(r.err, "llsfsim exercise: interrupted (Ctrl-C) after "));
  CHECK(has(r.out, "verdict  INTERRUPTED (Ctrl-C): "));
  CHECK(has(r.out, " of 200 seed(s) played"));
  std::error_code ec;
  CHECK(std::filesystem::is_empty(tmp, ec));
  std::filesystem::remove_all(tmp, ec);
}

TEST_CASE("exercise --seeds: bad input names the token, exit 2") {
  struct Bad {
    std::vector<std::string> args;
    std::string err;
  };
  const std::vector<Bad> bad = {
      {{"--seeds", "1,x"}, "'x' is not a seed"},
      {{"--seeds", "1,,2"}, "'' is empty"},
      {{"--seeds", "5-3"}, "'5-3' is an empty range"},
      {{"--seeds", "1-3,2"}, "seed 2 is given twice"},
      {{"--seeds", "1-3", "--jobs", "0"}, "--jobs"},
      {{"--jobs", "2"}, "--jobs requires --seeds"},  // (a single game has one job)
      {{"--seeds", "1-3", "--seed", "2"}, "--seed"},
      {{"--seeds", "1-3", "--serve"}, "give --seed N instead of --seeds"},
      {{"--seeds", "1-3", "--record", "x.gz"}, "give --seed N instead of --seeds"},
      {{"--json", "--serve"}, "--serve does not go with it"},
  };
  for (const Bad& b : bad) {
    std::vector<std::string> args = {"exercise", kExercise, "--skill", kReference};
    args.insert(args.end(), b.args.begin(), b.args.end());
    const Run r = llsfsim(args);
    INFO(b.args.front(), " ", b.args.at(1), "\n", r.out, r.err);
    CHECK(r.code == llsf::app::kExitBadInput);
    CHECK(has(r.err, b.err));
    CHECK(r.out.empty());
  }
}
