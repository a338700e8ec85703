// SPDX-License-Identifier: MIT
// Recordings of games for replay (the viewer) and analysis: the poses of every robot (true and
// believed) and puck at 10 Hz plus every event -- refbox phases and points, lamp changes, RFID,
// collisions, skill status changes, agent decisions, lock grants and refusals, radio drops; for
// skills also their states, log lines, the colour camera's sightings, the navigator's refusals
// and failures, and an exercise's verdict -- in
// gzip-compressed JSON lines, versioned. docs/recording.md documents the format.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "llsf/clips/agent.h"
#include "llsf/core/sim_time.h"
#include "llsf/core/version.h"
#include "llsf/sim/game.h"
#include "llsf/sim/skill_brain.h"

namespace llsf::study {

struct RunIssue;  // runner.h

/// Version of the recording format written by Recorder.
inline constexpr int kRecordingVersion = 1;

/// Identity of a recorded game (the header line).
struct RecordingInfo {
  std::string scenario;
  std::string variant;
  std::uint64_t seed = 0;
  std::string llsfsim_version{core::kVersion};
};

/// Receives every line of a recording as it is written (without the newline), e.g. for a live
/// viewer. The view is valid during the call only.
using LineSink = std::function<void(std::string_view line)>;

/// Writes a recording while a game runs. Call frame() after every tick (e.g. from
/// RunHooks::tick) and skill() from the skill brains' listeners; close() (or the destructor)
/// finishes the file. Throws std::runtime_error if the file cannot be written.
class Recorder {
 public:
  /// `pose_rate_hz`: pose frames per simulated second (default 10). `path` empty: no file,
  /// the lines go to `sink` only; with both, to both.
  Recorder(const std::string& path, const sim::Game& game, const RecordingInfo& info,
           double pose_rate_hz = 10.0, LineSink sink = {});
  ~Recorder();
  Recorder(const Recorder&) = delete;
  Recorder& operator=(const Recorder&) = delete;

  /// Takes the events of the last tick, and a pose frame when one is due.
  void frame(const sim::Game& game);
  /// A skill status change of a robot.
  void skill(const sim::SkillStatusChange& change);
  /// A line of agent output (its decisions: (log-info ...), warnings, errors).
  void agent(const clips::LogRecord& record);
  /// A change of a robot's lock state (grants, refusals, releases).
  void lock(const std::string& robot, const clips::LockEvent& event);
  /// An event of an agent's trace (clips::AgentHost::set_trace with rules and facts on): the
  /// agent's facts and rule firings become `facts` snapshots (at its first cycle and every
  /// kFactSnapshotPeriod), `fact` deltas and `rules` lines, one of each per cycle at most
  /// (docs/recording.md); kLog events at debug level (e.g. (watch facts) output) become `agent`
  /// lines. Other events are ignored. `robot` is the robot's index in the game (0-based).
  void agent_trace(int robot, const clips::TraceEvent& event);
  /// Simulated time between two `facts` snapshots of one robot.
  static constexpr core::SimTime kFactSnapshotPeriod = core::SimTime::from_sec(30);
  /// A change of the state of a robot's skill (sim::SkillBrain::set_state_listener):
  /// {"e":"skill_state","robot":..,"skill":..,"from":..,"to":..}.
  void skill_state(const sim::SkillStateChange& change);
  /// A line a robot's skill logged (print, printf, print_warn, ...; lua::SkillEngine's log sink):
  /// {"e":"log","robot":..,"level":..,"text":..}.
  void log(core::SimTime t, const std::string& robot, lua::LogLevel level, std::string_view text);
  /// The judged outcome of a game (an exercise): {"e":"verdict","result":..,"score":..,"why":..}
  /// (`why` only when not empty). Write it before close().
  void verdict(core::SimTime t, const std::string& result, const std::string& score,
               const std::string& why = {});
  /// A free-form event from an agent or tool ({"t":..,"e":"note","robot":..,"text":..}).
  void note(core::SimTime t, const std::string& robot, const std::string& text);
  /// An issue of the run (runner.h, RunIssue: a runtime error, a rule loop, a halted agent, a
  /// skill failure, ...) noticed at `t` (its own time, if earlier, is `time_s`).
  void issue(core::SimTime t, const RunIssue& issue);
  /// Flushes and closes the file (idempotent).
  void close();
  /// Lines written so far.
  std::int64_t lines() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// The file name of a game's recording: "<scenario>[-<variant>]-seed<N>.jsonl.gz", every
/// character other than letters, digits, '.', '_' and '-' replaced by '_'
/// (e.g. "auction-vs-roles-agent_auction-seed3.jsonl.gz").
std::string recording_file_name(const std::string& scenario, const std::string& variant,
                                std::uint64_t seed);

/// One parsed line of a recording (tests, tools): its time, its kind ("header", "frame", or the
/// event name) and the raw JSON text.
struct RecordingLine {
  double t = 0.0;
  std::string kind;
  std::string json;
};

/// Reads a recording (gzip or plain). Throws std::runtime_error naming the file and line for a
/// missing file, a corrupt stream, a line that is not a JSON object, or an unknown version.
std::vector<RecordingLine> read_recording(const std::string& path);

}  // namespace llsf::study
