// SPDX-License-Identifier: MIT
#include "llsf/sim/perception.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

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

bool same_reading(const lua::LightReading& a, const lua::LightReading& b) {
  return a.visible == b.visible && a.device == b.device && a.red == b.red && a.yellow == b.yellow &&
         a.green == b.green;
}

lua::Lamp& lamp_of(lua::LightReading& r, int i) {
  return i == 0 ? r.red : i == 1 ? r.yellow : r.green;
}

}  // namespace

// --- localization ------------------------------------------------------------------------------

Localization::Localization(const LocalizationConfig& config, const core::Pose2D& start,
                           core::RandomStream rng)
    : c_(config), rng_(rng) {
  pose_.pose = start;
  est_ref_ = start;
  odo_ref_ = start;
  next_correction_ = c_.correction_period;
}

void Localization::teleported(const core::Pose2D& from, const core::Pose2D& to) {
  teleported_ = true;
  teleport_from_ = from;
  teleport_to_ = to;
}

void Localization::update(SimTime now, const core::Pose2D& truth,
                          const kinematic::OdometryReading& o) {
  if (c_.level == LocalizationLevel::kGroundTruth) {
    pose_ = {truth, now, true};
    return;
  }
  // Odometry since the last correction, carried forward to now with the wheel velocity (the
  // odometry samples at its own rate, slower than the tick).
  core::Pose2D odo = odo_ref_;
  if (o.seq > 0) {
    const double dt = (now - o.stamp).seconds();
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
  if (now >= next_correction_) {
    // The periodic correction: pulled towards a noisy measurement of the true pose.
    const double mx = truth.x + rng_.normal(0.0, c_.position_noise_m);
    const double my = truth.y + rng_.normal(0.0, c_.position_noise_m);
    const double mt = truth.theta + rng_.normal(0.0, c_.heading_noise_rad);
    est.x += c_.correction_gain * (mx - est.x);
    est.y += c_.correction_gain * (my - est.y);
    est.theta =
        core::normalize_angle(est.theta + c_.correction_gain * core::angle_diff(mt, est.theta));
    est_ref_ = est;
    odo_ref_ = odo;
    while (next_correction_ <= now) next_correction_ += c_.correction_period;
  }
  est.theta = core::normalize_angle(est.theta);
  pose_ = {est, now, true};
}

// --- light detection ---------------------------------------------------------------------------

LightDetection::LightDetection(const LightDetectionConfig& config, std::vector<DeviceView> devices,
                               core::RandomStream rng)
    : c_(config), devices_(std::move(devices)), rng_(rng) {
  observed_since_ = kNever;
  // Frames within one blink period (inclusive at both ends), plus slack.
  lit_history_.resize(
      static_cast<std::size_t>(std::ceil(refbox::kBlinkPeriod.seconds() * c_.frame_rate_hz)) + 3);
  // Enough room for every frame within the delay, so the ring never overwrites one still due.
  const double frames_in_delay = c_.delay.seconds() * c_.frame_rate_hz;
  frames_.resize(static_cast<std::size_t>(std::ceil(frames_in_delay)) + 4);
}

void LightDetection::update(SimTime now, const core::Pose2D& truth,
                            std::span<const kinematic::SignalLights> lights) {
  if (c_.level == DetectionLevel::kGroundTruth) {
    update_ground_truth(now, truth, lights);
  } else {
    update_vision(now, truth, lights);
  }
}

int LightDetection::device_in_front(const core::Pose2D& pose, bool vision) {
  if (front_.device != -2 && front_.vision == vision && front_.pose.x == pose.x &&
      front_.pose.y == pose.y && front_.pose.theta == pose.theta) {
    return front_.device;
  }
  int best = -1;
  double best_d = 0.0;
  if (c_.view == LightView::kLaserCluster) {
    // The 2013 team's light detection: the laser cluster nearest to the robot within the
    // cluster window ahead (a device's RFID zone, where the laser sees its signal tower and
    // reader), from any side of the device; the camera then reads that device's lamps.
    const double c = std::cos(pose.theta), s = std::sin(pose.theta);
    for (int i = 0; i < static_cast<int>(devices_.size()); ++i) {
      const core::Vec2 v = devices_[static_cast<std::size_t>(i)].front - pose.position();
      const double x = c * v.x() + s * v.y();  // in the robot frame
      const double y = -s * v.x() + c * v.y();
      if (x < c_.cluster_min_x_m || x > c_.cluster_max_x_m) continue;
      if (std::abs(y) > c_.cluster_half_width_m) continue;
      const double dist2 = x * x + y * y;
      if (best < 0 || dist2 < best_d) {
        best = i;
        best_d = dist2;
      }
    }
    front_ = {pose, vision, best};
    return best;
  }
  const double range2_margin = c_.range_m * c_.range_m * (1.0 + 1e-9) + 1e-12;
  for (int i = 0; i < static_cast<int>(devices_.size()); ++i) {
    const DeviceView& d = devices_[static_cast<std::size_t>(i)];
    const core::Vec2 v = d.front - pose.position();  // robot -> device front
    // Far out of range, by a margin no rounding reaches: skip the square root (the exact test
    // below decides the rest).
    if (v.squaredNorm() > range2_margin) continue;
    const double dist = v.norm();
    if (dist > c_.range_m) continue;
    if (std::abs(core::angle_diff(std::atan2(v.y(), v.x()), pose.theta)) > c_.half_angle_rad) {
      continue;
    }
    // On the front's side of the device (its light faces the field there) ...
    if (v.dot(core::unit(d.pose.theta)) > 0.0) continue;
    // ... and, for the camera, within the facing cone of its front.
    if (vision && dist > 1e-9 &&
        std::abs(core::angle_diff(std::atan2(-v.y(), -v.x()), d.pose.theta)) >
            c_.facing_half_angle_rad) {
      continue;
    }
    if (best < 0 || dist < best_d) {
      best = i;
      best_d = dist;
    }
  }
  front_ = {pose, vision, best};
  return best;
}

void LightDetection::set(const lua::LightReading& r, SimTime now) {
  if (same_reading(r, light_)) return;
  light_ = r;
  light_.stable_since = now;
}

void LightDetection::update_ground_truth(SimTime now, const core::Pose2D& truth,
                                         std::span<const kinematic::SignalLights> lights) {
  const int d = device_in_front(truth, false);
  lua::LightReading r;
  if (d >= 0) {
    const kinematic::SignalLights& l = lights[static_cast<std::size_t>(d)];
    r.visible = true;
    r.device = devices_[static_cast<std::size_t>(d)].name;
    r.red = to_lamp(l.red);
    r.yellow = to_lamp(l.yellow);
    r.green = to_lamp(l.green);
  }
  set(r, now);
}

void LightDetection::update_vision(SimTime now, const core::Pose2D& truth,
                                   std::span<const kinematic::SignalLights> lights) {
  const int capacity = static_cast<int>(frames_.size());
  if (now >= next_frame_) {
    // A camera frame: which device is in front, and which of its lamps are lit right now.
    next_frame_ += SimTime::period_of_hz(c_.frame_rate_hz);
    if (next_frame_ <= now) next_frame_ = now + SimTime::period_of_hz(c_.frame_rate_hz);
    const int d = device_in_front(truth, true);
    if (d != device_) {
      device_ = d;
      observed_since_ = now;
      lit_head_ = 0;
      lit_count_ = 0;
    }
    Frame f;
    f.stamp = now;
    if (d >= 0) {
      // Which lamps are lit in this frame, into the history of the last blink period.
      const kinematic::SignalLights& l = lights[static_cast<std::size_t>(d)];
      const auto bits = static_cast<std::uint8_t>(
          (lit(l.red, now) ? 1 : 0) | (lit(l.yellow, now) ? 2 : 0) | (lit(l.green, now) ? 4 : 0));
      const int hcap = static_cast<int>(lit_history_.size());
      while (lit_count_ > 0 &&
             (lit_count_ == hcap || lit_history_[static_cast<std::size_t>(lit_head_)].first <
                                        now - refbox::kBlinkPeriod)) {
        lit_head_ = (lit_head_ + 1) % hcap;
        --lit_count_;
      }
      lit_history_[static_cast<std::size_t>((lit_head_ + lit_count_) % hcap)] = {now, bits};
      ++lit_count_;
      if (c_.reads_states) {
        // The lamps' states as the simulation knows them (Gazsim-Light-Front).
        f.reading.visible = true;
        f.reading.device = devices_[static_cast<std::size_t>(d)].name;
        f.reading.red = to_lamp(l.red);
        f.reading.yellow = to_lamp(l.yellow);
        f.reading.green = to_lamp(l.green);
      } else if (now - observed_since_ >= refbox::kBlinkPeriod) {
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
        const double u = rng_.uniform01();
        const auto lamp = static_cast<int>(rng_.uniform_int(0, 2));
        const auto shift = static_cast<int>(rng_.uniform_int(1, 2));
        if (u < c_.error_rate) {
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
  const SimTime due = now - c_.delay;
  int newest = -1;
  while (frame_count_ > 0 && frames_[static_cast<std::size_t>(frame_head_)].stamp <= due) {
    newest = frame_head_;
    frame_head_ = (frame_head_ + 1) % capacity;
    --frame_count_;
  }
  if (newest >= 0) set(frames_[static_cast<std::size_t>(newest)].reading, now);
}

// --- puck detection ----------------------------------------------------------------------------

PuckVision::PuckVision(const PuckDetectionConfig& config) : c_(config) {
  sightings_.reserve(64);
  scratch_.reserve(64);
  cluster_.reserve(64);
}

void PuckVision::update(SimTime now, const core::Pose2D& truth, std::span<const core::Vec2> pucks) {
  // Field -> robot frame with one sine and cosine per robot, once a puck is near enough (this
  // runs every tick; mostly no puck is).
  double cs = 0.0, sn = 0.0;
  bool turned = false;
  const core::Vec2 me = truth.position();
  auto local = [&](const core::Vec2& d) {
    if (!turned) {
      cs = std::cos(truth.theta);
      sn = std::sin(truth.theta);
      turned = true;
    }
    return core::Vec2(cs * d.x() + sn * d.y(), -sn * d.x() + cs * d.y());
  };
  if (c_.level == DetectionLevel::kGroundTruth) {
    sightings_.clear();
    for (const core::Vec2& w : pucks) {
      const core::Vec2 d = w - me;
      if (d.squaredNorm() <= c_.range_m * c_.range_m) sightings_.push_back({local(d)});
    }
    return;
  }
  if (now < next_frame_) return;
  next_frame_ += SimTime::period_of_hz(c_.frame_rate_hz);
  if (next_frame_ <= now) next_frame_ = now + SimTime::period_of_hz(c_.frame_rate_hz);
  // Pucks in the camera's view.
  scratch_.clear();
  for (const core::Vec2& w : pucks) {
    const core::Vec2 d = w - me;
    if (d.squaredNorm() > c_.vision_range_m * c_.vision_range_m) continue;
    const core::Vec2 l = local(d);
    if (std::abs(std::atan2(l.y(), l.x())) > c_.half_angle_rad) continue;
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
          c_.merge_distance_m) {
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

}  // namespace llsf::sim
