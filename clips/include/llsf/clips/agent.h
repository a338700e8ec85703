// SPDX-License-Identifier: MIT
// AgentHost: one robot's CLIPS agent — a CLIPS 6.30 environment with the llsfsim features
// (time, skills, config, protobuf, pose/identity, logging, seeded random), stepped by the caller
// at the agent rate (default 10 Hz of simulated time). See docs/clips.md.
#pragma once

#include <cstdint>
#include <functional>
#include <initializer_list>
#include <memory>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "llsf/clips/blackboard.h"
#include "llsf/clips/config_values.h"
#include "llsf/clips/lock_manager.h"
#include "llsf/clips/skill_runner.h"
#include "llsf/clips/trace.h"
#include "llsf/clips/value.h"
#include "llsf/core/error.h"
#include "llsf/core/geometry.h"
#include "llsf/core/sim_time.h"

namespace google::protobuf {
class Message;
}
namespace llsf::comm {
class MessageRegistry;
}

namespace llsf::clips {

/// Bad agent code: a syntax or semantic error while loading. The message reads
/// "file.clp:LINE: [ID] what (in defrule MAIN::name)", one line per error.
class AgentLoadError : public core::UserError {
 public:
  using core::UserError::UserError;
};

/// Log level of an agent's output.
enum class LogLevel : std::uint8_t { kDebug, kInfo, kWarn, kError };
/// "debug", "info", "warn", "error".
const char* to_string(LogLevel level);

/// One line of agent output: (printout t ...), (log-info ...), CLIPS' own warnings and errors.
/// Views are valid during the sink call only.
struct LogRecord {
  core::SimTime time;  ///< simulated time of the cycle that printed it
  LogLevel level = LogLevel::kInfo;
  std::string_view agent;  ///< the robot's name
  std::string_view text;   ///< without the trailing newline
};
using LogSink = std::function<void(const LogRecord&)>;

/// The kinds of mistakes the host reports as data (AgentIo::issues; docs/clips.md, "Issues").
enum class AgentIssueKind : std::uint8_t {
  kRuntimeError,  ///< a rule's actions failed (also stopped by the work budget)
  kRuleLoop,      ///< the firing limit of a cycle was reached with rules still on the agenda
};
/// "runtime-error", "rule-loop".
const char* to_string(AgentIssueKind kind);

/// One mistake of the agent, as data: the host logs the same as a line for people, but a reader
/// of outcomes takes it from here (the line's wording may change). Views are valid during the
/// sink call only.
struct AgentIssue {
  core::SimTime time;  ///< simulated time of the cycle
  AgentIssueKind kind = AgentIssueKind::kRuntimeError;
  std::string_view agent;  ///< the robot's name
  std::string_view rule;   ///< the rule running (kRuntimeError) or next (kRuleLoop); "" if none
  std::string_view file;   ///< the file the rule was loaded from; "" if unknown
  int line = 0;            ///< its line in `file`; 0 if unknown
  std::string_view text;   ///< what happened, without the rule and its place
};
using IssueSink = std::function<void(const AgentIssue&)>;

/// The kinds of events an agent declares with (agent-event KIND ...) (docs/clips.md, "Agent
/// events"). The host refuses a kind it does not know (a runtime error naming the kinds).
enum class AgentEventKind : std::uint8_t {
  /// (agent-event role-change FROM TO [WHY]): the robot's role changed from FROM to TO (symbols).
  kRoleChange,
};
/// "role-change".
const char* to_string(AgentEventKind kind);

/// One event an agent declared. Views are valid during the sink call only.
struct AgentEvent {
  core::SimTime time;  ///< simulated time of the cycle
  AgentEventKind kind = AgentEventKind::kRoleChange;
  std::string_view agent;   ///< the robot's name
  std::string_view rule;    ///< the rule that declared it ("" if none)
  std::vector<Value> args;  ///< the arguments after the kind, as given
};
using EventSink = std::function<void(const AgentEvent&)>;

/// Hands a message built by (pb-broadcast ?m) to the radio (sim plugs in RobotRadio::broadcast).
/// The message is borrowed for the duration of the call.
using BroadcastFn = std::function<void(const google::protobuf::Message&)>;

/// A change of this robot's state for one lock (AgentConfig::locks): e.g. REQUESTED -> ACCEPTED
/// is a grant, REQUESTED -> REFUSED a refusal. `resource` is valid during the call only.
struct LockEvent {
  core::SimTime time;  ///< simulated time of the cycle (or the lock-request/-release call)
  std::string_view resource;
  LockState from = LockState::kNone;
  LockState to = LockState::kNone;
};
using LockListener = std::function<void(const LockEvent&)>;

/// Read-only configuration of one agent.
struct AgentConfig {
  std::string robot_name = "robot1";          ///< ?*ROBOT-NAME* (a symbol)
  int robot_number = 1;                       ///< ?*ROBOT-NUMBER*
  std::string team_name = "Carologistics";    ///< ?*TEAM-NAME* (a string)
  std::uint64_t seed = 1;                     ///< seeds CLIPS' (random)
  std::int64_t max_rules_per_cycle = 10'000;  ///< rule firings per cycle before the run is cut
  /// The work budget of one cycle (docs/clips.md, "Budgets"): CLIPS steps (periodic callbacks:
  /// about two per rule firing, one per iteration of while, loop-for-count, ...) and wall time.
  /// Past either, the running rule's actions stop, the host logs a runtime error naming the rule
  /// and its file:line, and the cycle ends; the next cycle goes on. The shipped agents stay far
  /// below both (measured: docs/clips.md); the wall time only cuts runaway work.
  std::int64_t max_steps_per_cycle = 1'000'000;
  double max_cycle_wall_s = 10.0;
  /// Deffunction and generic-function calls nested deeper than this stop the rule's actions the
  /// same way (a recursion without end would otherwise overflow the C stack). A level takes
  /// 0.5-1 KB of stack (measured: docs/clips.md, "Budgets").
  int max_call_depth = 2'000;
  /// The memory budget (docs/clips.md, "Budgets"): the bytes CLIPS may hold for this agent
  /// (facts, strings, multifields, rules; CLIPS' own count, EnvMemUsed). Checked at every step of
  /// the work budget: past it, the running rule's actions stop as above (while the agent holds
  /// more, every cycle stops at its first step). The shipped LLSF 2013 agent holds at most 2 MB.
  std::int64_t max_memory_bytes = 128LL << 20;
  /// The largest string (characters) and multifield (fields) that one call of str-cat, sym-cat,
  /// implode$, format, printout (what one call prints), create$, insert$, replace$, explode$ or
  /// replace-member$ may build (and log-* print); a call past either is a runtime error naming
  /// the function and the rule, and builds nothing.
  std::int64_t max_string_length = 1'000'000;
  std::int64_t max_multifield_length = 1'000'000;
  ConfigEntries config;  ///< asserted as confval facts after (reset)
  /// The sandbox (docs/security.md): files, I/O routers, load/save, dribble, system, exit, clear,
  /// reset and construct removal are unavailable to the agent's code. Turn it off only for a
  /// trusted local agent that needs files.
  bool sandbox = true;
  /// Runs the resource-lock protocol (docs/locks.md): lock facts, lock messages consumed, the
  /// master's announcements. Off by default, so that agents without locks stay silent.
  bool locks = false;
  LockConfig lock_config;  ///< timing and team size of the lock protocol (if `locks`)
  /// Fawkes' agent model (docs/fawkes.md): load_file() runs the entry file as Fawkes' clips-agent
  /// did (top-level commands, path-load, (reset), config-load, the ff-feature facts), (now) is
  /// (sec usec), confval facts come only from config-load, received messages only after
  /// pb-peer-enable. Off: llsfsim's own agent model (docs/clips.md).
  bool fawkes = false;
  /// With `fawkes`: the agent directory (Fawkes' clips-dirs). path-load, path-resolve and the
  /// entry file resolve relative to it; no file outside it can be read, none can be written.
  std::string agent_dir;

