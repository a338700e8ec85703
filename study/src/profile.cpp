// SPDX-License-Identifier: MIT
#include "llsf/study/profile.h"

#include <cmath>
#include <sstream>
#include <stdexcept>

#include "llsf/core/error.h"
#include "llsf/lua/skill_engine.h"

namespace llsf::study {

namespace {

[[noreturn]] void fail(const std::string& field, const std::string& reason) {
  throw core::ConfigError("profile." + field + ": " + reason);
}

std::string num(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

void positive(const char* field, double v) {
  if (!(v > 0.0) || !std::isfinite(v)) fail(field, "must be > 0 (got " + num(v) + ")");
}

void non_negative(const char* field, double v) {
  if (!(v >= 0.0) || !std::isfinite(v)) fail(field, "must be >= 0 (got " + num(v) + ")");
}

void at_most(const char* field, double v, double max) {
  if (v > max) fail(field, "must be at most " + num(max) + " (got " + num(v) + ")");
}

// The 2013 Carologistics Robotino as the thesis' Gazebo games show it. docs/profiles.md has the
// same table with the reasoning; keep both in step.
RobotProfile robotino_2013() {
  RobotProfile p;
  p.name = "robotino-2013";
  // Assumption: a 2013 Robotino on move_base (no source gives its speed; the sensitivity sweep
  // varies it); the turn rate halved with it.
  p.max_speed_mps = 0.5;
  p.max_omega_rps = 1.0;
  p.max_accel_mps2 = 0.5;  // assumption: half the ideal, with the halved top speed
  p.max_alpha_rps2 = 2.0;  // assumption: likewise
  // Assumption: Fawkes' relative motion at a machine creeps (no source gives a figure).
  p.motor_max_speed_mps = 0.15;
  p.motor_max_omega_rps = 0.5;
  // Calibrated (the only calibrated figure): a single P1P2 robot's first complex product at
  // 10:30 min (thesis §5.3.3); move_base's goal approach and the laser alignment in front of a
  // machine after every drive.
  p.align_s = 12.0;
  // Thesis §6.1.1: webcam at 2 Hz, light detection about 1 s late; §6.1.3: the light
  // detection is very reliable in the simulation.
  p.light = sim::DetectionLevel::kVision;
  p.light_frame_rate_hz = 2.0;
  p.light_delay_s = 1.0;
  p.light_error_rate = 0.0;
  // Thesis §5.1.3: Gazsim-Light-Front takes the lights' states from the simulation (a blinking
  // lamp is a state, not pixels a 2 Hz camera would alias).
  p.light_reads_states = true;
  p.laser_rate_hz = 5.0;  // thesis §6.1.1: half the real sensor's 10 Hz
  // Thesis §6.1.1: amcl, no difference to reality seen; Fig. 6.4c: wrongly localized robots.
  p.localization = sim::LocalizationLevel::kNoisy;
  // Assumption: move_base's recovery behaviour (thesis §6.1.1 "looks nervous and does much
  // recovery behavior when facing obstacles"; §6.2: passing each other "can take much time").
  p.wait_before_replan_s = 3.0;
  p.backoff_min_s = 2.0;
  p.backoff_max_s = 8.0;
  p.blocked_timeout_s = 90.0;
  // Assumption (no source gives a rate; docs/validation.md sweeps it): Fig. 6.4a/b, stuck
  // at a machine during low-level movement.
  p.jam_probability = 0.02;
  // Thesis §6.2: "there is no timeout to detect that the robot is stuck".
  p.stuck_detection = false;
  return p;
}

}  // namespace

std::vector<std::string> RobotProfile::names() { return {"ideal", "robotino-2013"}; }

RobotProfile RobotProfile::named(std::string_view name) {
  if (name == "ideal") return RobotProfile{};
  if (name == "robotino-2013") return robotino_2013();
  throw std::invalid_argument("unknown robot profile '" + std::string(name) + "'");
}

void RobotProfile::validate() const {
  positive("max_speed_mps", max_speed_mps);
  positive("max_omega_rps", max_omega_rps);
  positive("max_accel_mps2", max_accel_mps2);
  positive("max_alpha_rps2", max_alpha_rps2);
  at_most("max_speed_mps", max_speed_mps, 3.0);
  non_negative("motor_max_speed_mps", motor_max_speed_mps);
  non_negative("motor_max_omega_rps", motor_max_omega_rps);
  non_negative("align_s", align_s);
  at_most("align_s", align_s, 60.0);
  positive("light_frame_rate_hz", light_frame_rate_hz);
  at_most("light_frame_rate_hz", light_frame_rate_hz, 100.0);
  non_negative("light_delay_s", light_delay_s);
  at_most("light_delay_s", light_delay_s, 60.0);
  if (!(light_error_rate >= 0.0 && light_error_rate <= 1.0))
    fail("light_error_rate", "must be in [0, 1] (got " + num(light_error_rate) + ")");
  positive("laser_rate_hz", laser_rate_hz);
  at_most("laser_rate_hz", laser_rate_hz, 100.0);
  non_negative("position_noise_m", position_noise_m);
  non_negative("heading_noise_rad", heading_noise_rad);
  non_negative("wait_before_replan_s", wait_before_replan_s);
  non_negative("backoff_min_s", backoff_min_s);
  if (!(backoff_max_s >= backoff_min_s) || !std::isfinite(backoff_max_s))
    fail("backoff_max_s", "must be >= backoff_min_s (got " + num(backoff_max_s) + ")");
  positive("blocked_timeout_s", blocked_timeout_s);
  at_most("blocked_timeout_s", blocked_timeout_s, 3600.0);
  if (!(jam_probability >= 0.0 && jam_probability <= 1.0))
    fail("jam_probability", "must be in [0, 1] (got " + num(jam_probability) + ")");
}

void RobotProfile::apply(sim::GameConfig& game, lua::SkillEngineConfig& skills) const {
  game.profile = name;
  kinematic::RobotModelConfig& r = game.world.robot;
  r.max_speed_mps = max_speed_mps;
  r.max_omega_rps = max_omega_rps;
  r.max_accel_mps2 = max_accel_mps2;
  r.max_alpha_rps2 = max_alpha_rps2;
  planner::ControllerConfig& c = game.controller;
  c.max_speed_mps = max_speed_mps;
  c.max_omega_rps = max_omega_rps;
  c.max_accel_mps2 = max_accel_mps2;
  c.max_alpha_rps2 = max_alpha_rps2;
  c.wait_before_replan_s = wait_before_replan_s;
  c.backoff_min_s = backoff_min_s;
  c.backoff_max_s = backoff_max_s;
  c.blocked_timeout_s = blocked_timeout_s;
  game.world.sensors.laser.rate_hz = laser_rate_hz;
  sim::LightDetectionConfig& l = game.levels.light;
  l.level = light;
  l.frame_rate_hz = light_frame_rate_hz;
  l.delay = core::SimTime::from_seconds(light_delay_s);
  l.error_rate = light_error_rate;
  l.reads_states = light_reads_states;
  sim::LocalizationConfig& loc = game.levels.localization;
  loc.level = localization;
  loc.position_noise_m = position_noise_m;
  loc.heading_noise_rad = heading_noise_rad;
  sim::HandlingConfig& h = game.handling;
  h.align_s = align_s;
  h.motor_max_speed_mps = motor_max_speed_mps;
  h.motor_max_omega_rps = motor_max_omega_rps;
  h.jam_probability = jam_probability;
  h.stuck_detection = stuck_detection;
  skills.stuck_detection = stuck_detection;
  skills.profile = name;
}

namespace {

// The profile's figures by key: what load_profile reads (and accepts besides name, light,
// localization).
struct NumberKey {
  const char* key;
  double RobotProfile::*field;
};
constexpr NumberKey kNumbers[] = {
    {"max_speed_mps", &RobotProfile::max_speed_mps},
    {"max_omega_rps", &RobotProfile::max_omega_rps},
    {"max_accel_mps2", &RobotProfile::max_accel_mps2},
    {"max_alpha_rps2", &RobotProfile::max_alpha_rps2},
    {"motor_max_speed_mps", &RobotProfile::motor_max_speed_mps},
    {"motor_max_omega_rps", &RobotProfile::motor_max_omega_rps},
    {"align_s", &RobotProfile::align_s},
    {"light_frame_rate_hz", &RobotProfile::light_frame_rate_hz},
    {"light_delay_s", &RobotProfile::light_delay_s},
    {"light_error_rate", &RobotProfile::light_error_rate},
    {"laser_rate_hz", &RobotProfile::laser_rate_hz},
    {"position_noise_m", &RobotProfile::position_noise_m},
    {"heading_noise_rad", &RobotProfile::heading_noise_rad},
    {"wait_before_replan_s", &RobotProfile::wait_before_replan_s},
    {"backoff_min_s", &RobotProfile::backoff_min_s},
    {"backoff_max_s", &RobotProfile::backoff_max_s},
    {"blocked_timeout_s", &RobotProfile::blocked_timeout_s},
    {"jam_probability", &RobotProfile::jam_probability},
};

RobotProfile named_or_fail(const core::ConfigNode& n) {
  try {
    return RobotProfile::named(n.as_string());
  } catch (const std::invalid_argument&) {
    n.fail("unknown profile '" + n.as_string() + "' (known: ideal, robotino-2013)");
  }
}

template <class E>
void read_level(const core::ConfigNode& node, const char* key, E& out, const char* a, E va,
                const char* b, E vb) {
  if (!node[key].defined()) return;
  const std::string v = node[key].as_string();
  if (v == a) {
    out = va;
  } else if (v == b) {
    out = vb;
  } else {
    node[key].fail("'" + v + "' is not one of " + a + ", " + b);
  }
}

}  // namespace

RobotProfile load_profile(const core::ConfigNode& node) {
  if (node.is_scalar()) return named_or_fail(node);
  node.require_map();
  for (const std::string& key : node.keys()) {
    bool known = key == "name" || key == "light" || key == "localization" ||
                 key == "light_reads_states" || key == "stuck_detection";
    for (const NumberKey& k : kNumbers) known = known || key == k.key;
    if (!known) {
      std::string allowed = "name, light, localization, light_reads_states, stuck_detection";
      for (const NumberKey& k : kNumbers) allowed += std::string(", ") + k.key;
      node[key].fail("unknown key '" + key + "' (allowed: " + allowed + ")");
    }
  }
  RobotProfile p;
  if (node["name"].defined()) p = named_or_fail(node["name"]);
  for (const NumberKey& k : kNumbers) node.read(k.key, p.*k.field);
  read_level(node, "light", p.light, "ground_truth", sim::DetectionLevel::kGroundTruth, "vision",
             sim::DetectionLevel::kVision);
  read_level(node, "localization", p.localization, "ground_truth",
             sim::LocalizationLevel::kGroundTruth, "noisy", sim::LocalizationLevel::kNoisy);
  node.read("light_reads_states", p.light_reads_states);
  node.read("stuck_detection", p.stuck_detection);
  try {
    p.validate();
  } catch (const core::ConfigError& e) {
    // Name the key in the file: "profile.max_speed_mps: ..." -> that key's node.
    const std::string what = e.what();
    const std::string prefix = "profile.";
    const std::size_t colon = what.find(':');
    if (what.rfind(prefix, 0) == 0 && colon != std::string::npos) {
      const std::string key = what.substr(prefix.size(), colon - prefix.size());
      if (node[key].defined()) node[key].fail(what.substr(colon + 2));
    }
    node.fail(what);
  }
  return p;
}

}  // namespace llsf::study
