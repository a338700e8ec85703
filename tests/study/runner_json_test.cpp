// SPDX-License-Identifier: MIT
// A run's summary as JSON (`llsfsim run --json`) and a recording's header: valid JSON whatever
// the names hold (tabs, quotes, backslashes, control and non-ASCII characters), read back with
// nlohmann-json.
#include <doctest/doctest.h>

#include <cmath>
#include <limits>
#include <nlohmann/json.hpp>
#include <string>

#include "llsf/study/recording.h"
#include "llsf/study/runner.h"
#include "llsf/study/scenario.h"

using namespace llsf;
using namespace llsf::sim;
using namespace llsf::study;
using Json = nlohmann::ordered_json;

namespace {

const std::string kOddName =
    "tab\there \"quoted\" back\\slash\nnew line \x01 Gr\xc3\xbc\xc3\x9f"
    "e \xe2\x9c\x93";

}  // namespace

TEST_CASE("to_json(RunResult): valid JSON for odd names, NaN as null, one line, keys in order") {
  RunResult r;
  r.scenario = kOddName;
  r.variant = "config=P3\t\"x\"";
  r.seed = 18446744073709551615ull;  // the largest seed
  r.profile = "robotino-2013";
  r.game_time_s = 1080.0;
  r.points = 42;
  r.orders.push_back({3, "P2", 2, 1, 120, 300});
  r.cpu_s = std::numeric_limits<double>::quiet_NaN();
  r.first_role_change_game_s = 750.0;  // first_complex_production_s absent
  r.result_hash = 0x00ab'cdef'0123'4567ull;
  r.tests.push_back({"points \"by\" 720 s", false, "12 points\t(need >= 30)\\", 720.0});
  const std::string text = to_json(r);
  CHECK(text.find('\n') == std::string::npos);
  const Json j = Json::parse(text);
  CHECK(j.begin().key() == "scenario");
  CHECK(j["scenario"] == kOddName);
  CHECK(j["variant"] == "config=P3\t\"x\"");
  CHECK(j["seed"] == 18446744073709551615ull);
  CHECK(j["game_time_s"] == 1080.0);
  CHECK(j["points"] == 42);
  CHECK(j["orders"][0]["window"] == Json{120, 300});
  CHECK(j["cpu_s"].is_null());
  CHECK(j["first_complex_production_s"].is_null());  // absent: null, not -1
  CHECK(j["first_role_change_game_s"] == 750.0);
  CHECK(j["result_hash"] == "00abcdef01234567");  // fixed width, as the text summary
  CHECK(j["passed"] == false);
  CHECK(j["tests"][0]["name"] == "points \"by\" 720 s");
  CHECK(j["tests"][0]["detail"] == "12 points\t(need >= 30)\\");
  CHECK_FALSE(j.contains("hackathon"));

  // Invalid UTF-8 (a byte from a Latin-1 file) becomes U+FFFD instead of an exception.
  r.scenario = "caf\xe9";
  CHECK(Json::parse(to_json(r))["scenario"] == "caf\xef\xbf\xbd");
}

TEST_CASE("a recording's header holds an odd scenario name as JSON") {
  ScenarioFile f = load_scenario(LLSF_SOURCE_DIR "/scenarios/default.yaml");
  Scenario s = f.variants[0];
  s.name = kOddName;
  s.variant = "v\t1";
  s.duration = core::SimTime::from_sec(1);
  std::vector<std::string> lines;
  RunHooks hooks;
  hooks.record_sink = [&](std::string_view line) { lines.emplace_back(line); };
  run_game(s, 1, hooks);
  REQUIRE(lines.size() > 2);
  const Json header = Json::parse(lines[0]);
  CHECK(header.begin().key() == "format");
  CHECK(header["scenario"] == kOddName);
  CHECK(header["variant"] == "v\t1");
  for (const std::string& l : lines) {
    CHECK(l.find('\n') == std::string::npos);
    CHECK(Json::parse(l).is_object());
  }
}
