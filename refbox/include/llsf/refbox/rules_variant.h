// SPDX-License-Identifier: MIT
// The one place where the two 2013 rule sets differ: the referee box as it scored RoboCup 2013
// (refbox 0.6.1, the default) and the 2013 rule book. Every rule that depends on the variant
// reads a field of RulesVariant; nothing else in the engine compares variant names.
#pragma once

#include <string>
#include <string_view>

#include "llsf/core/sim_time.h"

namespace llsf::refbox {

/// Flags and values in which `refbox-0.6.1` and `rulebook-2013` differ (spec §7, §10).
struct RulesVariant {
  /// "refbox-0.6.1" or "rulebook-2013".
  std::string name;

  // --- the four differences between the rule book and refbox 0.6.1 ---------------------------
  /// Points for recycling CONSUMED -> S0 (0.6.1: 3, rule book: 5).
  int recycle_points = 3;
  /// Points for a delivery outside every window of its product (0.6.1: 0, rule book: 1).
  int out_of_window_points = 0;
  /// 0.6.1: an out-of-window delivery stays pending and is credited to the first order of that
  /// product whose window opens later (quirk 4). Rule book: no pending deliveries.
  bool out_of_window_pending = true;
  /// Ordered product at an inactive gate (beyond the 3 s grace). 0.6.1 (quirk 2): no reaction,
  /// the gate stays red and the puck is delivered should the gate become active while it lies
  /// there (the RFID is polled). Rule book / 0.6.0: red + yellow blinking, puck out of the game
  /// (CONSUMED), 0 points.
  bool inactive_gate_rejects_product = false;
  /// How long before its window a late order becomes active (0.6.1: 5 s, rule book: 0 s).
  core::SimTime late_order_lead = core::SimTime::from_sec(5);

  // --- quirks of 0.6.1 (spec §10) -------------------------------------------------------------
  /// Quirk 1: order quantities are only drawn if the T5 machine received a down time; otherwise
  /// the defaults 3,2,4,1,6,2,3,3,3 are used. Rule book: always drawn.
  bool quantities_only_with_t5_down = true;
  /// Quirk 6: the test station answers in every phase and state (kept in both variants; the
  /// rule book says nothing about it).
  bool test_station_all_phases = true;
  // Quirk 5 (removing a puck mid-processing silently aborts the step) holds in both variants:
  // the rule book has no other rule for it.

  // --- values both variants share (kept here so that all rule constants sit together) --------
  /// Exploration points for a correct / wrong first report of a machine.
  int exploration_correct_points = 4;
  int exploration_wrong_points = -3;
  /// Grace after a gate turned inactive during which deliveries are still accepted.
  core::SimTime gate_grace = core::SimTime::from_sec(3);
  /// A robot without a beacon for longer than this is reported lost (once until seen again).
  core::SimTime robot_lost_after = core::SimTime::from_sec(5);
  /// A robot without a beacon for longer than this is removed from the list (0.5.x: 30 s).
  core::SimTime robot_removed_after = core::SimTime::from_sec(1080);
  /// Beacon clock offset that triggers a warning.
  core::SimTime clock_offset_warning = core::SimTime::from_sec(3);
  /// Maintenance: allowed time, warning time and the limit beyond which a robot is disqualified.
  core::SimTime maintenance_allowed = core::SimTime::from_sec(120);
  core::SimTime maintenance_warning = core::SimTime::from_sec(105);
  core::SimTime maintenance_limit = core::SimTime::from_sec(135);
  /// Intermediate consumption time of a multi-input machine, recycling time, delivery time.
  core::SimTime intermediate_time = core::SimTime::from_sec(2);
  core::SimTime recycle_time = core::SimTime::from_sec(2);
  core::SimTime delivery_time = core::SimTime::from_sec(1);
  /// How long attention messages about late orders are shown.
  double late_order_attention_s = 15.0;

  // --- technical challenges (spec §4, §7) ----------------------------------------------------
  /// Length of NAVIGATION_CHALLENGE and WHACK_A_MOLE_CHALLENGE (game time while RUNNING).
  core::SimTime navigation_challenge_duration = core::SimTime::from_sec(60);
  core::SimTime whack_a_mole_duration = core::SimTime::from_sec(300);
  /// Side of the square box around the mole machine (centred on its pose) in which a robot's
  /// vision pose counts as reaching it, metres (0.65 x 0.65 m).
  double whack_a_mole_box_m = 0.65;
};

/// Names accepted by make_rules_variant().
inline constexpr std::string_view kRulesRefbox061 = "refbox-0.6.1";
inline constexpr std::string_view kRulesRulebook2013 = "rulebook-2013";

/// The variant called `name`; requires is_known_rules_variant(name) (LLSF_DEMAND). Config
/// loaders check the name first and report a bad one as a ConfigError.
RulesVariant make_rules_variant(std::string_view name);
/// True for "refbox-0.6.1" and "rulebook-2013".
bool is_known_rules_variant(std::string_view name);

}  // namespace llsf::refbox
