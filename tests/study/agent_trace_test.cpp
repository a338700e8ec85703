// SPDX-License-Identifier: MIT
// The agents in a recording (docs/recording.md: facts, fact, rules): snapshots and deltas replay
// to the agent's actual facts; the lines are deterministic; `--trace` requests are checked.
#include <doctest/doctest.h>

#include <algorithm>
#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "llsf/core/error.h"
#include "llsf/sim/agent_brain.h"
#include "llsf/sim/driver.h"
#include "llsf/study/player.h"
#include "llsf/study/recording.h"
#include "llsf/study/runner.h"
#include "llsf/study/scenario.h"
#include "support/temp_dir.h"

using namespace llsf;
using namespace llsf::study;
using Json = nlohmann::json;

namespace {

std::filesystem::path temp_dir() {
  static const llsf::test::TempDir dir("llsf_agent_trace_test");
  return dir.path;
}

using Facts = std::map<std::int64_t, std::string>;

/// The facts of `robot` at time `t` as the viewer rebuilds them: the last snapshot at or before
/// t, then every delta after it (in file order) up to t.
Facts replay(const std::vector<RecordingLine>& lines, const std::string& robot, double t) {
  std::size_t start = lines.size();
  for (std::size_t i = 0; i < lines.size(); ++i) {
    if (lines[i].kind == "facts" && lines[i].t <= t && Json::parse(lines[i].json)["robot"] == robot)
      start = i;
  }
  REQUIRE(start < lines.size());
  Facts facts;
  const Json snapshot = Json::parse(lines[start].json);
  for (const auto& f : snapshot["facts"]) facts[f[0].get<std::int64_t>()] = f[1].get<std::string>();
  for (std::size_t i = start + 1; i < lines.size() && lines[i].t <= t; ++i) {
    if (lines[i].kind != "fact") continue;
    const Json j = Json::parse(lines[i].json);
    if (j["robot"] != robot) continue;
    if (j.contains("r"))
      for (const auto& r : j["r"]) facts.erase(r.get<std::int64_t>());
    if (j.contains("a"))
      for (const auto& a : j["a"]) facts[a[0].get<std::int64_t>()] = a[1].get<std::string>();
  }
  return facts;
}

/// The differences of two fact sets, for failure messages.
std::string diff(const Facts& replayed, const Facts& actual) {
  std::string out;
  for (const auto& [i, t] : replayed)
    if (actual.count(i) == 0 || actual.at(i) != t)
      out += "replayed only: " + std::to_string(i) + " " + t + "\n";
  for (const auto& [i, t] : actual)
    if (replayed.count(i) == 0 || replayed.at(i) != t)
      out += "actual only: " + std::to_string(i) + " " + t + "\n";
  return out;
}

Facts actual(const clips::AgentHost& agent) {
  std::vector<std::pair<std::int64_t, std::string>> all;
  agent.fact_texts(all);
  return Facts(all.begin(), all.end());
}

}  // namespace

TEST_CASE("an agent's facts replay from the recording's snapshots and deltas") {
  const ScenarioFile f = load_scenario(LLSF_SOURCE_DIR "/scenarios/default.yaml");
  const Scenario& s = f.variants.at(0);
  sim::GameConfig config = s.game;
  config.seed = 1;
  sim::GameDriver driver(config);
  sim::Game& game = driver.game();
  const std::string path = (temp_dir() / "agents.jsonl.gz").string();
  Recorder recorder(path, game, RecordingInfo{"agents", "", 1});
  sim::AgentBrain& brain = driver.plug_agent(0, agent_config(s, s.robots.at(0)));
  brain.agent().set_trace({.rules = true, .facts = true, .log = true},
                          [&recorder](const clips::TraceEvent& e) { recorder.agent_trace(0, e); });
  driver.start(refbox::GamePhase::kPreGame);
  // 70 s: snapshots at the first cycle, 30 s later and 60 s later.
  std::map<double, std::pair<double, Facts>> seen;  // probe -> (tick time, facts)
  const std::vector<double> probes{0.1, 12.3, 29.95, 45.0, 69.9};
  driver.run_until(core::SimTime::from_sec(70), [&](const sim::Game& g) {
    recorder.frame(g);
    for (const double p : probes) {
      if (g.time().seconds() >= p && seen.count(p) == 0)
        seen[p] = {g.time().seconds(), actual(brain.agent())};
    }
    return false;
  });
  const Facts at_end = actual(brain.agent());
  recorder.close();
  const std::vector<RecordingLine> lines = read_recording(path);
  int snapshots = 0, deltas = 0, rules = 0;
  for (const RecordingLine& l : lines) {
    snapshots += l.kind == "facts" ? 1 : 0;
    deltas += l.kind == "fact" ? 1 : 0;
    rules += l.kind == "rules" ? 1 : 0;
  }
  MESSAGE(snapshots, " snapshots, ", deltas, " deltas, ", rules, " rules lines in 70 s");
  CHECK(snapshots == 3);
  CHECK(deltas > 10);
  CHECK(rules > 10);
  REQUIRE(seen.size() == probes.size());
  for (const auto& probe : seen) {
    const double at = probe.second.first;
    const Facts& facts = probe.second.second;
    INFO("t = ", at);
    CHECK(facts.size() > 20);
    const Facts replayed = replay(lines, "robot1", at);
    INFO(diff(replayed, facts));
    CHECK(replayed == facts);
  }
  CHECK(replay(lines, "robot1", 70.0) == at_end);
  // The facts of the agent as AgentHost::facts() lists them, by index.
  const std::vector<clips::Fact> listed = brain.agent().facts();
  CHECK(listed.size() == at_end.size());
  for (const clips::Fact& fact : listed) CHECK(at_end.count(fact.index) == 1);

  // Line formats (docs/recording.md).
  for (const RecordingLine& l : lines) {
    if (l.kind == "rules") {
      const Json j = Json::parse(l.json);
      REQUIRE(j["fired"].is_array());
      REQUIRE(!j["fired"].empty());
      CHECK(j["fired"][0][0].is_string());
      CHECK(j["fired"][0][1].is_array());
      CHECK(l.json.starts_with("{\"t\":"));
    }
    if (l.kind == "fact") {
      const Json j = Json::parse(l.json);
      CHECK((j.contains("a") || j.contains("r")));
      if (j.contains("a")) CHECK(j["a"][0][1].get<std::string>().starts_with("("));
    }
  }
  driver.plug(0, nullptr);
}

