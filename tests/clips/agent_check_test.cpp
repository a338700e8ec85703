// SPDX-License-Identifier: MIT
// The static checks of an agent's source that `llsfsim check` prints (check_agent,
// source_check.h): each kind of finding with its file and line, nothing found in comments and
// strings, a clean agent without findings; the agent's files in load order (agent_files.h).
#include <doctest/doctest.h>

#include <filesystem>
#include <string>
#include <vector>

#include "llsf/clips/agent_files.h"
#include "llsf/clips/source_check.h"
#include "support/temp_dir.h"

using namespace llsf;
using namespace llsf::clips;
using Kind = AgentFinding::Kind;

namespace {

// The skills of the checks below: drive_to declares its arguments, wait none.
AgentCheckFacts with_skills() {
  AgentCheckFacts facts;
  facts.skills = std::vector<SkillFacts>{{"drive_to", {"place", "x", "y", "ori"}}, {"wait", {}}};
  return facts;
}

std::vector<AgentFinding> of_kind(const std::vector<AgentFinding>& all, Kind kind) {
  std::vector<AgentFinding> out;
  for (const AgentFinding& f : all) {
    if (f.kind == kind) out.push_back(f);
  }
  return out;
}

std::string texts(const std::vector<AgentFinding>& all) {
  std::string out;
  for (const AgentFinding& f : all) out += f.text() + "\n";
  return out;
}

}  // namespace

TEST_CASE("a clean agent has no findings") {
  AgentCheckFacts facts = with_skills();
  facts.locks = true;
  facts.config = {ConfigEntry::of("/clips-agent/roles", "P3"),
                  ConfigEntry::of("/clips-agent/use-locks", true)};  // the host's: not compared
  const std::vector<SourceFile> files = {
      {"a.clp",
       "; an agent that calls its skills as declared\n"
       "(defrule go (time $?) (place ?p) (not (went))\n"
       "  => (assert (went)) (skill-call drive_to place ?p ori 1.0))\n"
       "(defrule hold (time $?) => (skill-call wait anything 1))\n"},
      {"b.clp",
       "(defrule roles (confval (path \"/clips-agent/roles\") (value ?r)) => )\n"
       "(defrule ask (todo ?r) => (assert (resource-request (resource ?r))))\n"}};
  const std::vector<AgentFinding> found = check_agent(files, facts);
  INFO(texts(found));
  CHECK(found.empty());
}

TEST_CASE("a time read CLIPS never evaluates again: the rule's file and the test's line") {
  const std::vector<SourceFile> files = {{"t.clp",
                                          "(deftemplate idle (slot until (type FLOAT)))\n"
                                          "(defrule idle-over\n"
                                          "  ?f <- (idle (until ?u))\n"
                                          "  (test (>= (now) ?u))\n"
                                          "  =>\n"
                                          "  (retract ?f))\n"}};
  const std::vector<AgentFinding> found = check_agent(files, {});
  REQUIRE(found.size() == 1);
  CHECK(found[0].kind == Kind::kTimeRead);
  CHECK_FALSE(found[0].note);
  CHECK(found[0].file == "t.clp");
  CHECK(found[0].line == 4);
  CHECK(found[0].text().starts_with(
      "t.clp:4: rule idle-over: (test ...) reads the time ((now)) but no (time ...) pattern "
      "comes before it"));
}

TEST_CASE("a deffunction that reads the time counts in the files loaded after its own") {
  const SourceFile clock{"clock.clp", "(deffunction over (?t) (> (now) ?t))\n"};
  const SourceFile rules{"rules.clp",
                         "(deftemplate alarm (slot at))\n"
                         "(defrule due ?f <- (alarm (at ?t))\n"
                         "  (test (over ?t)) => (retract ?f))\n"};
  const std::vector<AgentFinding> in_order = check_agent({clock, rules}, {});
  REQUIRE(in_order.size() == 1);
  CHECK(in_order[0].text().starts_with(
      "rules.clp:3: rule due: (test ...) reads the time ((over ...), which calls (now))"));
  CHECK(check_agent({rules, clock}, {}).empty());  // loaded before the deffunction
}

