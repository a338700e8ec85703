// SPDX-License-Identifier: MIT
// The 2013 refbox's time base on the wire: Unix time. Inside a game every time is simulated
// time; the served sockets (llsfsim run --refbox-sockets) map it to the wall clock at the game's
// start, so that 2013 tools read clocks as they would from the real refbox.
#pragma once

#include <cstdint>

namespace google::protobuf {
class Message;
}

namespace llsf::refbox {

/// The mapping between simulated time and the 2013 refbox's clock on the wire (Unix time):
/// wire ns = simulated ns + offset_ns. Set once when a game is served (the wall clock at its
/// start minus the simulated time then); never enters the game.
struct WireClock {
  std::int64_t offset_ns = 0;
};

/// Rewrites the absolute times of `msg` from simulated time to wire time: every llsf_msgs.Time
/// field at any depth (BeaconSignal.time, RobotInfo's last_seen, every Pose2D.timestamp, ...)
/// except GameState.game_time, which is phase-relative on the wire as in the 2013 refbox, and
/// llsf_log_msgs.LogMessage's ts_sec/ts_nsec. Other messages pass unchanged. Saturates at the
/// int64 range instead of overflowing; a Time whose nsec is outside [0, 1e9) is shifted by
/// whole seconds only.
void to_wire_time(google::protobuf::Message& msg, const WireClock& clock);
/// The reverse of to_wire_time(), for messages that came from the wire.
void from_wire_time(google::protobuf::Message& msg, const WireClock& clock);

}  // namespace llsf::refbox
