// SPDX-License-Identifier: MIT
// `llsfsim report --html`: the page is written with the viewer's bundle; without the bundle the
// text report is still printed, no page is written and the exit code is 2.
#include <doctest/doctest.h>
#include <stdlib.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "app/cli_fixture.h"
#include "llsf/study/stats_store.h"
#include "support/temp_dir.h"

namespace {

namespace fs = std::filesystem;

using llsf::test::has;
using llsf::test::llsfsim;
using llsf::test::Run;

using llsf::test::TempDir;

/// A store with one batch of 2 variants x 2 runs (written directly: no game is played).
std::string make_store(const TempDir& dir) {
  const std::string db = dir.file("r.db");
  llsf::study::StatsStore store(db);
  llsf::study::BatchKey key;
  key.scenario_file = "tiny.yaml";
  key.scenario_name = "tiny";
  key.scenario_hash = "00000000000000aa";
  key.runs_per_variant = 2;
  key.variants = 2;
  key.seeds = {1, 2};
  const std::int64_t b = store.open_batch(key);
  for (const std::uint64_t seed : {1, 2}) {
    for (const char* v : {"config=P3-P3", "config=P1P2-P3"}) {
      llsf::study::RunResult r;
      r.scenario = "tiny";
      r.variant = v;
      r.seed = seed;
      r.points = static_cast<int>(seed) * 7;
      store.add_run(b, r);
    }
  }
  return db;
}

/// Sets LLSF_VIEWER_DIR for one scope.
struct ViewerDir {
  explicit ViewerDir(const std::string& dir) { ::setenv("LLSF_VIEWER_DIR", dir.c_str(), 1); }
  ~ViewerDir() { ::unsetenv("LLSF_VIEWER_DIR"); }
};

}  // namespace

TEST_CASE("report --html writes a page with the bundle and the data") {
  TempDir dir;
  const std::string db = make_store(dir);
  fs::create_directories(dir.path / "dist");
  std::ofstream(dir.file("dist/report.js")) << "/* fake bundle */";
  const ViewerDir viewer(dir.file("dist"));
  const Run r = llsfsim({"report", "--db", db, "--html", dir.file("report.html")});
  CHECK(r.code == 0);
  CHECK(has(r.out, "config=P1P2-P3"));  // the text report
  std::ifstream f(dir.file("report.html"));
  const std::string page((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
  CHECK(has(page, "<script id=\"llsf-report-data\" type=\"application/json\">"));
  CHECK(has(page, "\"scenario_name\": \"tiny\""));
  CHECK(has(page, "/* fake bundle */"));
  CHECK_FALSE(fs::exists(dir.file("report.html.tmp")));
}

TEST_CASE("report --html without the viewer bundle: the text report, an error, exit code 2") {
  TempDir dir;
  const std::string db = make_store(dir);
  const ViewerDir viewer(dir.file("no-such-dir"));
  const Run r = llsfsim({"report", "--db", db, "--html", dir.file("report.html")});
  CHECK(r.code == 2);
  CHECK(has(r.out, "config=P3-P3"));
  CHECK(has(r.err, "the viewer bundle is missing (run `make viewer`)"));
  CHECK_FALSE(fs::exists(dir.file("report.html")));
}

TEST_CASE("report --html into a directory that does not exist: exit code 2") {
  TempDir dir;
  const std::string db = make_store(dir);
  fs::create_directories(dir.path / "dist");
  std::ofstream(dir.file("dist/report.js")) << "/* fake bundle */";
  const ViewerDir viewer(dir.file("dist"));
  const Run r = llsfsim({"report", "--db", db, "--html", dir.file("missing/report.html")});
  CHECK(r.code == 2);
  CHECK(has(r.err, "cannot write"));
}

TEST_CASE("report --list: the single games of `llsfsim run` are neither finished nor unfinished") {
  TempDir dir;
  const std::string db = make_store(dir);
  {
    llsf::study::StatsStore store(db);
    llsf::study::BatchKey key;
    key.kind = llsf::study::BatchKey::Kind::kRun;
    key.scenario_file = "tiny.yaml";
    key.scenario_name = "tiny";
    key.scenario_hash = "00000000000000aa";
    key.variants = 2;
    key.seeds = {1};
    const std::int64_t b = store.open_batch(key);
    for (const std::uint64_t seed : {3, 4, 5}) {
      llsf::study::RunResult r;
      r.scenario = "tiny";
      r.variant = "config=P3-P3";
      r.seed = seed;
      store.add_run(b, r, /*replace=*/true);
    }
  }
  const Run r = llsfsim({"report", "--db", db, "--list"});
  CHECK(r.code == 0);
  CHECK(has(r.out, "1  batch  tiny  tiny.yaml  2 variant(s) x 2 run(s)  unfinished\n"));
  CHECK(has(r.out, "2  run  tiny  tiny.yaml  2 variant(s), 3 game(s) of llsfsim run\n"));
}
