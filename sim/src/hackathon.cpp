// SPDX-License-Identifier: MIT
#include "llsf/sim/hackathon.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <utility>

#include "llsf/core/error.h"

namespace llsf::sim {

namespace {

using core::Vec2;
using kinematic::ObstacleConfig;
using kinematic::Rect;

std::string num(double v) { return core::number_text(v); }

[[noreturn]] void fail(const std::string& path, const std::string& why) {
  throw core::ConfigError("hackathon." + path + ": " + why);
}

/// `value` of the hackathon field `path` (without the "hackathon." prefix) within `bound`.
void require_hackathon(const std::string& path, double value, const core::Bound& bound) {
  core::require("hackathon." + path, value, bound);
}

/// Distance from point `p` to the box (0 inside).
double distance_to_box(const Vec2& p, const core::OrientedBox& box) {
  const Vec2 l = box.pose.to_local(p);
  const Vec2 nearest(std::clamp(l.x(), -box.half_extents.x(), box.half_extents.x()),
                     std::clamp(l.y(), -box.half_extents.y(), box.half_extents.y()));
  return (l - nearest).norm();
}

/// Distance from point `p` to the rectangle (0 inside).
double distance_to_rect(const Vec2& p, const Rect& r) {
  const Vec2 nearest(std::clamp(p.x(), r.lo.x(), r.hi.x()), std::clamp(p.y(), r.lo.y(), r.hi.y()));
  return (p - nearest).norm();
}

/// The rectangle as an oriented box.
core::OrientedBox box_of(const Rect& r) {
  const Vec2 c = r.center();
  return {core::Pose2D{c.x(), c.y(), 0.0}, 0.5 * (r.hi - r.lo)};
}

std::string indexed(const char* list, std::size_t i) {
  return std::string(list) + "[" + std::to_string(i) + "]";
}

}  // namespace

// --- config ------------------------------------------------------------------------------------

std::vector<ObstacleConfig> HackathonConfig::default_obstacles() {
  // Free lanes of the 2013 field, clear of every device's input, side and look place.
  return {
      {"box1", {1.00, 4.20, 0.0}, 0.3, 0.3},
      {"box2", {3.60, 4.80, 0.0}, 0.3, 0.3},
      {"box3", {3.50, 2.60, 0.0}, 0.3, 0.3},
      {"box4", {4.65, 1.40, 0.0}, 0.3, 0.3},
  };
}

std::vector<HackathonColour> HackathonConfig::default_colours() {
  return {{"red", 3, false}, {"green", 3, false}, {"blue", 3, false}, {"yellow", 3, true}};
}

int HackathonConfig::colour_index(std::string_view name) const {
  for (std::size_t i = 0; i < colours.size(); ++i) {
    if (colours[i].name == name) return static_cast<int>(i);
  }
  return -1;
}

void HackathonConfig::validate(const kinematic::WorldConfig& world) const {
  const double w = world.field.width_m, h = world.field.height_m;
  // Safe area.
  for (const auto& [key, v] : {std::pair{"safe_area.x_min", safe_area.lo.x()},
                               std::pair{"safe_area.y_min", safe_area.lo.y()},
                               std::pair{"safe_area.x_max", safe_area.hi.x()},
                               std::pair{"safe_area.y_max", safe_area.hi.y()}}) {
    require_hackathon(key, v, core::finite());
  }
  if (!(safe_area.hi.x() - safe_area.lo.x() >= 0.1))
    fail("safe_area.x_max", "must be at least 0.1 m greater than x_min");
  if (!(safe_area.hi.y() - safe_area.lo.y() >= 0.1))
    fail("safe_area.y_max", "must be at least 0.1 m greater than y_min");
  if (safe_area.lo.x() < 0.0 || safe_area.lo.y() < 0.0 || safe_area.hi.x() > w ||
      safe_area.hi.y() > h) {
    fail("safe_area", "must lie inside the field (0..." + num(w) + " x 0..." + num(h) + ")");
  }
  const core::OrientedBox safe_box = box_of(safe_area);
  for (int d = 0; d < kinematic::kDeviceCount; ++d) {
    if (core::overlaps(safe_box, world.devices[static_cast<std::size_t>(d)].footprint())) {
      fail("safe_area", "overlaps the footprint of device " +
                            std::string(kinematic::kDeviceNames[static_cast<std::size_t>(d)]));
    }
  }
  if (safe_place.empty()) fail("safe_place", "must not be empty");

  // Obstacles: sizes and the field via the world's own checks, then against devices, the safe
  // area, each other and the robots' starts.
  kinematic::WorldConfig probe = world;
  probe.obstacles = obstacles;
  probe.pucks.clear();  // the layout replaces the world's pucks
  try {
    probe.validate();
  } catch (const core::ConfigError& e) {
    throw core::ConfigError("hackathon." + std::string(e.what()));
  }
  for (std::size_t i = 0; i < obstacles.size(); ++i) {
    const core::OrientedBox box = obstacles[i].footprint();
    const std::string p = indexed("obstacles", i);
    for (int d = 0; d < kinematic::kDeviceCount; ++d) {
      if (core::overlaps(box, world.devices[static_cast<std::size_t>(d)].footprint())) {
        fail(p, "obstacle '" + obstacles[i].name + "' overlaps the footprint of device " +
                    std::string(kinematic::kDeviceNames[static_cast<std::size_t>(d)]));
      }
    }
    if (core::overlaps(box, safe_box)) {
      fail(p, "obstacle '" + obstacles[i].name + "' overlaps the safe area");
    }
    for (std::size_t j = 0; j < i; ++j) {
      if (core::overlaps(box, obstacles[j].footprint())) {
        fail(p, "obstacle '" + obstacles[i].name + "' overlaps " + indexed("obstacles", j));
      }
    }
  }

  // Colours.
  if (colours.empty()) fail("colours", "give at least one colour");
  int pucks = 0;
  for (std::size_t i = 0; i < colours.size(); ++i) {
    const HackathonColour& c = colours[i];
    const std::string p = indexed("colours", i);
    if (c.name.empty()) fail(p + ".name", "must not be empty");
    for (std::size_t j = 0; j < i; ++j) {
      if (colours[j].name == c.name) {
        fail(p + ".name", "duplicate colour '" + c.name + "' (also " + indexed("colours", j) + ")");
      }
    }
    if (c.count < 0 || c.count > 100) {
      fail(p + ".count", "must be in 0..100 (got " + std::to_string(c.count) + ")");
    }
    pucks += c.count;
  }
  if (pucks == 0) fail("colours", "no pucks: every count is 0");

  // Numbers.
  require_hackathon("puck_clearance_m", puck_clearance_m, core::non_negative());
  if (!(puck_spacing_m >= 2.0 * world.puck.radius_m) || !std::isfinite(puck_spacing_m)) {
    fail("puck_spacing_m", "must be >= the puck diameter " + num(2.0 * world.puck.radius_m) +
                               " (got " + num(puck_spacing_m) + ")");
  }
  require_hackathon("points_per_puck", points_per_puck, core::non_negative());
  require_hackathon("decoy_penalty", decoy_penalty, core::non_negative());

  // Camera.
  const ColourCameraConfig& cam = camera;
  require_hackathon("camera.range_m", cam.range_m, core::positive());
  if (!(cam.fov_rad > 0.0 && cam.fov_rad <= 2.0 * core::kPi))
    fail("camera.fov_deg",
         "must be in (0, 360] (got " + num(cam.fov_rad * 180.0 / core::kPi) + ")");
  require_hackathon("camera.frame_rate_hz", cam.frame_rate_hz, core::positive());
  require_hackathon("camera.miss_rate", cam.miss_rate, core::probability());
  require_hackathon("camera.false_colour_rate", cam.false_colour_rate, core::probability());
  require_hackathon("camera.position_noise_m", cam.position_noise_m, core::non_negative());
}

// --- layout ------------------------------------------------------------------------------------

HackathonLayout generate_hackathon_layout(const HackathonConfig& config,
                                          const kinematic::WorldConfig& world,
                                          const core::Rng& rng) {
  core::RandomStream draw = rng.stream("sim/hackathon/layout");
  const double r = world.puck.radius_m;
  const double clear = r + config.puck_clearance_m;
  const double w = world.field.width_m, h = world.field.height_m;
  auto free = [&](const Vec2& p, const std::vector<HackathonPuck>& placed) {
    for (const kinematic::DeviceConfig& d : world.devices) {
      if (distance_to_box(p, d.footprint()) < clear) return false;
    }
    for (const ObstacleConfig& o : config.obstacles) {
      if (distance_to_box(p, o.footprint()) < clear) return false;
    }
    if (distance_to_rect(p, config.safe_area) < clear) return false;
    for (const kinematic::RobotStart& s : world.robots) {
      if ((p - s.pose.position()).norm() < clear + world.robot.radius_m) return false;
    }
    for (const HackathonPuck& q : placed) {
      if ((p - q.position).norm() < config.puck_spacing_m) return false;
    }
    return true;
  };
  HackathonLayout layout;
  constexpr int kTries = 10000;
  int id = 1;
  for (std::size_t c = 0; c < config.colours.size(); ++c) {
    for (int k = 0; k < config.colours[c].count; ++k) {
      bool placed = false;
      for (int t = 0; t < kTries && !placed; ++t) {
        const Vec2 p(draw.uniform(clear, w - clear), draw.uniform(clear, h - clear));
        if (!free(p, layout.pucks)) continue;
        layout.pucks.push_back({core::PuckId(id), static_cast<int>(c), p});
        placed = true;
      }
      if (!placed) {
        fail("colours", "no free spot for puck " + std::to_string(id) + " (" +
                            config.colours[c].name + ") within " + std::to_string(kTries) +
                            " draws: fewer pucks, a smaller puck_clearance_m or puck_spacing_m");
      }
      ++id;
    }
  }
  return layout;
}

void apply_hackathon_layout(const HackathonConfig& config, const HackathonLayout& layout,
                            kinematic::WorldConfig& world) {
  world.obstacles.insert(world.obstacles.end(), config.obstacles.begin(), config.obstacles.end());
  world.pucks.clear();
  for (const HackathonPuck& p : layout.pucks) world.pucks.push_back({p.id.value(), p.position});
}

core::Pose2D hackathon_safe_pose(const HackathonConfig& config, const kinematic::WorldConfig& world,
                                 double held_puck_offset_m) {
  const Vec2 c = config.safe_area.center();
  const Vec2 field_centre(0.5 * world.field.width_m, 0.5 * world.field.height_m);
  const Vec2 d = c - field_centre;
  double theta = 0.0;
  if (std::abs(d.x()) >= std::abs(d.y())) {
    theta = d.x() >= 0.0 ? 0.0 : core::kPi;
  } else {
    theta = d.y() >= 0.0 ? 0.5 * core::kPi : -0.5 * core::kPi;
  }
  const Vec2 dir(std::cos(theta), std::sin(theta));
  const Vec2 p = c - held_puck_offset_m * dir;
  return {p.x(), p.y(), theta};
}

// --- score -------------------------------------------------------------------------------------

HackathonScore score_hackathon(const HackathonConfig& config, const HackathonLayout& layout,
                               std::span<const HackathonPuckState> pucks) {
  HackathonScore s;
  for (const HackathonColour& c : config.colours) s.colours.push_back({c.name, c.decoy, 0, 0});
  std::map<std::int32_t, int> colour_of;
  for (const HackathonPuck& p : layout.pucks) {
    colour_of[p.id.value()] = p.colour;
    ++s.total_pucks;
    ++s.colours[static_cast<std::size_t>(p.colour)].total;
    if (!config.colours[static_cast<std::size_t>(p.colour)].decoy) ++s.rescuable;
  }
  for (const HackathonPuckState& p : pucks) {
    const auto it = colour_of.find(p.id.value());
    if (it == colour_of.end() || !p.on_field || p.held) continue;
    if (!config.safe_area.contains(p.position)) continue;
    HackathonColourScore& cs = s.colours[static_cast<std::size_t>(it->second)];
    ++cs.in_safe_area;
    if (cs.decoy) {
      ++s.decoys;
    } else {
      ++s.rescued;
    }
    s.in_safe_area.push_back(p.id);
  }
  std::sort(s.in_safe_area.begin(), s.in_safe_area.end());
  s.points = s.rescued * config.points_per_puck - s.decoys * config.decoy_penalty;
  return s;
}

// --- YAML --------------------------------------------------------------------------------------

namespace {

void read_int(const core::ConfigNode& m, const std::string& key, int& out) {
  if (const core::ConfigNode v = m[key]; v.defined()) {
    const std::int64_t x = v.as_int();
    if (x < -1000000 || x > 1000000) v.fail("out of range");
    out = static_cast<int>(x);
  }
}

void read_safe_area(const core::ConfigNode& n, Rect& r) {
  if (!n.defined()) return;
  n.require_map();
  double x0 = r.lo.x(), y0 = r.lo.y(), x1 = r.hi.x(), y1 = r.hi.y();
  n.read("x_min", x0);
  n.read("y_min", y0);
  n.read("x_max", x1);
  n.read("y_max", y1);
  n.no_other_keys();
  r = Rect{{x0, y0}, {x1, y1}};
}

void read_obstacles(const core::ConfigNode& n, std::vector<ObstacleConfig>& out) {
  if (!n.defined()) return;
  out.clear();  // a given list replaces the default
  if (n.is_null()) return;
  if (!n.is_sequence()) n.fail("expected a list of {name, x, y, size_x_m, size_y_m, ori_deg}");
  for (int i = 0; i < n.size(); ++i) {
    const core::ConfigNode e = n.at(i);
    if (!e.is_map()) e.fail("expected a map {name, x, y, size_x_m, size_y_m, ori_deg}");
    ObstacleConfig o;
    o.name = "box" + std::to_string(i + 1);
    e.read("name", o.name);
    o.pose.x = e.at("x").as_double();  // at(): required, "missing key" at the element
    o.pose.y = e.at("y").as_double();
    o.size_x_m = e.at("size_x_m").as_double();
    o.size_y_m = e.at("size_y_m").as_double();
    double deg = 0.0;
    e.read("ori_deg", deg);
    o.pose.theta = core::normalize_angle(deg * core::kPi / 180.0);
    e.no_other_keys();
    out.push_back(std::move(o));
  }
}

void read_colours(const core::ConfigNode& n, std::vector<HackathonColour>& out) {
  if (!n.defined()) return;
  if (!n.is_sequence()) n.fail("expected a list of {name, count, decoy}");
  out.clear();
  for (int i = 0; i < n.size(); ++i) {
    const core::ConfigNode e = n.at(i);
    if (!e.is_map()) e.fail("expected a map {name, count, decoy}");
    HackathonColour c;
    c.name = e.at("name").as_string();
    read_int(e, "count", c.count);
    e.read("decoy", c.decoy);
    e.no_other_keys();
    out.push_back(std::move(c));
  }
}

void read_camera(const core::ConfigNode& n, ColourCameraConfig& c) {
  if (!n.defined()) return;
  n.require_map();
  n.read("range_m", c.range_m);
  if (n["fov_deg"].defined()) c.fov_rad = n["fov_deg"].as_double() * core::kPi / 180.0;
  n.read("frame_rate_hz", c.frame_rate_hz);
  n.read("miss_rate", c.miss_rate);
  n.read("false_colour_rate", c.false_colour_rate);
  n.read("position_noise_m", c.position_noise_m);
  n.no_other_keys();
}

}  // namespace

HackathonConfig load_hackathon_config(const core::ConfigNode& node,
                                      const kinematic::WorldConfig& world) {
  HackathonConfig c;
  const core::ConfigNode& n = node;
  if (n.defined() && !n.is_null()) {
    n.require_map();
    read_safe_area(n["safe_area"], c.safe_area);
    n.read("safe_place", c.safe_place);
    read_obstacles(n["obstacles"], c.obstacles);
    read_colours(n["colours"], c.colours);
    n.read("puck_clearance_m", c.puck_clearance_m);
    n.read("puck_spacing_m", c.puck_spacing_m);
    read_int(n, "points_per_puck", c.points_per_puck);
    read_int(n, "decoy_penalty", c.decoy_penalty);
    read_camera(n["camera"], c.camera);
    n.no_other_keys();
  }
  try {
    c.validate(world);
  } catch (const core::ConfigError& e) {
    // validate() names fields "hackathon.<path>"; the path is relative to this map.
    const std::string what = e.what();
    const std::string prefix = "hackathon.";
    n.relocate(core::ConfigError(what.rfind(prefix, 0) == 0 ? what.substr(prefix.size()) : what));
  }
  return c;
}

}  // namespace llsf::sim
