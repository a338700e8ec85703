// SPDX-License-Identifier: MIT
// AgentBrain: a robot's whole brain in the game loop -- a CLIPS agent (clips::AgentHost) on top
// of the robot's skill engine (SkillBrain). The agent cycles at the game's agent rate with the
// robot's pose estimate and the messages its radio received; its skill-calls run on the skill
// engine; its pb-broadcasts go out on the robot's radio.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "llsf/clips/agent.h"
#include "llsf/clips/config_values.h"
#include "llsf/clips/skill_runner.h"
#include "llsf/lua/skill_engine.h"
#include "llsf/sim/game.h"
#include "llsf/sim/skill_brain.h"

namespace llsf::sim {

/// What an agent brain is built from.
struct AgentBrainConfig {
  /// CLIPS files, loaded in order (a load error throws clips::AgentLoadError, file:line); a
  /// directory stands for its *.clp files in name order (e.g. clips/agents/llsf2013).
  std::vector<std::string> agent_files;
  /// confval facts (e.g. clips::config_from_node(yaml, "/clips-agent")).
  clips::ConfigEntries config;
  /// The skill engine (empty skill_dirs: the library of the game's skill level).
  lua::SkillEngineConfig skills;
  /// Rule firings per agent cycle before the run is cut.
  std::int64_t max_rules_per_cycle = 10'000;
  /// Runaway cycles (cut by the firing limit or stopped by the work budget) after which the
  /// agent is halted for the rest of the game: it cycles no more and its robot stops
  /// (docs/clips.md, "Budgets"). A runaway agent otherwise costs a budget's worth of CPU at
  /// every cycle. 0: never halted.
  int max_runaway_cycles = 10;
  /// Team name for ?*TEAM-NAME* (empty: the game's team or the refbox's).
  std::string team;
  /// The lock protocol over the radio (clips::AgentConfig::locks, docs/locks.md); also sets the
  /// confval /clips-agent/use-locks TRUE for the team agents.
  bool locks = false;
  /// The agents' sandbox (clips::AgentConfig::sandbox, docs/security.md).
  bool sandbox = true;
  /// Fawkes' agent model (clips::AgentConfig::fawkes, docs/fawkes.md): `agent_files` is the one
  /// entry file, inside `agent_dir` (Fawkes' clips-dirs), which path-load reads from.
  bool fawkes = false;
  std::string agent_dir;
  /// Game time of the agent's first cycle (before it, the agent neither cycles nor hears the
  /// radio): robots whose software was switched on one after the other, as the 2013 team's
  /// were, so that their agents' lock-master elections do not start in the same tick.
  core::SimTime start;
  /// Robots that take part in the lock protocol (the majority is counted of these); 0: every
  /// robot of the game.
  int lock_team_size = 0;
};

/// What an agent reports as data besides its log (clips::AgentIo::issues and ::events): its
/// runtime errors and rule loops, and the events it declares with (agent-event ...).
struct AgentReports {
  clips::IssueSink issues;
  clips::EventSink events;
};

/// `entries` with every directory replaced by its *.clp files in name order.
std::vector<std::string> agent_files(const std::vector<std::string>& entries);

/// Robot `index`'s CLIPS agent with the skill engine it drives (its own, not plugged: the agent
/// brain cycles it). Its owner plugs it into the game (GameDriver::plug_agent, or
/// Game::set_brain) and unplugs it before destroying it; the game must outlive it.
class AgentBrain final : public RobotBrain, private clips::SkillRunner {
 public:
  /// Loads the agent files; throws clips::AgentLoadError for bad agent code and
  /// core::ConfigError for a bad skill-engine config. `log` receives the agent's output,
  /// `locks` every change of the robot's lock states (with locks on), `reports` its issues and
  /// events as data.
  AgentBrain(Game& game, int index, AgentBrainConfig config, clips::LogSink log = {},
             clips::LockListener locks = {}, AgentReports reports = {});
  ~AgentBrain() override;
  AgentBrain(const AgentBrain&) = delete;
  AgentBrain& operator=(const AgentBrain&) = delete;

