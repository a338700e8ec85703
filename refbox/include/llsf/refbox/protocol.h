// SPDX-License-Identifier: MIT
// The refbox protocol adapter (spec §9.6, §9.7): llsf_msgs messages in, the engine's inputs out;
// the engine's snapshot and outputs in, llsf_msgs messages out on the 2013 schedule. No sockets.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include <llsf_msgs/GameState.pb.h>

#include "llsf/core/rng.h"
#include "llsf/refbox/config.h"
#include "llsf/refbox/io.h"
#include "llsf/refbox/refbox.h"

namespace google::protobuf {
class Message;
}
namespace llsf_msgs {
class SyncInfo;
}

namespace llsf::refbox {

/// Where an incoming message came from.
struct Origin {
  enum class Channel : std::uint8_t {
    kPeer,    ///< UDP broadcast from a robot or another peer
    kStream,  ///< a TCP controller client (refbox shell, GUI, a slave refbox)
    kMaster,  ///< SLAVE only: the connection to the master refbox (spec §10)
  };
  Channel channel = Channel::kPeer;
  int client = -1;   ///< stream client id (kStream only)
  std::string host;  ///< source address; robots are keyed by (host, port) (spec §10)
  int port = 0;      ///< source port

  static Origin peer(std::string host, int port) {
    return {Channel::kPeer, -1, std::move(host), port};
  }
  static Origin stream(int client, std::string host = "127.0.0.1", int port = 0) {
    return {Channel::kStream, client, std::move(host), port};
  }
  static Origin master(std::string host = "127.0.0.1", int port = 4444) {
    return {Channel::kMaster, -1, std::move(host), port};
  }
};

/// Where an outgoing message goes.
struct Destination {
  enum class Kind : std::uint8_t {
    kAllPeers,    ///< UDP broadcast
    kAllClients,  ///< every connected stream client
    kClient,      ///< one stream client
    kMaster,      ///< SLAVE only: the master refbox, over the slave's connection
  };
  Kind kind = Kind::kAllPeers;
  int client = -1;  ///< kClient only

  friend bool operator==(const Destination&, const Destination&) = default;
};

/// One message to send. The message is immutable; copies sent to several destinations share it.
/// Holding the shared_ptr beyond the next step is allowed (a delayed radio copy); the adapter
/// then simply stops reusing that object.
struct Outgoing {
  Destination to;
  std::shared_ptr<const google::protobuf::Message> message;
};

/// The world's part of a step's inputs (the radio's part arrives through receive()).
struct WorldInputs {
  std::span<const RfidEvent> rfid;
  bool insertion_slot_occupied = false;
  /// Overhead-camera robot poses (whack-a-mole; Robot.vision_pose), if the world has them.
  std::span<const RobotPose> robot_poses;
};

/// What receive() did with a message (an expected outcome, never an exception).
enum class ReceiveStatus : std::uint8_t {
  kAccepted,         ///< queued for the next step
  kAcceptedIllegal,  ///< queued, but it came over an illegal channel (logged; 0.6.1 applies it)
  kRejected,         ///< dropped; `reason` says why
};

/// The outcome of receive(): status and, unless plainly accepted, a reason.
struct ReceiveResult {
  ReceiveStatus status = ReceiveStatus::kAccepted;
  std::string reason;
};

/// A line of the adapter's log (sent as llsf_log_msgs.LogMessage when enabled).
struct ProtocolLogLine {
  enum class Level : std::uint8_t { kDebug = 0, kInfo = 1, kWarn = 2, kError = 4 };
  SimTime time;  ///< simulated time of the last step when it was written
  Level level = Level::kInfo;
  std::string text;
};

/// Read-only settings of the adapter. The periods are those of spec §9.6 (RBX globals).
struct ProtocolConfig {
  /// GameInfo.known_teams (RBX config llsfrb/game/teams).
  std::vector<std::string> known_teams;
  /// VersionInfo content (refbox 0.6.1).
  int version_major = 0;
  int version_minor = 6;
  int version_micro = 1;
  std::string version_string = "0.6.1";
  /// Send the adapter's log lines to stream clients as llsf_log_msgs.LogMessage.
  bool send_log_messages = true;

