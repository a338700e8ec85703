// SPDX-License-Identifier: MIT
// GameConfig: everything a game is built from -- world, refbox, radio, navigation, the robots'
// abstraction levels, the seed and the tick rates (docs/sim.md documents every field).
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "llsf/comm/hub_config.h"
#include "llsf/comm/proto_library.h"
#include "llsf/core/sim_time.h"
#include "llsf/kinematic/world_config.h"
#include "llsf/planner/config.h"
#include "llsf/planner/move_base.h"
#include "llsf/refbox/config.h"
#include "llsf/refbox/protocol.h"

namespace llsf::sim {

using core::SimTime;

class GameExtensionFactory;  // extension.h

/// Localization abstraction level: what RobotApi::pose() returns.
enum class LocalizationLevel : std::uint8_t {
  kGroundTruth,  ///< the world's true pose
  kNoisy,        ///< wheel odometry between periodic noisy corrections (an AMCL stand-in)
};
/// Light-signal and puck detection abstraction levels.
enum class DetectionLevel : std::uint8_t {
  kGroundTruth,  ///< what is there, at once
  kVision,       ///< a camera: field of view, range, delay, errors, merged sightings
};
/// Skill abstraction level: how the skill library acts on the world.
enum class SkillLevel : std::uint8_t {
  kPhysical,  ///< skills drive the robot through navigator and motor; pucks move by contact
  kSymbolic,  ///< skills wait an estimated duration, then the world is changed directly
};
/// Navigation level: what drives the robot to a goal (docs/planner.md).
enum class NavigationLevel : std::uint8_t {
  kIdeal,         ///< planner::Navigator: OMPL paths, other robots known everywhere as discs
  kMoveBase2013,  ///< planner::MoveBaseNavigator: the 2013 team's move_base, laser-only
};
/// "ground_truth", "noisy", "vision", "physical", "symbolic", "ideal", "move_base-2013".
const char* to_string(NavigationLevel level);
const char* to_string(LocalizationLevel level);
const char* to_string(DetectionLevel level);
const char* to_string(SkillLevel level);

/// Localization. `noisy`: the estimate follows the odometry sensor's motion; every
/// `correction_period` it is pulled towards the true pose plus Gaussian noise
/// (estimate += correction_gain * (truth + noise - estimate)), like an AMCL update.
struct LocalizationConfig {
  LocalizationLevel level = LocalizationLevel::kGroundTruth;
  SimTime correction_period = SimTime::from_sec(1);
  double correction_gain = 1.0;  ///< (0, 1]: 1 = jump to the noisy measurement
  /// Std of the correction's x and y error. The default keeps the jumps mostly within the
  /// navigator's 2 cm arrival tolerance (see docs/sim.md).
  double position_noise_m = 0.01;
  double heading_noise_rad = 0.01;  ///< std of the correction's heading error
};

/// Which device the light detection reads.
enum class LightView : std::uint8_t {
  /// The device whose front is ahead and faces the robot (LightDetectionConfig): llsfsim's
  /// reader of the light the device shows towards the field.
  kFront,
  /// The 2013 Carologistics light detection (thesis §5.1.3, Gazsim-Light-Front): the laser
  /// cluster plugin finds the device nearest to the robot within its window ahead, from any side
  /// (a device's signal tower is seen all around), and the camera reads that device's lamps.
  kLaserCluster,
};

/// Light-signal detection of the device in front. A device is "in front" when its front (the
/// RFID zone centre) lies within `range_m` of the robot and within `half_angle_rad` of its
/// heading, and the robot is on the front's side; the nearest such device is read. `vision`
/// additionally needs the robot within `facing_half_angle_rad` of the device's facing (looking
/// at the front of the light, not from the side), samples at `frame_rate_hz`,
/// reports a reading only after a full blink period of frames of one device (blink = lit and
/// unlit frames within that period), `delay` late, and with probability `error_rate` per
/// reading one lamp is reported wrong. With `view` kLaserCluster the device is chosen as the
/// 2013 team's light detection chose it instead (see LightView).
struct LightDetectionConfig {
  DetectionLevel level = DetectionLevel::kGroundTruth;
  LightView view = LightView::kFront;
  /// kLaserCluster: the laser-cluster window in the robot frame (x forward, y left), metres: the
  /// 2013 team's cfg/conf.d/laser-cluster.yaml (cluster_min_x 0.02, cluster_max_x 0.8,
  /// cluster_min_y -0.7, cluster_max_y 0.7).
  double cluster_min_x_m = 0.02;
  double cluster_max_x_m = 0.8;
  double cluster_half_width_m = 0.7;
  double range_m = 1.0;
  double half_angle_rad = 0.35;
  double facing_half_angle_rad = 1.0;    ///< vision only
  double frame_rate_hz = 10.0;           ///< vision only
  SimTime delay = SimTime::from_sec(1);  ///< vision only
  double error_rate = 0.05;              ///< vision only; [0, 1]
  /// vision only: each frame reads the lamps' states (on, off, blinking) of the device in front,
  /// as the thesis' Gazsim-Light-Front plugin took them from the simulation (thesis §5.1.3),
  /// instead of classifying lit and unlit frames (which needs several frames per blink period:
  /// a 2 Hz camera cannot tell a 2 Hz blink from a steady lamp).
  bool reads_states = false;
};

/// Puck detection (relative positions in the robot frame). `ground_truth`: every puck within
/// `range_m`. `vision`: pucks within `vision_range_m` and `half_angle_rad` of the heading,
/// pucks closer than `merge_distance_m` to each other merged into one sighting (their centroid),
/// updated at `frame_rate_hz`.
struct PuckDetectionConfig {
  DetectionLevel level = DetectionLevel::kGroundTruth;
  double range_m = 2.0;
  double vision_range_m = 1.2;
  double half_angle_rad = 0.6;
  double merge_distance_m = 0.12;
  double frame_rate_hz = 10.0;
};

/// The symbolic skill level's duration estimate of a drive: planned path length over
/// `cruise_speed_mps` plus the heading change over `turn_rate_rps`.
struct SymbolicConfig {
  double cruise_speed_mps = 0.6;
  double turn_rate_rps = 1.5;
};

/// The robots' low-level behaviour that sets the pace and the failures of a game (set by a robot
/// profile, docs/profiles.md). The defaults change nothing.
struct HandlingConfig {
  /// After the navigator arrives at the end of a drive of at least `align_min_drive_m`, the
  /// robot spends this long on its fine alignment (move_base's goal approach and the alignment
  /// in front of a machine) before the navigator reports the arrival. Short moves (pushing a
  /// puck under a reader) are not aligned again.
  double align_s = 0.0;
  double align_min_drive_m = 0.5;
  /// Direct motor commands (RobotApi::set_velocity: motor_move, take_puck, ...) are capped to
  /// these; 0 = no cap.
  double motor_max_speed_mps = 0.0;
  double motor_max_omega_rps = 0.0;
  /// A jam: when the robot starts moving by direct motor commands within `jam_zone_m` of a
  /// device's front, it jams against the device with this probability (one draw per such
  /// approach, stream "sim/<robot>/jam"): from then on it neither moves towards the device nor
  /// turns, until a command moves it away from the device (which frees it).
  double jam_probability = 0.0;
  double jam_zone_m = 0.5;
  /// With `stuck_detection`, the skills' recovery frees a jammed robot after this long (their
  /// stall checks notice it and the robot wiggles free); without, only moving away frees it.
  double jam_recovery_s = 5.0;
  /// Whether skills give up when the robot makes no progress (motor_move's stall check and
  /// deadline, take_puck's creep timeout, drive_to's timeout). Skills read it as
  /// `profile.stuck_detection`; false = the thesis' agent, which had no stuck detection.
  bool stuck_detection = true;
};

/// The abstraction levels of every robot's interfaces (RobotApi).
struct RobotLevelsConfig {
  LocalizationConfig localization;
  LightDetectionConfig light;
  PuckDetectionConfig puck;
  SkillLevel skill = SkillLevel::kPhysical;
  SymbolicConfig symbolic;
  NavigationLevel navigation = NavigationLevel::kIdeal;
  /// The figures of the move_base-2013 level (used only at that level).
  planner::MoveBaseConfig move_base;
};

/// A radio peer outside the simulation (a 2013 tool on a served UDP socket, `llsfsim run
/// --refbox-sockets`): a hub peer like a robot, with the hub's loss, delay and outage models
/// (links and outages may name it), whose frames the caller puts into the hub between ticks.
struct ExternalPeerConfig {
  std::string name;
  /// The hub channel: "team" hears and is heard by the robots and the refbox; any other name
  /// (e.g. "public") only by the refbox and the peers of that channel.
  std::string channel = "team";
};

/// Everything a Game is built from. Aggregate with defaults; validate() (the Game constructor
/// calls it) throws core::ConfigError naming the field.
struct GameConfig {
  kinematic::WorldConfig world = kinematic::WorldConfig::default_2013();
  refbox::RefboxConfig refbox;
  refbox::ProtocolConfig protocol;
  comm::HubConfig hub;
  planner::PlannerConfig planner;
  planner::ControllerConfig controller;
  RobotLevelsConfig levels;
  HandlingConfig handling;
  /// The robot profile these fields came from ("ideal" unless a scenario says otherwise).
  std::string profile = "ideal";
  /// Scenario seed: every random draw comes from a named stream of it.
  std::uint64_t seed = 1;
  /// Skill cycles per second (RobotBrain::on_skill_cycle); the physics step comes from
  /// world.physics.step, the refbox is stepped every tick.
  double skill_rate_hz = 30.0;
  /// Agent cycles per second (RobotBrain::on_agent_cycle).
  double agent_rate_hz = 10.0;
  /// Period of every robot's BeaconSignal to the refbox.
  SimTime beacon_period = SimTime::from_sec(1);
  /// Team name in the robots' beacons (empty: the refbox's team).
  std::string team;
  /// How long after the refbox asks for it the referee takes a puck off the field (a delivered
  /// product, a puck out of the game): 0 at once. A delivery gate shows its three lamps until
  /// then (shared/specs/llsf2013-rules.md §2.4: the referee is told to remove the puck).
  SimTime referee_remove_delay;
  /// The game's variants (extension.h), e.g. the hackathon world (HackathonVariant, set by
  /// set_hackathon()): each game makes its own extension from every entry and calls them in this
  /// order at the fixed points of the tick.
  std::vector<std::shared_ptr<const GameExtensionFactory>> extensions;
  /// Radio peers outside the simulation (none unless the game is served on sockets); added to
  /// the hub after the refbox and the robots, in this order.
  std::vector<ExternalPeerConfig> external_peers;
  /// Message types of Fawkes-style agents' own .proto files (docs/fawkes.md), registered with
  /// the radio after llsfsim's (a key taken by another type is a core::ConfigError).
  std::vector<std::shared_ptr<const comm::ProtoLibrary>> agent_protos;

  /// Throws core::ConfigError "game.<field>: reason" for the first bad field (the world,
  /// refbox, protocol, hub and navigation configs are validated by their own validate(), then
  /// every extension by its factory's, in order).
  void validate() const;
};

/// The configuration a Game built from `config` plays (Game::config()): validated, with its
/// extensions' setup() applied (in the hackathon variant the layout of `config.seed` drawn,
/// stream "sim/hackathon/layout", put into the world -- boxes added, pucks replaced -- and the
/// safe place added to the planner's places). For looking at and checking a configuration; a
/// Game is built from the unprepared one (its extensions would add their changes again).
/// Throws core::ConfigError.
GameConfig prepare_game_config(GameConfig config);

}  // namespace llsf::sim