TEST_CASE("a skill call with a skill the library does not have, with its line and a hint") {
  const std::vector<SourceFile> files = {
      {"a.clp",
       "; (skill-call drve_to) in a comment is not a call\n"
       "(defrule go (time $?) (not (went))\n"
       "  => (assert (went))\n"
       "     (printout t \"(skill-call drve_to place M1)\" crlf)\n"
       "     (skill-call drve_to place \"M1\"))\n"
       "(defrule other (time $?) => (skill-call fly))\n"
       "(defrule computed (skill ?s) => (skill-call ?s))\n"}};
  const std::vector<AgentFinding> found = check_agent(files, with_skills());
  INFO(texts(found));
  REQUIRE(found.size() == 2);
  CHECK(found[0].kind == Kind::kUnknownSkill);
  CHECK(found[0].line == 5);
  CHECK(found[0].text() ==
        "a.clp:5: (skill-call drve_to ...): the skill library has no skill 'drve_to' (did you "
        "mean 'drive_to'?)");
  CHECK(found[1].line == 6);
  CHECK(found[1].text() ==
        "a.clp:6: (skill-call fly ...): the skill library has no skill 'fly' (`llsfsim skill "
        "--list` lists them)");
  // Without the skills (`run`), skill calls are not checked.
  CHECK(check_agent(files, {}).empty());
}

TEST_CASE("a skill-call argument the skill does not declare, with the call's line") {
  const std::vector<SourceFile> files = {
      {"a.clp",
       "(defrule go (time $?) (not (went))\n"
       "  => (assert (went))\n"
       "  (skill-call drive_to plac \"M1\" ori (+ 1 2)))\n"
       "(defrule fine (time $?) (place ?p) (not (fine))\n"
       "  => (assert (fine)) (skill-call drive_to x 1.0 y (* 2 1.5) place ?p))\n"
       "(defrule stops (time $?) => (skill-call drive_to ?key 1 plase 2))\n"
       "(defrule any (time $?) => (skill-call wait whatever 1))\n"}};
  const std::vector<AgentFinding> found = check_agent(files, with_skills());
  INFO(texts(found));
  REQUIRE(found.size() ==
          1);  // ori, x, y, place known; after ?key nothing is read; wait: no @param
  CHECK(found[0].kind == Kind::kUnknownArgument);
  CHECK(found[0].text() ==
        "a.clp:3: (skill-call drive_to plac ...): drive_to has no argument 'plac' (did you mean "
        "'place'? its arguments: place, x, y, ori)");
}

TEST_CASE("a configured confval the agent does not name: the near path and where it is read") {
  AgentCheckFacts facts;
  facts.config = {ConfigEntry::of("/clips-agent/rols", "P3")};
  const std::vector<SourceFile> files = {
      {"a.clp",
       "; \"/clips-agent/rols\" in a comment is not read\n"
       "(defrule idle (time $?) => )\n"
       "(defrule roles (confval (path \"/clips-agent/roles\")) => )\n"}};
  const std::vector<AgentFinding> found = check_agent(files, facts);
  INFO(texts(found));
  const std::vector<AgentFinding> not_read = of_kind(found, Kind::kConfvalNotRead);
  REQUIRE(not_read.size() == 1);
  CHECK(not_read[0].file == "robots.config");
  CHECK(not_read[0].line == 0);
  CHECK(not_read[0].text() ==
        "robots.config: the agent reads no confval /clips-agent/rols; it reads "
        "/clips-agent/roles (a.clp:3): one of the two is misspelt");
  // The path the agent reads that the configuration leaves out: a note.
  const std::vector<AgentFinding> unset = of_kind(found, Kind::kConfvalsDefault);
  REQUIRE(unset.size() == 1);
  CHECK(unset[0].note);
  CHECK(unset[0].text() ==
        "robots.config leaves these confvals of the agent at its defaults: /clips-agent/roles");
}

TEST_CASE("a confval with no path near it: what the agent reads; an agent that reads none") {
  AgentCheckFacts facts;
  facts.config = {ConfigEntry::of("/clips-agent/speed", 3)};
  facts.config_name = "config";
  const std::vector<AgentFinding> found = check_agent(
      {{"a.clp",
        "(defrule roles (confval (path \"/clips-agent/roles\")) => )\n"
        "(defrule ms (confval (path \"/clips-agent/machines\")) => )\n"
        "(defrule spaced (test (eq ?x \"/clips-agent/ speed\")) => )\n"}},  // not a path
      facts);
  INFO(texts(found));
  REQUIRE(!found.empty());
  CHECK(found[0].text() ==
        "config: the agent reads no confval /clips-agent/speed; it reads /clips-agent/machines, "
        "/clips-agent/roles");
  const std::vector<AgentFinding> none =
      check_agent({{"a.clp", "(defrule idle (time $?) (not (idle)) => (assert (idle)))\n"}}, facts);
  REQUIRE(none.size() == 1);
  CHECK(none[0].text() ==
        "config: the agent reads no confval /clips-agent/speed; its files name no /clips-agent/ "
        "path at all");
}

