// SPDX-License-Identifier: MIT
// `llsfsim check` on an agent author's usual mistakes: a skill name typo in a skill-call, a
// confval path typo in the scenario, the lock switch against the agent's use of lock facts.
#include <doctest/doctest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "app/cli_fixture.h"
#include "support/temp_dir.h"

using llsf::test::has;
using llsf::test::llsfsim;
using llsf::test::TempDir;

namespace {

void write(const TempDir& dir, const std::string& name, const std::string& text) {
  std::filesystem::create_directories(std::filesystem::path(dir.file(name)).parent_path());
  std::ofstream(dir.file(name)) << text;
}

}  // namespace

TEST_CASE("check warns on unknown skills, unread confvals and a lock switch the agent ignores") {
  const TempDir dir;
  write(dir, "agent/a.clp",
        "; (skill-call in_a_comment) is not a call\n"
        "(defrule go (time $?) (not (went))\n"
        "  => (assert (went)) (skill-call drve_to place \"M1\"))\n"
        "(defrule roles (confval (path \"/clips-agent/roles\")) => )\n");
  write(dir, "s.yaml",
        "name: c\nrobots:\n  count: 1\n  locks: true\n  agent: [agent]\n"
        "  config: {rols: [P3]}\n");
  const auto r = llsfsim({"check", dir.file("s.yaml")});
  INFO(r.out, r.err);
  CHECK(r.code == 0);  // warnings only
  CHECK(has(r.out,
            "a.clp:3: (skill-call drve_to ...): the skill library has no skill 'drve_to' "
            "(did you mean 'drive_to'?)"));
  CHECK_FALSE(has(r.out, "in_a_comment"));
  // The near path the agent reads, with its file and line; no direction (either may be wrong).
  CHECK(has(r.out,
            "robots.config: the agent reads no confval /clips-agent/rols; it reads "
            "/clips-agent/roles ("));
  CHECK(has(r.out, "a.clp:4): one of the two is misspelt"));
  CHECK(has(r.out, "robots.locks is on, but the agent uses no lock facts"));
  CHECK(has(r.out, "ok   "));
}

TEST_CASE("an agent that uses lock facts with the locks switch off: the error names the switch") {
  const TempDir dir;
  write(dir, "agent/a.clp", "(defrule held (lock (resource ?r)) => (printout t ?r crlf))\n");
  write(dir, "s.yaml", "name: c\nrobots: {count: 1, agent: [agent]}\n");
  const auto r = llsfsim({"check", dir.file("s.yaml")});
  CHECK(r.code == 2);
  CHECK(has(r.err, "a.clp:1:"));
  CHECK(has(r.err,
            "hint: the agent uses the host's lock facts, which exist only with the lock "
            "protocol on: set `robots.locks: true`"));
}

TEST_CASE("check warns on a skill-call argument the skill does not document") {
  const TempDir dir;
  write(dir, "agent/a.clp",
        "(defrule go (time $?) (not (went))\n"
        "  => (assert (went)) (skill-call drive_to plac \"M1\" ori (+ 1 2)))\n"
        "(defrule fine (time $?) (place ?p) (not (fine))\n"
        "  => (assert (fine)) (skill-call drive_to x 1.0 y (* 2 1.5) place ?p))\n");
  write(dir, "s.yaml", "name: c\nrobots:\n  count: 1\n  agent: [agent]\n");
  const auto r = llsfsim({"check", dir.file("s.yaml")});
  INFO(r.out, r.err);
  CHECK(r.code == 0);
  CHECK(has(r.out,
            "a.clp:2: (skill-call drive_to plac ...): drive_to has no argument 'plac' (did "
            "you mean 'place'? its arguments: place, x, y, ori, forward_only, timeout)"));
  CHECK(r.out.find("has no argument") == r.out.rfind("has no argument"));  // ori, x, y: known
}

TEST_CASE("check: the shipped scenarios get no warning") {
  for (const char* name : {"default", "auction-vs-roles", "packet-loss", "thesis-two-robots",
                           "thesis-three-robots", "hackathon"}) {
    CAPTURE(name);
    const auto r = llsfsim({"check", std::string(LLSF_SOURCE_DIR "/scenarios/") + name + ".yaml"});
    CHECK(r.code == 0);
    CHECK_FALSE(has(r.out, "warn "));
  }
}

TEST_CASE(
    "run shows a confval nobody reads and the sandbox switched off; check notes the sandbox") {
  const TempDir dir;
  write(dir, "agent/a.clp", "(defrule roles (confval (path \"/clips-agent/roles\")) => )\n");
  write(dir, "s.yaml",
        "name: c\nduration_s: 1\nrobots:\n  count: 1\n  sandbox: false\n  agent: [agent]\n"
        "  config: {rols: [P3]}\n");
  const auto r = llsfsim({"run", dir.file("s.yaml"), "--no-db", "--no-record"});
  INFO(r.out, r.err);
  CHECK(r.code == 0);
  CHECK(has(r.err,
            "llsfsim run: warn: robots.config: the agent reads no confval "
            "/clips-agent/rols; it reads /clips-agent/roles ("));
  CHECK(has(r.err, "llsfsim run: note: robots.sandbox is off"));
  CHECK_FALSE(has(r.err, "at its defaults"));  // check's notes stay check's
  const auto c = llsfsim({"check", dir.file("s.yaml")});
  CHECK(has(c.out, "note " + dir.file("s.yaml") + ": robots.sandbox is off"));
  // -q: nothing.
  CHECK(llsfsim({"run", dir.file("s.yaml"), "--no-db", "--no-record", "-q"}).err.empty());
}

