// SPDX-License-Identifier: MIT
// A run's issues (RunResult::issues, `run` summary and --json): runtime errors and a rule stopped
// by the work budget with robot, time, rule and file:line; a rule loop cut by the firing limit;
// skill failures with their error text.
#include <doctest/doctest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "llsf/study/runner.h"
#include "llsf/study/scenario.h"

using namespace llsf;
using namespace llsf::study;

namespace {

std::string write(const std::filesystem::path& p, const std::string& text) {
  std::filesystem::create_directories(p.parent_path());
  std::ofstream(p) << text;
  return p.string();
}

}  // namespace

TEST_CASE(
    "run issues: runtime errors, budget, rule loops and skill failures, each with its place") {
  const auto dir = std::filesystem::temp_directory_path() / "llsf_run_issues";
  std::filesystem::remove_all(dir);
  write(
      dir / "agent" / "mistakes.clp",
      "; an agent made of mistakes\n"
      "(defrule broken-eval (time $?) (not (broken-done))\n"
      "  => (assert (broken-done)) (eval \"(no-such-fn 1)\"))\n"
      "(defrule forever (time ?s ?) (test (>= ?s 2)) (not (forever-done))\n"
      "  => (assert (forever-done)) (while TRUE (bind ?x 1)))\n"
      "(defrule spin ?f <- (spin ?n) => (retract ?f) (assert (spin (+ ?n 1))))\n"
      "(defrule start-spin (time ?s ?) (test (>= ?s 3)) (not (spun)) => (assert (spun) (spin 0)))\n"
      "(defrule bad-skill (time $?) (not (called)) => (assert (called))\n"
      "  (skill-call no_such_skill))\n");
  const std::string scenario = write(dir / "issues.yaml",
                                     "name: issues\n"
                                     "duration_s: 5\n"
                                     "start: production\n"
                                     "robots:\n"
                                     "  count: 1\n"
                                     "  agent: [agent]\n");
  const ScenarioFile f = load_scenario(scenario);
  const RunResult r = run_game(f.variants.at(0), 1);
  int runtime = 0, loops = 0, skills = 0;
  bool budget = false;
  for (const RunIssue& i : r.issues) {
    CHECK(i.robot == "robot1");
    if (i.kind == IssueKind::kRuntimeError) {
      ++runtime;
      if (i.rule == "broken-eval") {
        CHECK(i.place().ends_with("mistakes.clp:2"));
        CHECK(i.text.find("no-such-fn") != std::string::npos);
        CHECK(i.is_mistake());
      }
      if (i.rule == "forever") {
        budget = true;
        CHECK(i.place().ends_with("mistakes.clp:4"));
        CHECK(i.text.find("steps of work in one agent cycle") != std::string::npos);
        CHECK(i.time_s >= 2.0);
      }
    } else if (i.kind == IssueKind::kRuleLoop) {
      ++loops;
      CHECK(i.rule == "spin");
      CHECK(i.place().ends_with("mistakes.clp:6"));
    } else if (i.kind == IssueKind::kUnknownSkill) {
      ++skills;
      CHECK(i.text.find("unknown skill 'no_such_skill'") != std::string::npos);
      CHECK(i.reason == lua::FailReason::kUnknownSkill);
      CHECK(i.skill.starts_with("no_such_skill"));
      CHECK(i.is_mistake());
    } else if (i.kind == IssueKind::kSkillFailure) {
      ++skills;
      CHECK_FALSE(i.is_mistake());
    }
  }
  CHECK(runtime == r.agent_runtime_errors);
  CHECK(runtime >= 2);
  CHECK(budget);
  CHECK(loops >= 1);
  CHECK(skills == r.skill_failures);
  CHECK(skills >= 1);
  for (std::size_t k = 1; k < r.issues.size(); ++k) {
    CHECK(r.issues[k - 1].time_s <= r.issues[k].time_s);
  }
  const nlohmann::json j = nlohmann::json::parse(to_json(r));
  REQUIRE(j["issues"].size() == r.issues.size());
  CHECK(j["issues"][0].contains("place"));
  CHECK(j["issues_dropped"] == 0);
  std::filesystem::remove_all(dir);
}
