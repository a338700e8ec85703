// SPDX-License-Identifier: MIT
// What goes into and comes out of one refbox step, as plain C++ values. A protocol adapter turns
// llsf_msgs messages into these inputs and the outputs/snapshot into llsf_msgs messages; the
// world adapter turns RFID zone events into RfidEvents and RefereeActions into puck moves.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <variant>
#include <vector>

#include "llsf/core/geometry.h"
#include "llsf/refbox/types.h"

namespace llsf::refbox {

// ---------------------------------------------------------------------------------------------
// Inputs
// ---------------------------------------------------------------------------------------------

/// A puck entered or left a device's RFID zone (reported by the world).
struct RfidEvent {
  DeviceId device;
  PuckId puck;
  bool entered = true;  ///< false = left
};

/// Controller commands (TCP in 2013). Machine names are already resolved to DeviceIds.
namespace command {
/// SetGameState.
struct SetGameState {
  GameState state = GameState::kRunning;
};
/// SetGamePhase: switches to `phase` and re-initialises it (game time 0).
struct SetGamePhase {
  GamePhase phase = GamePhase::kPreGame;
};
/// SetTeamName; in PRE_GAME a change clears the robot list.
struct SetTeamName {
  std::string team;
};
/// PlacePuckUnderMachine: as if the puck entered the device's RFID zone (PRODUCTION + RUNNING).
struct PlacePuck {
  DeviceId device;
  PuckId puck;
};
/// RemovePuckFromMachine: as if the puck left the RFID zone; a puck in the machine's loaded
/// list is taken out and becomes CONSUMED (PRODUCTION only).
struct RemovePuck {
  DeviceId device;
  PuckId puck;
};
/// LoadPuckInMachine: puts a valid input directly into a machine's loaded list; completing the
/// set finishes the machine's cycle with its points (PRODUCTION only).
struct LoadPuck {
  DeviceId device;
  PuckId puck;
};
/// SetPucks: replaces the puck list (all S0).
struct SetPucks {
  std::vector<int> ids;
};
/// SetRobotMaintenance: take the robot with this jersey number out (true) or bring it back.
struct SetRobotMaintenance {
  int number = 0;
  bool maintenance = true;
};
/// A referee penalty of the rule book (not in RBX): minor −25 % of the current score (at least
/// −1), major −50 % (at least −5). Recorded in the current phase.
struct Penalty {
  bool major = false;
};
}  // namespace command

/// One controller command.
using Command = std::variant<command::SetGameState, command::SetGamePhase, command::SetTeamName,
                             command::PlacePuck, command::RemovePuck, command::LoadPuck,
                             command::SetPucks, command::SetRobotMaintenance, command::Penalty>;

/// A robot's BeaconSignal as received (UDP in 2013).
struct Beacon {
  SimTime time;                      ///< the sender's clock (Time field)
  std::string team;                  ///< team_name
  std::string peer_name;             ///< peer_name
  int number = 0;                    ///< jersey number
  std::optional<core::Pose2D> pose;  ///< pose, if sent
  std::string host;                  ///< source address
  int port = 0;                      ///< source port
};

/// One entry of a MachineReport.
struct MachineReportEntry {
  std::string name;  ///< "M1".."M10" (other names are ignored)
  std::string type;  ///< "T1".."T5" (compared exactly)
};

/// A MachineReport from a robot.
struct MachineReport {
  std::vector<MachineReportEntry> machines;
};

/// A robot pose seen by the overhead camera (the world reports it; spec §7 whack-a-mole,
/// Robot.vision_pose). Keyed by jersey number.
struct RobotPose {
  int number = 0;     ///< jersey number of a robot of this field's team
  core::Pose2D pose;  ///< field frame, metres and radians
};

/// The GameState last received from the other refbox of a synchronised game (spec §10): what
/// the engine needs to decide on overtime.
struct PeerGameState {
  GamePhase phase = GamePhase::kPreGame;
  GameState state = GameState::kInit;
  SimTime game_time;  ///< phase-relative, as in GameState.game_time
  int points = 0;
};

/// Everything that reaches the refbox during one step. Spans borrow the caller's storage.
struct StepInput {
  std::span<const RfidEvent> rfid;
  std::span<const Command> commands;
  std::span<const Beacon> beacons;
  std::span<const MachineReport> reports;
  /// True if a puck lies in the late-order insertion slot (the world knows, the refbox does not).
  bool insertion_slot_occupied = false;
  /// Overhead-camera poses of the robots this step (optional; scores whack-a-mole, stored as
  /// Robot::vision_pose).
  std::span<const RobotPose> robot_poses;
  /// Synchronised mode (MASTER/SLAVE): the other field's latest GameState, if one arrived
  /// (decides overtime at the end of regular production).
  std::optional<PeerGameState> peer_game_state;
};

// ---------------------------------------------------------------------------------------------
// Outputs
// ---------------------------------------------------------------------------------------------

/// Why points were given (one entry per line of the spec's points table).
enum class AwardReason : std::uint8_t {
  kExplorationCorrect,       ///< first report of a machine, right type (+4)
  kExplorationWrong,         ///< first report of a machine, wrong type (−3)
  kMachineCompleted,         ///< T1..T5 finished a set (T1 0, T2 4, T3/T4 12, T5 0)
  kRecycled,                 ///< CONSUMED -> S0 (0.6.1: 3, rule book: 5)
  kDelivery,                 ///< product in the window of an order that still needs it (10/20)
  kDeliveryExtra,            ///< product in the window of an order already full (1 / 0)
  kDeliveryOutOfWindow,      ///< product outside every window (0.6.1: 0 and pending, RB: 1)
  kDeliveryPendingCredited,  ///< 0.6.1: a pending delivery credited when a window opened
  kDeliveryIntermediate,     ///< S0/S1/S2 at a gate (0)
  kPenaltyMinor,             ///< referee: −25 %, at least −1
  kPenaltyMajor,             ///< referee: −50 %, at least −5
  kMoleReached,              ///< whack-a-mole: a robot's vision pose in the mole's box (+1)
  kMoleReachedReferee,       ///< whack-a-mole: the referee paused on the mole (+1)
};
/// "EXPLORATION_CORRECT", ...
std::string_view to_string(AwardReason r);

/// One recorded points award.
struct PointsAward {
  SimTime game_time;  ///< phase-relative game time
  GamePhase phase = GamePhase::kPreGame;
  int points = 0;
  AwardReason reason = AwardReason::kMachineCompleted;
  DeviceId device;  ///< the machine/gate concerned, if any
  OrderId order;    ///< the order credited, if any
  PuckId puck;      ///< the puck concerned, if any
  friend bool operator==(const PointsAward&, const PointsAward&) = default;
};

/// An AttentionMessage for the controller/referee.
struct AttentionMessage {
  std::string text;
  double time_to_show_s = 5.0;
};

/// What the referee has to do on the field (the world adapter carries it out).
struct RefereeAction {
  enum class Kind : std::uint8_t {
    kRemovePuck,  ///< take `puck` away from `device` (delivered / out of the game)
    kPlacePuck,   ///< put the new S0 `puck` at `place`
  };
  enum class Place : std::uint8_t { kNone, kInsertionSlot, kInputStorage };
  Kind kind = Kind::kRemovePuck;
  DeviceId device;
  PuckId puck;
  Place place = Place::kNone;
};

/// Results of one step. Owned by the refbox; valid until the next step. Vectors keep their
/// capacity, so a steady-state step does not allocate.
struct StepOutput {
  /// Lamps of every device after the step (DeviceId order).
  std::array<Lights, kDeviceCount> lights{};
  /// Bit i set if device i's lights changed in this step.
  std::uint32_t lights_changed_mask = 0;
  std::vector<PointsAward> awards;
  std::vector<AttentionMessage> attention;
  std::vector<RefereeAction> actions;
  /// Orders that became active in this step (the OrderInfo burst restarts).
  std::vector<OrderId> orders_activated;
  bool phase_changed = false;
  bool state_changed = false;
};

}  // namespace llsf::refbox
