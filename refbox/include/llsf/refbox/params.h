// SPDX-License-Identifier: MIT
// The parameterisation of one game (spec §2, §5, §6, §8): everything the 2013 refbox drew at
// random when the game left PRE_GAME. Drawn from a seed, or given explicitly (tests, replaying
// the plan of a real game, or the SyncInfo of a master refbox).
#pragma once

#include <array>
#include <string>
#include <vector>

#include "llsf/core/rng.h"
#include "llsf/refbox/types.h"

namespace llsf::refbox {

struct RulesVariant;

/// A down period of one machine, in seconds of PRODUCTION game time ([start_s, end_s)).
struct DownTime {
  DeviceId device;  ///< M1..M10, R1 or R2
  int start_s = 0;
  int end_s = 0;
  friend bool operator==(const DownTime&, const DownTime&) = default;
};

/// One period of the delivery-gate schedule, in seconds of PRODUCTION game time.
struct GatePeriod {
  DeviceId gate;  ///< D1, D2 or D3: the only active gate during [start_s, end_s)
  int start_s = 0;
  int end_s = 0;
  friend bool operator==(const GatePeriod&, const GatePeriod&) = default;
};

/// Number of regular orders (1..9) and late orders (10, 11).
inline constexpr int kRegularOrderCount = 9;
inline constexpr int kLateOrderCount = 2;
inline constexpr int kOrderCount = kRegularOrderCount + kLateOrderCount;
/// Length of a late order's delivery window.
inline constexpr int kLateOrderWindowS = 120;
/// Production length the plan is made for (the schedule covers it even if a config shortens
/// the phase).
inline constexpr int kPlanProductionS = 900;
/// Overtime of a synchronised play-off game with equal non-zero points (spec §10).
inline constexpr int kOvertimeS = 300;
/// Production length a synchronised (MASTER/SLAVE) plan's gate schedule covers (spec §8).
inline constexpr int kPlanSynchronisedS = kPlanProductionS + kOvertimeS;
/// Default order quantities of RBX (used by quirk 1 when T5 received no down time).
inline constexpr std::array<int, kRegularOrderCount> kDefaultOrderQuantities = {3, 2, 4, 1, 6,
                                                                                2, 3, 3, 3};

/// Everything random about one game. Plain data: compare, copy, put into a config.
struct GameParams {
  /// Types dealt to M1..M10 (four T1, three T2, one each of T3, T4, T5).
  std::array<MachineType, kProductionMachineCount> machine_types{};
  /// Final processing time per type T1..T5, seconds (integers as in RBX).
  std::array<int, 5> proc_time_s{};
  /// Exploration light code per type T1..T5: steady lamps, at least one on, all distinct.
  std::array<Lights, 5> light_codes{};
  /// Quantities of orders 1..9 (late orders always ask for one P3).
  std::array<int, kRegularOrderCount> order_quantities{};
  /// Window starts of late orders 10 and 11 (each window lasts kLateOrderWindowS).
  std::array<int, kLateOrderCount> late_order_start_s{};
  /// 6..8 down periods, at most one per machine, never a gate.
  std::vector<DownTime> down_times;
  /// Consecutive gate periods from 0 to kPlanProductionS; neighbours use different gates.
  std::vector<GatePeriod> gate_schedule;

  friend bool operator==(const GameParams&, const GameParams&) = default;
};

/// Draws a game's parameterisation as RBX 0.6.1 does (spec §2.1, §5, §6, §8), from `stream`
/// (the engine passes rng.stream("refbox")). Deterministic in the stream's state.
GameParams draw_game_params(core::RandomStream& stream, const RulesVariant& rules);
/// As above, with the gate schedule covering `gate_schedule_end_s` (kPlanProductionS, or
/// kPlanSynchronisedS in synchronised mode; its last period is stretched to that end). Down
/// times and late orders stay within kPlanProductionS. With kPlanProductionS the draws are
/// exactly those of the two-argument form.
GameParams draw_game_params(core::RandomStream& stream, const RulesVariant& rules,
                            int gate_schedule_end_s);

/// Throws core::ConfigError "<path>.<field>: reason" if `p` breaks the spec's structure
/// (type counts, distinct non-empty codes, positive times, window and schedule ranges).
void validate_game_params(const GameParams& p, const std::string& path = "params");
/// As above, requiring the gate schedule to cover at least `gate_schedule_end_s`.
void validate_game_params(const GameParams& p, const std::string& path, int gate_schedule_end_s);

/// The 7 steady exploration light codes in RBX order: G, Y, GY, R, RG, RY, RYG.
const std::array<Lights, 7>& exploration_light_codes();
/// A light code written as lamp letters, e.g. "RY" (R, Y, G order); "" for all off.
std::string light_code_string(const Lights& code);

}  // namespace llsf::refbox
