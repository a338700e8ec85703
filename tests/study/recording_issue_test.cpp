// SPDX-License-Identifier: MIT
// A run's issues are lines of its recording ("e": "issue", docs/recording.md), so that the
// viewer's timeline marks an agent's errors: a runtime error with its rule and place, a skill
// failure; each once, at the time it happened.
#include <doctest/doctest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <string>

#include "llsf/study/recording.h"
#include "llsf/study/runner.h"
#include "llsf/study/scenario.h"

using namespace llsf;
using namespace llsf::study;

TEST_CASE("a run's issues are issue lines of its recording") {
  const auto dir = std::filesystem::temp_directory_path() / "llsf_recording_issue_test";
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir / "agent");
  std::ofstream(dir / "agent" / "a.clp")
      << "(defrule broken (time ?s ?) (test (>= ?s 2)) (not (broke)) => (assert (broke))\n"
         "  (eval \"(no-such-fn)\"))\n"
         "(defrule bad-skill (time ?s ?) (test (>= ?s 3)) (not (asked)) => (assert (asked))\n"
         "  (skill-call no_such_skill))\n";
  std::ofstream(dir / "s.yaml") << "name: issues\nduration_s: 5\nstart: production\n"
                                   "robots: {count: 1, agent: [agent]}\n";
  const ScenarioFile f = load_scenario((dir / "s.yaml").string());
  RunHooks hooks;
  hooks.record_path = (dir / "r.jsonl.gz").string();
  const RunResult r = run_game(f.variants.front(), 1, hooks);
  REQUIRE(r.issues.size() == 2);
  std::vector<RecordingLine> issues;
  for (const RecordingLine& l : read_recording(hooks.record_path)) {
    if (l.kind == "issue") issues.push_back(l);
  }
  REQUIRE(issues.size() == 2);
  CHECK(issues[0].t == doctest::Approx(r.issues[0].time_s));
  CHECK(issues[0].json.find(R"("robot":"robot1","kind":"runtime-error","rule":"broken",)"
                            R"("place":")") != std::string::npos);
  CHECK(issues[0].json.find("a.clp:1\"") != std::string::npos);
  CHECK(issues[0].json.find("no-such-fn") != std::string::npos);
  CHECK(issues[1].json.find(R"("kind":"unknown-skill")") != std::string::npos);
  CHECK(issues[1].json.find("time_s") == std::string::npos);  // noticed when it happened
  std::filesystem::remove_all(dir);
}
