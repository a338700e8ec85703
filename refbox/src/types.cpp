// SPDX-License-Identifier: MIT
// Names of the rule enums, device lookup, inputs and outputs of machine types, the rules variants.
#include "llsf/refbox/types.h"

#include "llsf/core/assert.h"
#include "llsf/refbox/rules_variant.h"

namespace llsf::refbox {

std::optional<DeviceId> device_by_name(std::string_view name) {
  for (int i = 0; i < kDeviceCount; ++i) {
    if (kDeviceNames[i] == name) return DeviceId(i);
  }
  return std::nullopt;
}

std::string_view device_name(DeviceId device) {
  LLSF_DEMAND(is_valid_device(device));
  return kDeviceNames[device.value()];
}

std::string_view to_string(GameState s) {
  switch (s) {
    case GameState::kInit:
      return "INIT";
    case GameState::kWaitStart:
      return "WAIT_START";
    case GameState::kRunning:
      return "RUNNING";
    case GameState::kPaused:
      return "PAUSED";
  }
  return "?";
}

std::string_view to_string(GamePhase p) {
  switch (p) {
    case GamePhase::kPreGame:
      return "PRE_GAME";
    case GamePhase::kSetup:
      return "SETUP";
    case GamePhase::kExploration:
      return "EXPLORATION";
    case GamePhase::kProduction:
      return "PRODUCTION";
    case GamePhase::kPostGame:
      return "POST_GAME";
    case GamePhase::kOpenChallenge:
      return "OPEN_CHALLENGE";
    case GamePhase::kNavigationChallenge:
      return "NAVIGATION_CHALLENGE";
    case GamePhase::kWhackAMoleChallenge:
      return "WHACK_A_MOLE_CHALLENGE";
  }
  return "?";
}

std::string_view to_string(RefBoxMode m) {
  switch (m) {
    case RefBoxMode::kStandalone:
      return "STANDALONE";
    case RefBoxMode::kMaster:
      return "MASTER";
    case RefBoxMode::kSlave:
      return "SLAVE";
  }
  return "?";
}

std::optional<RefBoxMode> refbox_mode_from_string(std::string_view s) {
  for (RefBoxMode m : {RefBoxMode::kStandalone, RefBoxMode::kMaster, RefBoxMode::kSlave}) {
    if (to_string(m) == s) return m;
  }
  return std::nullopt;
}

std::string_view to_string(PuckState s) {
  switch (s) {
    case PuckState::kS0:
      return "S0";
    case PuckState::kS1:
      return "S1";
    case PuckState::kS2:
      return "S2";
    case PuckState::kP1:
      return "P1";
    case PuckState::kP2:
      return "P2";
    case PuckState::kP3:
      return "P3";
    case PuckState::kConsumed:
      return "CONSUMED";
    case PuckState::kFinished:
      return "FINISHED";
  }
  return "?";
}

std::string_view to_string(LightState s) {
  switch (s) {
    case LightState::kOff:
      return "OFF";
    case LightState::kOn:
      return "ON";
    case LightState::kBlink:
      return "BLINK";
  }
  return "?";
}

std::string_view to_string(RobotState s) {
  switch (s) {
    case RobotState::kActive:
      return "ACTIVE";
    case RobotState::kMaintenance:
      return "MAINTENANCE";
    case RobotState::kDisqualified:
      return "DISQUALIFIED";
  }
  return "?";
}

std::string_view to_string(MachineState s) {
  switch (s) {
    case MachineState::kIdle:
      return "IDLE";
    case MachineState::kProcessing:
      return "PROCESSING";
    case MachineState::kWaiting:
      return "WAITING";
    case MachineState::kDown:
      return "DOWN";
    case MachineState::kInvalid:
      return "INVALID";
  }
  return "?";
}

std::string_view to_string(MachineType t) {
  switch (t) {
    case MachineType::kT1:
      return "T1";
    case MachineType::kT2:
      return "T2";
    case MachineType::kT3:
      return "T3";
    case MachineType::kT4:
      return "T4";
    case MachineType::kT5:
      return "T5";
    case MachineType::kRecycle:
      return "RECYCLE";
    case MachineType::kDeliver:
      return "DELIVER";
    case MachineType::kTest:
      return "TEST";
  }
  return "?";
}

std::optional<MachineType> machine_type_from_string(std::string_view s) {
  for (MachineType t :
       {MachineType::kT1, MachineType::kT2, MachineType::kT3, MachineType::kT4, MachineType::kT5,
        MachineType::kRecycle, MachineType::kDeliver, MachineType::kTest}) {
    if (to_string(t) == s) return t;
  }
  return std::nullopt;
}

TypeInputs inputs_of(MachineType type) {
  using P = PuckState;
  switch (type) {
    case MachineType::kT1:
      return {{P::kS0}, 1};
    case MachineType::kT2:
      return {{P::kS0, P::kS1}, 2};
    case MachineType::kT3:
    case MachineType::kT4:
      return {{P::kS0, P::kS1, P::kS2}, 3};
    case MachineType::kT5:
      return {{P::kS0}, 1};
    case MachineType::kRecycle:
      return {{P::kConsumed}, 1};
    case MachineType::kDeliver:
      return {{P::kP1, P::kP2, P::kP3}, 3};
    case MachineType::kTest:
      return {};
  }
  return {};
}

std::optional<PuckState> output_of(MachineType type) {
  switch (type) {
    case MachineType::kT1:
      return PuckState::kS1;
    case MachineType::kT2:
      return PuckState::kS2;
    case MachineType::kT3:
      return PuckState::kP1;
    case MachineType::kT4:
      return PuckState::kP2;
    case MachineType::kT5:
      return PuckState::kP3;
    case MachineType::kRecycle:
      return PuckState::kS0;
    case MachineType::kDeliver:
      return PuckState::kFinished;
    case MachineType::kTest:
      return std::nullopt;
  }
  return std::nullopt;
}

int type_index(MachineType type) {
  const int i = static_cast<int>(type);
  LLSF_DEMAND(i >= 0 && i < 5);
  return i;
}

// ---------------------------------------------------------------------------------------------
// Rules variants: every difference in one function.
// ---------------------------------------------------------------------------------------------

bool is_known_rules_variant(std::string_view name) {
  return name == kRulesRefbox061 || name == kRulesRulebook2013;
}

RulesVariant make_rules_variant(std::string_view name) {
  LLSF_DEMAND_MSG(is_known_rules_variant(name), "unknown rules variant " + std::string(name));
  RulesVariant v;  // the in-class defaults are refbox 0.6.1
  v.name = std::string(name);
  if (name == kRulesRulebook2013) {
    v.recycle_points = 5;
    v.out_of_window_points = 1;
    v.out_of_window_pending = false;
    v.inactive_gate_rejects_product = true;
    v.late_order_lead = core::SimTime::from_sec(0);
    v.quantities_only_with_t5_down = false;
  }
  return v;
}

}  // namespace llsf::refbox