TEST_CASE("recordings with the agents stay byte-identical for one seed") {
  ScenarioFile f = load_scenario(LLSF_SOURCE_DIR "/scenarios/default.yaml");
  Scenario s = f.variants.at(0);
  s.duration = core::SimTime::from_sec(40);
  std::vector<std::string> runs;
  for (int i = 0; i < 2; ++i) {
    RunHooks hooks;
    hooks.record_agents = true;
    std::string text;
    hooks.record_sink = [&text](std::string_view line) {
      text.append(line);
      text += '\n';
    };
    run_game(s, 2, hooks);
    runs.push_back(std::move(text));
  }
  CHECK(runs[0] == runs[1]);
  CHECK(runs[0].find("\"e\":\"facts\",\"robot\":\"robot3\"") != std::string::npos);
  CHECK(runs[0].find("\"e\":\"rules\"") != std::string::npos);
  // A delta of another robot, with assertions.
  CHECK(runs[0].find("\"e\":\"fact\",\"robot\":\"robot2\",\"a\":[[") != std::string::npos);
  // The skills' states too (the viewer's skill panel).
  CHECK(runs[0].find("\"e\":\"skill_state\",\"robot\":\"robot1\"") != std::string::npos);
}

TEST_CASE("--trace requests: kinds and robots are checked") {
  const TraceRequest all = parse_trace_request("robot1");
  CHECK(all.robot == "robot1");
  CHECK((all.rules && all.facts && all.skills && all.messages && all.log));
  const TraceRequest some = parse_trace_request("all:rules,msgs");
  CHECK(some.robot == "all");
  CHECK((some.rules && some.messages && !some.facts && !some.skills && !some.log));
  CHECK_THROWS_WITH_AS(parse_trace_request("robot1:rulez"),
                       doctest::Contains("unknown kind 'rulez' (kinds: rules, facts, skills, "
                                         "msgs, log)"),
                       core::UserError);
  CHECK_THROWS_AS(parse_trace_request(":rules"), core::UserError);
  const ScenarioFile f = load_scenario(LLSF_SOURCE_DIR "/scenarios/default.yaml");
  CHECK_NOTHROW(check_trace_requests(f.variants[0], {all, some}));
  CHECK_THROWS_WITH_AS(
      check_trace_requests(f.variants[0], {parse_trace_request("robot9")}),
      doctest::Contains("no robot 'robot9' (its robots: robot1, robot2, robot3, or all)"),
      core::UserError);
}

TEST_CASE("run_game's trace lines: firings, facts, skills of the traced robot only") {
  ScenarioFile f = load_scenario(LLSF_SOURCE_DIR "/scenarios/default.yaml");
  Scenario s = f.variants.at(0);
  s.duration = core::SimTime::from_sec(30);
  RunHooks hooks;
  hooks.trace.push_back(parse_trace_request("robot2"));
  std::vector<std::string> lines;
  hooks.trace_sink = [&lines](std::string_view l) { lines.emplace_back(l); };
  run_game(s, 1, hooks);
  auto has = [&lines](std::string_view a, std::string_view b = {}) {
    return std::any_of(lines.begin(), lines.end(), [&](const std::string& l) {
      return l.find(a) != std::string::npos && l.find(b) != std::string::npos;
    });
  };
  REQUIRE(!lines.empty());
  CHECK(has("] robot2 FIRE "));
  CHECK(has("] robot2 ==> f-"));
  CHECK(has("] robot2 <== f-"));
  CHECK(has("] robot2 skill ", " -> RUNNING"));
  CHECK(has("] robot2 msg -> "));
  CHECK(has("] robot2 msg <- "));
  CHECK_FALSE(has("] robot1 "));
  CHECK_FALSE(has("] robot3 "));
}
