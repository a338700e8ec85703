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
