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

TEST_CASE("a mistyped command or option: exit code 2 with a did-you-mean") {
  Run r = llsfsim({"rnu", kDefault});
  CHECK(r.code == llsf::app::kExitBadInput);
  CHECK(has(r.err, "llsfsim: unknown command 'rnu'; did you mean 'run'?"));
  CHECK(!has(r.err, "A subcommand is required"));
  r = llsfsim({"--verison"});
  CHECK(r.code == llsf::app::kExitBadInput);
  CHECK(has(r.err, "llsfsim: unknown option --verison; did you mean --version?"));
  r = llsfsim({"run", kDefault, "--sede", "3", "--no-db", "--no-record"});
  CHECK(r.code == llsf::app::kExitBadInput);
  CHECK(has(r.err, "llsfsim run: unknown option --sede; did you mean --seed?"));
  CHECK(has(r.err, "Run 'llsfsim run --help' for its options."));
  r = llsfsim({"batch", "stauts", "--db=x.db", "--no-such-option"});
  CHECK(r.code == llsf::app::kExitBadInput);
  CHECK(has(r.err, "llsfsim batch: unknown option --no-such-option\n"));
  // Far from every name: no guess, the commands are listed by --help.
  r = llsfsim({"zzzzzz"});
  CHECK(r.code == llsf::app::kExitBadInput);
  CHECK(has(r.err, "llsfsim: unknown command 'zzzzzz'\n"));
  CHECK(has(r.err, "Run 'llsfsim --help' for the commands."));
}

TEST_CASE("counts and seeds out of range: a readable error, no wrap-around") {
  const TempDir dir;
  Run r = llsfsim({"batch", kDefault, "--runs", "0", "--db", dir.file("s.db")});
  CHECK(r.code == llsf::app::kExitBadInput);
  CHECK(has(r.err, "--runs: must be greater than 0, not 0"));
  CHECK(r.err.size() < 200);  // no range up to the largest double
  r = llsfsim({"run", kDefault, "--seed", "-3", "--no-db", "--no-record"});
  CHECK(r.code == llsf::app::kExitBadInput);
  CHECK(has(r.err, "a seed is a whole number from 0 to 18446744073709551615, not '-3'"));
  r = llsfsim({"skill", "--seed=-1", "ppgoto{place=\"M1\"}"});
  CHECK(r.code == llsf::app::kExitBadInput);
  CHECK(has(r.err, "not '-1'"));
  r = llsfsim({"run", kDefault, "--seed", "18446744073709551616", "--no-db", "--no-record"});
  CHECK(r.code == llsf::app::kExitBadInput);
  CHECK(has(r.err, "a seed is a whole number"));
  // In a seed list: negative, not an "empty" first seed of a range.
  r = llsfsim({"batch", kDefault, "--seeds", "-1", "--db", dir.file("s.db")});
  CHECK(r.code == llsf::app::kExitBadInput);
  CHECK(has(r.err, "--seeds -1: '-1' is negative: a seed is a whole number from 0"));
}

TEST_CASE("exercise: a misspelt skill file gets the name meant") {
  const TempDir dir;
  dir.write("my_drive.lua", "-- a skill\n");
  const Run r = llsfsim({"exercise", "01", "--skill", dir.file("my_drvie.lua")});
  CHECK(r.code == llsf::app::kExitBadInput);
  CHECK(has(r.err, "no such skill file: " + dir.file("my_drvie.lua") + " (did you mean '" +
                       dir.file("my_drive.lua") + "'?)"));
}

TEST_CASE("run --variant on a scenario without a matrix says there are no variants") {
  const Run r = llsfsim({"run", kDefault, "--variant", "nope", "--no-db", "--no-record"});
  CHECK(r.code == llsf::app::kExitBadInput);
  CHECK(has(r.err, "has no matrix, so no variant 'nope': play it without --variant"));
  CHECK(!has(r.err, "its variants:"));
}

TEST_CASE("batch --help: every exclusion names its options") {
  const Run r = llsfsim({"batch", "--help"});
  CHECK(r.code == llsf::app::kExitOk);
  for (std::size_t p = r.out.find("Excludes:"); p != std::string::npos;
       p = r.out.find("Excludes:", p + 1)) {
    const std::string after = r.out.substr(p + 9, r.out.find('\n', p) - p - 9);
    CAPTURE(after);
    CHECK(after.find_first_not_of(' ') != std::string::npos);
  }
}

TEST_CASE("batch --task (the job script's) with --slurm is refused") {
  const Run r = llsfsim({"batch", kDefault, "--slurm", "--task", "0"});
  CHECK(r.code == llsf::app::kExitBadInput);
  CHECK(has(r.err, "--task is what a Slurm array task runs; it cannot be given with --slurm"));
}

TEST_CASE("check or run on an experiment file: exit code 2 and a hint to use `experiment`") {
  const std::vector<std::vector<std::string>> commands = {
      {"check", kExperiment},
      {"run", kExperiment, "--no-db", "--no-record"},
  };
  for (const std::vector<std::string>& args : commands) {
    CAPTURE(args[0]);
    const Run r = llsfsim(args);
    CHECK(r.code == llsf::app::kExitBadInput);
    CHECK(has(r.err,
              "this is an experiment file (it has `batches`), not a scenario: play it with "
              "`llsfsim experiment " +
                  kExperiment + "`"));
  }
}
