// SPDX-License-Identifier: MIT
// The skill engine: one sandboxed Lua 5.4 interpreter per robot running Fawkes-style skills
// (SkillHSM state machines) and the skill strings an agent sends (`goto_place{place="M1"}`).
#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "llsf/core/config.h"
#include "llsf/core/sim_time.h"
#include "llsf/lua/robot_api.h"

namespace llsf::lua {

/// Status of a skill string or of one skill (the Fawkes values S_INACTIVE..S_FAILED).
enum class SkillStatus : std::uint8_t { kInactive = 0, kFinal = 1, kRunning = 2, kFailed = 3 };

/// "INACTIVE", "FINAL", "RUNNING" or "FAILED".
const char* to_string(SkillStatus status);

/// Why a skill string failed, as data (docs/skills.md, "Failure reasons"): a reader of outcomes
/// takes it from here, never from the error text, whose wording may change.
enum class FailReason : std::uint8_t {
  kNone,          ///< it did not fail
  kFailed,        ///< a skill ended FAILED for its own reasons (fsm.error, execute's S_FAILED)
  kAborted,       ///< declared by the skill (fsm.reason = "aborted"): what it waited for was
                  ///< aborted (the navigator's goal)
  kNotFound,      ///< declared by the skill (fsm.reason = "not-found"): nothing where it looked
                  ///< (get_s0: no puck in the input storage)
  kUnknownSkill,  ///< the string (or a skill it calls) names a skill the library does not have
  kBadString,     ///< the skill string does not compile
  kError,         ///< a Lua error in a skill or the string, or a skill that did not load
  kBudget,        ///< the instruction, wall-time or memory budget stopped it
};

/// "none", "failed", "aborted", "not-found", "unknown-skill", "bad-string", "error", "budget".
const char* to_string(FailReason reason);

/// Severity of a line a skill logs (print_debug, print/print_info, print_warn, print_error).
enum class LogLevel : std::uint8_t { kDebug = 0, kInfo = 1, kWarn = 2, kError = 3 };

/// Read-only settings of a skill engine.
struct SkillEngineConfig {
  /// Directories whose `*.lua` files (not recursive, `init.lua` excluded) are skills; a skill of
  /// a later directory replaces one of the same name in an earlier one.
  std::vector<std::string> skill_dirs;
  /// Directories besides `skill_dirs` where `require("name")` finds Lua helper modules
  /// (`name.lua`, `a.b` as `a/b.lua`; files that are not skills, e.g. a team's tf_module.lua).
  /// `require` searches `skill_dirs` first, then these; it reads only files inside them.
  std::vector<std::string> module_dirs;
  /// Fawkes' cfg directories: where `fawkes.load_yaml_navgraph("navgraph-llsf.yaml")` finds
  /// navgraph files (read-only, only files inside them).
  std::vector<std::string> cfg_dirs;
  /// Fawkes configuration values skills read with `config:get_float("/skills/x/y")` etc.: path
  /// ("/skills/x/y") -> value as written in YAML ("0.05", "true", "text").
  std::map<std::string, std::string> fawkes_config;
  /// Rate at which `sim/` calls cycle(), in simulated Hz (the engine itself never waits).
  double rate_hz = 30.0;
  /// Lua VM instructions one cycle (or loading one file) may execute, counted in steps of 1000,
  /// plus the work library functions charge (docs/skills.md, "Sandbox"); beyond, the skill fails.
  std::int64_t instruction_budget = 1'000'000;
  /// Heap limit of the interpreter in bytes; allocations beyond fail with "not enough memory".
  /// Also the largest string string.rep may build.
  std::int64_t memory_limit_bytes = 64LL << 20;
  /// Bytes one cycle (or loading one file) may allocate in all (freed memory counts too): bounds
  /// the time spent copying big strings, e.g. `s .. s` or `s:upper()` in a loop.
  std::int64_t allocation_budget_bytes = 256LL << 20;
  /// Wall-clock seconds one cycle (or loading one file) may take, checked every 1000 VM
  /// instructions: bounds work inside one instruction that no count sees (comparing two long
  /// strings, `==` on 15 MB strings in a loop). Only a runaway skill reaches it; a game that
  /// reaches it is no longer deterministic, as with the agents' wall budget.
  double max_cycle_wall_s = 10.0;
  /// Reload skill files that changed (mtime or size) when a new skill string is executed.
  bool hot_reload = true;
  /// Seed of `math.random` inside the interpreter (e.g. from rng.stream("lua/robot1")).
  std::uint64_t random_seed = 0;
  /// The robot profile, as skills see it in the global table `profile` (`profile.name`,
  /// `profile.stuck_detection`): set by sim's robot profiles (docs/profiles.md), not a YAML key.
  std::string profile = "ideal";
  /// Whether skills give up when the robot makes no progress (their stall checks and timeouts).
  bool stuck_detection = true;
  /// How the library's skills move at machines (`profile.motions`): "llsfsim" (their own moves)
  /// or "carologistics-2013" (the team's 2013 skills' moves: turn to a puck before taking it,
  /// leave a recycler and a consumed puck's machine as the team did; docs/profiles.md). Set by
  /// the robot profile, not a YAML key.
  std::string motions = "llsfsim";
  /// A skill file's real path (as found in `skill_dirs`, e.g. "/tmp/llsfex-1-1/s.lua") -> the
  /// path every message, warning and traceback of that file shows instead (e.g. the
  /// participant's "my_skill.lua" of which the file is a copy). Files not listed show their real
  /// path (paths Lua shortens, "...tail", are written out in full). Not a YAML key.
  std::map<std::string, std::string> display_paths;

