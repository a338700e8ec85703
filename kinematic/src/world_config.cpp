// SPDX-License-Identifier: MIT
// The 2013 default world, WorldConfig::validate() and the YAML loader (docs/world-config.md).
#include "llsf/kinematic/world_config.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <map>
#include <set>
#include <utility>

namespace llsf::kinematic {

using core::ConfigError;
using core::ConfigNode;

// ---------------------------------------------------------------------------------------------
// The 2013 field
// ---------------------------------------------------------------------------------------------

namespace {

/// A rule-book device pose: position in metres, facing in degrees (RBX facts.clp orientation).
struct DevicePose {
  double x;
  double y;
  double ori_deg;
};

// In kDeviceNames order. The facings are given in degrees (270 = 3π/2, ...) so that the YAML
// form `ori_deg: 270` of config/world-2013.yaml converts to the bit-identical heading.
constexpr std::array<DevicePose, kDeviceCount> kPoses2013 = {{
    {3.92, 1.68, 270},  // M1  3π/2
    {3.92, 3.92, 0},    // M2  0
    {2.80, 0.56, 90},   // M3  π/2
    {2.80, 1.68, 90},   // M4  π/2
    {2.80, 2.80, 180},  // M5  π
    {2.80, 3.92, 90},   // M6  π/2
    {2.80, 5.04, 270},  // M7  3π/2
    {1.68, 1.68, 180},  // M8  π
    {1.68, 3.92, 270},  // M9  3π/2
    {1.68, 5.04, 0},    // M10 0
    {5.40, 0.20, 135},  // R1  3π/4, bottom-right corner, facing the field centre
    {0.20, 5.40, 315},  // R2  7π/4, top-left corner
    {5.40, 5.40, 225},  // TST 5π/4, top-right corner
    {5.34, 3.15, 180},  // D1  π, the delivery slot
    {5.34, 2.80, 180},  // D2
    {5.34, 2.45, 180},  // D3
}};

// Footprints. The sources give no device dimensions; these are assumptions.
// Production machines: a signal tower plus RFID reader on a stand, taken as a 0.20 m deep,
// 0.30 m wide box centred on the machine-space centre. The RFID zone centre lies 0.14 m ahead,
// 0.04 m beyond the body front: where the centre of a puck touching the front comes to rest.
constexpr double kMachineDepth = 0.20;
constexpr double kMachineWidth = 0.30;
constexpr double kMachineRfidOffset = 0.14;
// Recycling units and the test station: the same tower, narrower (0.24 m) stand.
constexpr double kCornerDepth = 0.20;
constexpr double kCornerWidth = 0.24;
constexpr double kCornerRfidOffset = 0.14;
// Delivery gates: the pose is the delivery slot directly under the reader; the gate body
// (0.16 m deep, 0.30 m wide as the RB gate width) stands behind the slot against the right
// wall, so its centre is 0.12 m behind the slot.
constexpr double kGateDepth = 0.16;
constexpr double kGateWidth = 0.30;
constexpr double kGateBodyOffset = -0.12;
constexpr double kGateRfidOffset = 0.0;
// The read zone: a puck tag is read within 0.05 m of the zone centre (RB: range <= 0.115 m).
constexpr double kRfidRadius = 0.05;

}  // namespace

WorldConfig WorldConfig::default_2013() {
  WorldConfig c;

  // Devices at the rule-book poses with the assumed footprints.
  for (int i = 0; i < kDeviceCount; ++i) {
    DeviceConfig& d = c.devices[i];
    const DevicePose& p = kPoses2013[i];
    d.pose = Pose2D{p.x, p.y, core::normalize_angle(core::deg_to_rad(p.ori_deg))};
    d.rfid_radius_m = kRfidRadius;
    switch (device_kind(DeviceId(i))) {
      case DeviceKind::kProduction:
        d.body_depth_m = kMachineDepth;
        d.body_width_m = kMachineWidth;
        d.body_offset_m = 0.0;
        d.rfid_offset_m = kMachineRfidOffset;
        break;
      case DeviceKind::kRecycling:
      case DeviceKind::kTest:
        d.body_depth_m = kCornerDepth;
        d.body_width_m = kCornerWidth;
        d.body_offset_m = 0.0;
        d.rfid_offset_m = kCornerRfidOffset;
        break;
      case DeviceKind::kDelivery:
        d.body_depth_m = kGateDepth;
        d.body_width_m = kGateWidth;
        d.body_offset_m = kGateBodyOffset;
        d.rfid_offset_m = kGateRfidOffset;
        break;
    }
  }

  // The 20 S0 pucks in the input storage as drawn in the RB: two columns of ten, ids 1..10 at
  // x = 0.12, ids 11..20 at x = 0.28, y = 2.35 .. 3.25. The y values are computed as integer
  // centimetres / 100 so that they equal the decimal literals of config/world-2013.yaml.
  for (int col = 0; col < 2; ++col) {
    for (int k = 0; k < 10; ++k) {
      const double x = col == 0 ? 0.12 : 0.28;
      const double y = static_cast<double>(235 + 10 * k) / 100.0;
      c.pucks.push_back(PuckPlacement{col * 10 + k + 1, Vec2(x, y)});
    }
  }

  // Three robots in the insertion area, facing the field.
  c.robots = {RobotStart{"robot1", Pose2D{0.20, 0.40, 0.0}},
              RobotStart{"robot2", Pose2D{0.20, 1.00, 0.0}},
              RobotStart{"robot3", Pose2D{0.20, 1.60, 0.0}}};
  return c;
}

// ---------------------------------------------------------------------------------------------
// Validation
// ---------------------------------------------------------------------------------------------

namespace {

constexpr double kRfidMaxRange = 0.115;  // RB: ISO 15693 reader, read range <= 115 mm
constexpr double kEps = 1e-9;            // touching is not overlapping
constexpr int kMaxBeams = 10000;

std::string num(double v) { return core::number_text(v); }

/// "(x.xx, y.yy)" for positions in messages.
std::string at_xy(const Vec2& p) {
  char buf[96];
  std::snprintf(buf, sizeof buf, "(%.2f, %.2f)", p.x(), p.y());
  return buf;
}

[[noreturn]] void fail(const std::string& path, const std::string& reason) {
  throw ConfigError(path + ": " + reason);
}

/// True if the whole circle lies inside [0, width] x [0, height].
bool circle_inside_field(const Vec2& c, double r, const FieldConfig& f) {
  return c.x() - r >= -kEps && c.y() - r >= -kEps && c.x() + r <= f.width_m + kEps &&
         c.y() + r <= f.height_m + kEps;
}

/// Exact circle-vs-oriented-box test: the distance from the centre to the box is below r.
bool circle_overlaps_box(const Vec2& c, double r, const core::OrientedBox& box) {
  const Vec2 l = box.pose.to_local(c);
  const Vec2 nearest(std::clamp(l.x(), -box.half_extents.x(), box.half_extents.x()),
                     std::clamp(l.y(), -box.half_extents.y(), box.half_extents.y()));
  return (l - nearest).norm() < r - kEps;
}

bool circles_overlap(const Vec2& a, double ra, const Vec2& b, double rb) {
  return (a - b).norm() < ra + rb - kEps;
}

// ---- Bounds (docs/world-config.md, "Bounds") ----
// Every figure has a finite upper bound, checked at its key by the loader (before anything is
// computed from it) and again by validate() for worlds built in code.
constexpr double kMaxLengthM = 100.0;       ///< the 2013 field is 5.6 m across
constexpr double kMaxCoordinateM = 1000.0;  ///< as a scenario's robot start; then the field
constexpr double kMaxMassKg = 1000.0;
constexpr double kMaxFriction = 10.0;  ///< a Coulomb coefficient; rubber on concrete is ~1
constexpr double kMaxSpeedMps = 10.0;  ///< ten times a 2013 robot's 1 m/s
constexpr double kMaxOmegaRps = 20.0;  ///< about three turns a second
constexpr double kMaxAccelMps2 = 100.0;
constexpr double kMaxAlphaRps2 = 200.0;
constexpr double kMinRateHz = 0.01;    ///< a reading at least every 100 s: a period of the clock
constexpr double kMaxRateHz = 1000.0;  ///< the fastest physics rate (1 ms steps)
constexpr double kMaxNoise = 10.0;     ///< a noise figure (per metre, per rad, rad/s)
constexpr int kMaxIterations = 1000;   ///< solver iterations per physics step

constexpr core::Bound positive_at_most(double hi) {
  return {core::Bound::Kind::kOpenClosed, 0.0, hi};
}
constexpr core::Bound kLength = positive_at_most(kMaxLengthM);
constexpr core::Bound kGap = core::in_range(0.0, kMaxLengthM);
constexpr core::Bound kOffset = core::in_range(-kMaxLengthM, kMaxLengthM);
constexpr core::Bound kCoordinate = core::in_range(-kMaxCoordinateM, kMaxCoordinateM);
constexpr core::Bound kMass = positive_at_most(kMaxMassKg);
constexpr core::Bound kFriction = core::in_range(0.0, kMaxFriction);
constexpr core::Bound kRate = core::in_range(kMinRateHz, kMaxRateHz);
constexpr core::Bound kNoise = core::in_range(0.0, kMaxNoise);
constexpr core::Bound kIterations = core::in_range(1, kMaxIterations);
constexpr core::Bound kOriDeg = core::in_range(-720.0, 720.0);
constexpr core::Bound kOriRad = core::in_range(-4.0 * core::kPi, 4.0 * core::kPi);

/// A number of a config struct `T` with its key and bound.
template <class T>
struct Key {
  const char* key;
  double T::*field;
  core::Bound bound;
};

template <class T, std::size_t N>
void require_keys(const std::string& prefix, const T& obj, const Key<T> (&keys)[N]) {
  for (const Key<T>& k : keys) core::require(prefix + k.key, obj.*k.field, k.bound);
}

constexpr Key<FieldConfig> kFieldKeys[] = {
    {"width_m", &FieldConfig::width_m, kLength},
    {"height_m", &FieldConfig::height_m, kLength},
    {"wall_thickness_m", &FieldConfig::wall_thickness_m, kLength},
};
constexpr Key<DeviceConfig> kDeviceKeys[] = {
    {"body_depth_m", &DeviceConfig::body_depth_m, kLength},
    {"body_width_m", &DeviceConfig::body_width_m, kLength},
    {"body_offset_m", &DeviceConfig::body_offset_m, kOffset},
    {"rfid_offset_m", &DeviceConfig::rfid_offset_m, kOffset},
};
constexpr Key<PuckModelConfig> kPuckKeys[] = {
    {"radius_m", &PuckModelConfig::radius_m, kLength},
    {"mass_kg", &PuckModelConfig::mass_kg, kMass},
    {"floor_friction", &PuckModelConfig::floor_friction, kFriction},
    {"contact_friction", &PuckModelConfig::contact_friction, kFriction},
    {"restitution", &PuckModelConfig::restitution, core::probability()},
};
constexpr Key<RobotModelConfig> kRobotKeys[] = {
    {"radius_m", &RobotModelConfig::radius_m, kLength},
    {"mass_kg", &RobotModelConfig::mass_kg, kMass},
    {"max_speed_mps", &RobotModelConfig::max_speed_mps, positive_at_most(kMaxSpeedMps)},
    {"max_omega_rps", &RobotModelConfig::max_omega_rps, positive_at_most(kMaxOmegaRps)},
    {"max_accel_mps2", &RobotModelConfig::max_accel_mps2, positive_at_most(kMaxAccelMps2)},
    {"max_alpha_rps2", &RobotModelConfig::max_alpha_rps2, positive_at_most(kMaxAlphaRps2)},
    {"contact_friction", &RobotModelConfig::contact_friction, kFriction},
    {"laser_radius_m", &RobotModelConfig::laser_radius_m, kGap},
    {"laser_offset_m", &RobotModelConfig::laser_offset_m, kOffset},
};
// inner_width_m: at most kMaxLengthM here, wider than a puck in validate_robots().
constexpr Key<HolderConfig> kHolderKeys[] = {
    {"inner_width_m", &HolderConfig::inner_width_m, kLength},
    {"arm_length_m", &HolderConfig::arm_length_m, kLength},
    {"arm_thickness_m", &HolderConfig::arm_thickness_m, kLength},
    {"arm_friction", &HolderConfig::arm_friction, kFriction},
    {"release_backing_speed_mps", &HolderConfig::release_backing_speed_mps,
     core::in_range(0.0, kMaxSpeedMps)},
};
constexpr Key<OdometryConfig> kOdometryKeys[] = {
    {"rate_hz", &OdometryConfig::rate_hz, kRate},
    {"trans_noise_per_m", &OdometryConfig::trans_noise_per_m, kNoise},
    {"rot_noise_per_rad", &OdometryConfig::rot_noise_per_rad, kNoise},
    {"accel_noise_per_mps", &OdometryConfig::accel_noise_per_mps, kNoise},
    {"accel_rot_noise_per_rps", &OdometryConfig::accel_rot_noise_per_rps, kNoise},
};
constexpr Key<GyroConfig> kGyroKeys[] = {
    {"rate_hz", &GyroConfig::rate_hz, kRate},
    {"noise_std_rps", &GyroConfig::noise_std_rps, kNoise},
    {"bias_rps", &GyroConfig::bias_rps, core::in_range(-kMaxNoise, kMaxNoise)},
};
constexpr Key<IrConfig> kIrKeys[] = {
    {"rate_hz", &IrConfig::rate_hz, kRate},
    {"range_m", &IrConfig::range_m, kLength},
    {"noise_std_m", &IrConfig::noise_std_m, kGap},
    {"threshold_m", &IrConfig::threshold_m, kLength},
};
constexpr Key<OpticalConfig> kOpticalKeys[] = {
    {"rate_hz", &OpticalConfig::rate_hz, kRate},
    {"range_m", &OpticalConfig::range_m, kLength},
    {"miss_probability", &OpticalConfig::miss_probability, core::probability()},
};
constexpr Key<GroundTruthConfig> kGroundTruthKeys[] = {
    {"rate_hz", &GroundTruthConfig::rate_hz, kRate},
};
constexpr Key<LaserConfig> kLaserKeys[] = {
    {"rate_hz", &LaserConfig::rate_hz, kRate},
    {"min_range_m", &LaserConfig::min_range_m, kGap},
    {"max_range_m", &LaserConfig::max_range_m, kLength},
    {"noise_std_m", &LaserConfig::noise_std_m, kGap},
    {"mount_x_m", &LaserConfig::mount_x_m, kOffset},
    {"mount_y_m", &LaserConfig::mount_y_m, kOffset},
};

std::string device_path(int i) { return "devices." + std::string(kDeviceNames[i]); }
std::string indexed(const char* list, std::size_t i) {
  return std::string(list) + "[" + std::to_string(i) + "]";
}

/// The field size with the keys it comes from (so a loader can point at them).
std::string field_size(const FieldConfig& f) {
  return "field.width_m x field.height_m = " + num(f.width_m) + " x " + num(f.height_m);
}

void validate_field(const FieldConfig& f) { require_keys("field.", f, kFieldKeys); }

void validate_devices(const WorldConfig& c) {
  const FieldConfig& f = c.field;
  for (int i = 0; i < kDeviceCount; ++i) {
    const DeviceConfig& d = c.devices[i];
    const std::string p = device_path(i);
    core::require(p + ".x", d.pose.x, kCoordinate);
    core::require(p + ".y", d.pose.y, kCoordinate);
    core::require(p + ".ori", d.pose.theta, core::finite());
    require_keys(p + ".", d, kDeviceKeys);
    if (!(d.rfid_radius_m > 0.0 && d.rfid_radius_m <= kRfidMaxRange)) {
      fail(p + ".rfid_radius_m", "must be > 0 and <= " + num(kRfidMaxRange) +
                                     " (the RFID reader range) (got " + num(d.rfid_radius_m) + ")");
    }
    if (!core::inside_rect(d.footprint(), Vec2(0.0, 0.0), Vec2(f.width_m, f.height_m))) {
      fail(p, "footprint at " + at_xy(d.footprint().pose.position()) +
                  " is not entirely inside the field (" + field_size(f) + ")");
    }
    const Vec2 rc = d.rfid_center();
    if (!(rc.x() >= 0.0 && rc.y() >= 0.0 && rc.x() <= f.width_m && rc.y() <= f.height_m)) {
      fail(p, "RFID zone centre " + at_xy(rc) + " is outside the field (" + field_size(f) + ")");
    }
  }
  for (int i = 0; i < kDeviceCount; ++i) {
    for (int j = i + 1; j < kDeviceCount; ++j) {
      if (core::overlaps(c.devices[i].footprint(), c.devices[j].footprint())) {
        fail(device_path(i), "footprint overlaps " + device_path(j));
      }
    }
  }
}

/// The device whose footprint the circle overlaps, if any.
std::optional<int> device_hit(const WorldConfig& c, const Vec2& center, double r) {
  for (int i = 0; i < kDeviceCount; ++i) {
    if (circle_overlaps_box(center, r, c.devices[i].footprint())) return i;
  }
  return std::nullopt;
}

/// The obstacle whose box the circle overlaps, if any.
std::optional<std::size_t> obstacle_hit(const WorldConfig& c, const Vec2& center, double r) {
  for (std::size_t i = 0; i < c.obstacles.size(); ++i) {
    if (circle_overlaps_box(center, r, c.obstacles[i].footprint())) return i;
  }
  return std::nullopt;
}

void validate_obstacles(const WorldConfig& c) {
  const FieldConfig& f = c.field;
  for (std::size_t i = 0; i < c.obstacles.size(); ++i) {
    const ObstacleConfig& o = c.obstacles[i];
    const std::string p = indexed("obstacles", i);
    if (o.name.empty()) fail(p + ".name", "must not be empty");
    for (std::size_t j = 0; j < i; ++j) {
      if (c.obstacles[j].name == o.name) {
        fail(p + ".name", "duplicate obstacle name '" + o.name + "' (also used by " +
                              indexed("obstacles", j) + ")");
      }
    }
    core::require(p + ".x", o.pose.x, core::finite());
    core::require(p + ".y", o.pose.y, core::finite());
    core::require(p + ".ori", o.pose.theta, core::finite());
    core::require(p + ".size_x_m", o.size_x_m, core::positive());
    core::require(p + ".size_y_m", o.size_y_m, core::positive());
    if (!core::inside_rect(o.footprint(), Vec2(0.0, 0.0), Vec2(f.width_m, f.height_m))) {
      fail(p, "obstacle '" + o.name + "' at " + at_xy(o.pose.position()) +
                  " is not entirely inside the field (" + field_size(f) + ")");
    }
  }
}

void validate_pucks(const WorldConfig& c) {
  const PuckModelConfig& m = c.puck;
  require_keys("puck.", m, kPuckKeys);

  const double r = m.radius_m;
  std::map<int, std::size_t> seen_ids;
  for (std::size_t i = 0; i < c.pucks.size(); ++i) {
    const PuckPlacement& pk = c.pucks[i];
    const std::string p = indexed("pucks", i);
    if (pk.id <= 0) fail(p + ".id", "must be > 0 (got " + std::to_string(pk.id) + ")");
    if (auto [it, fresh] = seen_ids.emplace(pk.id, i); !fresh) {
      fail(p + ".id", "duplicate puck id " + std::to_string(pk.id) + " (also used by " +
                          indexed("pucks", it->second) + ")");
    }
    core::require(p + ".x", pk.position.x(), kCoordinate);
    core::require(p + ".y", pk.position.y(), kCoordinate);
    const std::string what = "puck " + std::to_string(pk.id) + " at " + at_xy(pk.position);
    if (!circle_inside_field(pk.position, r, c.field)) {
      fail(p, what + " is outside the field (the whole circle of puck.radius_m = " + num(r) +
                  " must lie inside " + field_size(c.field) + ")");
    }
    if (auto d = device_hit(c, pk.position, r)) {
      fail(p, what + " overlaps the footprint of " + device_path(*d));
    }
    if (auto o = obstacle_hit(c, pk.position, r)) {
      fail(p, what + " overlaps " + indexed("obstacles", *o));
    }
    for (std::size_t j = 0; j < i; ++j) {
      if (circles_overlap(pk.position, r, c.pucks[j].position, r)) {
        fail(p, what + " overlaps puck " + std::to_string(c.pucks[j].id) + " (" +
                    indexed("pucks", j) + ", puck.radius_m = " + num(r) + ")");
      }
    }
  }
}

void validate_robots(const WorldConfig& c) {
  const RobotModelConfig& m = c.robot;
  require_keys("robot.", m, kRobotKeys);

  const HolderConfig& h = m.holder;
  require_keys("robot.holder.", h, kHolderKeys);
  if (!(h.inner_width_m > 2.0 * c.puck.radius_m)) {
    fail("robot.holder.inner_width_m",
         "must be wider than the puck diameter 2 * puck.radius_m = " + num(2.0 * c.puck.radius_m) +
             " (got " + num(h.inner_width_m) + ")");
  }

  const double r = m.radius_m;
  std::map<std::string, std::size_t> seen_names;
  std::map<int, std::size_t> seen_jerseys;
  for (std::size_t i = 0; i < c.robots.size(); ++i) {
    const RobotStart& rs = c.robots[i];
    const std::string p = indexed("robots", i);
    if (rs.name.empty()) fail(p + ".name", "must not be empty");
    if (rs.jersey < 0 || rs.jersey > 99) {
      fail(p + ".jersey", "must be in 1..99, or 0 for the robot's index + 1 (got " +
                              std::to_string(rs.jersey) + ")");
    }
    if (auto [it, fresh] = seen_jerseys.emplace(rs.jersey_or(static_cast<int>(i)), i); !fresh) {
      fail(p + ".jersey", "duplicate jersey number " + std::to_string(it->first) +
                              " (also worn by " + indexed("robots", it->second) + ")");
    }
    if (auto [it, fresh] = seen_names.emplace(rs.name, i); !fresh) {
      fail(p + ".name", "duplicate robot name '" + rs.name + "' (also used by " +
                            indexed("robots", it->second) + ")");
    }
    core::require(p + ".x", rs.pose.x, kCoordinate);
    core::require(p + ".y", rs.pose.y, kCoordinate);
    core::require(p + ".ori", rs.pose.theta, core::finite());
    const Vec2 pos = rs.pose.position();
    const std::string what = "robot '" + rs.name + "' at " + at_xy(pos);
    if (!circle_inside_field(pos, r, c.field)) {
      fail(p, what + " is outside the field (the whole circle of robot.radius_m = " + num(r) +
                  " must lie inside " + field_size(c.field) + ")");
    }
    if (auto d = device_hit(c, pos, r)) {
      fail(p, what + " overlaps the footprint of " + device_path(*d));
    }
    if (auto o = obstacle_hit(c, pos, r)) {
      fail(p, what + " overlaps " + indexed("obstacles", *o));
    }
    for (std::size_t j = 0; j < i; ++j) {
      if (circles_overlap(pos, r, c.robots[j].pose.position(), r)) {
        fail(p, what + " overlaps robot '" + c.robots[j].name + "' (" + indexed("robots", j) +
                    ", robot.radius_m = " + num(r) + ")");
      }
    }
    for (std::size_t j = 0; j < c.pucks.size(); ++j) {
      if (circles_overlap(pos, r, c.pucks[j].position, c.puck.radius_m)) {
        fail(p, what + " overlaps puck " + std::to_string(c.pucks[j].id) + " (" +
                    indexed("pucks", j) + ")");
      }
    }
  }
}

void validate_sensors(const SensorsConfig& s) {
  require_keys("sensors.odometry.", s.odometry, kOdometryKeys);
  require_keys("sensors.gyro.", s.gyro, kGyroKeys);
  require_keys("sensors.ir.", s.ir, kIrKeys);
  if (s.ir.threshold_m > s.ir.range_m) {
    fail("sensors.ir.threshold_m", "must be <= sensors.ir.range_m " + num(s.ir.range_m) + " (got " +
                                       num(s.ir.threshold_m) + ")");
  }

  require_keys("sensors.optical.", s.optical, kOpticalKeys);
  require_keys("sensors.ground_truth.", s.ground_truth, kGroundTruthKeys);

  const LaserConfig& l = s.laser;
  core::require("sensors.laser.beams", l.beams, core::in_range(1, kMaxBeams));
  require_keys("sensors.laser.", l, kLaserKeys);
  if (!(l.min_range_m < l.max_range_m)) {
    fail("sensors.laser.min_range_m", "must be < sensors.laser.max_range_m " + num(l.max_range_m) +
                                          " (got " + num(l.min_range_m) + ")");
  }
}

void validate_physics(const PhysicsConfig& p) {
  if (p.step <= SimTime() || p.step > SimTime::from_ms(100)) {
    fail("physics.step_ms", "must be > 0 and <= 100 (got " + num(p.step.seconds() * 1000.0) + ")");
  }
  core::require("physics.velocity_iterations", p.velocity_iterations, kIterations);
  core::require("physics.position_iterations", p.position_iterations, kIterations);
}

}  // namespace

void WorldConfig::validate() const {
  // Models before placements: the placement checks use the sizes.
  validate_field(field);
  validate_devices(*this);
  validate_obstacles(*this);
  validate_pucks(*this);
  validate_robots(*this);
  validate_sensors(sensors);
  validate_physics(physics);
}

// ---------------------------------------------------------------------------------------------
// YAML loading
// ---------------------------------------------------------------------------------------------

namespace {

/// Reads a document into a WorldConfig; core::ConfigNode checks for unknown keys and puts the
/// file:line on validate() errors.
class Loader {
 public:
  explicit Loader(const ConfigNode& root) : root_(root) {}

