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
  CHECK(has(r.out,
            "robots.config: the agent reads no confval /clips-agent/rols (did you mean "
            "/clips-agent/roles?)"));
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
