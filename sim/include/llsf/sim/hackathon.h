// SPDX-License-Identifier: MIT
// The hackathon variant (thesis §6.1.4): coloured pucks at seeded random spots on the field among
// static boxes, a flashlight + downward camera that tells puck colours only in a short cone ahead
// of the robot, and a safe area to bring the pucks of the counted colours to. docs/hackathon.md
// documents the world, the sensor, the Lua interfaces, the score and every YAML key.
#pragma once

#include <optional>
#include <span>
#include <string>
#include <vector>

#include "llsf/core/config.h"
#include "llsf/core/geometry.h"
#include "llsf/core/ids.h"
#include "llsf/core/rng.h"
#include "llsf/kinematic/world_config.h"

namespace llsf::sim {

/// One puck colour of the hackathon: how many pucks of it lie on the field and whether they
/// count (a decoy colour costs points in the safe area).
struct HackathonColour {
  std::string name;    ///< "red", "green", ...: unique, non-empty
  int count = 0;       ///< pucks of this colour, >= 0
  bool decoy = false;  ///< true: does not count, costs `decoy_penalty` in the safe area
};

/// The flashlight camera: colour detection in a cone ahead of the robot. Each frame, every puck
/// whose centre lies within `range_m` of the robot centre and within half the field of view of
/// its heading is reported, except with probability `miss_rate`; a reported puck has a wrong
/// colour (uniform among the other colours) with probability `false_colour_rate`.
struct ColourCameraConfig {
  double range_m = 0.6;
  double fov_rad = 50.0 * core::kPi / 180.0;  ///< full opening angle of the cone
  double frame_rate_hz = 10.0;
  double miss_rate = 0.1;           ///< [0, 1]
  double false_colour_rate = 0.05;  ///< [0, 1]
  double position_noise_m = 0.01;   ///< Gaussian std per axis of a sighting's position
};

/// The hackathon world on top of the 2013 field: the 16 devices stay as (unlit) obstacles, the
/// 20 S0 pucks are replaced by the coloured pucks, `obstacles` are added, the safe area marked.
/// Aggregate with defaults; validate() throws core::ConfigError "hackathon.<field>: reason".
struct HackathonConfig {
  std::vector<kinematic::ObstacleConfig> obstacles = default_obstacles();
  /// Where rescued pucks go (default: the input storage strip, widened to 0.5 m).
  kinematic::Rect safe_area{{0.0, 2.3}, {0.5, 3.3}};
  /// The planner place in front of the safe area (a held puck lands on the area's centre).
  std::string safe_place = "SAFE";
  std::vector<HackathonColour> colours = default_colours();
  /// Free space between a puck's edge and walls, devices, obstacles, the safe area and the
  /// robots' start discs.
  double puck_clearance_m = 0.2;
  /// Least distance between two puck centres.
  double puck_spacing_m = 0.3;
  int points_per_puck = 10;  ///< per counted puck in the safe area
  int decoy_penalty = 5;     ///< subtracted per decoy in the safe area
  ColourCameraConfig camera;

  /// Four 0.3 x 0.3 m boxes in free lanes of the 2013 field, clear of every device place.
  static std::vector<kinematic::ObstacleConfig> default_obstacles();
  /// red, green, blue (3 each, counted) and yellow (3, decoy).
  static std::vector<HackathonColour> default_colours();

  /// Throws core::ConfigError naming the field for bad values, obstacles outside the field or
  /// overlapping a device, the safe area, each other or a robot's start, a safe area outside
  /// the field or overlapping a device.
  void validate(const kinematic::WorldConfig& world) const;
  /// Index of colour `name` in `colours`, or -1.
  int colour_index(std::string_view name) const;
};

/// A coloured puck of the layout.
struct HackathonPuck {
  core::PuckId id;
  int colour = 0;  ///< index into HackathonConfig::colours
  core::Vec2 position{0.0, 0.0};
};

/// Where the pucks lie at the start of one game.
struct HackathonLayout {
  std::vector<HackathonPuck> pucks;  ///< ids 1..N, in the order of `colours`
};

/// Draws the layout from the stream "sim/hackathon/layout" of `rng`: every puck uniformly in the
/// field, rejected while it is within the clearances of a wall, device, obstacle, the safe area
/// or a robot's start, or closer than puck_spacing_m to an earlier puck. Throws core::ConfigError
/// "hackathon.colours: ..." if a puck finds no spot within 10,000 draws.
HackathonLayout generate_hackathon_layout(const HackathonConfig& config,
                                          const kinematic::WorldConfig& world,
                                          const core::Rng& rng);

/// Puts the layout into the world: obstacles added, pucks replaced.
void apply_hackathon_layout(const HackathonConfig& config, const HackathonLayout& layout,
                            kinematic::WorldConfig& world);

/// The pose of the safe place: facing from the field into the safe area (along its axis that
/// points away from the field centre), `held_puck_offset_m` before the area's centre, so that
/// a held puck lands on it.
core::Pose2D hackathon_safe_pose(const HackathonConfig& config, const kinematic::WorldConfig& world,
                                 double held_puck_offset_m);

/// A puck's state for scoring.
struct HackathonPuckState {
  core::PuckId id;
  core::Vec2 position{0.0, 0.0};
  bool on_field = true;  ///< false once removed
  bool held = false;     ///< in a robot's holder pocket
};

/// Counts of one colour.
struct HackathonColourScore {
  std::string colour;
  bool decoy = false;
  int total = 0;         ///< pucks of the colour in the layout
  int in_safe_area = 0;  ///< of them released inside the safe area
};

/// The hackathon score: a puck counts when its centre lies inside the safe area (closed
/// rectangle) and no robot holds it. points = rescued * points_per_puck - decoys *
/// decoy_penalty (may be negative).
struct HackathonScore {
  int points = 0;
  int rescued = 0;    ///< counted-colour pucks in the safe area
  int decoys = 0;     ///< decoy pucks in the safe area
  int rescuable = 0;  ///< counted-colour pucks in the layout
  int total_pucks = 0;
  std::vector<HackathonColourScore> colours;  ///< in the order of HackathonConfig::colours
  std::vector<core::PuckId> in_safe_area;     ///< pucks (of any colour) that count now
};

/// Scores `pucks` (any order; pucks not in the layout are ignored).
HackathonScore score_hackathon(const HackathonConfig& config, const HackathonLayout& layout,
                               std::span<const HackathonPuckState> pucks);

/// Reads the scenario's `hackathon:` map (null: all defaults) and validates it against `world`.
/// Throws core::ConfigError "file:line:column: hackathon.<key>: reason".
HackathonConfig load_hackathon_config(const core::ConfigNode& node,
                                      const kinematic::WorldConfig& world);

}  // namespace llsf::sim