  WorldConfig load(WorldConfig c) {
    root_.require_map();
    read_field(c.field);
    read_devices(c);
    read_puck_model(c.puck);
    read_pucks(c);
    read_robot_model(c.robot);
    read_robots(c);
    read_sensors(c.sensors);
    read_physics(c.physics);
    root_.no_other_keys();
    root_.locate_errors([&] { c.validate(); });
    return c;
  }

 private:
  /// The map under `key` (possibly undefined or null).
  static ConfigNode section(const ConfigNode& parent, std::string_view key) {
    ConfigNode n = parent[key];
    n.require_map();
    return n;
  }
  /// An element of a list that must be a map.
  static void element(const ConfigNode& e, const char* what) {
    if (!e.is_map()) e.fail(std::string("expected a map ") + what);
  }
  /// Each number checked at its own key against its bound.
  template <class T, std::size_t N>
  static void read_keys(const ConfigNode& n, T& obj, const Key<T> (&keys)[N]) {
    for (const Key<T>& k : keys) n.read(k.key, obj.*k.field, k.bound);
  }

  /// `ori` (radians) or `ori_deg` (degrees), normalised to (-pi, pi].
  static void read_orientation(const ConfigNode& m, double& theta) {
    const ConfigNode rad = m["ori"];
    const ConfigNode deg = m["ori_deg"];
    if (rad.defined() && deg.defined()) {
      deg.fail("give either 'ori' (radians) or 'ori_deg' (degrees), not both");
    }
    if (rad.defined()) {
      theta = core::normalize_angle(rad.as_double(kOriRad));
    } else if (deg.defined()) {
      theta = core::normalize_angle(core::deg_to_rad(deg.as_double(kOriDeg)));
    }
  }

