// SPDX-License-Identifier: MIT
// `llsfsim run --strict`: an agent mistake (runtime error, rule loop, long lock hold) fails the
// run with exit 1 and the summary names it; without --strict the same run passes.
#include <doctest/doctest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "app/cli_fixture.h"
#include "support/temp_dir.h"

using llsf::test::has;
using llsf::test::llsfsim;
using llsf::test::TempDir;

TEST_CASE("run --strict fails on an agent's runtime error and names the rule and its place") {
  const TempDir dir;
  std::filesystem::create_directories(dir.file("agent"));
  std::ofstream(dir.file("agent/one.clp"))
      << "(defrule fine (time $?) (not (fine)) => (assert (fine)))\n"
         "(defrule oops (time ?s ?) (test (>= ?s 1)) (not (oops))\n"
         "  => (assert (oops)) (eval \"(no-such-fn 1)\"))\n";
  std::ofstream(dir.file("s.yaml")) << "name: strict\nduration_s: 3\nstart: production\n"
                                       "robots: {count: 1, agent: [agent]}\n";
  const auto lenient = llsfsim({"run", dir.file("s.yaml"), "--no-db", "--no-record"});
  INFO(lenient.err);
  CHECK(lenient.code == 0);
  CHECK(has(lenient.out, "issue"));
  CHECK(has(lenient.out, "robot1 runtime-error rule oops ("));
  CHECK(has(lenient.out, "one.clp:2)"));
  const auto strict = llsfsim({"run", dir.file("s.yaml"), "--no-db", "--no-record", "--strict"});
  CHECK(strict.code == 1);
  CHECK(has(strict.out, "test       FAIL  strict: no agent mistakes: 1 mistakes"));
  CHECK_FALSE(has(lenient.out, "strict:"));
  // The scenario key does the same.
  std::ofstream(dir.file("k.yaml")) << "name: strict\nduration_s: 3\nstart: production\n"
                                       "strict: true\nrobots: {count: 1, agent: [agent]}\n";
  const auto keyed = llsfsim({"run", dir.file("k.yaml"), "--no-db", "--no-record"});
  CHECK(keyed.code == 1);
  CHECK(has(keyed.out, "FAIL  strict: no agent mistakes"));
}

TEST_CASE("run --strict counts every mistake, also past the 200 issues kept; skill failures none") {
  const TempDir dir;
  std::filesystem::create_directories(dir.file("unknown"));
  std::filesystem::create_directories(dir.file("failing"));
  // A skill-call every cycle (10 Hz) for 30 s: 300 issues, more than the 200 kept.
  std::ofstream(dir.file("unknown/a.clp"))
      << "(defrule again (time $?) => (skill-call no_such_skill))\n";
  std::ofstream(dir.file("failing/a.clp"))
      << "(defrule again (time $?) => (skill-call drive_to place \"NOWHERE\"))\n";
  for (const char* agent : {"unknown", "failing"}) {
    std::ofstream(dir.file(std::string(agent) + ".yaml"))
        << "name: strict\nduration_s: 30\nstart: production\n"
           "robots: {count: 1, agent: ["
        << agent << "]}\n";
  }
  const auto unknown =
      llsfsim({"run", dir.file("unknown.yaml"), "--no-db", "--no-record", "--strict"});
  INFO(unknown.out);
  CHECK(unknown.code == 1);
  CHECK(has(unknown.out, "test       FAIL  strict: no agent mistakes: 300 mistakes"));
  CHECK(has(unknown.out, "issue      ... and 290 more mistakes, 300 in all"));
  CHECK(has(unknown.out, "issue      100 more issues not kept (the first 200 are)"));
  const auto failing =
      llsfsim({"run", dir.file("failing.yaml"), "--no-db", "--no-record", "--strict"});
  INFO(failing.out);
  CHECK(failing.code == 0);  // skill failures are no mistakes, however many
  CHECK(has(failing.out, "test       PASS  strict: no agent mistakes: 0 mistakes"));
  CHECK(has(failing.out, "more issues not kept"));
}