  /// Throws std::invalid_argument naming the bad field.
  void validate() const;
};

/// What the agent talks to; everything is borrowed and must outlive the host. All optional:
/// without a runner, (skill-call) fails; without a registry, (pb-create) fails; without a
/// broadcast function, (pb-broadcast) drops the message; without a sink, output is discarded.
struct AgentIo {
  SkillRunner* skills = nullptr;
  const comm::MessageRegistry* messages = nullptr;
  BroadcastFn broadcast;
  LogSink log;
  LockListener lock_events;  ///< every lock state change of this robot (with locks on)
  IssueSink issues;          ///< every runtime error and rule loop, as data (also logged)
  EventSink events;          ///< every (agent-event ...) the agent declares
  /// (motor-enable) / (motor-disable): switches the robot's motors (Fawkes' motor-switch).
  std::function<void(bool on)> motor;
  /// The robot's blackboard for a Fawkes-style agent's blackboard feature (docs/fawkes.md):
  /// the interfaces the host does not write itself are read, written and sent messages here.
  /// Without it, only the host's own (the pose, write_interface) exist.
  Blackboard* blackboard = nullptr;
  /// (pb-send ?client ?msg): a message to the stream server the agent connected to with
  /// (pb-connect host port) (the refbox: the only server of a game). Without it, pb-send drops.
  BroadcastFn send;
};

/// What one cycle did.
struct CycleResult {
  std::int64_t rules_fired = 0;
  bool limit_reached = false;    ///< max_rules_per_cycle fired and the agenda was not empty
  bool budget_exceeded = false;  ///< the cycle was stopped by its work budget (a runtime error)
  std::int64_t steps = 0;        ///< CLIPS steps the cycle took (its work budget's measure)
  int runtime_errors = 0;        ///< runtime errors in this cycle (also logged)
};

/// A fact copied out of the agent (tests, tools).
struct Fact {
  std::int64_t index = 0;
  std::string template_name;
  /// Slots in template order; an ordered fact (time 1 2) has one slot "" with a multifield.
  std::vector<std::pair<std::string, Value>> slots;
  /// The slot's value; throws std::out_of_range if the template has no such slot.
  const Value& slot(std::string_view name) const;
  /// The fields of an ordered fact (the multifield of slot "").
  const std::vector<Value>& fields() const { return slot("").items; }
};

/// One robot's agent. Usage: construct, load_file()/load_string() the agent, then cycle(now) at
/// the agent rate; feed set_pose() and receive() between cycles. Not copyable; movable. Not
/// thread-safe (one host per robot; different hosts may run in different threads).
class AgentHost {
 public:
  /// Creates the environment and loads the built-in code (clips/clp/*.clp).
  AgentHost(AgentConfig config, AgentIo io);
  ~AgentHost();
  AgentHost(AgentHost&&) noexcept;
  AgentHost& operator=(AgentHost&&) noexcept;
  AgentHost(const AgentHost&) = delete;
  AgentHost& operator=(const AgentHost&) = delete;