  void read_field(FieldConfig& f) {
    const ConfigNode n = section(root_, "field");
    read_keys(n, f, kFieldKeys);
    n.no_other_keys();
  }

  void read_devices(WorldConfig& c) {
    const ConfigNode devs = section(root_, "devices");
    if (!devs.is_map()) return;
    for (const std::string& name : devs.keys()) {
      const ConfigNode d = devs[name];
      const auto id = device_by_name(name);
      if (!id) {
        d.fail("unknown device '" + name + "' (expected one of M1..M10, R1, R2, TST, D1, D2, D3)");
      }
      d.require_map();
      DeviceConfig& dev = c.devices[id->value()];
      d.read("x", dev.pose.x, kCoordinate);
      d.read("y", dev.pose.y, kCoordinate);
      read_orientation(d, dev.pose.theta);
      read_keys(d, dev, kDeviceKeys);
      d.read("rfid_radius_m", dev.rfid_radius_m);
      d.no_other_keys();
    }
  }

  void read_puck_model(PuckModelConfig& m) {
    const ConfigNode n = section(root_, "puck");
    read_keys(n, m, kPuckKeys);
    n.no_other_keys();
  }

  void read_pucks(WorldConfig& c) {
    const ConfigNode list = root_["pucks"];
    if (!list.defined()) return;
    c.pucks.clear();  // the list replaces the base's; null or [] means no pucks
    if (list.is_null()) return;
    for (const ConfigNode& e : list.elements()) {
      element(e, "{id, x, y}");
      PuckPlacement p;
      e.at("id");  // required keys: fail early with "missing required key"
      e.at("x");
      e.at("y");
      e.read("id", p.id);
      e.read("x", p.position.x(), kCoordinate);
      e.read("y", p.position.y(), kCoordinate);
      e.no_other_keys();
      c.pucks.push_back(p);
    }
  }

