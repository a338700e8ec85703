// SPDX-License-Identifier: MIT
// Mistakes in agent code that CLIPS loads without a word but that make a rule misbehave, found
// by reading the source: a rule condition that reads the clock where CLIPS never evaluates it
// again as time passes (docs/clips.md, "Where the (time) pattern goes"), and check_agent(), the
// static checks `llsfsim check` prints (docs/llsfsim.md, "llsfsim check"): skill calls against
// the skills, confval paths against the configuration, the lock switch against the lock facts.
#pragma once

#include <cstdint>
#include <optional>
#include <set>
#include <string>
#include <string_view>
#include <vector>

#include "llsf/clips/agent_files.h"
#include "llsf/clips/config_values.h"

namespace llsf::clips {

/// One finding in a source text: its 1-based line and what is wrong, for people.
struct SourceWarning {
  int line = 0;
  std::string message;
};

/// Finds rule conditions that read the time (`(now)`, `(now-sec-usec)`, or a deffunction that
/// calls one) where CLIPS
/// does not evaluate them again when time passes: a `(test ...)` with no `(time ...)` pattern
/// before it (a test is evaluated when the facts matched before it change), and a slot
/// constraint of a fact pattern (`(timer (until ?u&:(< ?u (now))))`: tested when that fact
/// changes) unless it joins a variable of an earlier pattern after a `(time ...)` pattern. Such a
/// rule fires late or never. Files are scanned in load order: a deffunction that reads the time
/// counts in the files after its own.
class TimeReadCheck {
 public:
  /// The findings in one file's code, in line order.
  std::vector<SourceWarning> scan(std::string_view code);

 private:
  /// The host's clock functions, then the deffunctions that call one.
  std::set<std::string, std::less<>> time_functions_ = {"now", "now-sec-usec"};
};

/// A skill the robot has, for check_agent().
struct SkillFacts {
  std::string name;
  /// The argument names its documentation declares (`@param`); empty: none declared, its calls'
  /// arguments are not compared.
  std::vector<std::string> params;
};

/// What check_agent() compares an agent's files with.
struct AgentCheckFacts {
  /// The robot's skills (their order decides between equally near names in a hint); nullopt:
  /// not known, skill calls are not checked.
  std::optional<std::vector<SkillFacts>> skills;
  /// The configuration the agent gets as confval facts (AgentConfig::config).
  std::vector<ConfigEntry> config;
  bool locks = false;  ///< the lock protocol is on (AgentConfig::locks)
  /// A Fawkes-style agent (AgentConfig::fawkes): /clips-agent/agent is the host's, not compared.
  bool fawkes = false;
  /// How findings name the configuration and the lock switch (a scenario's keys).
  std::string config_name = "robots.config";
  std::string locks_name = "robots.locks";
};

/// One finding of check_agent().
struct AgentFinding {
  enum class Kind : std::uint8_t {
    kTimeRead,         ///< a rule condition CLIPS does not evaluate again (TimeReadCheck)
    kUnknownSkill,     ///< `(skill-call NAME ...)` with a NAME the skills do not have
    kUnknownArgument,  ///< `(skill-call NAME ARG VALUE ...)` with an ARG the skill does not declare
    kConfvalNotRead,   ///< a configured path no agent file names
    kConfvalsDefault,  ///< the paths the agent names that the configuration leaves out (a note)
    kLocksUnused,      ///< the lock protocol on, but the agent uses no lock facts
  };
  Kind kind = Kind::kTimeRead;
  bool note = false;  ///< worth knowing rather than likely a mistake
  /// The agent file; for a finding about the configuration its name (config_name); "" for none.
  std::string file;
  int line = 0;         ///< 1-based line in `file`; 0 for none
  std::string message;  ///< what is wrong, for people
  /// "file:line: message", "file: message" or "message".
  std::string text() const;
};

/// The static checks of an agent's `files` (in load order: read_agent_sources(),
/// read_fawkes_sources()) against `facts`, as `llsfsim check` prints them: per file in order its
/// time reads (TimeReadCheck) then its skill calls with an unknown skill or argument; then the
/// configured paths no file names, the paths left at their defaults (a note), the lock switch.
/// Comments and strings are not code: a skill call or lock fact there does not count; a confval
/// path is a string whose whole text is "/clips-agent/..." (a trailing / names a prefix).
std::vector<AgentFinding> check_agent(const std::vector<SourceFile>& files,
                                      const AgentCheckFacts& facts);

}  // namespace llsf::clips
