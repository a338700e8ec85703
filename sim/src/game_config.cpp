// SPDX-License-Identifier: MIT
#include "llsf/sim/game_config.h"

#include <cmath>
#include <utility>

#include "llsf/core/assert.h"
#include "llsf/core/error.h"
#include "llsf/core/geometry.h"
#include "llsf/sim/extension.h"

namespace llsf::sim {

namespace {

[[noreturn]] void fail(const std::string& field, const std::string& reason) {
  throw core::ConfigError("game." + field + ": " + reason);
}

std::string num(double v) { return core::number_text(v); }

/// `value` of the game field `field` (named without the "game." prefix) within `bound`.
void require_game(const std::string& field, double value, const core::Bound& bound) {
  core::require("game." + field, value, bound);
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

const char* to_string(NavigationLevel level) {
  return level == NavigationLevel::kIdeal ? "ideal" : "move_base-2013";
}

void GameConfig::validate() const {
  // Localization.
  const LocalizationConfig& l = levels.localization;
  if (l.correction_period <= SimTime())
    fail("levels.localization.correction_period", "must be > 0");
  require_game("levels.localization.correction_gain", l.correction_gain, core::fraction());
  require_game("levels.localization.position_noise_m", l.position_noise_m, core::non_negative());
  require_game("levels.localization.heading_noise_rad", l.heading_noise_rad, core::non_negative());
  if (levels.navigation == NavigationLevel::kMoveBase2013) {
    levels.move_base.validate();
    if (!world.sensors.laser.enabled) {
      fail("levels.navigation",
           "move_base-2013 sees obstacles only with the laser: enable "
           "world.sensors.laser");
    }
  }
  // Symbolic skill level.
  if (!(levels.symbolic.cruise_speed_mps > 0.0)) {
    fail("levels.symbolic.cruise_speed_mps", "must be > 0");
  }
  if (!(levels.symbolic.turn_rate_rps > 0.0)) fail("levels.symbolic.turn_rate_rps", "must be > 0");
  if (referee_remove_delay < SimTime() || referee_remove_delay > SimTime::from_sec(60)) {
    fail("referee_remove_delay", "must be in [0, 60] s");
  }
  // Light detection.
  const LightDetectionConfig& li = levels.light;
  require_game("levels.light.range_m", li.range_m, core::positive());
  require_game("levels.light.cluster_max_x_m", li.cluster_max_x_m, core::positive());
  require_game("levels.light.cluster_half_width_m", li.cluster_half_width_m, core::positive());
  if (li.cluster_min_x_m < 0.0 || li.cluster_min_x_m >= li.cluster_max_x_m) {
    fail("levels.light.cluster_min_x_m", "must be in [0, cluster_max_x_m)");
  }
  angle("levels.light.half_angle_rad", li.half_angle_rad);
  angle("levels.light.facing_half_angle_rad", li.facing_half_angle_rad);
  require_game("levels.light.frame_rate_hz", li.frame_rate_hz, core::positive());
  if (li.delay < SimTime()) fail("levels.light.delay", "must be >= 0");
  if (li.delay > SimTime::from_sec(60)) fail("levels.light.delay", "must be at most 60 s");
  require_game("levels.light.error_rate", li.error_rate, core::probability());
  // Puck detection.
  const PuckDetectionConfig& p = levels.puck;
  require_game("levels.puck.range_m", p.range_m, core::positive());
  require_game("levels.puck.vision_range_m", p.vision_range_m, core::positive());
  angle("levels.puck.half_angle_rad", p.half_angle_rad);
  require_game("levels.puck.merge_distance_m", p.merge_distance_m, core::non_negative());
  require_game("levels.puck.frame_rate_hz", p.frame_rate_hz, core::positive());
  // Rates.
  require_game("skill_rate_hz", skill_rate_hz, core::positive());
  require_game("agent_rate_hz", agent_rate_hz, core::positive());
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
  require_game("handling.align_s", handling.align_s, core::non_negative());
  if (handling.align_s > 60.0) fail("handling.align_s", "must be at most 60 s");
  require_game("handling.motor_max_speed_mps", handling.motor_max_speed_mps, core::non_negative());
  require_game("handling.motor_max_omega_rps", handling.motor_max_omega_rps, core::non_negative());
  require_game("handling.jam_probability", handling.jam_probability, core::probability());
  require_game("handling.jam_zone_m", handling.jam_zone_m, core::non_negative());
  require_game("handling.jam_recovery_s", handling.jam_recovery_s, core::non_negative());
  require_game("handling.align_min_drive_m", handling.align_min_drive_m, core::non_negative());
  // External radio peers: names unique among the hub's peers (refbox, robots, each other).
  for (std::size_t i = 0; i < external_peers.size(); ++i) {
    const ExternalPeerConfig& e = external_peers[i];
    const std::string field = "external_peers[" + std::to_string(i) + "]";
    if (e.name.empty()) fail(field + ".name", "must not be empty");
    if (e.channel.empty()) fail(field + ".channel", "must not be empty");
    bool taken = e.name == "refbox";
    for (const kinematic::RobotStart& r : world.robots) taken = taken || r.name == e.name;
    for (std::size_t j = 0; j < i; ++j) taken = taken || external_peers[j].name == e.name;
    if (taken) fail(field + ".name", "'" + e.name + "' is the name of another radio peer");
  }
  // The modules' own configs.
  world.validate();
  refbox.validate();
  protocol.validate();
  hub.validate();
  planner.validate();
  controller.validate();
  for (const auto& extension : extensions) {
    LLSF_DEMAND(extension != nullptr);
    extension->validate(*this);
  }
}

GameConfig prepare_game_config(GameConfig config) { return prepare_game(std::move(config)).config; }

}  // namespace llsf::sim
