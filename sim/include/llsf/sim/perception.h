// SPDX-License-Identifier: MIT
// Perception models: what a robot's software believes from its sensors at the configured
// abstraction levels (docs/levels.md). Each model owns its state and its random stream; the
// RobotStack feeds them the world's readings in tick step 6 and serves their results to the
// skills (lua::RobotApi). None of them touches the World.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "llsf/core/rng.h"
#include "llsf/core/sim_time.h"
#include "llsf/kinematic/sensors.h"
#include "llsf/kinematic/world.h"
#include "llsf/lua/robot_api.h"
#include "llsf/sim/game_config.h"

namespace llsf::sim {

/// Static description of a device for the light detection: its pose (heading = the facing, the
/// direction its front looks onto the field) and its front (the RFID zone centre).
struct DeviceView {
  std::string name;
  core::Pose2D pose;
  core::Vec2 front{0.0, 0.0};
};

/// The pose estimate (LocalizationConfig): ground truth, or the AMCL stand-in -- odometry dead
/// reckoning, pulled towards a noisy measurement of the true pose every correction period.
class Localization {
 public:
  Localization(const LocalizationConfig& config, const core::Pose2D& start, core::RandomStream rng);
  /// Tick step 6: the estimate at `now` from the true pose and the wheel odometry.
  void update(SimTime now, const core::Pose2D& truth, const kinematic::OdometryReading& odometry);
  /// The robot was moved from `from` to `to` without driving (a symbolic move): the estimate
  /// jumps along at the next update, keeping its error relative to the truth.
  void teleported(const core::Pose2D& from, const core::Pose2D& to);
  const lua::PoseEstimate& estimate() const { return pose_; }

 private:
  LocalizationConfig c_;
  core::RandomStream rng_;
  lua::PoseEstimate pose_;
  core::Pose2D est_ref_;  ///< estimate at the last correction
  core::Pose2D odo_ref_;  ///< odometry at the last correction
  bool teleported_ = false;
  core::Pose2D teleport_from_;
  core::Pose2D teleport_to_;
  SimTime next_correction_;
};

/// The signal-light detection (LightDetectionConfig): ground truth, or the webcam -- frames at
/// its rate, the lamps' states read over a blink period (or as the simulation knows them with
/// `reads_states`), seeded misreads, and the processing delay.
class LightDetection {
 public:
  LightDetection(const LightDetectionConfig& config, std::vector<DeviceView> devices,
                 core::RandomStream rng);
  /// Tick step 6. `lights`: the 16 devices' lamps in DeviceId order.
  void update(SimTime now, const core::Pose2D& truth,
              std::span<const kinematic::SignalLights> lights);
  const lua::LightReading& reading() const { return light_; }

 private:
  /// A light reading of one vision frame (before the delay).
  struct Frame {
    SimTime stamp;
    lua::LightReading reading;
  };
  void update_ground_truth(SimTime now, const core::Pose2D& truth,
                           std::span<const kinematic::SignalLights> lights);
  void update_vision(SimTime now, const core::Pose2D& truth,
                     std::span<const kinematic::SignalLights> lights);
  /// The nearest device whose front is in front of `pose` (within the range and the heading
  /// cone, with the robot on the front's side); with `vision` the robot must also stand within
  /// the facing cone of the device. -1 if none. The last answer is kept: a robot standing
  /// still (the same pose to the bit) is answered without looking at the devices again.
  int device_in_front(const core::Pose2D& pose, bool vision);
  void set(const lua::LightReading& r, SimTime now);

  LightDetectionConfig c_;
  std::vector<DeviceView> devices_;
  core::RandomStream rng_;
  lua::LightReading light_;
  SimTime next_frame_;
  int device_ = -1;         ///< device observed by the vision frames, -1 none
  SimTime observed_since_;  ///< first frame of the current device
  /// Recent frames of the current device: stamp and lit lamps (bit 0 red, 1 yellow, 2 green).
  std::vector<std::pair<SimTime, std::uint8_t>> lit_history_;
  int lit_head_ = 0;
  int lit_count_ = 0;
  std::vector<Frame> frames_;  ///< ring buffer of vision frames awaiting their delay
  int frame_head_ = 0;         ///< index of the oldest frame
  int frame_count_ = 0;
  struct FrontAnswer {
    core::Pose2D pose;
    bool vision = false;
    int device = -2;  ///< -2: none kept yet
  };
  FrontAnswer front_;  ///< device_in_front()'s last answer
};

/// The puck detection (PuckDetectionConfig): every puck in range (ground truth), or the camera
/// -- frames at its rate, pucks in the view cone, close pucks merged into one blob.
class PuckVision {
 public:
  explicit PuckVision(const PuckDetectionConfig& config);
  /// Tick step 6. `pucks`: field positions of every puck on the field.
  void update(SimTime now, const core::Pose2D& truth, std::span<const core::Vec2> pucks);
  std::span<const lua::PuckSighting> sightings() const { return sightings_; }

 private:
  PuckDetectionConfig c_;
  SimTime next_frame_;
  std::vector<lua::PuckSighting> sightings_;
  std::vector<core::Vec2> scratch_;
  std::vector<int> cluster_;
};

}  // namespace llsf::sim
