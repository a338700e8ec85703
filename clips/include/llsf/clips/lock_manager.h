// SPDX-License-Identifier: MIT
// LockManager: one robot's side of the master/slave resource-lock protocol (fawkes-conventions
// §3.3) over llsf_agent_msgs LockMessage / LockMasterAnnounce / LockStatus, as a pure state
// machine in simulated time (no CLIPS, no radio). Safe under loss, duplicates, reordering,
// outages and split masters: at no time do two robots hold one resource. See docs/locks.md for
// the protocol, the timing and the safety argument.
#pragma once

#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "llsf/core/geometry.h"
#include "llsf/core/rng.h"
#include "llsf/core/sim_time.h"

namespace google::protobuf {
class Message;
}

namespace llsf::clips {

/// Timing and quorum of the lock protocol. Plain aggregate; validate() checks the relations the
/// safety argument needs (docs/locks.md, "Timing").
struct LockConfig {
  /// Every robot broadcasts LockMasterAnnounce{its master} this often; the master also its
  /// LockStatus (the confirmations that keep leases alive).
  core::SimTime announce_period = core::SimTime::from_ms(500);
  /// A master not heard announcing itself for this long is given up.
  core::SimTime master_timeout = core::SimTime::from_sec(2);
  /// GET and RELEASE are resent this often until answered.
  core::SimTime resend_period = core::SimTime::from_sec(1);
  /// The master drops the locks of a robot it has not heard from for this long (> lease).
  core::SimTime lost_timeout = core::SimTime::from_sec(5);
  /// A holder believes it holds a resource only while the master confirmed it within this time.
  core::SimTime lease = core::SimTime::from_sec(3);
  /// Upper bound on the time from a step() that sends a message to the receive() of a copy
  /// (radio delay + the receiver's polling). Safety assumes it; larger delays are unsafe.
  core::SimTime max_delay = core::SimTime::from_ms(250);
  /// After announcing X as master, a robot announces no other master for this long (its
  /// endorsement of X is a promise; a master counts it for endorse_hold - max_delay).
  core::SimTime endorse_hold = core::SimTime::from_sec(3);
  /// Upper bound of the seeded random back-off before a robot may claim mastership.
  core::SimTime backoff_max = core::SimTime::from_sec(2);
  /// A release is sent only once the robot is this far (m) from where release() was called.
  double release_distance_m = 0.5;
  /// Number of robots in the team (with locks). A master needs the endorsement of a majority
  /// (team_size / 2 + 1, itself included) to grant or confirm anything.
  int team_size = 3;

  /// Throws std::invalid_argument naming the first bad field.
  void validate() const;
};

/// This robot's view of one resource.
enum class LockState : std::uint8_t {
  kNone,       ///< not requested, or released (RELEASE_RVCD received)
  kRequested,  ///< GET pending
  kAccepted,   ///< held: the master confirmed it within the lease
  kRefused,    ///< refused by the master, or the lease ran out; request() again to retry
  kReleasing,  ///< release() called: RELEASE waits for 0.5 m, then is resent until RELEASE_RVCD
};
/// "NONE", "REQUESTED", "ACCEPTED", "REFUSED", "RELEASING".
const char* to_string(LockState s);

/// Counters for tests and run statistics.
struct LockStats {
  std::int64_t requests = 0;       ///< request() calls that started a request
  std::int64_t accepted = 0;       ///< transitions REQUESTED -> ACCEPTED
  std::int64_t refused = 0;        ///< transitions REQUESTED -> REFUSED (REFUSE received)
  std::int64_t lease_expired = 0;  ///< transitions ACCEPTED -> REFUSED (no confirmation)
  std::int64_t released = 0;       ///< transitions RELEASING -> NONE
  std::int64_t became_master = 0;  ///< claims of mastership
  std::int64_t stepped_down = 0;   ///< step-downs on meeting another master
  std::int64_t authority_gained = 0;
  std::int64_t messages_sent = 0;
};

/// One robot's lock manager. Feed it received messages (receive), the pose (set_pose) and the
/// requests of the agent (request/release); call step(now) at the agent rate and broadcast what
/// it returns. Deterministic: randomness only from the seed. Copyable, not thread-safe.
class LockManager {
 public:
  /// `agent` is this robot's name as it appears in the messages; throws std::invalid_argument
  /// for a bad config or an empty name.
  LockManager(std::string agent, LockConfig config, std::uint64_t seed);

  /// Asks for `resource`. From NONE/REFUSED: REQUESTED. Idempotent while REQUESTED or ACCEPTED;
  /// while RELEASING it takes the lock back (ACCEPTED if the RELEASE was not sent yet).
  void request(std::string_view resource);
  /// Gives `resource` up. ACCEPTED (or REFUSED after a lost lease): RELEASING, the RELEASE goes
  /// out once the robot is release_distance_m from its pose now. REQUESTED: withdrawn at once.
  void release(std::string_view resource);
  /// The robot's pose (for the release distance). Without a pose releases go out at once.
  void set_pose(const core::Pose2D& pose) { pose_ = pose; }