  /// Throws core::ConfigError naming the bad field.
  void validate() const;
  /// Reads `skill_dirs`, `rate_hz`, `instruction_budget`, `memory_limit_bytes`,
  /// `allocation_budget_bytes`, `max_cycle_wall_s`, `hot_reload`, `random_seed` from a map node
  /// (unknown keys are errors). Relative dirs are taken relative to `base_dir` (e.g. the scenario
  /// file's directory); with no `base_dir` they stay as written (relative to the working
  /// directory).
  static SkillEngineConfig from_config(const core::ConfigNode& node,
                                       const std::string& base_dir = {});
};

/// Outcome of exec(): `ok`, or the reason the skill string was refused.
struct ExecResult {
  bool ok = false;
  std::string error;
  explicit operator bool() const { return ok; }
};

/// One field of a blackboard interface skills wrote (docs/fawkes.md, "The blackboard in skills").
struct InterfaceField {
  enum class Kind : std::uint8_t { kSymbol, kString, kInteger, kFloat, kBool };
  std::string name;
  Kind kind = Kind::kSymbol;
  bool array = false;              ///< an array field: one element per entry below
  std::vector<std::string> texts;  ///< kSymbol, kString
  std::vector<double> numbers;     ///< kInteger, kFloat, kBool (0 or 1)
};

/// A blackboard interface skills wrote with Fawkes' API (`set_field(...)`, `write()`), e.g. the
/// team's RobotinoLightInterface "Light determined".
struct WrittenInterface {
  std::string type;
  std::string id;
  std::int64_t serial = 0;             ///< counts the cycles in which skills wrote it
  std::vector<InterfaceField> fields;  ///< every field, by name
};

/// One blackboard interface as the robot's agent reads it (SkillEngine::read_interface).
struct InterfaceSnapshot {
  bool known = false;         ///< the type is one of Fawkes' the engine offers (docs/fawkes.md)
  bool has_writer = false;    ///< something writes it (Fawkes' has_writer())
  bool robot_writer = false;  ///< llsfsim's sensors or actuators write it (at every time stamp)
  std::optional<core::SimTime> written;  ///< when its data were last written (none: never)
  std::vector<InterfaceField> fields;    ///< every field, by name
  std::string error;                     ///< why not, if !known
};

/// What the engine knows about one skill file.
struct SkillInfo {
  std::string name;
  std::string path;
  std::string documentation;
  std::vector<std::string> depends_skills;
  std::string load_error;  ///< empty if the skill loaded ("file:line: ..." otherwise)
};

/// One robot's skill engine. Owns its Lua interpreter and borrows `robot` (which must outlive it).
/// Not thread-safe: one thread drives an engine; different engines are independent. Movable, not
/// copyable. Errors in skill files and skill strings never throw: they show up as load errors,
/// exec() errors or a FAILED status with the error text.
class SkillEngine {
 public:
  /// Loads every skill of `cfg.skill_dirs`. Throws core::ConfigError for a bad config or a
  /// missing directory; a broken skill file is recorded (load_errors()) and fails when called.
  SkillEngine(const SkillEngineConfig& cfg, RobotApi& robot);
  ~SkillEngine();
  SkillEngine(SkillEngine&&) noexcept;
  SkillEngine& operator=(SkillEngine&&) noexcept;
  SkillEngine(const SkillEngine&) = delete;
  SkillEngine& operator=(const SkillEngine&) = delete;