  clips::AgentHost& agent() { return *agent_; }
  const clips::AgentHost& agent() const { return *agent_; }
  /// Runtime errors of this robot's agent since the game started (over reloads).
  int runtime_errors() const { return errors_before_reload_ + agent_->runtime_errors(); }

  /// Why the agent was halted (AgentBrainConfig::max_runaway_cycles).
  struct Halt {
    core::SimTime time;    ///< the cycle that halted it
    int rule_loops = 0;    ///< runaway cycles cut by the rule firing limit
    int budget_stops = 0;  ///< runaway cycles stopped by the work budget
    std::string text;      ///< for people: what happened and what it means
  };
  /// Set once the agent is halted (until a reload brings new files).
  const std::optional<Halt>& halt() const { return halt_; }

  /// What reload_if_changed() did.
  struct Reload {
    bool changed = false;   ///< an agent file changed, appeared or disappeared
    bool reloaded = false;  ///< the new files loaded: the agent restarted with them
    std::string text;       ///< "agent reloaded (FILE changed)" or the load error (old agent kept)
  };
  /// Live editing (paced runs): if an agent file changed since it was loaded (modification time
  /// or size; a directory's *.clp files are listed anew), loads the files into a new agent. If
  /// they load, the robot's agent restarts with them at its next cycle (facts, locks and the
  /// running skill are dropped; rules and confvals are the new files'); if not, the old agent
  /// goes on and `text` has the error (file:line). Never called in unpaced games: a game's
  /// result must not depend on the file system's timing.
  Reload reload_if_changed();
  /// Traces the agent (clips::AgentHost::set_trace), also after a reload: the new agent gets
  /// the same trace.
  void set_trace(clips::TraceOptions options, clips::TraceSink sink);
  SkillBrain& skills() { return *skills_; }
  const SkillBrain& skills() const { return *skills_; }

  void on_skill_cycle(lua::RobotApi& robot) override;
  void on_agent_cycle(lua::RobotApi& robot, RobotRadio& radio) override;

 private:
  // clips::SkillRunner over the skill engine.
  void exec(std::string_view skill_string) override;
  void stop() override;
  clips::SkillStatus status() const override;
  std::string error() const override;
  std::string skill_string() const override;
  std::string result() const override;

  // A new host with the agent files loaded (throws clips::AgentLoadError).
  std::unique_ptr<clips::AgentHost> make_host() const;
  // The agent files (directories expanded) with their modification time and size.
  struct FileStamp {
    std::string path;
    std::int64_t mtime_ns = 0;
    std::uintmax_t size = 0;
    bool operator==(const FileStamp&) const = default;
  };
  std::vector<FileStamp> stamp_files() const;

  std::unique_ptr<SkillBrain> skills_;
  // A Fawkes-style agent's blackboard: the skill engine's interface objects (agent_brain.cpp).
  std::unique_ptr<clips::Blackboard> blackboard_;
  std::vector<std::string> file_entries_;  // as configured (files and directories)
  bool locks_ = false;
  clips::AgentConfig host_config_;
  clips::AgentIo host_io_;
  std::vector<FileStamp> loaded_;  // the files as last loaded
  int errors_before_reload_ = 0;
  int max_runaway_cycles_ = 10;
  core::SimTime start_;  // AgentBrainConfig::start
  int rule_loops_ = 0;   // runaway cycles of the current agent
  int budget_stops_ = 0;
  std::optional<Halt> halt_;
  // A Fawkes-style agent's RobotinoLightInterface "Light_State": since when no device is seen.
  bool light_seen_ = false;
  core::SimTime light_lost_since_;
  /// RobotinoLightInterface "Light_State" as last written (its values replaced at each cycle).
  std::vector<std::pair<std::string, clips::Value>> light_fields_;
  clips::TraceOptions trace_options_;  // set_trace(), for reloaded agents
  clips::TraceSink trace_sink_;
  std::unique_ptr<clips::AgentHost> agent_;
};

}  // namespace llsf::sim
