// SPDX-License-Identifier: MIT
// Hostile input to the commands that load a scenario (issue #21): a directory as the scenario,
// a batch over the games budget, a statistics store or a recording folder that cannot be
// written -- each refused with exit code 2 before any game is played.
#include <doctest/doctest.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "cli_fixture.h"
#include "llsf/app/cli.h"
#include "support/temp_dir.h"

using llsf::test::has;
using llsf::test::llsfsim;
using llsf::test::Run;
namespace fs = std::filesystem;

namespace {

/// `llsfsim ARGS...` as a user without privileges: in a child process that drops root's when the
/// tests run as root (root may write read-only files and folders).
Run llsfsim_unprivileged(const std::vector<std::string>& args) {
  if (::geteuid() != 0) return llsfsim(args);
  int pipe_fd[2];
  REQUIRE(::pipe(pipe_fd) == 0);
  const pid_t pid = ::fork();
  REQUIRE(pid >= 0);
  if (pid == 0) {
    ::close(pipe_fd[0]);
    if (::setgid(65534) != 0 || ::setuid(65534) != 0) ::_exit(99);  // nobody
    const Run r = llsfsim(args);
    const std::string text = r.out + r.err;
    std::size_t done = 0;
    while (done < text.size()) {
      const ssize_t n = ::write(pipe_fd[1], text.data() + done, text.size() - done);
      if (n <= 0) break;
      done += static_cast<std::size_t>(n);
    }
    ::_exit(r.code);
  }
  ::close(pipe_fd[1]);
  Run r;
  char buf[4096];
  ssize_t n = 0;
  while ((n = ::read(pipe_fd[0], buf, sizeof buf)) > 0)
    r.err.append(buf, static_cast<std::size_t>(n));
  ::close(pipe_fd[0]);
  int status = 0;
  ::waitpid(pid, &status, 0);
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return r;
}

/// A scenario of one robot without an agent: a game of `duration_s` seconds.
std::string write_scenario(const fs::path& dir, int duration_s) {
  const fs::path p = dir / "s.yaml";
  std::ofstream(p) << "name: s\nduration_s: " << duration_s << "\nrobots: {count: 1}\n";
  return p.string();
}

}  // namespace

TEST_CASE("check, run and batch: a directory given as the scenario is named as such") {
  const llsf::test::TempDir dir("llsf_app_scenario_dir");
  const std::string d = dir.path.string();
  for (const std::vector<std::string>& args :
       {std::vector<std::string>{"check", d},
        {"run", d, "--no-db", "--no-record"},
        {"batch", d, "--db", (dir.path / "x.db").string(), "--no-record"}}) {
    const Run r = llsfsim(args);
    INFO(args.front() << ": " << r.err);
    CHECK(r.code == llsf::app::kExitBadInput);
    CHECK(has(r.err, d + ": not a regular file (a directory); the scenario file must be one"));
  }
}

TEST_CASE("batch: --runs and variants x seeds are bounded before a game is played") {
  const llsf::test::TempDir dir("llsf_app_batch_budget");
  const std::string db = (dir.path / "x.db").string();
  const std::string one = write_scenario(dir.path, 1);
  Run r = llsfsim({"batch", one, "--db", db, "--no-record", "--runs", "100001"});
  CHECK(r.code == llsf::app::kExitBadInput);
  CHECK(has(r.err, "--runs 100001: at most 100000 seeds per variant"));
  const fs::path two = dir.path / "two.yaml";
  std::ofstream(two) << "name: two\nduration_s: 1\nrobots: {count: 1}\n"
                        "matrix:\n  a: {x: {}, y: {}}\n";
  r = llsfsim({"batch", two.string(), "--db", db, "--no-record", "--runs", "60000"});
  CHECK(r.code == llsf::app::kExitBadInput);
  CHECK(has(r.err, "2 variants x --runs 60000 = 120000 games: at most 100000"));
  CHECK_FALSE(fs::exists(db));  // refused before the store was opened
}