  SimTime beacon_period = SimTime::from_sec(1);
  SimTime game_state_period = SimTime::from_sec(1);
  SimTime version_burst_period = SimTime::from_ms(500);
  int version_burst_count = 10;
  SimTime exploration_info_period = SimTime::from_sec(1);
  SimTime machine_report_info_period = SimTime::from_sec(1);
  SimTime machine_info_robot_burst_period = SimTime::from_ms(500);
  int machine_info_robot_burst_count = 30;
  SimTime machine_info_robot_period = SimTime::from_sec(2);
  SimTime machine_info_controller_period = SimTime::from_ms(250);
  SimTime order_info_burst_period = SimTime::from_ms(500);
  int order_info_burst_count = 10;
  SimTime order_info_period = SimTime::from_sec(5);
  SimTime robot_info_stream_period = SimTime::from_ms(250);
  SimTime robot_info_peer_period = SimTime::from_ms(2500);
  SimTime puck_info_period = SimTime::from_sec(1);

  /// Throws core::ConfigError "protocol.<field>: reason" (periods > 0, counts >= 0, versions
  /// >= 0).
  void validate() const;
};

/// GameState.Phase for an engine phase (every value of spec §9.4).
llsf_msgs::GameState::Phase to_msg_phase(GamePhase p);
/// The engine phase for a GameState.Phase value, if it is one of spec §9.4.
std::optional<GamePhase> from_msg_phase(int phase);
/// GameState.RefBoxMode for an engine mode.
llsf_msgs::GameState::RefBoxMode to_msg_mode(RefBoxMode m);
/// SyncInfo (spec §9.5) describing `params`.
void to_sync_info(const GameParams& params, llsf_msgs::SyncInfo& out);
/// The plan a SyncInfo describes, or the reason it cannot be read (a missing or unknown entry;
/// the structure is checked by the engine's validate_game_params()).
std::optional<GameParams> from_sync_info(const llsf_msgs::SyncInfo& in, std::string& error);
/// GameState.State for an engine state.
llsf_msgs::GameState::State to_msg_state(GameState s);
/// The engine state for a GameState.State value, if valid.
std::optional<GameState> from_msg_state(int state);

/// The referee box as a protocol endpoint: owns a Refbox, turns accepted messages into its
/// inputs (spec §9.7) and its snapshot into the messages of spec §9.6, on their schedule in
/// simulated time. Single-threaded. Neither copyable nor movable: engine_output() refers into
/// the owned engine (take a snapshot with `Refbox(refbox())`; hold the adapter in place or in a
/// unique_ptr).
class RefboxProtocol {
 public:
  /// Builds the engine from `config` and `rng` (as Refbox does) and validates `protocol`.
  RefboxProtocol(RefboxConfig config, const core::Rng& rng, ProtocolConfig protocol = {});
  ~RefboxProtocol();
  RefboxProtocol(const RefboxProtocol&) = delete;
  RefboxProtocol& operator=(const RefboxProtocol&) = delete;
  RefboxProtocol(RefboxProtocol&&) = delete;
  RefboxProtocol& operator=(RefboxProtocol&&) = delete;

  /// Takes a message that arrived from `from`, checks it against spec §9.7 (channel, fields,
  /// phase) and queues it for the next step. Never throws on bad content.
  ReceiveResult receive(const google::protobuf::Message& msg, const Origin& from);

  /// A stream client connected: it gets VersionInfo, then GameInfo, and the timers of GameState,
  /// RobotInfo, both MachineInfo views, PuckInfo and OrderInfo are reset (sent at the next step).
  void client_connected(int client);
  /// A stream client went away; nothing more is addressed to it.
  void client_disconnected(int client);
  /// SLAVE: the connection to the master is up; InitiateSync goes out at the next step and the
  /// slave's GameState follows every second while connected (spec §10).
  void master_connected();
  /// SLAVE: the connection to the master is gone.
  void master_disconnected();

  /// Runs the engine to simulated time `now` (never decreasing) with the received messages and
  /// `world`, then emits every message that is due. Returns the messages, valid until the next
  /// step. Order within a step: connect greetings, InitiateSync / SyncInfo, BeaconSignal,
  /// VersionInfo, GameState, ExplorationInfo, MachineReportInfo, MachineInfo (robot,
  /// controller), OrderInfo, RobotInfo (stream, peers), PuckInfo, AttentionMessage, LogMessage.
  std::span<const Outgoing> step(SimTime now, const WorldInputs& world);

