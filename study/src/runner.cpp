// SPDX-License-Identifier: MIT
#include "llsf/study/runner.h"

#include <llsf_msgs/GameState.pb.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>

#include "llsf/core/rng.h"
#include "llsf/core/version.h"
#include "llsf/refbox/protocol.h"
#include "llsf/sim/agent_brain.h"
#include "llsf/sim/driver.h"
#include "llsf/sim/hackathon_extension.h"
#include "llsf/study/metrics.h"
#include "llsf/study/player.h"
#include "llsf/study/recording.h"

namespace llsf::study {

namespace {

std::string fmt_s(double v) {
  std::ostringstream o;
  o.setf(std::ios::fixed);
  o.precision(1);
  o << v;
  return o.str();
}

/// `format` ("{} points", "{:.1f} s the longest lock hold") with its one field replaced by
/// `v`: "{}" as a stream prints a double, "{:.Nf}" with N decimals.
std::string format_value(std::string_view format, double v) {
  const std::size_t open = format.find('{');
  const std::size_t close = format.find('}', open);
  if (open == std::string_view::npos || close == std::string_view::npos) return std::string(format);
  std::ostringstream o;
  const std::string_view spec = format.substr(open + 1, close - open - 1);
  if (spec.starts_with(":.") && spec.ends_with('f')) {
    o.setf(std::ios::fixed);
    o.precision(std::stoi(std::string(spec.substr(2, spec.size() - 3))));
  }
  o << v;
  return std::string(format.substr(0, open)) + o.str() + std::string(format.substr(close + 1));
}

double cpu_seconds() {
  timespec ts{};
  // A measurement only, never a game input. The thread's clock: a game runs on one thread, and
  // a batch plays several games at once in one process.
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

// Lock waits of the team. A wait opens with a request and closes with the grant. A refusal ends
// it for now: asked again within kRetryGap (the agents retry every second) the wait goes on,
// refusals and the time in between included; otherwise (the robot gave up) it ended with the
// refusal. Waits still open at the end of the game count until the end.
class LockWaits {
 public:
  static constexpr core::SimTime kRetryGap = core::SimTime::from_sec(5);

  void on(const std::string& robot, const clips::LockEvent& e) {
    using clips::LockState;
    auto key = std::make_pair(robot, std::string(e.resource));
    auto it = open_.find(key);
    switch (e.to) {
      case LockState::kRequested:
        if (it != open_.end() && it->second.refused_at) {
          if (e.time - *it->second.refused_at > kRetryGap) {  // a new wait
            close(it->second, *it->second.refused_at);
            it->second = Wait{e.time, {}};
          } else {
            it->second.refused_at.reset();
          }
        } else if (it == open_.end()) {
          open_.emplace(std::move(key), Wait{e.time, {}});
        }
        return;
      case LockState::kRefused:
        if (e.from == LockState::kRequested) ++refusals_;
        if (it != open_.end()) it->second.refused_at = e.time;
        return;
      case LockState::kAccepted:
        ++grants_;
        if (it != open_.end()) {
          close(it->second, e.time);
          open_.erase(it);
        }
        return;
      case LockState::kNone:
      case LockState::kReleasing:
        if (it != open_.end()) {
          close(it->second, it->second.refused_at.value_or(e.time));
          open_.erase(it);
        }
        return;
    }
  }
  void finish(core::SimTime end, RunResult& r) {
    for (const auto& [key, w] : open_) close(w, w.refused_at.value_or(end));
    open_.clear();
    r.lock_grants = grants_;
    r.lock_refusals = refusals_;
    r.lock_waits = waits_;
    r.lock_wait_s = total_s_;
    r.lock_wait_max_s = max_s_;
  }

 private:
  struct Wait {
    core::SimTime since;
    std::optional<core::SimTime> refused_at;  ///< refused and not asked again yet
  };
  void close(const Wait& w, core::SimTime until) {
    const core::SimTime waited = until - w.since;
    if (waited <= core::SimTime{}) return;  // granted in the cycle that asked
    ++waits_;
    total_s_ += waited.seconds();
    max_s_ = std::max(max_s_, waited.seconds());
  }
  std::map<std::pair<std::string, std::string>, Wait> open_;
  int grants_ = 0, refusals_ = 0, waits_ = 0;
  double total_s_ = 0.0, max_s_ = 0.0;
};

// Lock holds: from a grant to the release (RELEASING or NONE) or the end of the game. A hold that
// ends while its robot is jammed (robot profiles) is the jam's doing and is not counted.
class LockHolds {
 public:
  void on(const std::string& robot, const clips::LockEvent& e, bool jammed) {
    using clips::LockState;
    auto key = std::make_pair(robot, std::string(e.resource));
    if (e.to == LockState::kAccepted) {
      open_.try_emplace(std::move(key), e.time);
      return;
    }
    if (e.to == LockState::kRequested) return;  // taking a pending release back: still held
    auto it = open_.find(key);
    if (it == open_.end()) return;
    if (!jammed) held(key, it->second, e.time);
    open_.erase(it);
  }
  /// Holds longer than RunIssue::kLongLockHold_s: (robot, resource, from, to).
  struct LongHold {
    std::string robot, resource;
    core::SimTime from, to;
  };
  const std::vector<LongHold>& long_holds() const { return long_; }
  /// `jammed(robot)` says whether a robot is jammed at the end.
  template <class F>
  double finish(core::SimTime end, F&& jammed) {
    for (const auto& [key, since] : open_) {
      if (!jammed(key.first)) held(key, since, end);
    }
    open_.clear();
    return max_s_;
  }

 private:
  void held(const std::pair<std::string, std::string>& key, core::SimTime from, core::SimTime to) {
    const double s = (to - from).seconds();
    max_s_ = std::max(max_s_, s);
    if (s > RunIssue::kLongLockHold_s) long_.push_back({key.first, key.second, from, to});
  }
  std::vector<LongHold> long_;
  std::map<std::pair<std::string, std::string>, core::SimTime> open_;
  double max_s_ = 0.0;
};

// Runs of failures of one skill by one robot (a FINAL of that skill ends the run).
class FailureStreaks {
 public:
  void on(const sim::SkillStatusChange& ch) {
    const std::string skill = ch.skill_string.substr(0, ch.skill_string.find('{'));
    int& n = runs_[{ch.robot, skill}];
    if (ch.status == lua::SkillStatus::kFailed) {
      // A skill whose navigation goal was aborted did not fail on its own; an empty storage is
      // no livelock (the agents wait before they look again).
      if (ch.reason == lua::FailReason::kAborted || ch.reason == lua::FailReason::kNotFound) return;
      max_ = std::max(max_, ++n);
    } else if (ch.status == lua::SkillStatus::kFinal) {
      n = 0;
    }
  }
  int max() const { return max_; }

 private:
  std::map<std::pair<std::string, std::string>, int> runs_;
  int max_ = 0;
};

/// Pucks in `area` that no robot holds.
int pucks_in(const sim::Game& g, const kinematic::Rect& area) {
  const kinematic::World& w = g.world();
  int n = 0;
  for (const core::PuckId p : w.pucks()) {
    if (!area.contains(w.puck_position(p))) continue;
    bool held = false;
    for (int i = 0; i < g.robot_count(); ++i) {
      const auto h = w.held_puck(core::RobotId(i));
      if (h && *h == p) held = true;
    }
    if (!held) ++n;
  }
  return n;
}

/// The issue the agent host reported as data.
RunIssue issue_of(const clips::AgentIssue& i) {
  RunIssue issue;
  issue.time_s = i.time.seconds();
  issue.robot = std::string(i.agent);
  issue.kind =
      i.kind == clips::AgentIssueKind::kRuleLoop ? IssueKind::kRuleLoop : IssueKind::kRuntimeError;
  issue.rule = std::string(i.rule);
  issue.file = std::string(i.file);
  issue.line = i.line;
  issue.text = std::string(i.text);
  return issue;
}

/// The trace request for robot `name` (all requests that name it or "all", merged); nullopt if
/// none does.
std::optional<TraceRequest> trace_for(const std::vector<TraceRequest>& requests,
                                      std::string_view name) {
  std::optional<TraceRequest> out;
  for (const TraceRequest& r : requests) {
    if (r.robot != name && r.robot != "all") continue;
    if (!out) {
      out = r;
      continue;
    }
    out->rules = out->rules || r.rules;
    out->facts = out->facts || r.facts;
    out->skills = out->skills || r.skills;
    out->messages = out->messages || r.messages;
    out->log = out->log || r.log;
  }
  return out;
}

/// Whether `request` shows events of `kind` (skills come from the skill engine, not the agent).
bool wants(const TraceRequest& request, clips::TraceEvent::Kind kind) {
  using Kind = clips::TraceEvent::Kind;
  switch (kind) {
    case Kind::kFire:
      return request.rules;
    case Kind::kAssert:
    case Kind::kRetract:
      return request.facts;
    case Kind::kMsgIn:
    case Kind::kMsgOut:
      return request.messages;
    case Kind::kLog:
      return request.log;
    case Kind::kCycleEnd:
      break;
  }
  return false;
}

}  // namespace

TraceRequest parse_trace_request(std::string_view arg) {
  TraceRequest r;
  const std::size_t colon = arg.find(':');
  r.robot = std::string(arg.substr(0, colon));
  const std::string kinds_list = "rules, facts, skills, msgs, log";
  if (r.robot.empty()) {
    throw core::UserError("--trace " + std::string(arg) +
                          ": name a robot (robot1, ...) or all, optionally with kinds: "
                          "ROBOT[:KIND,...], kinds " +
                          kinds_list);
  }
  if (colon == std::string_view::npos) return r;
  r.rules = r.facts = r.skills = r.messages = r.log = false;
  std::string_view rest = arg.substr(colon + 1);
  while (true) {
    const std::size_t comma = rest.find(',');
    const std::string_view kind = rest.substr(0, comma);
    if (kind == "rules") {
      r.rules = true;
    } else if (kind == "facts") {
      r.facts = true;
    } else if (kind == "skills") {
      r.skills = true;
    } else if (kind == "msgs") {
      r.messages = true;
    } else if (kind == "log") {
      r.log = true;
    } else {
      throw core::UserError("--trace " + std::string(arg) + ": unknown kind '" + std::string(kind) +
                            "' (kinds: " + kinds_list + ")");
    }
    if (comma == std::string_view::npos) break;
    rest = rest.substr(comma + 1);
  }
  return r;
}

void check_trace_requests(const Scenario& scenario, const std::vector<TraceRequest>& requests) {
  std::string names;
  for (const auto& robot : scenario.game.world.robots) names += robot.name + ", ";
  for (const TraceRequest& r : requests) {
    if (r.robot == "all") continue;
    bool known = false;
    for (const auto& robot : scenario.game.world.robots) known = known || robot.name == r.robot;
    if (!known) {
      throw core::UserError("--trace " + r.robot + ": the scenario has no robot '" + r.robot +
                            "' (its robots: " + names + "or all)");
    }
  }
}

const char* to_string(IssueKind kind) {
  switch (kind) {
    case IssueKind::kRuntimeError:
      return "runtime-error";
    case IssueKind::kRuleLoop:
      return "rule-loop";
    case IssueKind::kSkillFailure:
      return "skill-failure";
    case IssueKind::kUnknownSkill:
      return "unknown-skill";
    case IssueKind::kLockHold:
      return "lock-hold";
    case IssueKind::kAgentHalted:
      return "agent-halted";
  }
  return "runtime-error";
}

std::string RunIssue::place() const {
  if (file.empty()) return "";
  return file + ":" + std::to_string(line);
}

int delivered_products(const refbox::Refbox& refbox) {
  return static_cast<int>(refbox.report().deliveries.size());
}

bool RunResult::agent_error() const {
  if (agent_runtime_errors > 0) return true;
  return std::any_of(issues.begin(), issues.end(),
                     [](const RunIssue& i) { return i.kind == IssueKind::kAgentHalted; });
}

bool RunResult::passed() const {
  for (const TestVerdict& t : tests) {
    if (!t.passed) return false;
  }
  return true;
}

RunResult run_game(const Scenario& scenario, std::uint64_t seed, const RunHooks& hooks) {
  // What the brains call, declared before the player whose driver owns them (destroyed after
  // them).
  LockWaits lock_waits;
  LockHolds lock_holds;
  FailureStreaks streaks;
  int role_changes = 0;
  std::optional<double> first_role_change_game_s;
  int skill_failures = 0;
  std::vector<RunIssue> issues;
  int issues_dropped = 0;
  int mistakes = 0;  // every one, kept or not
  check_trace_requests(scenario, hooks.trace);
  std::unique_ptr<Recorder> recorder;
  Player player(scenario, seed);
  sim::GameDriver& driver = player.driver();
  sim::Game& game = player.game();
  if (!hooks.record_path.empty() || hooks.record_sink) {
    recorder = std::make_unique<Recorder>(
        hooks.record_path, game,
        RecordingInfo{scenario.name, scenario.variant, seed, std::string(core::kVersion)}, 10.0,
        hooks.record_sink);
  }
  auto add_issue = [&issues, &issues_dropped, &mistakes, &recorder, &game](RunIssue i) {
    if (i.is_mistake()) ++mistakes;
    // A halt (at most one per robot) is always kept: RunResult::agent_error() reads it.
    if (issues.size() < RunResult::kMaxIssues || i.kind == IssueKind::kAgentHalted) {
      if (recorder) recorder->issue(game.time(), i);  // the viewer's timeline marks it
      issues.push_back(std::move(i));
    } else {
      ++issues_dropped;
    }
  };
  for (int i = 0; i < game.robot_count(); ++i) {
    if (scenario.robots.at(static_cast<std::size_t>(i)).agent.empty()) continue;
    const std::string name(game.robot(i).name());
    // The agent's decisions (info and above) go into the recording. Its issues and events
    // come as data (clips::AgentIo::issues, ::events): the role changes it declares are
    // counted, whatever its log lines say.
    clips::LogSink log = [&recorder](const clips::LogRecord& rec) {
      if (rec.level == clips::LogLevel::kDebug) return;
      if (recorder) recorder->agent(rec);
    };
    sim::AgentReports reports;
    reports.issues = [&add_issue](const clips::AgentIssue& reported) {
      add_issue(issue_of(reported));
    };
    reports.events = [&role_changes, &first_role_change_game_s](const clips::AgentEvent& e) {
      if (e.kind != clips::AgentEventKind::kRoleChange) return;
      if (role_changes++ == 0) first_role_change_game_s = e.time.seconds();
    };
    auto locks = [&recorder, &lock_waits, &lock_holds, &game, i, name](const clips::LockEvent& e) {
      lock_waits.on(name, e);
      lock_holds.on(name, e, game.robot(i).jammed());
      if (recorder) recorder->lock(name, e);
    };
    sim::AgentBrain& brain =
        *player.plug_agent(i, std::move(log), std::move(locks), std::move(reports));
    // The agent's trace: --trace lines and the agent's facts and firings in the recording.
    const std::optional<TraceRequest> trace =
        hooks.trace_sink ? trace_for(hooks.trace, name) : std::nullopt;
    const bool record_agent = recorder != nullptr && hooks.record_agents;
    if (trace || record_agent) {
      clips::TraceOptions options;
      options.rules = record_agent || trace->rules;
      options.facts = record_agent || trace->facts;
      options.messages = trace && trace->messages;
      options.log = record_agent || trace->log;
      options.fact_texts = trace && trace->facts;  // the recorder prints what is left at the end
      auto sink = [&recorder, &hooks, trace, record_agent, i](const clips::TraceEvent& e) {
        if (record_agent) recorder->agent_trace(i, e);
        if (trace && wants(*trace, e.kind)) hooks.trace_sink(clips::trace_line(e));
      };
      brain.set_trace(options, std::move(sink));
    }
    const bool trace_skills = trace && trace->skills;
    brain.skills().set_listener([&skill_failures, &hooks, &recorder, &streaks, &game, &add_issue, i,
                                 trace_skills](const sim::SkillStatusChange& ch) {
      if (recorder) recorder->skill(ch);
      if (trace_skills) {
        std::string line = clips::trace_prefix(ch.time, ch.robot) + "skill " + ch.skill_string +
                           " -> " + std::string(lua::to_string(ch.status));
        if (!ch.result.empty()) line += " result " + ch.result;
        if (!ch.error.empty()) line += " error " + ch.error;
        hooks.trace_sink(line);
      }
      if (hooks.skill) hooks.skill(ch);
      if (ch.status == lua::SkillStatus::kFailed) {
        ++skill_failures;
        RunIssue issue;
        issue.time_s = ch.time.seconds();
        issue.robot = ch.robot;
        // A skill name the library does not have is the agent's mistake.
        issue.kind = ch.reason == lua::FailReason::kUnknownSkill ? IssueKind::kUnknownSkill
                                                                 : IssueKind::kSkillFailure;
        issue.skill = ch.skill_string;
        issue.reason = ch.reason;
        issue.text = ch.error;
        add_issue(std::move(issue));
      }
      // A jammed robot's failures are the jam's (robot profiles), not a livelock's.
      if (!game.robot(i).jammed()) streaks.on(ch);
    });
    // With the agents recorded, also their skills' states and log lines (the viewer's skill
    // panel and timeline markers, as in an exercise's recording).
    if (record_agent) {
      brain.skills().set_state_listener(
          [&recorder](const sim::SkillStateChange& change) { recorder->skill_state(change); });
      brain.skills().engine().set_log_sink(
          [&recorder, &game, name](lua::LogLevel level, std::string_view text) {
            recorder->log(game.time(), name, level, text);
          });
    }
  }
  // Test cases with a deadline are judged when the game passes it.
  std::vector<TestVerdict> verdicts(scenario.tests.size());
  std::vector<bool> judged(scenario.tests.size(), false);
  // `now`: the result so far (during the game only the metrics that may be judged by a
  // deadline, Metric::test_by_s, are filled in).
  auto judge = [&](std::size_t i, const RunResult& now) {
    const TestCase& t = scenario.tests[i];
    TestVerdict& v = verdicts[i];
    v.name = t.name;
    std::ostringstream d;
    if (t.no_agent_errors()) {
      // Runtime errors, and halted agents (a rule loop cut by the firing limit is no runtime
      // error, but an agent halted for it is).
      int errors = 0;
      int halts = 0;
      for (int k = 0; k < game.robot_count(); ++k) {
        if (const sim::AgentBrain* b = driver.agent(k)) {
          errors += b->runtime_errors();
          halts += b->halt() ? 1 : 0;
        }
      }
      d << errors << " agent runtime errors";
      if (halts > 0) d << ", " << halts << " agent(s) halted";
      v.passed = errors + halts == 0;
    } else {
      const double value = t.metric->value(now).value_or(0.0);
      d << format_value(t.metric->test_value, value);
      v.passed = t.metric->bound == Bound::kAtMost ? value <= t.value : value >= t.value;
    }
    d << " (need " << describe(t) << ")";
    v.detail = d.str();
    v.at_s = game.time().seconds();
    judged[i] = true;
  };

  game.enable_profile(hooks.profile);
  if (hooks.attach) hooks.attach(game);
  player.start();
  const core::SimTime end = scenario.duration;
  core::SimTime next_progress = hooks.progress_every;
  const double t0 = cpu_seconds();
  double recording_ns =
      0.0;  // with hooks.profile: the recorder's frames (wall clock, profile only)
  // The refbox records awards with its phase-relative time; the run notes the game time too.
  std::vector<double> award_times_s;
  // The input storage, grown by 0.1 m: pucks pushed just past its marks are still there to take.
  kinematic::Rect storage = game.config().world.field.input_storage;
  storage.lo -= core::Vec2(0.1, 0.1);
  storage.hi += core::Vec2(0.1, 0.1);
  int storage_min = pucks_in(game, storage);
  std::optional<double> storage_empty_game_s;
  if (storage_min == 0) storage_empty_game_s = 0.0;
  core::SimTime next_storage_sample = core::SimTime::from_sec(1);
  core::SimTime next_reload_check = core::SimTime::from_sec(1);
  // Halted agents (sim::AgentBrain::halt), each reported once as an issue and a note; the
  // first agent error (runtime error or halt) for hooks.stop_at_agent_error.
  std::vector<bool> halt_reported(static_cast<std::size_t>(game.robot_count()), false);
  std::vector<std::string> halted;  // "robot1 at 12.3 s"
  std::optional<std::string> first_agent_error;
  auto check_agents = [&]() {
    for (int k = 0; k < game.robot_count(); ++k) {
      const sim::AgentBrain* b = driver.agent(k);
      if (b == nullptr) continue;
      // Every tick: no string is built unless something is to be reported.
      if (!first_agent_error && (b->runtime_errors() > 0 || b->halt())) {
        first_agent_error =
            std::string(game.robot(k).name()) + " at " + fmt_s(game.time().seconds()) + " s";
      }
      const auto& h = b->halt();
      if (!h || halt_reported[static_cast<std::size_t>(k)]) continue;
      halt_reported[static_cast<std::size_t>(k)] = true;
      const std::string robot(game.robot(k).name());
      halted.push_back(robot + " at " + fmt_s(h->time.seconds()) + " s");
      RunIssue issue;
      issue.time_s = h->time.seconds();
      issue.robot = robot;
      issue.kind = IssueKind::kAgentHalted;
      issue.text = h->text;
      add_issue(std::move(issue));
      if (recorder) recorder->note(h->time, robot, h->text);
      if (hooks.note) hooks.note(h->time, robot, h->text);
    }
  };
  player.observe([&](const sim::Game&) {
    check_agents();
    if (hooks.stop_at_agent_error && first_agent_error) return true;
    if (hooks.reload_agents && game.time() >= next_reload_check) {
      next_reload_check += core::SimTime::from_sec(1);
      for (int k = 0; k < game.robot_count(); ++k) {
        sim::AgentBrain* b = driver.agent(k);
        if (b == nullptr) continue;
        const sim::AgentBrain::Reload re = b->reload_if_changed();
        if (!re.changed) continue;
        const std::string robot(game.robot(k).name());
        if (recorder) recorder->note(game.time(), robot, re.text);
        if (hooks.note) hooks.note(game.time(), robot, re.text);
      }
    }
    if (game.time() >= next_storage_sample) {
      next_storage_sample += core::SimTime::from_sec(1);
      const int n = pucks_in(game, storage);
      storage_min = std::min(storage_min, n);
      if (n == 0 && !storage_empty_game_s) storage_empty_game_s = game.time().seconds();
    }
    if (recorder) {
      if (hooks.profile) {
        const auto t = std::chrono::steady_clock::now();
        recorder->frame(game);
        recording_ns +=
            std::chrono::duration<double, std::nano>(std::chrono::steady_clock::now() - t).count();
      } else {
        recorder->frame(game);
      }
    }
    if (hooks.tick) hooks.tick(game);
    while (award_times_s.size() < game.refbox().awards().size()) {
      award_times_s.push_back(game.time().seconds());
    }
    for (std::size_t i = 0; i < scenario.tests.size(); ++i) {
      const auto& by = scenario.tests[i].by_s;
      if (!judged[i] && by && game.time() >= core::SimTime::from_seconds(*by)) {
        RunResult now;  // what a deadline may judge (Metric::test_by_s)
        now.points = game.refbox().points();
        now.deliveries = delivered_products(game.refbox());
        judge(i, now);
      }
    }
    if (hooks.progress && game.time() >= next_progress) {
      hooks.progress(game);
      next_progress += hooks.progress_every;
    }
    return false;
  });
  player.play_until(end);
  const double cpu = cpu_seconds() - t0;

  RunResult r;
  r.scenario = scenario.name;
  r.variant = scenario.variant;
  r.seed = seed;
  r.profile = scenario.game.profile;
  r.game_time_s = game.time().seconds();
  const sim::GameSummary s = game.summary();
  r.points = s.points;
  r.exploration_points = s.exploration_points;
  r.production_points = s.production_points;
  const refbox::Refbox& rb = game.refbox();
  for (std::size_t i = 0; i < rb.awards().size(); ++i) {
    const refbox::PointsAward& a = rb.awards()[i];
    RunAward& w = r.awards.emplace_back();
    w.time_s = i < award_times_s.size() ? award_times_s[i] : r.game_time_s;
    w.game_time_s = a.game_time.seconds();
    w.phase = std::string(refbox::to_string(a.phase));
    w.points = a.points;
    w.reason = std::string(refbox::to_string(a.reason));
    if (refbox::is_valid_device(a.device)) w.device = std::string(refbox::device_name(a.device));
    w.order = a.order.valid() ? static_cast<int>(a.order.value()) : -1;
    w.puck = a.puck.valid() ? static_cast<int>(a.puck.value()) : -1;
  }
  for (const refbox::PointsAward& a : rb.awards()) {
    switch (a.reason) {
      case refbox::AwardReason::kExplorationCorrect:
        ++r.exploration_reports;
        ++r.exploration_correct;
        break;
      case refbox::AwardReason::kExplorationWrong:
        ++r.exploration_reports;
        break;
      case refbox::AwardReason::kRecycled:
        ++r.recycled;
        r.recycle_points += a.points;
        break;
      case refbox::AwardReason::kMachineCompleted: {
        const auto type = rb.machine(a.device).type;
        if (type == refbox::MachineType::kT3) ++r.products_p1;
        if (type == refbox::MachineType::kT4) ++r.products_p2;
        if ((type == refbox::MachineType::kT3 || type == refbox::MachineType::kT4) &&
            !r.first_complex_production_s) {
          r.first_complex_production_s = a.game_time.seconds();
        }
        if (type == refbox::MachineType::kT5) ++r.products_p3;
        break;
      }
      default:
        break;
    }
  }
  for (const auto& o : rb.orders()) {
    if (!o.active) continue;
    r.orders.push_back({static_cast<int>(o.id.value()), std::string(refbox::to_string(o.product)),
                        o.quantity_requested, o.quantity_delivered, o.window_begin_s,
                        o.window_end_s});
  }
  r.deliveries = delivered_products(rb);
  r.collisions = s.collisions_robot_robot + s.collisions_robot_wall + s.collisions_robot_device;
  r.skill_failures = skill_failures;
  for (int k = 0; k < game.robot_count(); ++k) {
    if (const sim::AgentBrain* b = driver.agent(k)) r.agent_runtime_errors += b->runtime_errors();
  }
  lock_waits.finish(game.time(), r);
  r.lock_hold_max_s = lock_holds.finish(game.time(), [&game](const std::string& robot) {
    for (int i = 0; i < game.robot_count(); ++i) {
      if (game.robot(i).name() == robot) return game.robot(i).jammed();
    }
    return false;
  });
  for (const LockHolds::LongHold& h : lock_holds.long_holds()) {
    RunIssue issue;
    issue.time_s = h.to.seconds();
    issue.robot = h.robot;
    issue.kind = IssueKind::kLockHold;
    issue.text = "held the lock on " + h.resource + " for " + fmt_s((h.to - h.from).seconds()) +
                 " s (from " + fmt_s(h.from.seconds()) + " s; more than " +
                 fmt_s(RunIssue::kLongLockHold_s) + " s)";
    add_issue(std::move(issue));
  }
  std::stable_sort(issues.begin(), issues.end(),
                   [](const RunIssue& a, const RunIssue& b) { return a.time_s < b.time_s; });
  r.issues = std::move(issues);
  r.issues_dropped = issues_dropped;
  r.mistakes = mistakes;
  r.role_changes = role_changes;
  r.first_role_change_game_s = first_role_change_game_s;
  r.storage_min = storage_min;
  r.storage_empty_game_s = storage_empty_game_s;
  for (int i = 0; i < game.robot_count(); ++i) {
    r.jams += game.robot(i).jams();
    if (game.robot(i).jammed()) ++r.jammed_at_end;
  }
  r.skill_failure_streak_max = streaks.max();
  r.messages_sent = s.comm.sent;
  r.messages_dropped = s.comm.dropped_total();
  r.cpu_s = cpu;
  r.real_time_factor = cpu > 0.0 ? r.game_time_s / cpu : 0.0;
  std::uint64_t h = core::kFnvOffset;
  auto mix = [&h](const auto& v) { h = core::fnv1a(&v, sizeof(v), h); };
  mix(s.world_hash);
  mix(s.refbox_hash);
  mix(s.comm.sent);
  r.result_hash = h;
  for (std::size_t i = 0; i < scenario.tests.size(); ++i) {
    if (!judged[i]) judge(i, r);
  }
  if (scenario.strict) {
    // Strict (scenario key `strict`, `run --strict`): any agent mistake fails the run.
    // The complete count (r.mistakes), not the kept issues': skill failures are no mistakes.
    TestVerdict v;
    v.name = "strict: no agent mistakes";
    v.passed = r.mistakes == 0;
    v.detail = std::to_string(r.mistakes) +
               " mistakes (runtime errors, rule loops, locks held over 300 s, unknown skills, "
               "halted agents; the issue lines name them)";
    v.at_s = r.game_time_s;
    verdicts.push_back(std::move(v));
  }
  if (!halted.empty()) {
    // A halted agent played no game worth its points: the run fails whatever its test cases.
    std::string who;
    for (const std::string& robot : halted) who += (who.empty() ? "" : ", ") + robot;
    TestVerdict v;
    v.name = "no agent halted";
    v.passed = false;
    v.detail = "halted for running away: " + who + " (the agent-halted issue says why)";
    v.at_s = r.game_time_s;
    verdicts.push_back(std::move(v));
  }
  if (hooks.stop_at_agent_error && first_agent_error) {
    TestVerdict v;
    v.name = "fail-fast: no agent error";
    v.passed = false;
    v.detail = "stopped at the first agent error: " + *first_agent_error;
    v.at_s = r.game_time_s;
    verdicts.push_back(std::move(v));
  }
  r.tests = std::move(verdicts);
  r.hackathon = sim::hackathon_score(game);
  if (hooks.profile) {
    for (int i = 0; i < sim::Game::TickProfile::kSteps; ++i) {
      r.time_split.emplace_back(
          sim::Game::TickProfile::step_name(i),
          1e-9 * static_cast<double>(game.profile().ns[static_cast<std::size_t>(i)]));
    }
    if (recorder) r.time_split.emplace_back("recording", 1e-9 * recording_ns);
  }
  if (recorder) {
    recorder->close();  // throws if the file could not be finished
    r.recording = hooks.record_path;
  }
  for (int i = 0; i < game.robot_count(); ++i) game.set_brain(i, nullptr);
  return r;
}

std::string to_json(const RunResult& r) {
  using Json = nlohmann::ordered_json;  // keys in the order documented (docs/llsfsim.md)
  // JSON has no NaN or infinity: null instead.
  auto number = [](double v) { return std::isfinite(v) ? Json(v) : Json(nullptr); };
  Json orders = Json::array();
  for (const OrderResult& x : r.orders) {
    orders.push_back({{"id", x.id},
                      {"product", x.product},
                      {"requested", x.requested},
                      {"delivered", x.delivered},
                      {"window", Json::array({x.window_begin_s, x.window_end_s})}});
  }
  Json tests = Json::array();
  for (const TestVerdict& t : r.tests) {
    tests.push_back({{"name", t.name}, {"passed", t.passed}, {"detail", t.detail}});
  }
  char hash[17];
  std::snprintf(hash, sizeof hash, "%016llx", static_cast<unsigned long long>(r.result_hash));
  Json j = {
      {"scenario", r.scenario}, {"variant", r.variant}, {"seed", r.seed}, {"profile", r.profile}};
  // The metrics, as the metric table says (metrics.h): "locks.grants" is the key grants of an
  // object locks; absent (it did not happen) is null, like a number that is not finite.
  for (const Metric& m : metrics()) {
    const std::optional<double> v = m.value(r);
    Json* at = &j;
    std::string_view path = m.json;
    for (std::size_t dot = path.find('.'); dot != std::string_view::npos; dot = path.find('.')) {
      at = &(*at)[std::string(path.substr(0, dot))];
      path.remove_prefix(dot + 1);
    }
    Json& slot = (*at)[std::string(path)];
    switch (m.json_form) {
      case JsonForm::kInteger:
        slot = v ? Json(static_cast<std::int64_t>(*v)) : Json(nullptr);
        break;
      case JsonForm::kNumber:
        slot = v ? number(*v) : Json(nullptr);
        break;
      case JsonForm::kBool:
        slot = v && *v != 0.0;
        break;
      case JsonForm::kArrayLength:
        slot = m.json == "orders" ? orders : tests;  // copies: the loop may meet a key twice
        break;
    }
  }
  j["result_hash"] = hash;
  Json issues = Json::array();
  for (const RunIssue& i : r.issues) {
    issues.push_back(
        {{"time_s", number(i.time_s)},
         {"robot", i.robot},
         {"kind", to_string(i.kind)},
         {"rule", i.rule},
         {"place", i.place()},
         {"skill", i.skill},
         {"reason", i.kind == IssueKind::kSkillFailure || i.kind == IssueKind::kUnknownSkill
                        ? lua::to_string(i.reason)
                        : ""},
         {"text", i.text}});
  }
  j["issues"] = std::move(issues);
  j["issues_dropped"] = r.issues_dropped;
  j["mistakes"] = r.mistakes;
  if (r.hackathon) {
    const sim::HackathonScore& h = *r.hackathon;
    j["hackathon"] = {{"points", h.points},
                      {"rescued", h.rescued},
                      {"decoys", h.decoys},
                      {"rescuable", h.rescuable},
                      {"total_pucks", h.total_pucks}};
  }
  // One line; invalid UTF-8 (a scenario name from a file) becomes U+FFFD.
  return j.dump(-1, ' ', false, Json::error_handler_t::replace);
}

}  // namespace llsf::study
