// SPDX-License-Identifier: MIT
// The report's JSON (structure, raw per-run values, determinism, no NaN/inf) and the HTML page
// (data block and bundle inlined and escaped, a missing bundle, the viewer directory).
#include <doctest/doctest.h>
#include <stdlib.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>
#include <string>

#include "llsf/study/report.h"
#include "llsf/study/stats_store.h"
#include "support/temp_dir.h"

using namespace llsf;
using namespace llsf::sim;
using namespace llsf::study;
using nlohmann::json;

namespace {

namespace fs = std::filesystem;

using llsf::test::TempDir;

/// A store with one batch: variants "b" and "a</script>" x seeds 3, 1, 2 (stored in that order),
/// points 10 * seed (+100 for "b"); one run's real-time factor is infinite.
std::string make_store(const TempDir& dir) {
  const std::string db = dir.file("r.db");
  StatsStore store(db);
  BatchKey key;
  key.scenario_file = "x.yaml";
  key.scenario_name = "x";
  key.scenario_hash = "0123456789abcdef";
  key.runs_per_variant = 3;
  key.variants = 2;
  key.seeds = {1, 2, 3};
  const std::int64_t b = store.open_batch(key);
  for (const std::uint64_t seed : {3, 1, 2}) {
    for (const char* v : {"b", "a</script>"}) {
      RunResult r;
      r.scenario = "x";
      r.variant = v;
      r.seed = seed;
      r.points = static_cast<int>(10 * seed) + (std::string(v) == "b" ? 100 : 0);
      r.exploration_points = 4;
      r.production_points = r.points - 4;
      r.result_hash = 0xabc0 + seed;
      r.real_time_factor = seed == 2 ? std::numeric_limits<double>::infinity() : 500.0;
      r.tests.push_back({"t", seed != 1, "", 0.0});
      store.add_run(b, r);
    }
  }
  return db;
}

}  // namespace

TEST_CASE("to_json holds the batch, the summaries, the differences and every run's values") {
  TempDir dir;
  const StatsStore store(make_store(dir));
  const std::int64_t id = store.batches().front().id;
  const BatchReport r = make_report(store, id);
  const std::vector<RunValues> runs = run_values(store, id);
  const std::string text = to_json(r, runs);
  const json j = json::parse(text);  // throws on invalid JSON (NaN, inf, ...)

  CHECK(j["format"] == "llsfsim-report");
  CHECK(j["format_version"] == 2);
  CHECK(j["llsfsim_version"] == std::string(llsfsim_version()));
  CHECK(j["batch"]["id"] == id);
  CHECK(j["batch"]["scenario_name"] == "x");
  CHECK(j["batch"]["scenario_hash"] == "0123456789abcdef");
  CHECK(j["batch"]["runs_per_variant"] == 3);
  CHECK(j["batch"]["seeds"] == "1,2,3");
  // No wall-clock time in the data.
  CHECK_FALSE(j["batch"].contains("created"));
  CHECK_FALSE(j["batch"].contains("finished"));

  REQUIRE(j["variants"].size() == 2);
  CHECK(j["variants"][0]["variant"] == "a</script>");  // name order, as in the text report
  CHECK(j["variants"][0]["runs"] == 3);
  CHECK(j["variants"][0]["passed"] == 2);
  CHECK(j["variants"][0]["pass_rate"].get<double>() == doctest::Approx(2.0 / 3.0));
  CHECK(j["variants"][1]["statistics"]["points"]["median"] == 120.0);
  CHECK(j["variants"][1]["statistics"]["points"]["q1"] == 115.0);

  bool points_difference = false;
  for (const json& d : j["differences"]) {
    if (d["statistic"] != "points") continue;
    points_difference = true;
    CHECK(d["variant"] == "b");
    CHECK(d["baseline"] == "a</script>");
    CHECK(d["diff"].get<double>() == doctest::Approx(100.0));
    CHECK(d["ci_low"].get<double>() <= 100.0);
  }
  CHECK(points_difference);

  // The raw runs in (variant, seed) order, whatever order they were stored in.
  REQUIRE(j["runs"].size() == 6);
  CHECK(j["runs"][0]["variant"] == "a</script>");
  CHECK(j["runs"][0]["seed"] == 1);
  CHECK(j["runs"][0]["passed"] == false);
  CHECK(j["runs"][0]["result_hash"] == "000000000000abc1");
  CHECK(j["runs"][5]["variant"] == "b");
  CHECK(j["runs"][5]["seed"] == 3);
  CHECK(j["runs"][5]["statistics"]["points"] == 130.0);
  CHECK(j["runs"][5]["statistics"]["production_points"] == 126.0);
  // Every statistic the store holds for the run.
  CHECK(j["runs"][5]["statistics"].size() == store.statistics(store.runs(id).front().id).size());
  // The infinite real-time factor is null, the finite ones numbers.
  CHECK(j["runs"][1]["seed"] == 2);
  CHECK(j["runs"][1]["statistics"]["real_time_factor"].is_null());
  CHECK(j["runs"][0]["statistics"]["real_time_factor"] == 500.0);

  // Deterministic: the same store gives the same bytes.
  CHECK(to_json(make_report(store, id), run_values(store, id)) == text);
}