TEST_CASE("run and batch --fail-fast stop at the first agent error") {
  const TempDir dir;
  std::filesystem::create_directories(dir.file("agent"));
  std::ofstream(dir.file("agent/one.clp"))
      << "(defrule oops (time ?s ?) (test (>= ?s 2)) (not (oops))\n"
         "  => (assert (oops)) (eval \"(no-such-fn 1)\"))\n";
  std::ofstream(dir.file("s.yaml")) << "name: ff\nduration_s: 20\nstart: production\n"
                                       "seeds: {first: 1, count: 4}\n"
                                       "robots: {count: 1, agent: [agent]}\n";
  const auto run = llsfsim({"run", dir.file("s.yaml"), "--no-db", "--no-record", "--fail-fast"});
  INFO(run.out, run.err);
  CHECK(run.code == 1);
  CHECK(has(run.out,
            "FAIL  fail-fast: no agent error: stopped at the first agent error: robot1 "
            "at 2."));
  const auto batch = llsfsim({"batch", dir.file("s.yaml"), "--db", dir.file("b.db"), "--no-record",
                              "--fail-fast", "-j", "1"});
  INFO(batch.out, batch.err);
  CHECK(batch.code == 1);
  CHECK(has(batch.err,
            "llsfsim batch: --fail-fast: stopped at the first run with an agent error "
            "(seed 1 of "));
  const auto list = llsfsim({"report", "--db", dir.file("b.db"), "--list"});
  CHECK(has(list.out, "1 variant(s) x 4 run(s)  unfinished"));  // 3 seeds never played
  CHECK(llsfsim({"batch", dir.file("s.yaml"), "--slurm", "--fail-fast"}).code == 2);
}

TEST_CASE("the summary shows the agent-halted issue also after the first 10 issue lines") {
  // (while TRUE) in every cycle: 10 runtime errors (the work budget), then the agent is halted.
  const TempDir dir;
  std::filesystem::create_directories(dir.file("agent"));
  std::ofstream(dir.file("agent/a.clp"))
      << "(defrule spin (time $?) => (while TRUE do (bind ?x 1)))\n";
  std::ofstream(dir.file("s.yaml")) << "name: spin\nduration_s: 5\n"
                                       "robots: {count: 1, agent: [agent]}\n";
  const auto r = llsfsim({"run", dir.file("s.yaml"), "--no-db", "--no-record"});
  INFO(r.out, r.err);
  CHECK(r.code == 1);
  CHECK(has(r.out, "robot1 agent-halted"));
  CHECK_FALSE(has(r.out, "more mistakes"));  // 11 in all, every one shown
}

TEST_CASE("a rule that re-fires forever: the recording stays small (the agent is halted)") {
  // 10,000 firings a cycle from 2 s on: before runaway agents were halted, every cycle of the
  // game recorded them (578 MB for a 900 s game); now 10 cycles do. 60 s of game.
  const TempDir dir;
  std::filesystem::create_directories(dir.file("agent"));
  std::ofstream(dir.file("agent/a.clp"))
      << "(defrule start-spin (time ?s ?) (test (>= ?s 2)) (not (spun)) => (assert (spun) "
         "(spin 0)))\n"
         "(defrule spin ?f <- (spin ?n) => (retract ?f) (assert (spin (+ ?n 1))))\n";
  std::ofstream(dir.file("s.yaml")) << "name: spin\nduration_s: 60\n"
                                       "robots: {count: 1, agent: [agent]}\n";
  const auto r =
      llsfsim({"run", dir.file("s.yaml"), "--no-db", "--record", dir.file("r.jsonl.gz"), "-q"});
  CHECK(r.code == 1);
  const auto bytes = std::filesystem::file_size(dir.file("r.jsonl.gz"));
  CAPTURE(bytes);
  CHECK(bytes < 1'000'000);  // about 250 kB: the 10 cycles before the halt
}
