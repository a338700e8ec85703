// SPDX-License-Identifier: MIT
// Plain value types of the 2013 rules: game states and phases, devices, machine types and
// states, puck states, lights. Enum values equal the 2013 llsf_msgs numbers where one exists,
// so that a protocol adapter can cast them.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string_view>

#include "llsf/core/ids.h"
#include "llsf/core/sim_time.h"

namespace llsf::refbox {

using core::DeviceId;
using core::OrderId;
using core::PuckId;
using core::SimTime;

/// GameState.State of the 2013 protocol.
enum class GameState : std::uint8_t { kInit = 0, kWaitStart = 1, kRunning = 2, kPaused = 3 };
/// GameState.Phase of the 2013 protocol, including the technical-challenge phases (spec §4).
enum class GamePhase : std::uint16_t {
  kPreGame = 0,
  kSetup = 10,
  kExploration = 20,
  kProduction = 30,
  kPostGame = 40,
  kOpenChallenge = 1000,
  kNavigationChallenge = 1001,
  kWhackAMoleChallenge = 1002
};
/// GameState.RefBoxMode of the 2013 protocol: a refbox alone, or the master / a slave of a
/// synchronised two-field play-off game (spec §10).
enum class RefBoxMode : std::uint8_t { kStandalone = 0, kMaster = 1, kSlave = 2 };
/// PuckState of the 2013 protocol (there is no value 3).
enum class PuckState : std::uint8_t {
  kS0 = 0,
  kS1 = 1,
  kS2 = 2,
  kP1 = 4,
  kP2 = 5,
  kP3 = 6,
  kConsumed = 7,
  kFinished = 8
};
/// LightState of the 2013 protocol; blinking is at 2 Hz (see blink_phase_on()).
enum class LightState : std::uint8_t { kOff = 0, kOn = 1, kBlink = 2 };
/// RobotState of the 2013 protocol.
enum class RobotState : std::uint8_t { kActive = 1, kMaintenance = 2, kDisqualified = 3 };
/// The state of a device's state machine (RBX machines.clp).
enum class MachineState : std::uint8_t { kIdle, kProcessing, kWaiting, kDown, kInvalid };
/// A device's type: T1..T5 are dealt to M1..M10 each game; the others never change.
enum class MachineType : std::uint8_t { kT1, kT2, kT3, kT4, kT5, kRecycle, kDeliver, kTest };

/// The 16 signal/RFID devices, indexed M1..M10, R1, R2, TST, D1, D2, D3 (DeviceId values).
inline constexpr int kDeviceCount = 16;
/// Number of production machines M1..M10 (DeviceId 0..9).
inline constexpr int kProductionMachineCount = 10;
inline constexpr int kR1 = 10;
inline constexpr int kR2 = 11;
inline constexpr int kTst = 12;
inline constexpr int kD1 = 13;
inline constexpr int kD2 = 14;
inline constexpr int kD3 = 15;
/// Device names in DeviceId order (the same order as kinematic::kDeviceNames).
inline constexpr std::array<std::string_view, kDeviceCount> kDeviceNames = {
    "M1", "M2",  "M3", "M4", "M5",  "M6", "M7", "M8",
    "M9", "M10", "R1", "R2", "TST", "D1", "D2", "D3"};

/// The device called `name` (exact, case-sensitive), if there is one.
std::optional<DeviceId> device_by_name(std::string_view name);
/// "M1".."D3"; requires a valid device id.
std::string_view device_name(DeviceId device);
inline bool is_production_machine(DeviceId d) { return d.value() >= 0 && d.value() < 10; }
inline bool is_recycler(DeviceId d) { return d.value() == kR1 || d.value() == kR2; }
inline bool is_gate(DeviceId d) { return d.value() >= kD1 && d.value() <= kD3; }
inline bool is_test_station(DeviceId d) { return d.value() == kTst; }
inline bool is_valid_device(DeviceId d) { return d.value() >= 0 && d.value() < kDeviceCount; }

/// The three lamps of one signal tower.
struct Lights {
  LightState red = LightState::kOff;
  LightState yellow = LightState::kOff;
  LightState green = LightState::kOff;
  friend bool operator==(const Lights&, const Lights&) = default;
};
inline constexpr Lights kAllOff{};
inline constexpr Lights kAllOn{LightState::kOn, LightState::kOn, LightState::kOn};

/// Period of the 2 Hz blinking; a blinking lamp is lit in the first half of each period.
inline constexpr SimTime kBlinkPeriod = SimTime::from_ms(500);
/// True if a blinking lamp is lit at simulated time `now` (for light sensors of the world).
inline bool blink_phase_on(SimTime now) { return (now.ns() / (kBlinkPeriod.ns() / 2)) % 2 == 0; }

/// "INIT", "RUNNING", ... (protocol enum names).
std::string_view to_string(GameState s);
/// "PRE_GAME", "SETUP", ... (protocol enum names).
std::string_view to_string(GamePhase p);
/// "STANDALONE", "MASTER", "SLAVE" (protocol enum names).
std::string_view to_string(RefBoxMode m);
/// Parses a name of to_string(RefBoxMode).
std::optional<RefBoxMode> refbox_mode_from_string(std::string_view s);
/// True for the technical-challenge phases OPEN_CHALLENGE, NAVIGATION_CHALLENGE and
/// WHACK_A_MOLE_CHALLENGE.
inline bool is_challenge(GamePhase p) {
  return p == GamePhase::kOpenChallenge || p == GamePhase::kNavigationChallenge ||
         p == GamePhase::kWhackAMoleChallenge;
}
/// "S0", ..., "CONSUMED", "FINISHED".
std::string_view to_string(PuckState s);
/// "OFF", "ON", "BLINK".
std::string_view to_string(LightState s);
/// "ACTIVE", "MAINTENANCE", "DISQUALIFIED".
std::string_view to_string(RobotState s);
/// "IDLE", "PROCESSING", "WAITING", "DOWN", "INVALID".
std::string_view to_string(MachineState s);
/// "T1".."T5", "RECYCLE", "DELIVER", "TEST" (the type strings of Machine and MachineReport).
std::string_view to_string(MachineType t);
/// Parses a type string of to_string(MachineType).
std::optional<MachineType> machine_type_from_string(std::string_view s);

/// Inputs of a machine type (any order), e.g. T3: S0, S1, S2; empty for non-production types.
struct TypeInputs {
  std::array<PuckState, 3> states{};
  int count = 0;
};
/// The inputs of `type` (RECYCLE: CONSUMED; DELIVER: P1, P2, P3; TEST: none).
TypeInputs inputs_of(MachineType type);
/// The output of a production type or recycler, if it has one.
std::optional<PuckState> output_of(MachineType type);
/// Index 0..4 of T1..T5; requires a production type.
int type_index(MachineType type);
/// True for P1, P2, P3.
inline bool is_product(PuckState s) {
  return s == PuckState::kP1 || s == PuckState::kP2 || s == PuckState::kP3;
}

}  // namespace llsf::refbox
