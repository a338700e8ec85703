// SPDX-License-Identifier: MIT
// Tracing an agent: its rule firings with the facts that matched, fact assertions and
// retractions, the messages it receives and broadcasts, its log lines (printout, log-*, CLIPS'
// own (watch ...) output), each with the simulated time of the cycle. See docs/clips.md,
// "Tracing". Without a trace installed, the host registers no hook with CLIPS.
#pragma once

#include <cstdint>
#include <functional>
#include <span>
#include <string>
#include <string_view>

#include "llsf/core/sim_time.h"

namespace llsf::clips {

class AgentHost;
enum class LogLevel : std::uint8_t;

/// One event of an agent's trace. Views and spans are valid during the sink call only.
struct TraceEvent {
  enum class Kind : std::uint8_t {
    kFire,     ///< a rule fires: `name` the rule, `facts` the indices of the facts that matched
    kAssert,   ///< a fact was asserted: `fact` its index, `text` as CLIPS prints it
    kRetract,  ///< a fact is retracted: `fact`, `text` (modify is a retract and an assert)
    kMsgIn,    ///< a message arrived: `name` its type, `peer` the sender, `text` its fields
    kMsgOut,   ///< the agent broadcast a message: `name` its type, `text` its fields
    kLog,      ///< a log line: `level`, `text` (printout, log-*, (watch ...) output at debug)
    kCycleEnd  ///< a cycle ended (after its clean-up): recorders take their per-cycle lines
  };
  Kind kind = Kind::kLog;
  core::SimTime time;      ///< simulated time of the cycle
  std::string_view agent;  ///< the robot's name
  std::string_view name;
  std::int64_t fact = -1;
  std::span<const std::int64_t> facts;
  std::string_view text;
  std::string_view peer;
  LogLevel level{};
  /// The traced host (borrowed), e.g. for AgentHost::fact_text() of a matched fact: at a kFire
  /// event every matched fact still exists.
  const AgentHost* host = nullptr;
};
using TraceSink = std::function<void(const TraceEvent&)>;

/// What a trace observes; kCycleEnd is always sent.
struct TraceOptions {
  bool rules = false;     ///< kFire
  bool facts = false;     ///< kAssert, kRetract
  bool messages = false;  ///< kMsgIn, kMsgOut
  bool log = false;       ///< kLog, all levels (the run's log sink sees info and above only)
  /// kAssert and kRetract events carry the fact's text; false: an empty text (a recorder that
  /// takes the texts of the facts still there at the end of the cycle saves the printing).
  bool fact_texts = true;
};

/// "[  12.30] robot1 " : the simulated time in seconds (%7.2f) and the robot, the prefix of every
/// trace line.
std::string trace_prefix(core::SimTime time, std::string_view robot);

/// The event as one trace line (docs/clips.md, "Tracing"), e.g.
/// "[  12.30] robot1 FIRE production-start  f-3 (machine (name M1)), f-17 (time 12 300000)",
/// "[  12.30] robot1 ==> f-18 (state IDLE)", "[  12.30] robot1 msg <- robot2 LockMessage {...}";
/// "" for kCycleEnd. A kFire line shows the matched facts' text (looked up in `host`). Addresses
/// are stripped (strip_addresses): the same game gives the same trace.
std::string trace_line(const TraceEvent& event);

/// Replaces CLIPS' "<Pointer-C-0x55d0c2a1e2b0>" (an external address, e.g. a protobuf message
/// kept in a fact) by "<Pointer-C>": addresses differ from run to run, traces and recordings
/// must not.
void strip_addresses(std::string& text);

}  // namespace llsf::clips