  void read_robot_model(RobotModelConfig& m) {
    const ConfigNode n = section(root_, "robot");
    read_keys(n, m, kRobotKeys);

    HolderConfig& h = m.holder;
    const ConfigNode hn = section(n, "holder");
    hn.read_enum("mode", h.mode,
                 {{"physical", HolderMode::kPhysical}, {"assisted", HolderMode::kAssisted}},
                 "holder mode");
    read_keys(hn, h, kHolderKeys);
    hn.no_other_keys();
    n.no_other_keys();
  }

  void read_robots(WorldConfig& c) {
    const ConfigNode list = root_["robots"];
    if (!list.defined()) return;
    c.robots.clear();  // the list replaces the base's; null or [] means no robots
    if (list.is_null()) return;
    for (const ConfigNode& e : list.elements()) {
      element(e, "{name, x, y, ori_deg, jersey}");
      RobotStart r;
      r.name = e.at("name").as_string();
      r.pose.x = e.at("x").as_double(kCoordinate);
      r.pose.y = e.at("y").as_double(kCoordinate);
      read_orientation(e, r.pose.theta);
      e.read("jersey", r.jersey);
      e.no_other_keys();
      c.robots.push_back(std::move(r));
    }
  }

  void read_sensors(SensorsConfig& s) {
    const ConfigNode n = section(root_, "sensors");

    const ConfigNode odo = section(n, "odometry");
    read_keys(odo, s.odometry, kOdometryKeys);
    odo.no_other_keys();

    const ConfigNode gyro = section(n, "gyro");
    read_keys(gyro, s.gyro, kGyroKeys);
    gyro.no_other_keys();

    const ConfigNode ir = section(n, "ir");
    read_keys(ir, s.ir, kIrKeys);
    ir.no_other_keys();

    const ConfigNode opt = section(n, "optical");
    read_keys(opt, s.optical, kOpticalKeys);
    opt.no_other_keys();

    const ConfigNode gt = section(n, "ground_truth");
    read_keys(gt, s.ground_truth, kGroundTruthKeys);
    gt.no_other_keys();

    const ConfigNode las = section(n, "laser");
    las.read("enabled", s.laser.enabled);
    las.read("beams", s.laser.beams, core::in_range(1, kMaxBeams));
    read_keys(las, s.laser, kLaserKeys);
    las.no_other_keys();
    n.no_other_keys();
  }

  void read_physics(PhysicsConfig& p) {
    const ConfigNode n = section(root_, "physics");
    if (const ConfigNode step = n["step_ms"]; step.defined()) {
      const double ms = step.as_double();
      // Checked here too: a huge value would overflow the nanosecond conversion.
      if (!(ms > 0.0 && ms <= 100.0)) step.fail("must be > 0 and <= 100 (got " + num(ms) + ")");
      p.step = SimTime::from_seconds(ms / 1000.0);
    }
    n.read("velocity_iterations", p.velocity_iterations, kIterations);
    n.read("position_iterations", p.position_iterations, kIterations);
    n.no_other_keys();
  }

  ConfigNode root_;
};

}  // namespace

WorldConfig load_world_config(const core::ConfigNode& node, WorldConfig base) {
  if (!node.defined() || node.is_null()) {
    // An empty document: the base unchanged (still checked, it may come from elsewhere).
    node.locate_errors([&] { base.validate(); });
    return base;
  }
  return Loader(node).load(std::move(base));
}

WorldConfig load_world_config_file(const std::string& path) {
  return load_world_config(core::ConfigNode::load_file(path));
}

}  // namespace llsf::kinematic