TEST_CASE("a path ending in / names every path below it; the host's paths are not compared") {
  AgentCheckFacts facts;
  facts.fawkes = true;
  facts.config = {ConfigEntry::of("/clips-agent/llsf2013/team", "Carologistics"),
                  ConfigEntry::of("/clips-agent/agent", "demo"),
                  ConfigEntry::of("/clips-agent/use-locks", false)};
  const std::vector<AgentFinding> found = check_agent(
      {{"a.clp",
        "(defrule cfg (confval (path ?p&:(str-index \"/clips-agent/llsf2013/\" ?p))) => )\n"}},
      facts);
  INFO(texts(found));
  CHECK(found.empty());
  facts.fawkes = false;  // /clips-agent/agent is the agent's own then
  CHECK(of_kind(check_agent({{"a.clp", ""}}, facts), Kind::kConfvalNotRead).size() == 2);
}

TEST_CASE("the lock protocol on, the agent without lock facts; one in a string does not count") {
  AgentCheckFacts facts;
  facts.locks = true;
  const std::vector<AgentFinding> found =
      check_agent({{"a.clp",
                    "; (resource-request (resource M1)) in a comment\n"
                    "(defrule say (time $?) => (printout t \"(lock (resource M1)) "
                    "resource-request\" crlf))\n"}},
                  facts);
  REQUIRE(found.size() == 1);
  CHECK(found[0].kind == Kind::kLocksUnused);
  CHECK(found[0].text() ==
        "robots.locks is on, but the agent uses no lock facts (no resource-request or lock fact "
        "in its files): the lock protocol runs for nothing (set `robots.locks: false`?)");
  for (const char* uses :
       {"(defrule a (todo ?r) => (assert (resource-request (resource ?r))))",
        "(defrule b (lock (resource ?r)) => )", "(defrule c (todo ?r) => (lock-assert ?r))"}) {
    CAPTURE(uses);
    CHECK(check_agent({{"a.clp", uses}}, facts).empty());
  }
  facts.locks = false;
  CHECK(check_agent({{"a.clp", ""}}, facts).empty());
}

TEST_CASE("findings come per file in load order: time reads, then skill calls, then the config") {
  AgentCheckFacts facts = with_skills();
  facts.config = {ConfigEntry::of("/clips-agent/x", 1)};
  const std::vector<AgentFinding> found =
      check_agent({{"a.clp",
                    "(defrule s (time $?) => (skill-call nope))\n"
                    "(defrule t (f ?u) (test (> (now) ?u)) => )\n"},
                   {"b.clp", "\n(defrule s2 (time $?) => (skill-call nada))\n"}},
                  facts);
  INFO(texts(found));
  REQUIRE(found.size() == 4);
  CHECK(found[0].kind == Kind::kTimeRead);
  CHECK(found[0].line == 2);
  CHECK(found[1].kind == Kind::kUnknownSkill);
  CHECK(found[1].line == 1);
  CHECK(found[2].file == "b.clp");
  CHECK(found[2].line == 2);
  CHECK(found[3].kind == Kind::kConfvalNotRead);
}

TEST_CASE("path-load names: symbols and strings in text order, not in comments or strings") {
  CHECK(path_load_names("; (path-load \"commented.clp\")\n"
                        "(path-load agent/a.clp)\n"
                        "(printout t \"(path-load quoted.clp)\" crlf)\n"
                        "(if TRUE then (path-load \"agent/b.clp\"))\n"
                        "(path-load (str-cat ?dir \"/c.clp\"))\n") ==
        std::vector<std::string>{"agent/a.clp", "agent/b.clp"});
}

TEST_CASE("a Fawkes-style agent's files: the entry, what it path-loads, then the rest by name") {
  const test::TempDir dir;
  std::filesystem::create_directories(dir.path / "fk/agent");
  dir.write("fk/agent/demo.clp", "(path-load agent/zz.clp)\n(path-load \"agent/mm.clp\")\n");
  dir.write("fk/agent/zz.clp", "(path-load agent/yy.clp)\n(path-load ../outside.clp)\n");
  dir.write("fk/agent/yy.clp", "(path-load agent/zz.clp)\n");  // each file once
  dir.write("fk/agent/mm.clp", "");
  dir.write("fk/agent/aa.clp", "");
  dir.write("outside.clp", "");  // outside the agent directory: the host refuses it
  std::vector<std::string> names;
  for (const SourceFile& f : read_fawkes_sources(dir.file("fk"), dir.file("fk/agent/demo.clp")))
    names.push_back(std::filesystem::path(f.name).filename().string());
  CHECK(names == std::vector<std::string>{"demo.clp", "zz.clp", "yy.clp", "mm.clp", "aa.clp"});
  // A plain agent: its directories' .clp files in name order, with their texts.
  const std::vector<SourceFile> plain = read_agent_sources({dir.file("fk/agent")});
  REQUIRE(plain.size() == 5);
  CHECK(std::filesystem::path(plain[0].name).filename() == "aa.clp");
  CHECK(plain[1].text == "(path-load agent/zz.clp)\n(path-load \"agent/mm.clp\")\n");
}