TEST_CASE("run: a read-only statistics store is refused before the game") {
  const llsf::test::TempDir dir("llsf_app_ro_store");
  fs::permissions(dir.path, fs::perms::all);  // the unprivileged child writes here
  const std::string scenario = write_scenario(dir.path, 30);
  const std::string db = (dir.path / "ro.db").string();
  REQUIRE(llsfsim({"run", scenario, "--db", db, "--no-record", "-q"}).code == 0);
  fs::permissions(db, fs::perms::owner_read | fs::perms::group_read | fs::perms::others_read);
  const fs::path recording = dir.path / "r.jsonl.gz";
  const Run r = llsfsim_unprivileged({"run", scenario, "--db", db, "--record", recording.string()});
  INFO(r.err);
  CHECK(r.code == llsf::app::kExitBadInput);
  CHECK(has(r.err, db + ": the statistics store is read-only"));
  CHECK_FALSE(fs::exists(recording));  // no game was played
}

TEST_CASE("run: a store in a read-only folder is refused before the game") {
  const llsf::test::TempDir dir("llsf_app_ro_store_dir");
  fs::permissions(dir.path, fs::perms::all);
  const std::string scenario = write_scenario(dir.path, 30);
  const fs::path folder = dir.path / "ro";
  fs::create_directories(folder);
  const std::string db = (folder / "x.db").string();
  REQUIRE(llsfsim({"run", scenario, "--db", db, "--no-record", "-q"}).code == 0);
  fs::permissions(db, fs::perms::all);  // the file is writable, its folder (the journal's) not
  fs::permissions(folder, fs::perms::owner_read | fs::perms::owner_exec | fs::perms::group_read |
                              fs::perms::group_exec | fs::perms::others_read |
                              fs::perms::others_exec);
  const fs::path recording = dir.path / "r.jsonl.gz";
  const Run r = llsfsim_unprivileged({"run", scenario, "--db", db, "--record", recording.string()});
  INFO(r.err);
  CHECK(r.code == llsf::app::kExitBadInput);
  CHECK(has(r.err, "is not writable (SQLite writes its journal there)"));
  CHECK_FALSE(fs::exists(recording));
  fs::permissions(folder, fs::perms::all);  // for TempDir's clean-up
}

TEST_CASE("--db into a folder that does not exist: exit code 2, no folder created") {
  const llsf::test::TempDir dir("llsf_app_missing_db_dir");
  const std::string scenario = write_scenario(dir.path, 30);
  const fs::path missing = dir.path / "no" / "such";
  const std::string db = (missing / "x.db").string();
  const fs::path recording = dir.path / "r.jsonl.gz";
  for (const char* command : {"run", "batch"}) {
    CAPTURE(command);
    const Run r = llsfsim({command, scenario, "--db", db, "--no-record", "-q"});
    INFO(r.err);
    CHECK(r.code == llsf::app::kExitBadInput);
    CHECK(has(r.err, "the folder " + missing.string() + " does not exist"));
    CHECK_FALSE(fs::exists(dir.path / "no"));
  }
}

TEST_CASE("run: a recording folder that cannot be written is refused before the game") {
  const llsf::test::TempDir dir("llsf_app_ro_recording");
  fs::permissions(dir.path, fs::perms::all);
  const std::string scenario = write_scenario(dir.path, 30);
  const fs::path folder = dir.path / "ro";
  fs::create_directories(folder);
  fs::permissions(folder, fs::perms::owner_read | fs::perms::owner_exec | fs::perms::group_read |
                              fs::perms::group_exec | fs::perms::others_read |
                              fs::perms::others_exec);
  const Run r = llsfsim_unprivileged(
      {"run", scenario, "--no-db", "--record", (folder / "r.jsonl.gz").string()});
  INFO(r.err);
  CHECK(r.code == llsf::app::kExitBadInput);
  CHECK(has(r.err, "r.jsonl.gz: cannot create the recording: the folder"));
  CHECK(has(r.err, "is not writable"));
  // A missing folder too.
  const Run missing =
      llsfsim({"run", scenario, "--no-db", "--record", (dir.path / "no" / "r.jsonl.gz").string()});
  CHECK(missing.code == llsf::app::kExitBadInput);
  CHECK(has(missing.err, "does not exist"));
  fs::permissions(folder, fs::perms::all);
}