TEST_CASE("check and run warn on a time test CLIPS never evaluates again, with file:line") {
  const TempDir dir;
  write(dir, "agent/a.clp",
        "(deftemplate idle (slot until (type FLOAT)))\n"
        "(defrule idle-over\n"
        "  ?f <- (idle (until ?u))\n"
        "  (test (>= (now) ?u))\n"
        "  =>\n"
        "  (retract ?f))\n");
  write(dir, "s.yaml", "name: c\nduration_s: 1\nrobots:\n  count: 1\n  agent: [agent]\n");
  const std::string want =
      "a.clp:4: rule idle-over: (test ...) reads the time ((now)) but no (time ...) pattern "
      "comes before it";
  const auto c = llsfsim({"check", dir.file("s.yaml")});
  INFO(c.out, c.err);
  CHECK(c.code == 0);  // a warning
  CHECK(has(c.out, want));
  const auto r = llsfsim({"run", dir.file("s.yaml"), "--no-db", "--no-record"});
  INFO(r.out, r.err);
  CHECK(has(r.err, "llsfsim run: warn: "));
  CHECK(has(r.err, want));
}

TEST_CASE("check reads a Fawkes-style agent's files in the order its entry file loads them") {
  // The entry loads zz_clock.clp (a deffunction that reads the time) before aa_rules.clp (a
  // test that calls it): in name order the test would come first and look harmless.
  const TempDir dir;
  write(dir, "fk/agent/demo.clp",
        "(path-load agent/zz_clock.clp)\n"
        "(path-load \"agent/aa_rules.clp\")\n");
  write(dir, "fk/agent/zz_clock.clp", "(deffunction clock-over (?t) (> (now) ?t))\n");
  write(dir, "fk/agent/aa_rules.clp",
        "(deftemplate alarm (slot at (type FLOAT)))\n"
        "(defrule due\n"
        "  ?f <- (alarm (at ?t))\n"
        "  (test (clock-over ?t))\n"
        "  =>\n"
        "  (retract ?f))\n");
  write(dir, "s.yaml",
        "name: c\nduration_s: 1\nrobots:\n  count: 1\n"
        "  agent: {fawkes: fk, entry: agent/demo.clp}\n");
  const auto c = llsfsim({"check", dir.file("s.yaml")});
  INFO(c.out, c.err);
  CHECK(c.code == 0);  // a warning
  CHECK(has(c.out,
            "aa_rules.clp:4: rule due: (test ...) reads the time ((clock-over ...), which calls "
            "(now))"));
}

TEST_CASE("a confval the agent does not read, with no path near it: what the agent reads") {
  const TempDir dir;
  write(dir, "agent/a.clp",
        "(defrule roles (confval (path \"/clips-agent/roles\")) => )\n"
        "(defrule ms (confval (path \"/clips-agent/machines\")) => )\n");
  write(dir, "s.yaml",
        "name: c\nduration_s: 1\nrobots:\n  count: 1\n  agent: [agent]\n"
        "  config: {speed: 3}\n");
  const std::string want =
      "robots.config: the agent reads no confval /clips-agent/speed; it reads "
      "/clips-agent/machines, /clips-agent/roles\n";
  const auto c = llsfsim({"check", dir.file("s.yaml")});
  INFO(c.out, c.err);
  CHECK(c.code == 0);
  CHECK(has(c.out, "warn " + dir.file("s.yaml") + ": " + want));
  const auto r = llsfsim({"run", dir.file("s.yaml"), "--no-db", "--no-record"});
  CHECK(has(r.err, "llsfsim run: warn: " + want));
  // An agent that names no confval at all.
  write(dir, "agent/a.clp", "(defrule idle (time $?) (not (idle)) => (assert (idle)))\n");
  const auto n = llsfsim({"check", dir.file("s.yaml")});
  CHECK(has(n.out,
            "the agent reads no confval /clips-agent/speed; its files name no /clips-agent/ "
            "path at all\n"));
}

TEST_CASE("a misspelt path: the scenario file or an agent directory gets the name meant") {
  const TempDir dir;
  write(dir, "agents/a.clp", "(defrule idle (time $?) (not (idle)) => (assert (idle)))\n");
  write(dir, "s.yaml", "name: c\nduration_s: 1\nrobots: {count: 1, agent: [agnets]}\n");
  const auto c = llsfsim({"check", dir.file("s.yaml")});
  CHECK(c.code == 2);
  CHECK(has(c.err, "robots.agent[0]: agent file or directory 'agnets' not found (looked at "));
  CHECK(has(c.err, "agnets) (did you mean 'agents'?)"));
  const auto r = llsfsim({"run", dir.file("s.yml"), "--no-db", "--no-record"});
  CHECK(r.code == 2);
  CHECK(has(r.err, "(No such file or directory) (did you mean '" + dir.file("s.yaml") + "'?)"));
}
