// SPDX-License-Identifier: MIT
// Exit codes: the user's errors give 2, a bug in llsfsim gives 3 with a request to report it (the
// bug is made by the test hook LLSF_TEST_INTERNAL_ERROR of study::load_scenario).
#include <doctest/doctest.h>

#include <cstdlib>
#include <fstream>
#include <string>
#include <vector>

#include "app/cli_fixture.h"
#include "llsf/app/cli.h"
#include "support/temp_dir.h"

namespace {

using llsf::test::has;
using llsf::test::llsfsim;
using llsf::test::Run;
using llsf::test::TempDir;

const std::string kDefault = LLSF_SOURCE_DIR "/scenarios/default.yaml";
const std::string kExperiment = LLSF_SOURCE_DIR "/experiments/thesis-2013/experiment.yaml";

/// Sets LLSF_TEST_INTERNAL_ERROR for its lifetime.
struct InternalErrorHook {
  InternalErrorHook() { ::setenv("LLSF_TEST_INTERNAL_ERROR", "1", 1); }
  ~InternalErrorHook() { ::unsetenv("LLSF_TEST_INTERNAL_ERROR"); }
  InternalErrorHook(const InternalErrorHook&) = delete;
  InternalErrorHook& operator=(const InternalErrorHook&) = delete;
};

std::string write_bad_scenario(const TempDir& dir) {
  std::ofstream f(dir.file("bad.yaml"));
  f << "name: bad\nduration_s: 60\nrobots: {count: 1}\nno_such_key: 1\n";
  return dir.file("bad.yaml");
}

}  // namespace

TEST_CASE("a bad scenario is the user's error: exit code 2, no report request") {
  const TempDir dir;
  const std::string bad = write_bad_scenario(dir);
  const std::string db = dir.file("s.db");
  const std::vector<std::vector<std::string>> commands = {
      {"run", bad, "--no-db", "--no-record"},
      {"check", bad},
      {"batch", bad, "--db", db, "--no-record", "-q"},
      {"run", dir.file("missing.yaml"), "--no-db", "--no-record"},
  };
  for (const std::vector<std::string>& args : commands) {
    CAPTURE(args[0]);
    CAPTURE(args[1]);
    const Run r = llsfsim(args);
    CHECK(r.code == llsf::app::kExitBadInput);
    CHECK(!has(r.err, "internal error"));
    CHECK(!has(r.err, "please report"));
  }
  CHECK(has(llsfsim({"run", bad, "--no-db", "--no-record"}).err, "no_such_key"));
  // A bad command line too.
  CHECK(llsfsim({"run", kDefault, "--no-such-option"}).code == llsf::app::kExitBadInput);
  CHECK(llsfsim({"run", kDefault, "--seed", "x"}).code == llsf::app::kExitBadInput);
}

TEST_CASE("a bug is an internal error: exit code 3 and a request to report it") {
  const TempDir dir;
  const std::string db = dir.file("s.db");
  const InternalErrorHook hook;
  const std::vector<std::vector<std::string>> commands = {
      {"run", kDefault, "--no-db", "--no-record"},
      {"check", kDefault},
      {"batch", kDefault, "--db", db, "--no-record", "-q"},
      {"experiment", kExperiment, "--db", db, "--no-record", "-q"},
  };
  for (const std::vector<std::string>& args : commands) {
    CAPTURE(args[0]);
    const Run r = llsfsim(args);
    CHECK(r.code == llsf::app::kExitInternalError);
    CHECK(has(r.err, "llsfsim " + args[0] + ": internal error: LLSF_TEST_INTERNAL_ERROR is set"));
    CHECK(has(r.err, "This is a bug in llsfsim"));
    CHECK(has(r.err, "please report it with the command line and the scenario file"));
  }
}

TEST_CASE("every command's help names its exit codes") {
  for (const char* command : {"run", "check", "batch", "report", "experiment", "skill", "exercise",
                              "serve", "test-agent", "new"}) {
    CAPTURE(command);
    const Run r = llsfsim({command, "--help"});
    CHECK(r.code == llsf::app::kExitOk);
    CHECK(has(r.out, "Exit code: 0"));
    CHECK(has(r.out, "3 internal error"));
  }
  const Run agent = llsfsim({"new", "agent", "--help"});
  CHECK(agent.code == llsf::app::kExitOk);
  CHECK(has(agent.out, "Exit code: 0"));
  CHECK(has(agent.out, "3 internal error"));
  CHECK(has(llsfsim({"--help"}).out, "3 internal error"));
}
