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

std::string num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%g", v);
  return buf;
}

[[noreturn]] void fail(const std::string& path, const std::string& why) {
  throw core::ConfigError("hackathon." + path + ": " + why);
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
    if (!std::isfinite(v)) fail(key, "must be a finite number (got " + num(v) + ")");
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
  if (!(puck_clearance_m >= 0.0) || !std::isfinite(puck_clearance_m))
    fail("puck_clearance_m", "must be >= 0 (got " + num(puck_clearance_m) + ")");
  if (!(puck_spacing_m >= 2.0 * world.puck.radius_m) || !std::isfinite(puck_spacing_m)) {
    fail("puck_spacing_m", "must be >= the puck diameter " + num(2.0 * world.puck.radius_m) +
                               " (got " + num(puck_spacing_m) + ")");
  }
  if (points_per_puck < 0)
    fail("points_per_puck", "must be >= 0 (got " + std::to_string(points_per_puck) + ")");
  if (decoy_penalty < 0)
    fail("decoy_penalty", "must be >= 0 (got " + std::to_string(decoy_penalty) + ")");

  // Camera.
  const ColourCameraConfig& cam = camera;
  if (!(cam.range_m > 0.0) || !std::isfinite(cam.range_m))
    fail("camera.range_m", "must be > 0 (got " + num(cam.range_m) + ")");
  if (!(cam.fov_rad > 0.0 && cam.fov_rad <= 2.0 * core::kPi))
    fail("camera.fov_deg",
         "must be in (0, 360] (got " + num(cam.fov_rad * 180.0 / core::kPi) + ")");
  if (!(cam.frame_rate_hz > 0.0) || !std::isfinite(cam.frame_rate_hz))
    fail("camera.frame_rate_hz", "must be > 0 (got " + num(cam.frame_rate_hz) + ")");
  if (!(cam.miss_rate >= 0.0 && cam.miss_rate <= 1.0))
    fail("camera.miss_rate", "must be in [0, 1] (got " + num(cam.miss_rate) + ")");
  if (!(cam.false_colour_rate >= 0.0 && cam.false_colour_rate <= 1.0))
    fail("camera.false_colour_rate", "must be in [0, 1] (got " + num(cam.false_colour_rate) + ")");
  if (!(cam.position_noise_m >= 0.0) || !std::isfinite(cam.position_noise_m))
    fail("camera.position_noise_m", "must be >= 0 (got " + num(cam.position_noise_m) + ")");
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

/// Reads the map and remembers the node of every path, so that a validate() error can be
/// reported at the line of the value it names.
class HackathonLoader {
 public:
  HackathonConfig load(const core::ConfigNode& n, const kinematic::WorldConfig& world) {
    HackathonConfig c;
    remember("", n);
    if (n.defined() && !n.is_null()) {
      n.require_map();
      n.check_keys({"safe_area", "safe_place", "obstacles", "colours", "puck_clearance_m",
                    "puck_spacing_m", "points_per_puck", "decoy_penalty", "camera"});
      read_safe_area(n["safe_area"], c.safe_area);
      if (n["safe_place"].defined()) c.safe_place = value(n, "safe_place").as_string();
      read_obstacles(n["obstacles"], c.obstacles);
      read_colours(n["colours"], c.colours);
      number(n, "puck_clearance_m", "puck_clearance_m", c.puck_clearance_m);
      number(n, "puck_spacing_m", "puck_spacing_m", c.puck_spacing_m);
      integer(n, "points_per_puck", "points_per_puck", c.points_per_puck);
      integer(n, "decoy_penalty", "decoy_penalty", c.decoy_penalty);
      read_camera(n["camera"], c.camera);
    }
    try {
      c.validate(world);
    } catch (const core::ConfigError& e) {
      fail_at(e.what());
    }
    return c;
  }

 private:
  void remember(const std::string& path, const core::ConfigNode& n) {
    if (n.defined()) seen_.insert_or_assign(path, n);
  }
  core::ConfigNode value(const core::ConfigNode& m, const std::string& key,
                         const std::string& path = "") {
    const core::ConfigNode v = m[key];
    remember(path.empty() ? key : path, v);
    return v;
  }
  void number(const core::ConfigNode& m, const std::string& key, const std::string& path,
              double& out) {
    if (m[key].defined()) out = value(m, key, path).as_double();
  }
  void integer(const core::ConfigNode& m, const std::string& key, const std::string& path,
               int& out) {
    if (!m[key].defined()) return;
    const std::int64_t v = value(m, key, path).as_int();
    if (v < -1000000 || v > 1000000) m[key].fail("out of range");
    out = static_cast<int>(v);
  }

  void read_safe_area(const core::ConfigNode& n, Rect& r) {
    if (!n.defined()) return;
    n.require_map();
    n.check_keys({"x_min", "y_min", "x_max", "y_max"});
    remember("safe_area", n);
    double x0 = r.lo.x(), y0 = r.lo.y(), x1 = r.hi.x(), y1 = r.hi.y();
    number(n, "x_min", "safe_area.x_min", x0);
    number(n, "y_min", "safe_area.y_min", y0);
    number(n, "x_max", "safe_area.x_max", x1);
    number(n, "y_max", "safe_area.y_max", y1);
    r = Rect{{x0, y0}, {x1, y1}};
  }

  void read_obstacles(const core::ConfigNode& n, std::vector<ObstacleConfig>& out) {
    if (!n.defined()) return;
    out.clear();  // a given list replaces the default
    if (n.is_null()) return;
    if (!n.is_sequence()) n.fail("expected a list of {name, x, y, size_x_m, size_y_m, ori_deg}");
    remember("obstacles", n);
    for (int i = 0; i < n.size(); ++i) {
      const core::ConfigNode e = n.at(i);
      if (!e.is_map()) e.fail("expected a map {name, x, y, size_x_m, size_y_m, ori_deg}");
      e.check_keys({"name", "x", "y", "size_x_m", "size_y_m", "ori_deg"});
      const std::string p = indexed("obstacles", static_cast<std::size_t>(i));
      remember(p, e);
      ObstacleConfig o;
      o.name = e["name"].defined() ? value(e, "name", p + ".name").as_string()
                                   : "box" + std::to_string(i + 1);
      auto required = [&](const char* key) {
        static_cast<void>(e.at(key));  // throws "missing key" at the element
        return value(e, key, p + "." + key).as_double();
      };
      o.pose.x = required("x");
      o.pose.y = required("y");
      o.size_x_m = required("size_x_m");
      o.size_y_m = required("size_y_m");
      double deg = 0.0;
      number(e, "ori_deg", p + ".ori", deg);
      o.pose.theta = core::normalize_angle(deg * core::kPi / 180.0);
      out.push_back(std::move(o));
    }
  }

  void read_colours(const core::ConfigNode& n, std::vector<HackathonColour>& out) {
    if (!n.defined()) return;
    if (!n.is_sequence()) n.fail("expected a list of {name, count, decoy}");
    remember("colours", n);
    out.clear();
    for (int i = 0; i < n.size(); ++i) {
      const core::ConfigNode e = n.at(i);
      if (!e.is_map()) e.fail("expected a map {name, count, decoy}");
      e.check_keys({"name", "count", "decoy"});
      const std::string p = indexed("colours", static_cast<std::size_t>(i));
      remember(p, e);
      HackathonColour c;
      static_cast<void>(e.at("name"));  // required
      c.name = value(e, "name", p + ".name").as_string();
      integer(e, "count", p + ".count", c.count);
      if (e["decoy"].defined()) c.decoy = value(e, "decoy", p + ".decoy").as_bool();
      out.push_back(std::move(c));
    }
  }

  void read_camera(const core::ConfigNode& n, ColourCameraConfig& c) {
    if (!n.defined()) return;
    n.require_map();
    n.check_keys({"range_m", "fov_deg", "frame_rate_hz", "miss_rate", "false_colour_rate",
                  "position_noise_m"});
    remember("camera", n);
    number(n, "range_m", "camera.range_m", c.range_m);
    if (n["fov_deg"].defined()) {
      c.fov_rad = value(n, "fov_deg", "camera.fov_deg").as_double() * core::kPi / 180.0;
    }
    number(n, "frame_rate_hz", "camera.frame_rate_hz", c.frame_rate_hz);
    number(n, "miss_rate", "camera.miss_rate", c.miss_rate);
    number(n, "false_colour_rate", "camera.false_colour_rate", c.false_colour_rate);
    number(n, "position_noise_m", "camera.position_noise_m", c.position_noise_m);
  }

  /// Re-throws a validate() error ("hackathon.obstacles[1].x: reason") at the line of the node
  /// of its path, or of its nearest parent (then the full path stays in the reason).
  [[noreturn]] void fail_at(const std::string& message) const {
    const auto colon = message.find(": ");
    std::string path = message.substr(0, colon);
    const std::string reason = colon == std::string::npos ? message : message.substr(colon + 2);
    if (path.rfind("hackathon.", 0) == 0) path = path.substr(10);
    bool exact = true;
    while (true) {
      if (const auto it = seen_.find(path); it != seen_.end()) {
        it->second.fail(exact ? reason : message);
      }
      if (path.empty()) break;
      const auto pos = path.find_last_of(".[");
      path = pos == std::string::npos ? std::string() : path.substr(0, pos);
      exact = false;
    }
    seen_.at("").fail(message);
  }

  std::map<std::string, core::ConfigNode> seen_;
};

}  // namespace

HackathonConfig load_hackathon_config(const core::ConfigNode& node,
                                      const kinematic::WorldConfig& world) {
  return HackathonLoader().load(node, world);
}

}  // namespace llsf::sim
