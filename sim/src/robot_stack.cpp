// SPDX-License-Identifier: MIT
#include "llsf/sim/robot_stack.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include "llsf/core/assert.h"
#include "llsf/core/geometry.h"
#include "llsf/refbox/types.h"

namespace llsf::sim {

namespace {

/// "Never" for the last-seen times of the vision's lamp history.
constexpr SimTime kNever = SimTime::from_ns(std::numeric_limits<std::int64_t>::min() / 4);

lua::Lamp to_lamp(kinematic::LampState s) {
  switch (s) {
    case kinematic::LampState::kOff:
      return lua::Lamp::kOff;
    case kinematic::LampState::kOn:
      return lua::Lamp::kOn;
    case kinematic::LampState::kBlink:
      return lua::Lamp::kBlink;
  }
  return lua::Lamp::kOff;
}

/// Whether a lamp in state `s` is lit at `now` (a blinking lamp is lit in the first half of each
/// 2 Hz period, as the refbox drives it).
bool lit(kinematic::LampState s, SimTime now) {
  return s == kinematic::LampState::kOn ||
         (s == kinematic::LampState::kBlink && refbox::blink_phase_on(now));
}

lua::NavStatus to_api(planner::NavOutcome o) {
  switch (o) {
    case planner::NavOutcome::kIdle:
      return lua::NavStatus::kIdle;
    case planner::NavOutcome::kRunning:
      return lua::NavStatus::kRunning;
    case planner::NavOutcome::kArrived:
      return lua::NavStatus::kArrived;
    case planner::NavOutcome::kNoPath:
      return lua::NavStatus::kNoPath;
    case planner::NavOutcome::kInvalidGoal:
      return lua::NavStatus::kInvalidGoal;
    case planner::NavOutcome::kBlocked:
      return lua::NavStatus::kBlocked;
    case planner::NavOutcome::kStuck:
      return lua::NavStatus::kStuck;
    case planner::NavOutcome::kAborted:
      return lua::NavStatus::kAborted;
  }
  return lua::NavStatus::kIdle;
}

bool same_reading(const lua::LightReading& a, const lua::LightReading& b) {
  return a.visible == b.visible && a.device == b.device && a.red == b.red && a.yellow == b.yellow &&
         a.green == b.green;
}

lua::Lamp& lamp_of(lua::LightReading& r, int i) {
  return i == 0 ? r.red : i == 1 ? r.yellow : r.green;
}

}  // namespace

comm::FrameError RobotRadio::broadcast(const google::protobuf::Message& message) {
  LLSF_DEMAND_MSG(hub_ != nullptr, "the robot stack is not attached to a hub");
  return hub_->broadcast(peer_, message, now_);
}

RobotStack::RobotStack(std::string name, int index, const core::Pose2D& start,
                       const GameConfig& config, planner::Planner& planner,
                       std::vector<std::string> robot_names, std::vector<DeviceView> devices,
                       const core::Rng& rng)
    : name_(std::move(name)),
      index_(index),
      levels_(config.levels),
      robot_names_(std::move(robot_names)),
      devices_(std::move(devices)),
      planner_(&planner),
      nav_(planner, config.controller, rng.stream("planner/" + name_)),
      handling_(config.handling),
      jam_rng_(rng.stream("sim/" + name_ + "/jam")),
      loc_rng_(rng.stream("sim/" + name_ + "/localization")),
      light_rng_(rng.stream("sim/" + name_ + "/light")),
      colour_rng_(rng.stream("sim/" + name_ + "/colour")) {
  nav_.set_obstacle_names(robot_names_);  // "held back by robot2"
  pose_.pose = start;
  est_ref_ = start;
  odo_ref_ = start;
  next_correction_ = levels_.localization.correction_period;
  light_observed_since_ = kNever;
  // Frames within one blink period (inclusive at both ends), plus slack.
  lit_history_.resize(static_cast<std::size_t>(
                          std::ceil(refbox::kBlinkPeriod.seconds() * levels_.light.frame_rate_hz)) +
                      3);
  // Enough room for every frame within the delay, so the ring never overwrites one still due.
  const double frames_in_delay = levels_.light.delay.seconds() * levels_.light.frame_rate_hz;
  frames_.resize(static_cast<std::size_t>(std::ceil(frames_in_delay)) + 4);
  sightings_.reserve(64);
  scratch_.reserve(64);
  cluster_.reserve(64);
  if (config.hackathon) {
    const HackathonConfig& h = *config.hackathon;
    camera_ = h.camera;
    lua::RescueInfo info;
    info.safe_lo = h.safe_area.lo;
    info.safe_hi = h.safe_area.hi;
    info.safe_place = h.safe_place;
    for (const HackathonColour& c : h.colours) {
      colour_names_.push_back(c.name);
      (c.decoy ? info.decoys : info.counted).push_back(c.name);
    }
    info.held_puck_offset_m = config.world.robot.radius_m + config.world.puck.radius_m;
    rescue_ = std::move(info);
    colour_sightings_.reserve(64);
  }
}

// --- actuation -------------------------------------------------------------------------------

kinematic::MotorCommand RobotStack::actuate(SimTime now,
                                            std::span<const planner::DiscObstacle> others) {
  switch (drive_) {
    case Drive::kNavigator: {
      const planner::VelocityCommand c = nav_.update(now, pose_.pose, others);
      if (!arrived_at_ && nav_.status().outcome == planner::NavOutcome::kArrived) {
        // Only the end of a real drive is aligned again (robot profiles): a short push is not.
        const bool drove =
            (true_pose_.position() - goal_from_).norm() >= handling_.align_min_drive_m;
        arrived_at_ = drove ? now : now - SimTime::from_seconds(handling_.align_s);
      }
      return handle({c.vx_mps, c.vy_mps, c.omega_rps}, false);
    }
    case Drive::kMotor:
      return handle(velocity_, true);
    case Drive::kIdle:
      break;
  }
  return {};
}

kinematic::MotorCommand RobotStack::handle(kinematic::MotorCommand c, bool motor) {
  const HandlingConfig& h = handling_;
  if (motor && h.motor_max_speed_mps > 0.0) {
    const double v = std::hypot(c.vx_mps, c.vy_mps);
    if (v > h.motor_max_speed_mps) {
      c.vx_mps *= h.motor_max_speed_mps / v;
      c.vy_mps *= h.motor_max_speed_mps / v;
    }
  }
  if (motor && h.motor_max_omega_rps > 0.0) {
    c.omega_rps = std::clamp(c.omega_rps, -h.motor_max_omega_rps, h.motor_max_omega_rps);
  }
  // A new run of motor commands near a device may jam (one draw per approach, only near one).
  if (motor && motor_started_ && jam_device_ < 0 && h.jam_probability > 0.0) {
    motor_started_ = false;
    int nearest = -1;
    double best = h.jam_zone_m;
    for (std::size_t i = 0; i < devices_.size(); ++i) {
      const double d = (devices_[i].front - true_pose_.position()).norm();
      if (d <= best) {
        best = d;
        nearest = static_cast<int>(i);
      }
    }
    if (nearest >= 0 && jam_rng_.bernoulli(h.jam_probability)) {
      jam_device_ = nearest;
      jammed_since_ = now_;
      ++jams_;
    }
  }
  if (jam_device_ < 0) return c;
  if (h.stuck_detection && now_ >= jammed_since_ + SimTime::from_seconds(h.jam_recovery_s)) {
    jam_device_ = -1;  // the skills' recovery got it free
    return c;
  }
  // Jammed: only a motion away from the device's front gets the robot free.
  const core::Vec2 to_device =
      devices_[static_cast<std::size_t>(jam_device_)].front - true_pose_.position();
  const double cs = std::cos(true_pose_.theta), sn = std::sin(true_pose_.theta);
  const core::Vec2 v_field(cs * c.vx_mps - sn * c.vy_mps, sn * c.vx_mps + cs * c.vy_mps);
  const double n = to_device.norm();
  const double towards = n > 1e-9 ? v_field.dot(to_device) / n : 0.0;
  if (towards < -0.02) {
    jam_device_ = -1;
    return c;
  }
  return {};
}

void RobotStack::goto_place(std::string_view place, bool forward_only) {
  arrived_at_.reset();
  goal_from_ = true_pose_.position();
  nav_.go_to_place(place, forward_only);
  drive_ = Drive::kNavigator;
  ++goal_id_;
}

void RobotStack::goto_pose(const core::Pose2D& pose, bool forward_only) {
  arrived_at_.reset();
  goal_from_ = true_pose_.position();
  nav_.go_to(pose, forward_only);
  drive_ = Drive::kNavigator;
  ++goal_id_;
}

lua::NavState RobotStack::navigator() const {
  const planner::NavStatus& s = nav_.status();
  lua::NavState out;
  out.status = to_api(s.outcome);
  // The fine alignment after an arrival (robot profiles): still running until it is done.
  if (s.outcome == planner::NavOutcome::kArrived && handling_.align_s > 0.0 &&
      (!arrived_at_ || now_ < *arrived_at_ + SimTime::from_seconds(handling_.align_s))) {
    out.status = lua::NavStatus::kRunning;
  }
  out.error = s.message;
  if (s.blocked_by >= 0 && s.blocked_by < static_cast<int>(robot_names_.size())) {
    out.blocked_by = robot_names_[static_cast<std::size_t>(s.blocked_by)];
  }
  out.goal_id = goal_id_;
  return out;
}

void RobotStack::stop() {
  if (nav_.status().outcome == planner::NavOutcome::kRunning) nav_.abort();
  drive_ = Drive::kIdle;
  velocity_ = {};
}

void RobotStack::set_velocity(double vx_mps, double vy_mps, double omega_rps) {
  if (nav_.status().outcome == planner::NavOutcome::kRunning) nav_.abort();
  if (drive_ != Drive::kMotor) motor_started_ = true;
  drive_ = Drive::kMotor;
  velocity_ = {vx_mps, vy_mps, omega_rps};
}

std::optional<lua::PlaceInfo> RobotStack::place(std::string_view name) const {
  const planner::Place* p = planner_->place(name);
  if (p == nullptr) return std::nullopt;
  return lua::PlaceInfo{p->pose, p->target};
}

// --- symbolic skill level --------------------------------------------------------------------

namespace {
void require_symbolic(bool symbolic, const char* what) {
  if (!symbolic) {
    throw std::logic_error(std::string(what) +
                           ": the robot does not run at the symbolic skill level");
  }
}
}  // namespace

lua::TravelEstimate RobotStack::symbolic_travel(const core::Pose2D& goal) const {
  require_symbolic(symbolic(), "symbolic_travel");
  planner::PlanRequest req;
  req.start = pose_.pose;
  req.goal = goal;
  req.seed = ++travel_queries_;
  const planner::PlanResult r = planner_->plan(req);
  lua::TravelEstimate out;
  if (r.status != planner::PlanStatus::kFound) {
    out.error = std::string(planner::to_string(r.status)) + ": " + r.message;
    return out;
  }
  out.ok = true;
  out.length_m = r.path.length_m();
  // Turning: along the path's segments, and to the goal heading at the end.
  double turn = 0.0;
  double heading = pose_.pose.theta;
  const auto& pts = r.path.points;
  for (std::size_t i = 1; i < pts.size(); ++i) {
    const core::Vec2 d = pts[i] - pts[i - 1];
    if (d.norm() < 1e-6) continue;
    const double h = std::atan2(d.y(), d.x());
    turn += std::abs(core::angle_diff(h, heading));
    heading = h;
  }
  turn += std::abs(core::angle_diff(goal.theta, heading));
  out.seconds =
      out.length_m / levels_.symbolic.cruise_speed_mps + turn / levels_.symbolic.turn_rate_rps;
  return out;
}

void RobotStack::symbolic_move(const core::Pose2D& pose) {
  require_symbolic(symbolic(), "symbolic_move");
  stop();
  SymbolicRequest r;
  r.kind = SymbolicRequest::Kind::kMove;
  r.pose = pose;
  symbolic_requests_.push_back(r);
}

void RobotStack::on_teleported(const core::Pose2D& from, const core::Pose2D& to) {
  teleported_ = true;
  teleport_from_ = from;
  teleport_to_ = to;
}

void RobotStack::symbolic_pick(const core::Vec2& point, double radius_m) {
  require_symbolic(symbolic(), "symbolic_pick");
  SymbolicRequest r;
  r.kind = SymbolicRequest::Kind::kPick;
  r.point = point;
  r.radius_m = radius_m;
  symbolic_requests_.push_back(r);
}

void RobotStack::symbolic_drop(const core::Vec2& point) {
  require_symbolic(symbolic(), "symbolic_drop");
  SymbolicRequest r;
  r.kind = SymbolicRequest::Kind::kDrop;
  r.point = point;
  symbolic_requests_.push_back(r);
}

// --- sensing ---------------------------------------------------------------------------------

void RobotStack::sense(const RobotPercept& p) {
  LLSF_ASSERT(p.sensors != nullptr);
  now_ = p.now;
  radio_.now_ = p.now;
  true_pose_ = p.true_pose;
  const kinematic::RobotSensors& s = *p.sensors;
  puck_in_holder_ = s.ir.puck_detected;
  ir_distance_m_ = s.ir.distance_m;
  optical_ = {s.optical.left, s.optical.right};
  laser_ = {s.laser.angle_min_rad, s.laser.angle_increment_rad, s.laser.ranges};
  sense_localization(p);
  if (levels_.light.level == DetectionLevel::kGroundTruth) {
    sense_light(p);
  } else {
    sense_light_vision(p);
  }
  sense_pucks(p);
  if (camera_) sense_colour_pucks(p);
}

void RobotStack::sense_localization(const RobotPercept& p) {
  const LocalizationConfig& c = levels_.localization;
  if (c.level == LocalizationLevel::kGroundTruth) {
    pose_ = {p.true_pose, p.now, true};
    return;
  }
  // Odometry since the last correction, carried forward to now with the wheel velocity (the
  // odometry samples at its own rate, slower than the tick).
  const kinematic::OdometryReading& o = p.sensors->odometry;
  core::Pose2D odo = odo_ref_;
  if (o.seq > 0) {
    const double dt = (p.now - o.stamp).seconds();
    odo = o.pose.compose({o.vx_mps * dt, o.vy_mps * dt, o.omega_rps * dt});
  }
  if (teleported_) {
    // Moved by a symbolic skill (odometry did not see it): the estimate jumps with the robot,
    // keeping its error relative to the truth.
    teleported_ = false;
    est_ref_ = teleport_to_.compose(
        teleport_from_.inverse().compose(est_ref_.compose(odo_ref_.inverse().compose(odo))));
    odo_ref_ = odo;
  }
  core::Pose2D est = est_ref_.compose(odo_ref_.inverse().compose(odo));
  if (p.now >= next_correction_) {
    // The periodic correction: pulled towards a noisy measurement of the true pose.
    const double mx = p.true_pose.x + loc_rng_.normal(0.0, c.position_noise_m);
    const double my = p.true_pose.y + loc_rng_.normal(0.0, c.position_noise_m);
    const double mt = p.true_pose.theta + loc_rng_.normal(0.0, c.heading_noise_rad);
    est.x += c.correction_gain * (mx - est.x);
    est.y += c.correction_gain * (my - est.y);
    est.theta =
        core::normalize_angle(est.theta + c.correction_gain * core::angle_diff(mt, est.theta));
    est_ref_ = est;
    odo_ref_ = odo;
    while (next_correction_ <= p.now) next_correction_ += c.correction_period;
  }
  est.theta = core::normalize_angle(est.theta);
  pose_ = {est, p.now, true};
}

int RobotStack::device_in_front(const core::Pose2D& pose, bool vision) const {
  const LightDetectionConfig& c = levels_.light;
  int best = -1;
  double best_d = 0.0;
  for (int i = 0; i < static_cast<int>(devices_.size()); ++i) {
    const DeviceView& d = devices_[static_cast<std::size_t>(i)];
    const core::Vec2 v = d.front - pose.position();  // robot -> device front
    const double dist = v.norm();
    if (dist > c.range_m) continue;
    if (std::abs(core::angle_diff(std::atan2(v.y(), v.x()), pose.theta)) > c.half_angle_rad) {
      continue;
    }
    // On the front's side of the device (its light faces the field there) ...
    if (v.dot(core::unit(d.pose.theta)) > 0.0) continue;
    // ... and, for the camera, within the facing cone of its front.
    if (vision && dist > 1e-9 &&
        std::abs(core::angle_diff(std::atan2(-v.y(), -v.x()), d.pose.theta)) >
            c.facing_half_angle_rad) {
      continue;
    }
    if (best < 0 || dist < best_d) {
      best = i;
      best_d = dist;
    }
  }
  return best;
}

void RobotStack::set_light(const lua::LightReading& r, SimTime now) {
  if (same_reading(r, light_)) return;
  light_ = r;
  light_.stable_since = now;
}

void RobotStack::sense_light(const RobotPercept& p) {
  const int d = device_in_front(p.true_pose, false);
  lua::LightReading r;
  if (d >= 0) {
    const kinematic::SignalLights& l = p.lights[static_cast<std::size_t>(d)];
    r.visible = true;
    r.device = devices_[static_cast<std::size_t>(d)].name;
    r.red = to_lamp(l.red);
    r.yellow = to_lamp(l.yellow);
    r.green = to_lamp(l.green);
  }
  set_light(r, p.now);
}

void RobotStack::sense_light_vision(const RobotPercept& p) {
  const LightDetectionConfig& c = levels_.light;
  const int capacity = static_cast<int>(frames_.size());
  if (p.now >= light_next_frame_) {
    // A camera frame: which device is in front, and which of its lamps are lit right now.
    light_next_frame_ += SimTime::period_of_hz(c.frame_rate_hz);
    if (light_next_frame_ <= p.now)
      light_next_frame_ = p.now + SimTime::period_of_hz(c.frame_rate_hz);
    const int d = device_in_front(p.true_pose, true);
    if (d != light_device_) {
      light_device_ = d;
      light_observed_since_ = p.now;
      lit_head_ = 0;
      lit_count_ = 0;
    }
    Frame f;
    f.stamp = p.now;
    if (d >= 0) {
      // Which lamps are lit in this frame, into the history of the last blink period.
      const kinematic::SignalLights& l = p.lights[static_cast<std::size_t>(d)];
      const auto bits =
          static_cast<std::uint8_t>((lit(l.red, p.now) ? 1 : 0) | (lit(l.yellow, p.now) ? 2 : 0) |
                                    (lit(l.green, p.now) ? 4 : 0));
      const int hcap = static_cast<int>(lit_history_.size());
      while (lit_count_ > 0 &&
             (lit_count_ == hcap || lit_history_[static_cast<std::size_t>(lit_head_)].first <
                                        p.now - refbox::kBlinkPeriod)) {
        lit_head_ = (lit_head_ + 1) % hcap;
        --lit_count_;
      }
      lit_history_[static_cast<std::size_t>((lit_head_ + lit_count_) % hcap)] = {p.now, bits};
      ++lit_count_;
      if (c.reads_states) {
        // The lamps' states as the simulation knows them (Gazsim-Light-Front).
        f.reading.visible = true;
        f.reading.device = devices_[static_cast<std::size_t>(d)].name;
        f.reading.red = to_lamp(l.red);
        f.reading.yellow = to_lamp(l.yellow);
        f.reading.green = to_lamp(l.green);
      } else if (p.now - light_observed_since_ >= refbox::kBlinkPeriod) {
        // A reading needs a full blink period of frames of this device. A lamp that changed
        // between lit and unlit twice within the period blinks; otherwise its latest state
        // holds (a steady lamp switching on or off changes once).
        f.reading.visible = true;
        f.reading.device = devices_[static_cast<std::size_t>(d)].name;
        for (int i = 0; i < 3; ++i) {
          int changes = 0;
          for (int k = 1; k < lit_count_; ++k) {
            const auto a =
                lit_history_[static_cast<std::size_t>((lit_head_ + k - 1) % hcap)].second;
            const auto b = lit_history_[static_cast<std::size_t>((lit_head_ + k) % hcap)].second;
            if (((a ^ b) >> i) & 1) ++changes;
          }
          lamp_of(f.reading, i) = changes >= 2      ? lua::Lamp::kBlink
                                  : (bits >> i) & 1 ? lua::Lamp::kOn
                                                    : lua::Lamp::kOff;
        }
      }
      if (f.reading.visible) {
        // A misread: one lamp reported in one of the two wrong states. Three draws per
        // reading, whatever the outcome, so the stream does not depend on the error rate.
        const double u = light_rng_.uniform01();
        const auto lamp = static_cast<int>(light_rng_.uniform_int(0, 2));
        const auto shift = static_cast<int>(light_rng_.uniform_int(1, 2));
        if (u < c.error_rate) {
          lua::Lamp& l_ref = lamp_of(f.reading, lamp);
          l_ref = static_cast<lua::Lamp>((static_cast<int>(l_ref) + shift) % 3);
        }
      }
    }
    // Into the delay line (the capacity covers the delay; a full ring drops the oldest).
    if (frame_count_ == capacity) {
      frame_head_ = (frame_head_ + 1) % capacity;
      --frame_count_;
    }
    frames_[static_cast<std::size_t>((frame_head_ + frame_count_) % capacity)] = std::move(f);
    ++frame_count_;
  }
  // Report the newest frame that is at least `delay` old.
  const SimTime due = p.now - c.delay;
  int newest = -1;
  while (frame_count_ > 0 && frames_[static_cast<std::size_t>(frame_head_)].stamp <= due) {
    newest = frame_head_;
    frame_head_ = (frame_head_ + 1) % capacity;
    --frame_count_;
  }
  if (newest >= 0) set_light(frames_[static_cast<std::size_t>(newest)].reading, p.now);
}

void RobotStack::sense_pucks(const RobotPercept& p) {
  const PuckDetectionConfig& c = levels_.puck;
  // Field -> robot frame with one sine and cosine per robot (this runs every tick).
  const double cs = std::cos(p.true_pose.theta);
  const double sn = std::sin(p.true_pose.theta);
  const core::Vec2 me = p.true_pose.position();
  auto local = [&](const core::Vec2& d) {
    return core::Vec2(cs * d.x() + sn * d.y(), -sn * d.x() + cs * d.y());
  };
  if (c.level == DetectionLevel::kGroundTruth) {
    sightings_.clear();
    for (const core::Vec2& w : p.pucks) {
      const core::Vec2 d = w - me;
      if (d.squaredNorm() <= c.range_m * c.range_m) sightings_.push_back({local(d)});
    }
    return;
  }
  if (p.now < puck_next_frame_) return;
  puck_next_frame_ += SimTime::period_of_hz(c.frame_rate_hz);
  if (puck_next_frame_ <= p.now) puck_next_frame_ = p.now + SimTime::period_of_hz(c.frame_rate_hz);
  // Pucks in the camera's view.
  scratch_.clear();
  for (const core::Vec2& w : p.pucks) {
    const core::Vec2 d = w - me;
    if (d.squaredNorm() > c.vision_range_m * c.vision_range_m) continue;
    const core::Vec2 l = local(d);
    if (std::abs(std::atan2(l.y(), l.x())) > c.half_angle_rad) continue;
    scratch_.push_back(l);
  }
  // Pucks closer than the merge distance form one blob (single linkage, union-find).
  const int n = static_cast<int>(scratch_.size());
  cluster_.resize(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) cluster_[static_cast<std::size_t>(i)] = i;
  auto root = [this](int i) {
    while (cluster_[static_cast<std::size_t>(i)] != i) i = cluster_[static_cast<std::size_t>(i)];
    return i;
  };
  for (int i = 0; i < n; ++i) {
    for (int j = i + 1; j < n; ++j) {
      if ((scratch_[static_cast<std::size_t>(i)] - scratch_[static_cast<std::size_t>(j)]).norm() <
          c.merge_distance_m) {
        const int a = root(i);
        const int b = root(j);
        if (a != b) cluster_[static_cast<std::size_t>(std::max(a, b))] = std::min(a, b);
      }
    }
  }
  sightings_.clear();
  for (int i = 0; i < n; ++i) {
    if (root(i) != i) continue;
    core::Vec2 sum(0.0, 0.0);
    int count = 0;
    for (int j = i; j < n; ++j) {
      if (root(j) == i) {
        sum += scratch_[static_cast<std::size_t>(j)];
        ++count;
      }
    }
    sightings_.push_back({sum / static_cast<double>(count)});
  }
}

// The hackathon's flashlight camera: a cone ahead of the robot, one frame every 1/frame_rate_hz;
// per puck in the cone three draws (miss, false colour, which colour) and two for the position
// noise, whatever the outcome, so that one puck's luck does not shift the others'.
void RobotStack::sense_colour_pucks(const RobotPercept& p) {
  const ColourCameraConfig& c = *camera_;
  if (p.now < colour_next_frame_) return;
  const SimTime period = SimTime::period_of_hz(c.frame_rate_hz);
  colour_next_frame_ += period;
  if (colour_next_frame_ <= p.now) colour_next_frame_ = p.now + period;
  colour_sightings_.clear();
  const double half_fov = 0.5 * c.fov_rad;
  const int colours = static_cast<int>(colour_names_.size());
  for (std::size_t i = 0; i < p.pucks.size() && i < p.puck_colours.size(); ++i) {
    const int colour = p.puck_colours[i];
    if (colour < 0) continue;
    const core::Vec2 l = p.true_pose.to_local(p.pucks[i]);
    const double d = l.norm();
    if (d > c.range_m || std::abs(std::atan2(l.y(), l.x())) > half_fov) continue;
    const bool missed = colour_rng_.bernoulli(c.miss_rate);
    const bool wrong = colour_rng_.bernoulli(c.false_colour_rate);
    const std::int64_t other = colours > 1 ? colour_rng_.uniform_int(0, colours - 2) : 0;
    const core::Vec2 noise(colour_rng_.normal(0.0, c.position_noise_m),
                           colour_rng_.normal(0.0, c.position_noise_m));
    if (missed) continue;
    int seen = colour;
    if (wrong && colours > 1)
      seen =
          static_cast<int>(other) >= colour ? static_cast<int>(other) + 1 : static_cast<int>(other);
    const core::Vec2 at = l + noise;
    colour_sightings_.push_back(
        {at, at.norm(), std::atan2(at.y(), at.x()), colour_names_[static_cast<std::size_t>(seen)]});
  }
}

}  // namespace llsf::sim