TEST_CASE("to_html inlines the bundle and the data, escaped for <script>") {
  TempDir dir;
  const StatsStore store(make_store(dir));
  const std::int64_t id = store.batches().front().id;
  const BatchReport r = make_report(store, id);
  const std::string data = to_json(r, run_values(store, id));
  fs::create_directories(dir.path / "viewer");
  {
    std::ofstream f(dir.file("viewer/report.js"));
    f << "console.log(\"</SCRIPT> is not the end\");";
  }
  const std::string page = to_html(r, data, dir.file("viewer"));
  CHECK(page.rfind("<!DOCTYPE html>", 0) == 0);
  CHECK(page.find("<title>llsfsim report: x (batch 1)</title>") != std::string::npos);
  // Exactly two elements end a script: the data block and the bundle.
  std::size_t ends = 0;
  for (std::size_t at = page.find("</script>"); at != std::string::npos;
       at = page.find("</script>", at + 1)) {
    ++ends;
  }
  CHECK(ends == 2);
  CHECK(page.find("console.log(\"<\\/SCRIPT> is not the end\");") != std::string::npos);
  // The data block parses to the same JSON.
  const std::string open = "<script id=\"llsf-report-data\" type=\"application/json\">";
  const std::size_t begin = page.find(open);
  REQUIRE(begin != std::string::npos);
  const std::size_t end = page.find("</script>", begin);
  const std::string block = page.substr(begin + open.size(), end - begin - open.size());
  CHECK(block.find('<') == std::string::npos);
  CHECK(json::parse(block) == json::parse(data));
  // The text report for browsers without JavaScript, HTML-escaped.
  CHECK(page.find("<noscript><pre>batch 1  x (x.yaml)") != std::string::npos);
  CHECK(page.find("a&lt;/script&gt;") != std::string::npos);

  // A missing bundle is an error that says how to build it.
  CHECK_THROWS_WITH_AS(to_html(r, data, dir.file("nowhere")),
                       doctest::Contains("the viewer bundle is missing (run `make viewer`)"),
                       ViewerBundleMissing);
}

TEST_CASE("the viewer directory comes from LLSF_VIEWER_DIR, else from the source tree") {
  const char* before = std::getenv("LLSF_VIEWER_DIR");
  const std::string saved = before != nullptr ? before : "";
  ::setenv("LLSF_VIEWER_DIR", "/some/where", 1);
  CHECK(viewer_dir() == "/some/where");
  ::setenv("LLSF_VIEWER_DIR", "", 1);
  CHECK(viewer_dir() == std::string(LLSF_SOURCE_DIR) + "/viewer/dist");
  ::unsetenv("LLSF_VIEWER_DIR");
  CHECK(viewer_dir() == std::string(LLSF_SOURCE_DIR) + "/viewer/dist");
  if (before != nullptr) ::setenv("LLSF_VIEWER_DIR", saved.c_str(), 1);
}
