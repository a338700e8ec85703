// SPDX-License-Identifier: MIT
// Runner: plays one game of a scenario (one variant, one seed) and sums it up -- points by phase,
// deliveries, products, recycling, exploration, collisions, skill failures, radio drops, agent
// errors, the real-time factor, test-case verdicts and a result hash (same scenario + seed =
// same hash).
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "llsf/sim/game.h"
#include "llsf/sim/hackathon.h"
#include "llsf/sim/skill_brain.h"
#include "llsf/study/scenario.h"

namespace llsf::study {

/// The verdict of one test case.
struct TestVerdict {
  std::string name;
  bool passed = false;
  std::string detail;  ///< "42 points (need >= 30 by 720 s)"
  double at_s = 0.0;   ///< game time (s since the start) at which it was judged
};

/// One points award of the refbox, as the statistics store keeps it.
struct RunAward {
  double time_s = 0.0;       ///< game time since the start of the run (s)
  double game_time_s = 0.0;  ///< the refbox's phase-relative game time (s)
  std::string phase;         ///< "EXPLORATION", "PRODUCTION", ... (refbox::to_string)
  int points = 0;            ///< may be negative (wrong report, penalty)
  std::string reason;        ///< "EXPLORATION_CORRECT", ... (refbox::to_string(AwardReason))
  std::string device;        ///< "M3", "D1", ...; "" if none
  int order = -1;            ///< the order credited; -1 if none
  int puck = -1;             ///< the puck concerned; -1 if none
};

/// One order as it ended.
struct OrderResult {
  int id = 0;
  std::string product;  ///< "P1", "P2", "P3"
  int requested = 0;
  int delivered = 0;
  int window_begin_s = 0;
  int window_end_s = 0;
};

/// The kinds of issues of a run (docs/llsfsim.md, "Issues").
enum class IssueKind : std::uint8_t {
  kRuntimeError,  ///< a rule's actions failed, incl. a work budget that stopped them
  kRuleLoop,      ///< the firing limit of a cycle was reached
  kSkillFailure,  ///< a skill string ended FAILED (`skill`, `reason`, `text` its error)
  kUnknownSkill,  ///< it failed because the library has no such skill (reason kUnknownSkill)
  kLockHold,      ///< one robot held one lock longer than RunIssue::kLongLockHold_s (not
                  ///< counting a jammed robot's)
  kAgentHalted,   ///< the agent ran away for sim::AgentBrainConfig::max_runaway_cycles cycles
                  ///< and was halted; its robot stops
};
/// "runtime-error", "rule-loop", "skill-failure", "unknown-skill", "lock-hold", "agent-halted".
const char* to_string(IssueKind kind);

/// A mistake or anomaly of a run that an agent or skill author should see, with its place. Its
/// fields come as data from the agent host, the skill engine and the game (never parsed from
/// log text).
struct RunIssue {
  double time_s = 0.0;  ///< game time since the start of the run
  std::string robot;
  IssueKind kind = IssueKind::kRuntimeError;
  std::string rule;                                 ///< the CLIPS rule, if known
  std::string file;                                 ///< the rule's file, if known
  int line = 0;                                     ///< the rule's line in `file`; 0 if unknown
  std::string skill;                                ///< skill failures: the skill string
  lua::FailReason reason = lua::FailReason::kNone;  ///< skill failures: why (lua::FailReason)
  std::string text;  ///< what happened (skill failures: the engine's error)
  static constexpr double kLongLockHold_s = 300.0;
  /// "file:line" of the rule; "" if unknown.
  std::string place() const;
  /// All kinds but kSkillFailure are mistakes: a strict run (Scenario::strict, `run --strict`)
  /// fails on them.
  bool is_mistake() const { return kind != IssueKind::kSkillFailure; }
};

/// Everything a run reports.
struct RunResult {
  std::string scenario;
  std::string variant;
  std::uint64_t seed = 0;
  std::string profile;  ///< the robot profile's name (docs/profiles.md)
  double game_time_s = 0.0;
  int points = 0;  ///< the refbox's total
  int exploration_points = 0;
  int production_points = 0;
  int exploration_reports = 0;  ///< machines reported
  int exploration_correct = 0;
  int deliveries = 0;  ///< products the delivery gates took (credited to an order or not)
  std::vector<OrderResult> orders;
  int products_p1 = 0, products_p2 = 0, products_p3 = 0;  ///< made (machine completions)
  int recycled = 0;
  int recycle_points = 0;  ///< points the recycling awards gave
  int collisions = 0;
  int skill_failures = 0;
  int agent_runtime_errors = 0;
  /// Locks (robots with locks on): grants, refusals, and the waits -- a wait runs from a
  /// request to the grant, through refusals the robot answered by asking again within 5 s; a
  /// robot that gave up stopped waiting at the last refusal; a wait still open at the end counts
  /// until the end. lock_waits counts the waits that took time (not granted in the asking cycle).
  int lock_grants = 0;
  int lock_refusals = 0;
  int lock_waits = 0;
  double lock_wait_s = 0.0;      ///< summed over robots and resources
  double lock_wait_max_s = 0.0;  ///< the longest single wait
  /// The longest time one robot held one lock (grant to release or the end), not counting
  /// holds of a robot that was jammed (robot profiles) when the hold ended.
  double lock_hold_max_s = 0.0;
  /// The thesis' measures (docs/statistics.md): the production time (the refbox's phase clock,
  /// s) at which the first complex product (P1/P2: a T3 or T4 completed) was made, absent if
  /// none; the agents' role changes (the events (agent-event role-change ...) they declare,
  /// docs/clips.md) and the game time
  /// (s since the start) of the first, absent if none; the fewest pucks left in the input storage
  /// (its area grown by 0.1 m, so that pucks pushed just past its marks count; sampled every
  /// second; pucks held by a robot not counted) and the game time it first was empty, absent if
  /// never. Absent is not a value: the store keeps no row for it.
  std::optional<double> first_complex_production_s;
  int role_changes = 0;
  std::optional<double> first_role_change_game_s;
  int storage_min = 0;
  std::optional<double> storage_empty_game_s;
  /// Robot profiles: jams at devices, robots jammed at the end, and the longest run of failures
  /// of one skill by one robot without a success of that skill in between (not counting
  /// failures of a jammed robot, and failures for the reasons lua::FailReason::kAborted (a
  /// navigation goal aborted) and kNotFound (get_s0: no puck in the storage)).
  int jams = 0;
  int jammed_at_end = 0;
  int skill_failure_streak_max = 0;
  std::int64_t messages_sent = 0;
  std::int64_t messages_dropped = 0;
  double cpu_s = 0.0;
  double real_time_factor = 0.0;
  std::uint64_t result_hash = 0;
  std::vector<TestVerdict> tests;
  /// With RunHooks::profile: seconds spent per tick step (Game::TickProfile names), plus
  /// "recording" (the recorder's frames) when the game was recorded.
  std::vector<std::pair<std::string, double>> time_split;
  std::vector<RunAward> awards;  ///< every points award, in order
  /// The run's issues in time order: the first kMaxIssues kept, `issues_dropped` counts the rest
  /// (the counts above are complete); "agent-halted" issues are always kept.
  std::vector<RunIssue> issues;
  int issues_dropped = 0;
  /// Every issue that is a mistake (RunIssue::is_mistake), kept in `issues` or dropped.
  int mistakes = 0;
  static constexpr std::size_t kMaxIssues = 200;
  std::string recording;  ///< RunHooks::record_path if the game was recorded
  /// The hackathon score at the end (scenarios with `hackathon:` only).
  std::optional<sim::HackathonScore> hackathon;
  bool passed() const;
  /// An agent made a runtime error or was halted (`--fail-fast` stops at the first).
  bool agent_error() const;
};

/// What `run --trace ROBOT[:KINDS]` asks for (docs/llsfsim.md): a robot's name or "all", and
/// which kinds of trace lines.
struct TraceRequest {
  std::string robot = "all";
  bool rules = true;     ///< "FIRE rule  f-3 (fact), ..."
  bool facts = true;     ///< "==> f-18 (fact)", "<== f-17 (fact)"
  bool skills = true;    ///< "skill drive_to{place=\"M1\"} -> RUNNING"
  bool messages = true;  ///< "msg <- robot2 LockMessage {...}", "msg -> BeaconSignal {...}"
  bool log = true;       ///< "log info text": printout, log-*, (watch ...) output
};
/// The kinds `--trace` knows, in order: rules, facts, skills, msgs, log.
inline constexpr const char* kTraceKinds[] = {"rules", "facts", "skills", "msgs", "log"};
/// Parses "ROBOT[:KIND,KIND...]" (no kinds: all). Throws core::UserError naming the valid kinds
/// for an unknown one or an empty robot.
TraceRequest parse_trace_request(std::string_view arg);
/// Throws core::UserError if a request names a robot `scenario` does not have (naming its
/// robots).
void check_trace_requests(const Scenario& scenario, const std::vector<TraceRequest>& requests);

/// Called every `progress_every` of game time with the game (for a progress line).
struct RunHooks {
  std::function<void(const sim::Game&)> progress;
  core::SimTime progress_every = core::SimTime::from_sec(30);
  /// Called once with the game before its first tick, after the brains are plugged in and
  /// before the refbox is started (a caller that serves the game on sockets keeps the game to
  /// act on it between ticks from `tick`). May throw core::UserError (nothing played yet).
  std::function<void(sim::Game&)> attach;
  /// Called at every tick after step 9 (recorders, live viewers).
  std::function<void(const sim::Game&)> tick;
  /// Called with every skill status change of every robot.
  std::function<void(const sim::SkillStatusChange&)> skill;
  /// If set, the game is recorded to this file (docs/recording.md).
  std::string record_path;
  /// If set, every recording line also goes here as it is written (a live viewer), whether or
  /// not a file is recorded. Called on the game's thread.
  std::function<void(std::string_view line)> record_sink;
  /// Measure where the tick's time goes (RunResult::time_split).
  bool profile = false;
  /// Record the agents' facts and rule firings (`facts`, `fact`, `rules` lines and the debug
  /// log, docs/recording.md) when the game is recorded.
  bool record_agents = false;
  /// Agents to trace (`run --trace`); every trace line (without newline) goes to trace_sink,
  /// on the game's thread. Requests for a robot the scenario lacks make run_game throw
  /// core::UserError before anything is written.
  std::vector<TraceRequest> trace;
  std::function<void(std::string_view line)> trace_sink;
  /// Live editing (paced runs only: `run --realtime`/`--speed`): every simulated second, each
  /// robot's CLIPS files are checked and reloaded when they changed
  /// (sim::AgentBrain::reload_if_changed); what happened goes to `note` and the recording
  /// (a `note` line).
  bool reload_agents = false;
  /// Stop the game at the first agent error (a runtime error or a halted agent; `--fail-fast`):
  /// the run then fails with the verdict "fail-fast: no agent error".
  bool stop_at_agent_error = false;
  /// Messages about the game for the user (agent reloads, halted agents), with the robot they
  /// concern.
  std::function<void(core::SimTime t, const std::string& robot, const std::string& text)> note;
};

/// Plays `scenario` with `seed`. Throws clips::AgentLoadError / core::ConfigError before the
/// first tick for bad agent or skill files.
RunResult run_game(const Scenario& scenario, std::uint64_t seed, const RunHooks& hooks = {});

/// The summary as one JSON object (fixed key order; the metrics as the metric table says,
/// metrics.h).
std::string to_json(const RunResult& r);

/// Products the delivery gates of `refbox` took so far: RunResult::deliveries and the test case
/// deliveries_at_least (docs/statistics.md, "Deliveries").
int delivered_products(const refbox::Refbox& refbox);

}  // namespace llsf::study