  /// Aborts the running skill string (exit hooks run), reloads changed skill files (hot reload)
  /// and compiles `skill_string`; it runs from the next cycle(). A syntax error refuses the string
  /// (status FAILED, error() set).
  ExecResult exec(std::string_view skill_string);
  /// Aborts the running skill string and stops the robot (navigator and motor); status INACTIVE.
  void stop();
  /// Runs the skill string once (all skills it calls take one step) and returns the status. Does
  /// nothing unless RUNNING; when the string ends (FINAL/FAILED) its skills are reset.
  SkillStatus cycle();

  /// Status of the current (or last) skill string.
  SkillStatus status() const;
  /// Why the skill string failed ("skill: STATE: file:line: ..."); empty unless FAILED.
  const std::string& error() const;
  /// Why the skill string failed, as a reason code (that of its first failed skill); kNone
  /// unless FAILED.
  FailReason fail_reason() const;
  /// What the string's skills reported when it ended (FINAL or FAILED): the `fsm.result` of
  /// each skill it called that set one, joined by "; " (e.g. "WAITING", "R:ON Y:OFF G:BLINK");
  /// empty while RUNNING or if none did.
  const std::string& result() const;
  /// The current (or last) skill string.
  const std::string& skill_string() const;
  /// Simulated period between cycles (1 / rate_hz).
  core::SimTime cycle_period() const;

  /// Status of one skill in the current string (also sub-skills); kInactive for unknown names.
  SkillStatus skill_status(std::string_view skill) const;
  /// A skill's error text (empty unless it failed).
  std::string skill_error(std::string_view skill) const;
  /// The state a skill's state machine is in ("" if inactive or not an FSM skill).
  std::string skill_state(std::string_view skill) const;
  /// The states a skill's last step went through, first to last ("GO", "NEXT", "GO"), and that
  /// step's number (it counts the skill's steps; the same number: no step since).
  struct StatePath {
    std::vector<std::string> states;  ///< empty if the step stayed in its state
    std::int64_t step = 0;
    /// With `with_via`: what took the step from states[i] to states[i + 1], e.g.
    /// `{"START", "DRIVE", cond=true} at skill.lua:19` or `its sub-skills ended FINAL
    /// (final_to)` (paths as the engine loaded the files).
    std::vector<std::string> via;
  };
  StatePath skill_state_path(std::string_view skill, bool with_via = false) const;
  /// Why a running state-machine skill has not ended (for a report when time is up): "in state
  /// CHECK since 14.91 s, waiting for {"CHECK", "FINAL", cond="vars.arived"} (skill.lua:20);
  /// vars.arived is never set (did you mean vars.arrived?)"; "" if it is not running.
  std::string skill_wait(std::string_view skill) const;

  /// The blackboard interfaces skills wrote since the last call (each once, in writing order),
  /// as Fawkes' skiller wrote its writing interfaces after every loop: for the agent's
  /// blackboard (sim's AgentBrain forwards them to a Fawkes-style agent).
  std::vector<WrittenInterface> written_interfaces();
  /// The agent's side of the same blackboard (a Fawkes-style agent's blackboard feature,
  /// docs/fawkes.md): interface (type, id) as the skills' objects hold it, read now.
  InterfaceSnapshot read_interface(std::string_view type, std::string_view id);
  /// Changes whenever skills or the agent write an interface or send a message (never 0): an
  /// interface no sensor writes (InterfaceSnapshot::robot_writer false) is unchanged as long as
  /// this is.
  std::int64_t blackboard_version() const;
  /// Writes fields of interface (type, id), as a writer's set_field(...) and write() do (the
  /// skills read them); "" or why not (an unknown type or field).
  std::string write_interface(std::string_view type, std::string_view id,
                              const std::vector<InterfaceField>& fields);
  /// Sends message `message` ("CartesianGotoMessage") with `fields` to interface (type, id), as
  /// msgq_enqueue_copy does; the message id, or 0 with `error` set.
  std::int64_t send_interface_message(std::string_view type, std::string_view id,
                                      std::string_view message,
                                      const std::vector<InterfaceField>& fields,
                                      std::string& error);

  /// Every skill file found, in name order.
  std::vector<SkillInfo> skills() const;
  /// "file:line: ..." of every skill that failed to load (syntax, declarations, dependencies).
  std::vector<std::string> load_errors() const;

  /// Rebuilds the interpreter from the skill files now (aborting a running string).
  void reload();
  /// Number of times the skill files were loaded (1 after construction).
  int load_count() const;

  /// Receives the lines skills log; without a sink they are dropped.
  void set_log_sink(std::function<void(LogLevel, std::string_view)> sink);

  struct Impl;

 private:
  std::unique_ptr<Impl> impl_;
};

}  // namespace llsf::lua
