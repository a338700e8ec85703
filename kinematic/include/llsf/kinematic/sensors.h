// SPDX-License-Identifier: MIT
// Sensor readings a simulated Robotino produces; each sensor samples at its own rate.
#pragma once

#include <cstdint>
#include <vector>

#include "llsf/core/geometry.h"
#include "llsf/core/sim_time.h"

namespace llsf::kinematic {

/// Wheel odometry: the pose integrated from the motion the wheels were commanded to make, in the
/// odometry frame (which coincides with the field frame at the robot's start pose), with error.
struct OdometryReading {
  core::SimTime stamp;
  std::int64_t seq = 0;  ///< increments with every new reading; 0 = none yet
  core::Pose2D pose;
  double vx_mps = 0.0;  ///< commanded wheel velocity, robot frame
  double vy_mps = 0.0;
  double omega_rps = 0.0;
};

/// Gyroscope: measured yaw rate and its integral (starting at the start heading).
struct GyroReading {
  core::SimTime stamp;
  std::int64_t seq = 0;
  double rate_rps = 0.0;
  double yaw_rad = 0.0;
};

/// Infrared distance sensor looking into the puck pocket.
struct IrReading {
  core::SimTime stamp;
  std::int64_t seq = 0;
  double distance_m = 0.0;  ///< from the body front to the puck; the range when nothing is there
  bool puck_detected = false;
};

/// The two digital optical sensors at the holder's arm tips (true = obstacle within range).
struct OpticalReading {
  core::SimTime stamp;
  std::int64_t seq = 0;
  bool left = false;
  bool right = false;
};

/// Ground-truth pose.
struct PoseReading {
  core::SimTime stamp;
  std::int64_t seq = 0;
  core::Pose2D pose;
};

/// A planar laser scan; beam i points at angle_min_rad + i * angle_increment_rad in the robot
/// frame. Ranges in metres; +infinity where no echo came back within the maximum range.
struct LaserScan {
  core::SimTime stamp;
  std::int64_t seq = 0;
  double angle_min_rad = 0.0;
  double angle_increment_rad = 0.0;
  double min_range_m = 0.0;
  double max_range_m = 0.0;
  std::vector<float> ranges;
};

/// The latest reading of every sensor of one robot.
struct RobotSensors {
  OdometryReading odometry;
  GyroReading gyro;
  IrReading ir;
  OpticalReading optical;
  PoseReading ground_truth;
  LaserScan laser;
};

}  // namespace llsf::kinematic
