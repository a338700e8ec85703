// SPDX-License-Identifier: MIT
// `llsfsim run --trace ROBOT[:KINDS]`: trace lines with simulated time stamps on stderr or in a
// file; a bad robot or kind exits 2 naming the valid ones.
#include <doctest/doctest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "app/cli_fixture.h"
#include "support/temp_dir.h"

using llsf::test::has;
using llsf::test::llsfsim;
using llsf::test::TempDir;

namespace {

void write_scenario(const TempDir& dir) {
  std::filesystem::create_directories(dir.file("agent"));
  std::ofstream(dir.file("agent/one.clp"))
      << "(deftemplate machine (slot name) (slot mtype))\n"
         "(deffacts start (state IDLE) (machine (name M1) (mtype T1)))\n"
         "(defrule go ?s <- (state IDLE) (machine (name ?m) (mtype T1)) (time ?sec ?)\n"
         "  (test (>= ?sec 1))\n"
         "  => (retract ?s) (assert (state GOTO ?m)) (printout t \"going to \" ?m crlf)\n"
         "  (skill-call drive_to place ?m))\n"
         "(defrule game-state ?pf <- (protobuf-msg (type \"llsf_msgs.GameState\")) =>\n"
         "  (retract ?pf))\n";
  std::ofstream(dir.file("s.yaml")) << "name: trace\nduration_s: 2\nstart: production\n"
                                       "robots: {count: 2, agent: [agent]}\n";
}

}  // namespace

TEST_CASE("run --trace prints firings with matched facts, fact changes, skills and log lines") {
  const TempDir dir;
  write_scenario(dir);
  const auto r =
      llsfsim({"run", dir.file("s.yaml"), "--no-db", "--no-record", "--trace", "robot1"});
  INFO(r.err);
  CHECK(r.code == 0);
  CHECK(has(r.err, "[   0.01] robot1 ==> f-1 (state IDLE)"));
  CHECK(has(r.err, "] robot1 FIRE go  f-1 (state IDLE), f-2 (machine (name M1) (mtype T1)), f-"));
  CHECK(has(r.err, "] robot1 <== f-1 (state IDLE)"));
  CHECK(has(r.err, "] robot1 log info going to M1"));
  CHECK(has(r.err, "] robot1 skill drive_to{place=\"M1\"} -> RUNNING"));
  CHECK_FALSE(has(r.err, "] robot2 "));
  // The summary stays on stdout.
  CHECK(has(r.out, "scenario   trace"));
  // Received messages are facts with an external address: written without it, so that the
  // same game gives the same trace.
  CHECK(has(r.err, "(ptr <Pointer-C>)"));
  CHECK_FALSE(has(r.err, "<Pointer-C-"));
  // Only the types a rule can match become facts (docs/clips.md, "Protobuf"); the message trace
  // shows every message.
  CHECK(has(r.err, "(protobuf-msg (type \"llsf_msgs.GameState\")"));
  CHECK(has(r.err, "] robot1 msg <- robot2 BeaconSignal"));
  CHECK_FALSE(has(r.err, "(protobuf-msg (type \"llsf_msgs.BeaconSignal\")"));
  const auto again =
      llsfsim({"run", dir.file("s.yaml"), "--no-db", "--no-record", "--trace", "robot1"});
  CHECK(again.err == r.err);
}

TEST_CASE("run --trace with kinds, all robots, into a file") {
  const TempDir dir;
  write_scenario(dir);
  const auto r = llsfsim({"run", dir.file("s.yaml"), "--no-db", "--no-record", "--trace",
                          "all:rules", "--trace-file", dir.file("trace.txt")});
  CHECK(r.code == 0);
  CHECK_FALSE(has(r.err, "FIRE"));
  std::ifstream in(dir.file("trace.txt"));
  std::stringstream text;
  text << in.rdbuf();
  CHECK(has(text.str(), "] robot1 FIRE go  f-1 (state IDLE)"));
  CHECK(has(text.str(), "] robot2 FIRE go  f-1 (state IDLE)"));
  CHECK_FALSE(has(text.str(), "==>"));
  CHECK_FALSE(has(text.str(), "skill "));
}

TEST_CASE("run --trace: an unknown robot or kind exits 2 naming the valid ones") {
  const TempDir dir;
  write_scenario(dir);
  const auto robot =
      llsfsim({"run", dir.file("s.yaml"), "--no-db", "--no-record", "--trace", "robot7"});
  CHECK(robot.code == 2);
  CHECK(has(robot.err,
            "--trace robot7: the scenario has no robot 'robot7' (its robots: robot1, "
            "robot2, or all)"));
  const auto kind =
      llsfsim({"run", dir.file("s.yaml"), "--no-db", "--no-record", "--trace", "robot1:rule"});
  CHECK(kind.code == 2);
  CHECK(has(kind.err, "unknown kind 'rule' (kinds: rules, facts, skills, msgs, log)"));
}
