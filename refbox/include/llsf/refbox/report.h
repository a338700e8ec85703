// SPDX-License-Identifier: MIT
// The game report: parameterisation, every points award, per-phase totals, deliveries per
// order and the machine history, as a plain struct with a deterministic JSON rendering.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "llsf/refbox/io.h"
#include "llsf/refbox/params.h"
#include "llsf/refbox/types.h"

namespace llsf::refbox {

/// A machine changed state (recorded only for changes in PRODUCTION).
struct MachineHistoryEntry {
  SimTime game_time;
  GamePhase phase = GamePhase::kProduction;
  DeviceId device;
  MachineState from = MachineState::kIdle;
  MachineState to = MachineState::kIdle;
  PuckId puck;  ///< the puck under the reader at the change, if any
  friend bool operator==(const MachineHistoryEntry&, const MachineHistoryEntry&) = default;
};

/// A puck delivered at a gate (a delivery, not an intermediate or rejected puck).
struct DeliveryRecord {
  SimTime game_time;
  DeviceId gate;
  PuckId puck;
  PuckState product = PuckState::kP1;
  OrderId order;   ///< credited order; invalid while pending or when out of every window
  int points = 0;  ///< points credited (so far)
  friend bool operator==(const DeliveryRecord&, const DeliveryRecord&) = default;
};

/// Final counts of one order.
struct OrderSummary {
  OrderId id;
  PuckState product = PuckState::kP1;
  int requested = 0;
  int delivered = 0;
  int window_begin_s = 0;
  int window_end_s = 0;
  bool late = false;
  friend bool operator==(const OrderSummary&, const OrderSummary&) = default;
};

/// Points of one phase: raw sum and the counted max(0, sum).
struct PhaseTotal {
  GamePhase phase = GamePhase::kExploration;
  int sum = 0;
  int counted = 0;
  friend bool operator==(const PhaseTotal&, const PhaseTotal&) = default;
};

/// Everything worth keeping about one game.
struct GameReport {
  std::string rules;
  std::string team;
  std::uint64_t seed = 0;
  GameState final_state = GameState::kInit;
  GamePhase final_phase = GamePhase::kPreGame;
  RefBoxMode mode = RefBoxMode::kStandalone;
  bool overtime = false;  ///< a synchronised game played its overtime
  std::optional<GameParams> params;
  std::vector<PointsAward> awards;
  std::vector<PhaseTotal> phase_totals;  ///< EXPLORATION, PRODUCTION (and any other with awards)
  int total_points = 0;
  std::vector<OrderSummary> orders;
  std::vector<DeliveryRecord> deliveries;
  std::vector<MachineHistoryEntry> machine_history;
  friend bool operator==(const GameReport&, const GameReport&) = default;
};

/// The report as JSON (indented): fixed key order, times as seconds (whole milliseconds), names
/// for enums; the same report always gives the same bytes.
std::string to_json(const GameReport& report);

}  // namespace llsf::refbox
