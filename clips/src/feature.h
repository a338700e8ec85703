// SPDX-License-Identifier: MIT
// Features (not "features.h": that would shadow glibc's <features.h> on our include path):
// small units that each register their functions (define), find their templates
// (bind, after the built-in code clips/clp/*.clp is loaded) and assert or clean up facts around
// each run (Fawkes' ClipsFeature). AgentHost (agent.cpp) calls them in a fixed order.
#pragma once

#include <google/protobuf/message.h>

#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "environment.h"
#include "llsf/clips/agent.h"

namespace llsf::clips::detail {

/// Built-in CLIPS code, embedded at build time (builtin_clp.cpp, generated).
struct BuiltinCode {
  const char* name;  ///< "builtin/time.clp"
  const char* text;
};
extern const BuiltinCode kBuiltinCode[];
extern const int kBuiltinCodeCount;

/// State the host shares with its features.
struct HostState {
  AgentConfig config;
  AgentIo io;
  core::SimTime now;  ///< time of the current (or last) cycle

  /// Pose for the pose fact; `pose_dirty` until asserted.
  std::optional<core::Pose2D> pose;
  bool pose_dirty = false;

  /// Messages received since the last cycle.
  struct Received {
    std::unique_ptr<google::protobuf::Message> message;
    std::string from;
    int from_id = 0;
    core::SimTime at;
  };
  std::vector<Received> inbox;
  int live_messages = 0;  ///< maintained by the protobuf feature
  /// The blackboard of a Fawkes-style agent (type, id) -> the interface's data, written by the
  /// host (AgentHost::write_interface, the pose), read by (blackboard-read).
  struct InterfaceData {
    core::SimTime time;  ///< when it was written
    std::vector<std::pair<std::string, Value>> fields;
    std::uint64_t serial = 0;  ///< counts the writes (the reader asserts a fact per change)
  };
  std::map<std::pair<std::string, std::string>, InterfaceData> blackboard;
  /// A Fawkes-style agent broadcasts and receives only once it enabled its peer
  /// (pb-peer-enable / pb-peer-create); llsfsim's agents always do.
  bool peer_enabled = false;

  /// Emits one log line at `now` (set by the host).
  std::function<void(LogLevel, std::string_view)> log;
};

/// One feature; see the file comment for when each hook runs.
class Feature {
 public:
  virtual ~Feature() = default;
  /// Registers functions (before the built-in code is loaded, so that it may call them).
  virtual void define(Environment&) {}
  /// Looks up templates after the built-in code is loaded.
  virtual void bind(Environment&) {}
  /// After each (reset): facts of the reset are gone; assert start-up facts.
  virtual void after_reset(Environment&) {}
  /// Each cycle, before the run: assert what is new.
  virtual void before_run(Environment&) {}
  /// Each cycle, after the run: clean up.
  virtual void after_run(Environment&) {}
};

std::unique_ptr<Feature> make_log_feature(HostState& state);
std::unique_ptr<Feature> make_random_feature(HostState& state);
std::unique_ptr<Feature> make_robot_feature(HostState& state);
std::unique_ptr<Feature> make_time_feature(HostState& state);
std::unique_ptr<Feature> make_config_feature(HostState& state);
std::unique_ptr<Feature> make_skills_feature(HostState& state);
std::unique_ptr<Feature> make_protobuf_feature(HostState& state);
/// Always registered, inactive unless AgentConfig::locks (the host then skips locks.clp). Runs
/// before the protobuf feature: it takes the lock messages out of the inbox.
std::unique_ptr<Feature> make_locks_feature(HostState& state);
/// blackboard-open, blackboard-enable-time-read, blackboard-read (Fawkes-style agents).
std::unique_ptr<Feature> make_blackboard_feature(HostState& state);
/// ff-feature-request and the feature facts (Fawkes-style agents), motor-enable/-disable.
std::unique_ptr<Feature> make_fawkes_feature(HostState& state);
/// The features a Fawkes-style agent finds as (ff-feature X) facts and may request.
std::span<const std::string_view> fawkes_features();

/// Formats a value as printout does: symbols and strings bare, numbers as CLIPS prints them.
std::string print_form(const Value& v);

}  // namespace llsf::clips::detail
