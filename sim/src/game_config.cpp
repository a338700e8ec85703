// SPDX-License-Identifier: MIT
#include "llsf/sim/game_config.h"

#include <cmath>
#include <sstream>

#include "llsf/core/error.h"
#include "llsf/core/geometry.h"

namespace llsf::sim {

namespace {

[[noreturn]] void fail(const std::string& field, const std::string& reason) {
  throw core::ConfigError("game." + field + ": " + reason);
}

std::string num(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

void positive(const std::string& field, double v) {
  if (!(v > 0.0) || !std::isfinite(v)) fail(field, "must be > 0 (got " + num(v) + ")");
}

void non_negative(const std::string& field, double v) {
  if (!(v >= 0.0) || !std::isfinite(v)) fail(field, "must be >= 0 (got " + num(v) + ")");
}

void probability(const std::string& field, double v) {
  if (!(v >= 0.0 && v <= 1.0)) fail(field, "must be in [0, 1] (got " + num(v) + ")");
}

void angle(const std::string& field, double v) {
  if (!(v > 0.0 && v <= core::kPi)) fail(field, "must be in (0, pi] (got " + num(v) + ")");
}

}  // namespace

const char* to_string(LocalizationLevel level) {
  return level == LocalizationLevel::kGroundTruth ? "ground_truth" : "noisy";
}

const char* to_string(DetectionLevel level) {
  return level == DetectionLevel::kGroundTruth ? "ground_truth" : "vision";
}

const char* to_string(SkillLevel level) {
  return level == SkillLevel::kPhysical ? "physical" : "symbolic";
}

void GameConfig::validate() const {
  // Localization.
  const LocalizationConfig& l = levels.localization;
  if (l.correction_period <= SimTime())
    fail("levels.localization.correction_period", "must be > 0");
  if (!(l.correction_gain > 0.0 && l.correction_gain <= 1.0)) {
    fail("levels.localization.correction_gain",
         "must be in (0, 1] (got " + num(l.correction_gain) + ")");
  }
  non_negative("levels.localization.position_noise_m", l.position_noise_m);
  non_negative("levels.localization.heading_noise_rad", l.heading_noise_rad);
  // Symbolic skill level.
  if (!(levels.symbolic.cruise_speed_mps > 0.0)) {
    fail("levels.symbolic.cruise_speed_mps", "must be > 0");
  }
  if (!(levels.symbolic.turn_rate_rps > 0.0)) fail("levels.symbolic.turn_rate_rps", "must be > 0");
  // Light detection.
  const LightDetectionConfig& li = levels.light;
  positive("levels.light.range_m", li.range_m);
  angle("levels.light.half_angle_rad", li.half_angle_rad);
  angle("levels.light.facing_half_angle_rad", li.facing_half_angle_rad);
  positive("levels.light.frame_rate_hz", li.frame_rate_hz);
  if (li.delay < SimTime()) fail("levels.light.delay", "must be >= 0");
  if (li.delay > SimTime::from_sec(60)) fail("levels.light.delay", "must be at most 60 s");
  probability("levels.light.error_rate", li.error_rate);
  // Puck detection.
  const PuckDetectionConfig& p = levels.puck;
  positive("levels.puck.range_m", p.range_m);
  positive("levels.puck.vision_range_m", p.vision_range_m);
  angle("levels.puck.half_angle_rad", p.half_angle_rad);
  non_negative("levels.puck.merge_distance_m", p.merge_distance_m);
  positive("levels.puck.frame_rate_hz", p.frame_rate_hz);
  // Rates.
  positive("skill_rate_hz", skill_rate_hz);
  positive("agent_rate_hz", agent_rate_hz);
  if (beacon_period <= SimTime()) fail("beacon_period", "must be > 0");
  const double physics_hz = 1e9 / static_cast<double>(world.physics.step.ns());
  if (world.physics.step > SimTime() && skill_rate_hz > physics_hz) {
    fail("skill_rate_hz", "must not exceed the physics rate " + num(physics_hz) + " Hz (got " +
                              num(skill_rate_hz) + ")");
  }
  if (world.physics.step > SimTime() && agent_rate_hz > physics_hz) {
    fail("agent_rate_hz", "must not exceed the physics rate " + num(physics_hz) + " Hz (got " +
                              num(agent_rate_hz) + ")");
  }
  // Handling (robot profiles).
  non_negative("handling.align_s", handling.align_s);
  if (handling.align_s > 60.0) fail("handling.align_s", "must be at most 60 s");
  non_negative("handling.motor_max_speed_mps", handling.motor_max_speed_mps);
  non_negative("handling.motor_max_omega_rps", handling.motor_max_omega_rps);
  probability("handling.jam_probability", handling.jam_probability);
  non_negative("handling.jam_zone_m", handling.jam_zone_m);
  non_negative("handling.jam_recovery_s", handling.jam_recovery_s);
  non_negative("handling.align_min_drive_m", handling.align_min_drive_m);
  // The modules' own configs.
  world.validate();
  refbox.validate();
  protocol.validate();
  hub.validate();
  planner.validate();
  controller.validate();
  if (hackathon) {
    try {
      hackathon->validate(world);
    } catch (const core::ConfigError& e) {
      throw core::ConfigError("game." + std::string(e.what()));
    }
  }
}

GameConfig prepare_game_config(GameConfig config) {
  config.validate();
  if (!config.hackathon || config.hackathon_layout) return config;
  const HackathonConfig& h = *config.hackathon;
  config.hackathon_layout = generate_hackathon_layout(h, config.world, core::Rng(config.seed));
  apply_hackathon_layout(h, *config.hackathon_layout, config.world);
  config.planner.places.extra.push_back(
      {h.safe_place,
       hackathon_safe_pose(h, config.world, config.planner.places.held_puck_offset_m)});
  return config;
}

}  // namespace llsf::sim
