// SPDX-License-Identifier: MIT
#include "llsf/study/profile.h"

#include <cmath>
#include <stdexcept>

#include "llsf/core/error.h"
#include "llsf/lua/skill_engine.h"

namespace llsf::study {

namespace {

// The 2013 Carologistics Robotino as the thesis' Gazebo games show it, with an omniscient
// navigator and jam dice: the experiment's profile until issue #32 (docs/validation.md, then
// "robotino-2013"), kept to show both side by side. docs/profiles.md has the same table with
// the reasoning; keep both in step.
RobotProfile robotino_2013_omniscient() {
  RobotProfile p;
  p.name = "robotino-2013-omniscient";
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

// The 2013 Carologistics Robotino with the team's own navigation configuration
// (carologistics/fawkes-robotino 6cffc15f2, cfg/move_base_robotino/) and the machines of the
// team's Gazebo simulation. docs/profiles.md has the same table with the sources.
RobotProfile robotino_2013() {
  RobotProfile p = robotino_2013_omniscient();
  p.name = "robotino-2013";
  // base_local_planner_params.yaml: max_vel_x 0.5, acc_lim_x/y 2.5, acc_lim_th 3.2 -- for
  // move_base and for the world's robot alike. move_base turns at most at max_rotational_vel
  // 0.78 rad/s (MoveBaseConfig); the base itself turned as fast as the skills' motor_move
  // commanded (src/lua/skills/robotino/motor_move.lua V_MAX: 0.4 m/s, 2.2 rad/s), which also
  // caps the skills' own motor moves.
  p.max_speed_mps = 0.5;
  p.max_omega_rps = 2.2;
  p.max_accel_mps2 = 2.5;
  p.max_alpha_rps2 = 3.2;
  p.motor_max_speed_mps = 0.4;
  p.motor_max_omega_rps = 2.2;
  // move_base's navigation sees other robots only with the laser (costmap_common_params.yaml:
  // the laser is the only observation source), at the thesis' 5 Hz.
  p.navigation = sim::NavigationLevel::kMoveBase2013;
  p.laser = true;
  // The machine model of the team's Gazebo simulation (carologistics/gazsim-models, as imported
  // into robocup-logistics/gazebo-rcll 15878b3, models/machine/model.sdf): its collision parts
  // span 0.11 m along the facing (x -0.03 .. 0.08) and 0.16 m across it.
  p.machine_depth_m = 0.11;
  p.machine_width_m = 0.16;
  // The Robotino of the team's Gazebo simulation (gazebo-rcll 15878b3, models/robotino/model.sdf;
  // thesis §5.1.1: "The cylinder on laser height is smaller and shifted back so that it does not
  // block the laser sensor"): the laser 0.085 m ahead of the centre, the robot at laser height a
  // cylinder of radius 0.12 m whose centre is 0.05 m behind the robot's.
  p.laser_mount_x_m = 0.085;
  p.robot_laser_radius_m = 0.12;
  p.robot_laser_offset_m = -0.05;
  // The optical sensors as in the thesis' simulation, not on the field: "Because we can decrease
  // this range in the simulation, it is possible to test and continue the rest of the
  // development" (§5.3.2; the real range saw the walls beside the recyclers). No figure is given:
  // assumption, 0.05 m sees a machine's plate 1-2 cm ahead of the arm tips at the reader and no
  // wall beside a recycler; the sensitivity sweep plays the world's 0.30 m (the real sensors).
  p.optical_range_m = 0.05;
  // The skills move at machines as the team's 2013 skills did (src/lua/skills/robotino/ at
  // 6cffc15f2: fetch_puck turns to a puck first, leave_area_recycle, get_consumed's leave), so
  // their failures come from contact, not dice (docs/profiles.md, "Failures").
  p.motions = "carologistics-2013";
  // Jams at machines: contact and move_base, not dice (docs/profiles.md, "Failures").
  p.jam_probability = 0.0;
  // Calibrated: a single P1P2 robot's first complex product at 10:30 min (thesis §5.3.3). At
  // this level move_base's goal approach and move_under_rfid's creep take the time; any extra
  // alignment takes the robot further from the target (docs/validation.md, "Calibration").
  p.align_s = 0.0;
  return p;
}

}  // namespace

std::vector<std::string> RobotProfile::names() {
  return {"ideal", "robotino-2013", "robotino-2013-omniscient"};
}

RobotProfile RobotProfile::named(std::string_view name) {
  if (name == "ideal") return RobotProfile{};
  if (name == "robotino-2013") return robotino_2013();
  if (name == "robotino-2013-omniscient") return robotino_2013_omniscient();
  throw std::invalid_argument("unknown robot profile '" + std::string(name) + "'");
}

void RobotProfile::validate() const {
  const std::string p = "profile.";
  core::require(p + "max_speed_mps", max_speed_mps, core::positive());
  core::require(p + "max_omega_rps", max_omega_rps, core::positive());
  core::require(p + "max_accel_mps2", max_accel_mps2, core::positive());
  core::require(p + "max_alpha_rps2", max_alpha_rps2, core::positive());
  core::require(p + "max_speed_mps", max_speed_mps, core::at_most(3.0));
  core::require(p + "motor_max_speed_mps", motor_max_speed_mps, core::in_range(0.0, 3.0));
  core::require(p + "motor_max_omega_rps", motor_max_omega_rps, core::non_negative());
  core::require(p + "align_s", align_s, core::non_negative());
  core::require(p + "align_s", align_s, core::at_most(60.0));
  core::require(p + "light_frame_rate_hz", light_frame_rate_hz, core::positive());
  core::require(p + "light_frame_rate_hz", light_frame_rate_hz, core::at_most(100.0));
  core::require(p + "light_delay_s", light_delay_s, core::non_negative());
  core::require(p + "light_delay_s", light_delay_s, core::at_most(60.0));
  core::require(p + "light_error_rate", light_error_rate, core::probability());
  core::require(p + "laser_rate_hz", laser_rate_hz, core::positive());
  core::require(p + "laser_rate_hz", laser_rate_hz, core::at_most(100.0));
  // As the scenario's levels keys (docs/security.md, "Scenario budgets").
  core::require(p + "position_noise_m", position_noise_m, core::in_range(0.0, 1.0));
  core::require(p + "heading_noise_rad", heading_noise_rad, core::in_range(0.0, core::kPi));
  core::require(p + "wait_before_replan_s", wait_before_replan_s, core::in_range(0.0, 60.0));
  core::require(p + "backoff_min_s", backoff_min_s, core::non_negative());
  core::require(p + "backoff_max_s", backoff_max_s, core::at_most(60.0));
  if (!(backoff_max_s >= backoff_min_s) || !std::isfinite(backoff_max_s)) {
    throw core::ConfigError(p + "backoff_max_s: must be >= backoff_min_s (got " +
                            core::number_text(backoff_max_s) + ")");
  }
  core::require(p + "blocked_timeout_s", blocked_timeout_s, core::positive());
  core::require(p + "blocked_timeout_s", blocked_timeout_s, core::at_most(3600.0));
  core::require(p + "jam_probability", jam_probability, core::probability());
  core::require(p + "machine_depth_m", machine_depth_m, core::in_range(0.0, 1.0));
  core::require(p + "machine_width_m", machine_width_m, core::in_range(0.0, 1.0));
  core::require(p + "laser_mount_x_m", laser_mount_x_m, core::in_range(-0.5, 0.5));
  core::require(p + "robot_laser_radius_m", robot_laser_radius_m, core::in_range(0.0, 0.5));
  core::require(p + "robot_laser_offset_m", robot_laser_offset_m, core::in_range(-0.5, 0.5));
  core::require(p + "optical_range_m", optical_range_m, core::in_range(0.0, 1.0));
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
  game.world.sensors.laser.enabled = laser;
  game.world.sensors.laser.mount_x_m = laser_mount_x_m;
  game.world.robot.laser_radius_m = robot_laser_radius_m;
  game.world.robot.laser_offset_m = robot_laser_offset_m;
  if (optical_range_m > 0.0) game.world.sensors.optical.range_m = optical_range_m;
  game.levels.navigation = navigation;
  for (int i = 0; i < kinematic::kDeviceCount; ++i) {
    if (kinematic::device_kind(core::DeviceId(i)) == kinematic::DeviceKind::kDelivery) continue;
    kinematic::DeviceConfig& d = game.world.devices[static_cast<std::size_t>(i)];
    const double front = d.body_offset_m + 0.5 * d.body_depth_m;
    if (machine_depth_m > 0.0) d.body_depth_m = machine_depth_m;
    if (machine_width_m > 0.0) d.body_width_m = machine_width_m;
    d.body_offset_m = front - 0.5 * d.body_depth_m;
  }
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
  skills.motions = motions;
  skills.profile = name;
}

namespace {

// The profile's figures by key: what load_profile reads besides name, light, localization,
// light_reads_states and stuck_detection.
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
    {"machine_depth_m", &RobotProfile::machine_depth_m},
    {"machine_width_m", &RobotProfile::machine_width_m},
    {"laser_mount_x_m", &RobotProfile::laser_mount_x_m},
    {"robot_laser_radius_m", &RobotProfile::robot_laser_radius_m},
    {"robot_laser_offset_m", &RobotProfile::robot_laser_offset_m},
    {"optical_range_m", &RobotProfile::optical_range_m},
};

RobotProfile named_or_fail(const core::ConfigNode& n) {
  try {
    return RobotProfile::named(n.as_string());
  } catch (const std::invalid_argument&) {
    std::string known;
    for (const std::string& name : RobotProfile::names()) {
      known += (known.empty() ? "" : ", ") + name;
    }
    n.fail("unknown profile '" + n.as_string() + "' (known: " + known + ")");
  }
}

}  // namespace

RobotProfile load_profile(const core::ConfigNode& node) {
  if (node.is_scalar()) return named_or_fail(node);
  node.require_map();
  RobotProfile p;
  if (const core::ConfigNode name = node["name"]; name.defined()) p = named_or_fail(name);
  for (const NumberKey& k : kNumbers) node.read(k.key, p.*k.field);
  node.read_enum("light", p.light,
                 {{"ground_truth", sim::DetectionLevel::kGroundTruth},
                  {"vision", sim::DetectionLevel::kVision}},
                 "detection level");
  node.read_enum("localization", p.localization,
                 {{"ground_truth", sim::LocalizationLevel::kGroundTruth},
                  {"noisy", sim::LocalizationLevel::kNoisy}},
                 "localization level");
  node.read_enum("navigation", p.navigation,
                 {{"ideal", sim::NavigationLevel::kIdeal},
                  {"move_base-2013", sim::NavigationLevel::kMoveBase2013}},
                 "navigation level");
  node.read("laser", p.laser);
  node.read("light_reads_states", p.light_reads_states);
  node.read("stuck_detection", p.stuck_detection);
  node.read_enum("motions", p.motions,
                 {{"llsfsim", std::string("llsfsim")},
                  {"carologistics-2013", std::string("carologistics-2013")}},
                 "skill motions");
  node.no_other_keys();
  try {
    p.validate();
  } catch (const core::ConfigError& e) {
    // validate() names fields "profile.<key>"; the key is this map's.
    const std::string what = e.what();
    const std::string prefix = "profile.";
    node.relocate(
        core::ConfigError(what.rfind(prefix, 0) == 0 ? what.substr(prefix.size()) : what));
  }
  return p;
}

}  // namespace llsf::study