  /// Takes a received message from peer `from` at time `at` (>= the previous step's time).
  /// LockMessage, LockMasterAnnounce and LockStatus are used and true is returned; any other
  /// message only counts as a sign of life of `from` (false).
  bool receive(const google::protobuf::Message& message, std::string_view from, core::SimTime at);
  /// A sign of life of `agent` (e.g. a beacon) at `at`: the master keeps its locks.
  void heard_from(std::string_view agent, core::SimTime at);

  /// Advances to `now` (non-decreasing): leases, election, answers, resends. Returns the messages
  /// to broadcast (LockMessage, LockMasterAnnounce, LockStatus), in a deterministic order.
  std::vector<std::unique_ptr<google::protobuf::Message>> step(core::SimTime now);

  // ---- queries ----
  /// This robot's state for `resource` as of the last step()/receive().
  LockState state(std::string_view resource) const;
  /// True if this robot holds `resource` at `now`: ACCEPTED, or RELEASING with the RELEASE not
  /// yet sent, and a confirmation younger than the lease.
  bool holds(std::string_view resource, core::SimTime now) const;
  /// Resources with a state other than NONE, sorted.
  std::vector<std::string> resources() const;
  /// Calls `f(resource, state)` for every resource this robot has had a state for (NONE
  /// included), sorted by name; without the copies of resources().
  template <class F>
  void for_each_state(F&& f) const {
    for (const auto& [r, o] : own_) f(r, o.state);
  }
  /// Changes whenever for_each_state() would show something new (a state changed or a resource
  /// was added): a caller that showed the states at one version need not walk them again.
  std::uint64_t states_version() const { return states_version_; }
  /// True while this robot claims mastership (announces itself).
  bool is_master() const { return endorsee_ == agent_; }
  /// True while this robot is master with a majority's endorsement (it may confirm locks).
  bool has_authority() const { return authority_; }
  /// True while a new master waits for old leases to run out (it grants nothing).
  bool quiet(core::SimTime now) const { return authority_ && now < quiet_until_; }
  /// The master this robot announces (itself if master); empty if none.
  const std::string& master() const { return endorsee_; }
  /// The lock table: the master's own, or a slave's copy of the last LockStatus.
  const std::map<std::string, std::string, std::less<>>& holders() const { return table_; }
  const std::string& agent() const { return agent_; }
  const LockConfig& config() const { return config_; }
  const LockStats& stats() const { return stats_; }

 private:
  struct Own {
    LockState state = LockState::kNone;
    core::SimTime confirmed_at;  ///< receipt of the last confirmation
    bool get_sent = false;       ///< a GET of the current request went out
    bool was_held = false;       ///< ACCEPTED at some time since the request
    std::optional<core::SimTime> last_get;
    core::SimTime get_not_before;  ///< no GET before: older confirmations may still arrive
    bool release_sent = false;
    std::optional<core::Pose2D> release_pose;
    std::optional<core::SimTime> last_release;
    bool stray = false;  ///< the master lists us but we do not want it: RELEASE
  };
  struct Pending {
    int type;  ///< LockMessage::LockType
    std::string agent;
    std::string resource;
  };
  struct Confirm {
    core::SimTime at;
    std::string agent;
  };

  Own& own(std::string_view resource);
  void set_state(Own& o, LockState state);  ///< (every change of a state goes through here)
  void advance(core::SimTime t);
  void step_down(core::SimTime t);
  void update_election(core::SimTime now);
  void update_authority(core::SimTime now);
  void serve(core::SimTime now, bool granting,
             std::vector<std::unique_ptr<google::protobuf::Message>>& out);
  bool may_grant(std::string_view resource, std::string_view agent, core::SimTime now) const;
  void confirm_own(std::string_view resource, core::SimTime at);
  void run_own(core::SimTime now, std::vector<std::unique_ptr<google::protobuf::Message>>& out);
  void send_lock(int type, std::string_view agent, std::string_view resource,
                 std::vector<std::unique_ptr<google::protobuf::Message>>& out);
  bool far_enough(const Own& o) const;
  core::SimTime draw_backoff();

  std::string agent_;
  LockConfig config_;
  core::RandomStream rng_;
  std::optional<core::Pose2D> pose_;
  core::SimTime now_;
  bool started_ = false;

  std::map<std::string, Own, std::less<>> own_;
  std::uint64_t states_version_ = 0;  ///< states_version()

  // Election: whom we endorse, our promise, who announced themselves.
  std::string endorsee_;
  std::string pledged_to_;
  core::SimTime pledge_until_;
  std::optional<core::SimTime> last_announce_;
  std::map<std::string, core::SimTime, std::less<>> masters_heard_;  ///< own announcements
  core::SimTime master_seen_;  ///< last sign of any other master (announcement, endorsement)
  core::SimTime backoff_;

  // Authority: endorsements of us (valid until), and the quiet period.
  std::map<std::string, core::SimTime, std::less<>> support_;
  bool authority_ = false;
  core::SimTime quiet_until_;
  std::optional<core::SimTime> last_status_;

  // Master table (or a slave's copy), confirmations, liveness, requests to answer.
  std::map<std::string, std::string, std::less<>> table_;
  std::map<std::string, Confirm, std::less<>> last_confirm_;
  std::map<std::string, core::SimTime, std::less<>> heard_;
  std::vector<Pending> inbox_;

  LockStats stats_;
};

}  // namespace llsf::clips