  /// Loads an agent file (read in C++, parsed from a string). Throws AgentLoadError
  /// ("path:line: ...") on bad code or if the file cannot be read. With AgentConfig::fawkes the
  /// file is the entry file (once): it starts the agent as Fawkes' clips-agent did
  /// (docs/fawkes.md) and runs it to quiescence; every load error of the files it path-loads on
  /// the way is in the AgentLoadError.
  void load_file(const std::string& path);
  /// Loads code from a string; `source_name` stands for the file name in error messages.
  void load_string(std::string_view code, std::string_view source_name);

  /// (reset): deffacts, confval facts, identity; called by the first cycle() if not before.
  /// Calling it again restarts the agent's facts (the rules stay).
  void start(core::SimTime now);
  /// One agent cycle at simulated time `now`: (time) fact, skill status updates, pose, received
  /// messages; run to quiescence (at most max_rules_per_cycle firings); clean-up. Runtime errors
  /// are logged with the rule's name and counted; the agent keeps going.
  CycleResult cycle(core::SimTime now);

  /// The robot's pose for the (pose (x) (y) (ori)) fact, updated at the next cycle if changed.
  void set_pose(const core::Pose2D& pose);
  /// Writes a blackboard interface of a Fawkes-style agent (docs/fawkes.md): the fields of
  /// interface `type` ("RobotinoLightInterface") with id `id` ("Light_State") by name, stamped
  /// with the time of the last cycle. (blackboard-read) asserts it once per write. The pose
  /// (set_pose) is written as Position3DInterface "Pose" by the host itself.
  void write_interface(std::string_view type, std::string_view id, InterfaceFields fields);
  /// A message received from peer `from` (name and id) at `at`; it becomes a protobuf-msg fact
  /// at the next cycle. The host takes ownership.
  void receive(std::unique_ptr<google::protobuf::Message> message, std::string_view from,
               int from_id, core::SimTime at);

  // ---- inspection (tests, tools; slow paths) ----
  /// Facts of a template (all facts if empty).
  std::vector<Fact> facts(std::string_view template_name = {}) const;
  /// Facts of a template whose slots equal the given values, e.g.
  /// find_facts("skill", {{"status", Value::symbol("FINAL")}}).
  std::vector<Fact> find_facts(
      std::string_view template_name,
      std::initializer_list<std::pair<std::string_view, Value>> where) const;
  /// Asserts a fact from text, e.g. "(machine (name M1))"; throws std::invalid_argument if CLIPS
  /// cannot parse it.
  void assert_fact(std::string_view fact);
  /// Evaluates an expression, e.g. "(now)" or "(+ 1 2)" (void on error).
  Value eval(std::string_view expression);

  // ---- tracing (docs/clips.md, "Tracing") ----
  /// Sends the events `options` selects to `sink` (called on the caller's thread, during
  /// cycle(), receive() and the other calls; it must not call back into this host except for
  /// the const inspection functions). An empty sink stops tracing; untraced, the host registers
  /// no hook with CLIPS.
  void set_trace(TraceOptions options, TraceSink sink);
  /// The fact with `index` as CLIPS prints it, "(state IDLE)"; "" if there is none.
  std::string fact_text(std::int64_t index) const;
  /// Every fact with an index >= `from_index` as (index, text), in fact-list order, which is
  /// index order (`out` is cleared first; cheap for the newest facts).
  void fact_texts(std::vector<std::pair<std::int64_t, std::string>>& out,
                  std::int64_t from_index = 0) const;

  /// The most CLIPS steps one cycle took so far (the measure of max_steps_per_cycle).
  std::int64_t max_cycle_steps() const;
  /// Runtime errors since construction.
  int runtime_errors() const;
  /// Cycles whose run was cut by max_rules_per_cycle.
  int limit_hits() const;
  /// Rule firings since construction.
  std::int64_t rules_fired() const;
  /// Protobuf messages alive in the pool (pb-create'd and not destroyed, received this cycle).
  int live_messages() const;
  const AgentConfig& config() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace llsf::clips