  /// The messages of the last step.
  std::span<const Outgoing> outgoing() const { return out_; }
  /// The engine's output of the last step (referee actions, lights, awards, ...).
  const StepOutput& engine_output() const { return *engine_out_; }
  /// A line from the transport in front of the adapter (a controller's frame the stream server
  /// dropped as malformed): into the adapter's log, and to the stream clients as a LogMessage
  /// with the next step, as refbox 0.6.1 logged a client's failed message (handle_client_fail)
  /// through its network logger.
  void log_transport(ProtocolLogLine::Level level, std::string text) {
    log(level, std::move(text));
  }
  /// The adapter's log lines of the last step (including those of receive() calls before it).
  std::span<const ProtocolLogLine> log() const { return log_out_; }
  /// The engine (its snapshot).
  const Refbox& refbox() const { return refbox_; }
  const ProtocolConfig& config() const { return config_; }
  /// Connected stream clients, in connection order.
  std::span<const int> clients() const { return clients_; }

 private:
  /// A periodic message: due time and the remaining messages of a burst.
  struct Timer {
    SimTime due;
    int burst_left = 0;
    /// Reset by a connecting client: sent at the next step, the rhythm restarting from there.
    bool restart = false;
  };
  /// A small pool of reusable messages: one whose only owner is the pool is cleared and reused,
  /// so steady-state steps do not allocate (unless a receiver keeps the messages).
  template <class T>
  class Pool {
   public:
    std::shared_ptr<T> acquire();

   private:
    std::vector<std::shared_ptr<T>> slots_;
    std::size_t next_replace_ = 0;
  };
  struct Pools;

  ReceiveResult illegal(const char* what, const Origin& from, bool applied);
  ReceiveResult reject(std::string reason);
  void log(ProtocolLogLine::Level level, std::string text);
  template <class C>
  void queue_command(const C& c) {
    commands_.emplace_back(std::in_place_type<C>, c);
  }

  bool fire(Timer& t, SimTime period, SimTime burst_period);
  void emit(Destination to, std::shared_ptr<const google::protobuf::Message> msg);
  void emit_all_clients(std::shared_ptr<const google::protobuf::Message> msg);
  void emit_periodic();
  void build_beacon();
  void build_version_info(Destination to);
  void build_game_info(int client);
  void build_game_state();
  void build_exploration_info();
  void build_machine_report_info();
  void build_machine_info_robot();
  void build_machine_info_controller();
  void build_order_info();
  void build_robot_info(bool stream);
  void build_puck_info();
  void build_sync_info(int client);

  ProtocolConfig config_;
  Refbox refbox_;
  const StepOutput* engine_out_ = nullptr;
  std::unique_ptr<Pools> pools_;
  SimTime now_;
  bool stepped_ = false;
  std::uint64_t beacon_seq_ = 0;

  std::vector<int> clients_;
  bool master_link_ = false;
  bool send_initiate_sync_ = false;
  /// MASTER: slaves that asked for SyncInfo since the last step.
  std::vector<int> sync_requests_;
  /// The other refbox's GameState received since the last step (synchronised play).
  std::optional<PeerGameState> peer_game_state_;
  /// Clients that connected since the last step (greeted at the next one).
  std::vector<int> new_clients_;

  // Inputs collected by receive(), handed to the engine at the next step.
  std::vector<Command> commands_;
  std::vector<Beacon> beacons_;
  std::vector<MachineReport> reports_;
  /// (host, port) of beacon sources queued since the last step (new-source detection).
  std::vector<std::pair<std::string, int>> pending_sources_;
  bool version_burst_requested_ = false;

  Timer beacon_;
  Timer version_;
  Timer game_state_;
  Timer exploration_info_;
  Timer machine_report_info_;
  Timer machine_info_robot_;
  Timer machine_info_controller_;
  Timer order_info_;
  Timer robot_info_stream_;
  Timer robot_info_peer_;
  Timer puck_info_;

  std::vector<Outgoing> out_;
  std::vector<ProtocolLogLine> log_pending_;
  std::vector<ProtocolLogLine> log_out_;
};

}  // namespace llsf::refbox
