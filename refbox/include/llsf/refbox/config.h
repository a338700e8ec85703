// SPDX-License-Identifier: MIT
// RefboxConfig: the read-only configuration of the rules engine, its validation and its YAML
// loader (docs/refbox.md).
#pragma once

#include <array>
#include <optional>
#include <string>
#include <vector>

#include "llsf/core/config.h"
#include "llsf/core/geometry.h"
#include "llsf/refbox/params.h"
#include "llsf/refbox/rules_variant.h"

namespace llsf::refbox {

/// Configuration of one referee box. Aggregate with the 2013 defaults; validate() before use.
struct RefboxConfig {
  /// Rules variant name: "refbox-0.6.1" (default) or "rulebook-2013" (see RulesVariant).
  std::string rules = std::string(kRulesRefbox061);
  /// Points per recycled puck instead of the rules variant's (3 in refbox-0.6.1, 5 in the
  /// rule book); unset = the variant's. The thesis' games counted 5 (thesis §5.3.2).
  std::optional<int> recycle_points;
  /// Team name. Empty = training game: start goes straight to EXPLORATION (spec §4).
  std::string team;
  /// Skip SETUP even with a team name.
  bool skip_setup = false;
  /// Phase lengths; may be shortened (the plan in params still covers 900 s of production).
  SimTime setup_duration = SimTime::from_sec(300);
  SimTime exploration_duration = SimTime::from_sec(180);
  SimTime production_duration = SimTime::from_sec(900);
  /// Puck ids known at start, all S0 (RBX without PLC: 1..20).
  std::vector<int> pucks = {1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15, 16, 17, 18, 19, 20};
  /// PLC behaviour: an unknown id seen at a reader is learned as a new S0 puck; otherwise ignored.
  bool learn_unknown_pucks = true;
  /// An explicit parameterisation; without it the game draws one from rng.stream("refbox").
  std::optional<GameParams> params;
  /// STANDALONE, or MASTER / SLAVE of a synchronised two-field play-off game (spec §10). Any
  /// mode but STANDALONE is synchronised play: production pauses at its regular end and waits
  /// for the other field (StepInput::peer_game_state) to decide on overtime, and a drawn gate
  /// schedule covers kPlanSynchronisedS (1200 s). A SLAVE takes the master's plan (params or
  /// Refbox::sync_from()).
  RefBoxMode mode = RefBoxMode::kStandalone;
  /// Overtime of a synchronised game with equal non-zero points (spec §10: 300 s).
  SimTime overtime_duration = SimTime::from_sec(kOvertimeS);
  /// Device poses (for ExplorationMachine and MachineInfo), in DeviceId order; spec §1 table.
  std::array<core::Pose2D, kDeviceCount> device_poses = default_device_poses();

  /// Throws core::ConfigError naming the first bad field ("refbox.production_s: must be > 0").
  void validate() const;
  /// True in MASTER and SLAVE mode (synchronised play-off game with overtime).
  bool synchronised() const { return mode != RefBoxMode::kStandalone; }
  /// The device poses of the spec's table (RBX facts.clp).
  static std::array<core::Pose2D, kDeviceCount> default_device_poses();
};

/// Reads a RefboxConfig from `node` (the map of refbox settings) on top of the defaults and
/// validates it. Errors name file:line:column and the field.
RefboxConfig load_refbox_config(const core::ConfigNode& node);
/// Loads a YAML file whose top-level map is the refbox settings (config/refbox-*.yaml).
RefboxConfig load_refbox_config_file(const std::string& path);

}  // namespace llsf::refbox
