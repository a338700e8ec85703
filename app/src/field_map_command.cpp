// SPDX-License-Identifier: MIT
// `llsfsim field-map`: the field drawn as an SVG with a coordinate grid (or written out as
// Markdown tables), from the same configuration a game is built from: the world file, a
// scenario or an exercise, read by the loaders the game uses (docs/field.md).
#include <fmt/format.h>

#include <array>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>
#include <numbers>
#include <optional>
#include <ostream>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "commands.h"
#include "llsf/app/cli.h"
#include "llsf/core/config.h"
#include "llsf/core/data_dir.h"
#include "llsf/core/error.h"
#include "llsf/core/text.h"
#include "llsf/planner/planner.h"
#include "llsf/sim/game.h"
#include "llsf/sim/game_config.h"
#include "llsf/sim/hackathon_extension.h"
#include "llsf/study/scenario.h"

namespace llsf::app {

namespace {

namespace fs = std::filesystem;

struct FieldMapOptions {
  std::string scenario;
  std::string exercise;
  std::string exercises_root;
  std::string world;
  std::string output;
  bool table = false;
};

/// What is drawn: the game's configuration (prepared: the hackathon's boxes in the world, its
/// safe place among the planner's places) and a title that names no absolute path.
struct MapSource {
  std::string title;
  sim::GameConfig config;
};

// --- Reading the configuration ---------------------------------------------------------------

std::string exercises_root(const std::string& option) {
  if (!option.empty()) return option;
  const char* env = std::getenv("LLSF_EXERCISES_DIR");
  if (env != nullptr && *env != '\0') return env;
  return core::data_dir() + "/exercises";
}

/// The directory of exercise `name` (a directory with an exercise.yaml, or a name or unique
/// prefix in `root`, as `llsfsim exercise` finds it); throws core::UserError.
std::string find_exercise_dir(const std::string& name, const std::string& root) {
  if (fs::is_directory(name) && fs::exists(fs::path(name) / "exercise.yaml")) return name;
  std::vector<std::string> hits;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(root, ec)) {
    const std::string n = e.path().filename().string();
    if (!e.is_directory() || !fs::exists(e.path() / "exercise.yaml")) continue;
    if (n == name) return e.path().string();
    if (n.rfind(name, 0) == 0) hits.push_back(e.path().string());
  }
  if (hits.size() == 1) return hits.front();
  throw core::UserError(hits.empty() ? "unknown exercise '" + name + "' in " + root
                                     : "'" + name + "' names several exercises in " + root);
}

MapSource read_source(const FieldMapOptions& o) {
  MapSource s;
  const int given = static_cast<int>(!o.scenario.empty()) + static_cast<int>(!o.exercise.empty()) +
                    static_cast<int>(!o.world.empty());
  if (given > 1) throw core::UserError("give one of SCENARIO, --exercise and --world");
  if (!o.exercise.empty()) {
    // The exercise's `scenario:` section, read as `llsfsim exercise` reads it.
    const std::string dir = find_exercise_dir(o.exercise, exercises_root(o.exercises_root));
    const std::string file = (fs::path(dir) / "exercise.yaml").string();
    const core::ConfigNode root = core::ConfigNode::load_file(file);
    root.require_map();
    core::ConfigNode sc = root.at("scenario");
    sc.require_map();
    const std::string name = fs::path(dir).lexically_normal().filename().string();
    if (!sc["name"].defined()) sc.set("name", core::ConfigNode::parse("'" + name + "'", file));
    s.config = study::read_scenario_map(sc, file).game;
    s.title = "exercise " + name;
  } else if (!o.scenario.empty()) {
    const study::ScenarioFile f = study::load_scenario(o.scenario);
    s.config = f.variants.front().game;
    s.title = "scenario " + f.variants.front().name;
  } else {
    const std::string file =
        o.world.empty() ? core::data_dir() + "/config/world-2013.yaml" : o.world;
    s.config.world = kinematic::load_world_config_file(file);
    s.title = "world " + fs::path(file).filename().string();
  }
  s.config = sim::prepare_game_config(std::move(s.config));
  return s;
}

// --- Drawing ---------------------------------------------------------------------------------

constexpr double kScale = 120.0;  // px per metre
constexpr double kLeft = 56.0;    // px left of the field (y labels)
constexpr double kTop = 48.0;     // px above the field (title)
constexpr double kBottom = 44.0;  // px below the field (x labels)
constexpr double kPanel = 300.0;  // px of the coordinate list right of the field
constexpr double kGridM = 0.5;    // grid spacing; every second line is a full metre
constexpr double kPi = std::numbers::pi;

/// Fixed formatting: metres with two decimals, pixels with one, degrees as integers.
std::string m2(double v) { return fmt::format("{:.2f}", std::abs(v) < 0.005 ? 0.0 : v); }
std::string px1(double v) { return fmt::format("{:.1f}", std::abs(v) < 0.05 ? 0.0 : v); }
int deg(double rad) {
  int d = static_cast<int>(std::lround(rad * 180.0 / kPi)) % 360;
  return d < 0 ? d + 360 : d;
}

class Svg {
 public:
  Svg(double field_w, double field_h) : field_h_(field_h) {
    width_ = kLeft + field_w * kScale + 24.0 + kPanel;
    height_ = kTop + field_h * kScale + kBottom;
  }
  double x(double mx) const { return kLeft + mx * kScale; }
  double y(double my) const { return kTop + (field_h_ - my) * kScale; }
  double width() const { return width_; }
  double height() const { return height_; }
  std::ostringstream& out() { return out_; }

  void text(double px, double py, const std::string& s, const std::string& cls,
            const std::string& anchor = "middle") {
    out_ << "<text x=\"" << px1(px) << "\" y=\"" << px1(py) << "\" class=\"" << cls
         << "\" text-anchor=\"" << anchor << "\">" << core::xml_escape(s) << "</text>\n";
  }
  void polygon(const std::array<core::Vec2, 4>& c, const std::string& cls) {
    out_ << "<polygon class=\"" << cls << "\" points=\"";
    for (std::size_t i = 0; i < c.size(); ++i) {
      out_ << (i == 0 ? "" : " ") << px1(x(c[i].x())) << "," << px1(y(c[i].y()));
    }
    out_ << "\"/>\n";
  }
  void rect(double x0, double y0, double x1, double y1, const std::string& cls, double r = 0.0) {
    out_ << "<rect class=\"" << cls << "\" x=\"" << px1(x(x0)) << "\" y=\"" << px1(y(y1))
         << "\" width=\"" << px1((x1 - x0) * kScale) << "\" height=\"" << px1((y1 - y0) * kScale)
         << "\"";
    if (r > 0.0) out_ << " rx=\"" << px1(r * kScale) << "\"";
    out_ << "/>\n";
  }
  /// A box grown by `r` on every side with rounded corners (the Minkowski sum with a disc).
  void inflated(const core::OrientedBox& b, double r, const std::string& cls) {
    const double w = 2.0 * (b.half_extents.x() + r);
    const double h = 2.0 * (b.half_extents.y() + r);
    out_ << "<rect class=\"" << cls << "\" x=\"" << px1(-0.5 * w * kScale) << "\" y=\""
         << px1(-0.5 * h * kScale) << "\" width=\"" << px1(w * kScale) << "\" height=\""
         << px1(h * kScale) << "\" rx=\"" << px1(r * kScale) << "\" transform=\"translate("
         << px1(x(b.pose.x)) << "," << px1(y(b.pose.y)) << ") rotate(" << -deg(b.pose.theta)
         << ")\"/>\n";
  }
  void circle(double mx, double my, double r_px, const std::string& cls) {
    out_ << "<circle class=\"" << cls << "\" cx=\"" << px1(x(mx)) << "\" cy=\"" << px1(y(my))
         << "\" r=\"" << px1(r_px) << "\"/>\n";
  }
  /// A pose: a dot and a short line along the heading.
  void pose(const core::Pose2D& p, double len_px, const std::string& cls) {
    circle(p.x, p.y, 2.5, cls);
    out_ << "<line class=\"" << cls << "\" x1=\"" << px1(x(p.x)) << "\" y1=\"" << px1(y(p.y))
         << "\" x2=\"" << px1(x(p.x) + len_px * std::cos(p.theta)) << "\" y2=\""
         << px1(y(p.y) - len_px * std::sin(p.theta)) << "\"/>\n";
  }

 private:
  double field_h_;
  double width_ = 0.0;
  double height_ = 0.0;
  std::ostringstream out_;
};

const char* kStyle = R"(<style>
text { font-family: DejaVu Sans, Verdana, sans-serif; fill: #222; }
.title { font-size: 15px; font-weight: bold; }
.sub { font-size: 11px; fill: #444; }
.axis { font-size: 10px; fill: #555; }
.field { fill: #fbfaf5; stroke: none; }
.wall { fill: none; stroke: #333; }
.grid { stroke: #e2e2dc; stroke-width: 0.6; }
.grid-m { stroke: #c6c6bd; stroke-width: 1; }
.area-insertion { fill: #fff3c4; stroke: #c9b45c; }
.area-storage { fill: #d6e6ff; stroke: #6d8fc9; }
.area-late { fill: #eadcf7; stroke: #9c7cc0; }
.area-delivery { fill: #d9f2d9; stroke: #6aa86a; }
.area-safe { fill: #ffd9b3; stroke: #e07b00; stroke-width: 2; }
.area-label { font-size: 9px; fill: #555; }
.clearance { fill: #d6453d; fill-opacity: 0.07; stroke: #d6453d; stroke-width: 0.8; stroke-dasharray: 4 3; }
.clearance-wall { fill: none; stroke: #d6453d; stroke-width: 0.8; stroke-dasharray: 4 3; }
.dev-production { fill: #4a4a4a; }
.dev-recycling { fill: #8a5a2b; }
.dev-test { fill: #6b3fa0; }
.dev-delivery { fill: #2e7d32; }
.dev-label { font-size: 10px; font-weight: bold; fill: #fff; }
.rfid { fill: none; stroke: #1a73e8; stroke-width: 1; }
.obstacle { fill: #b3261e; }
.obstacle-label { font-size: 10px; font-weight: bold; fill: #b3261e; }
.place { fill: #1a73e8; stroke: #1a73e8; stroke-width: 1.2; }
.place-input { fill: #0b8043; stroke: #0b8043; stroke-width: 1.6; }
.place-label { font-size: 7px; fill: #1a4f9c; }
.robot { fill: #ffffff; fill-opacity: 0.6; stroke: #111; stroke-width: 1.2; }
.robot-heading { fill: #111; stroke: #111; stroke-width: 1.6; }
.robot-label { font-size: 10px; font-weight: bold; }
.free { fill: #2e9e44; fill-opacity: 0.8; }
.puck { fill: #f0c000; stroke: #7a6100; stroke-width: 0.6; }
.panel-h { font-size: 11px; font-weight: bold; }
.panel { font-size: 9.5px; font-family: DejaVu Sans Mono, monospace; fill: #222; }
</style>
)";

const char* device_class(planner::DeviceRole role) {
  switch (role) {
    case planner::DeviceRole::kProduction:
      return "dev-production";
    case planner::DeviceRole::kRecycling:
      return "dev-recycling";
    case planner::DeviceRole::kTest:
      return "dev-test";
    case planner::DeviceRole::kDelivery:
      return "dev-delivery";
  }
  return "dev-production";
}

/// The short label of a place next to its device ("in", "L", "R", "look"), else its name.
std::string place_label(const planner::Place& p) {
  switch (p.kind) {
    case planner::PlaceKind::kDeviceInput:
      return "in";
    case planner::PlaceKind::kDeviceSide:
      return p.name.ends_with("_left") ? "L" : "R";
    case planner::PlaceKind::kDeviceLook:
      return "look";
    default:
      return p.name;
  }
}

std::string draw_svg(const MapSource& src, const planner::Planner& planner) {
  const sim::GameConfig& c = src.config;
  const sim::HackathonConfig* hackathon = sim::hackathon_config(c);
  const kinematic::FieldConfig& f = c.world.field;
  const planner::FieldMap& map = planner.field();
  const double r = planner.config().inflated_radius_m();
  Svg s(f.width_m, f.height_m);
  std::ostringstream& o = s.out();

  // Title and the field with its grid.
  s.text(kLeft, 20, "llsfsim field map: " + src.title, "title", "start");
  s.text(kLeft, 36,
         fmt::format("field {} x {} m, origin bottom left, x right, y up, angles "
                     "counter-clockwise from +x; grid {} m",
                     m2(f.width_m), m2(f.height_m), m2(kGridM)),
         "sub", "start");
  s.rect(0.0, 0.0, f.width_m, f.height_m, "field");
  const int nx = static_cast<int>(std::floor(f.width_m / kGridM + 1e-9));
  const int ny = static_cast<int>(std::floor(f.height_m / kGridM + 1e-9));
  for (int i = 0; i <= nx; ++i) {
    const double v = i * kGridM;
    const bool metre = i % 2 == 0;
    o << "<line class=\"" << (metre ? "grid-m" : "grid") << "\" x1=\"" << px1(s.x(v)) << "\" y1=\""
      << px1(s.y(0.0)) << "\" x2=\"" << px1(s.x(v)) << "\" y2=\"" << px1(s.y(f.height_m))
      << "\"/>\n";
    s.text(s.x(v), s.y(0.0) + 16, metre ? fmt::format("{}", i / 2) : m2(v).substr(0, 3), "axis");
  }
  for (int i = 0; i <= ny; ++i) {
    const double v = i * kGridM;
    const bool metre = i % 2 == 0;
    o << "<line class=\"" << (metre ? "grid-m" : "grid") << "\" x1=\"" << px1(s.x(0.0))
      << "\" y1=\"" << px1(s.y(v)) << "\" x2=\"" << px1(s.x(f.width_m)) << "\" y2=\"" << px1(s.y(v))
      << "\"/>\n";
    s.text(s.x(0.0) - 8, s.y(v) + 3.5, metre ? fmt::format("{}", i / 2) : m2(v).substr(0, 3),
           "axis", "end");
  }
  s.text(s.x(0.5 * f.width_m), s.y(0.0) + 34, "x (m)", "axis");
  s.text(s.x(0.0) - 30, s.y(0.5 * f.height_m), "y (m)", "axis");

  // The marked areas.
  auto area = [&](const planner::AreaRect& a, const std::string& cls, const std::string& label,
                  const std::string& id) {
    o << "<g id=\"" << id << "\" data-x-min=\"" << m2(a.lo.x()) << "\" data-y-min=\""
      << m2(a.lo.y()) << "\" data-x-max=\"" << m2(a.hi.x()) << "\" data-y-max=\"" << m2(a.hi.y())
      << "\">\n";
    s.rect(a.lo.x(), a.lo.y(), a.hi.x(), a.hi.y(), cls);
    o << "</g>\n";
    if (!label.empty()) {
      o << "<text class=\"area-label\" text-anchor=\"middle\" transform=\"translate("
        << px1(s.x(a.center().x())) << "," << px1(s.y(a.center().y())) << ") rotate(-90)\">"
        << core::xml_escape(label) << "</text>\n";
    }
  };
  area(map.insertion_area, "area-insertion", "insertion area", "area-insertion");
  area(map.input_storage, "area-storage", hackathon != nullptr ? "" : "input storage",
       "area-storage");
  area(map.late_order_area, "area-late", "late orders", "area-late-order");
  area(map.delivery_zone, "area-delivery", "delivery zone", "area-delivery");
  if (hackathon != nullptr) {
    const kinematic::Rect& a = hackathon->safe_area;
    area(planner::AreaRect{a.lo, a.hi}, "area-safe", "SAFE AREA", "safe-area");
  }
  s.circle(map.late_order_slot.x(), map.late_order_slot.y(), 0.05 * kScale, "rfid");

  // The navigator's clearance: no robot centre inside the dashed lines.
  o << "<clipPath id=\"field-clip\"><rect x=\"" << px1(s.x(0.0)) << "\" y=\""
    << px1(s.y(f.height_m)) << "\" width=\"" << px1(f.width_m * kScale) << "\" height=\""
    << px1(f.height_m * kScale) << "\"/></clipPath>\n<g id=\"clearance\" data-m=\""
    << fmt::format("{:.3f}", r) << "\" clip-path=\"url(#field-clip)\">\n";
  s.rect(r, r, f.width_m - r, f.height_m - r, "clearance-wall");
  for (const planner::FieldDevice& d : map.devices) s.inflated(d.footprint, r, "clearance");
  for (const planner::NamedBox& b : map.obstacles) s.inflated(b.box, r, "clearance");
  o << "</g>\n";
  s.rect(0.0, 0.0, f.width_m, f.height_m, "wall");
  o << "<rect class=\"wall\" x=\"" << px1(s.x(0.0) - f.wall_thickness_m * kScale) << "\" y=\""
    << px1(s.y(f.height_m) - f.wall_thickness_m * kScale) << "\" width=\""
    << px1((f.width_m + 2.0 * f.wall_thickness_m) * kScale) << "\" height=\""
    << px1((f.height_m + 2.0 * f.wall_thickness_m) * kScale) << "\"/>\n";

  // The grid points a robot may be sent to (drive_to{x=, y=} accepts them as goals).
  o << "<g id=\"free-grid\">\n";
  for (int i = 1; i * kGridM < f.width_m - 1e-9; ++i) {
    for (int j = 1; j * kGridM < f.height_m - 1e-9; ++j) {
      if (planner.is_free(core::Vec2(i * kGridM, j * kGridM))) {
        s.circle(i * kGridM, j * kGridM, 2.0, "free");
      }
    }
  }
  o << "</g>\n";

  // Devices, obstacles, places.
  for (const planner::FieldDevice& d : map.devices) {
    o << "<g id=\"device-" << d.name << "\" data-x=\"" << m2(d.pose.x) << "\" data-y=\""
      << m2(d.pose.y) << "\" data-ori-deg=\"" << deg(d.pose.theta) << "\">\n";
    s.polygon(d.footprint.corners(), device_class(d.role));
    s.circle(d.rfid_center.x(), d.rfid_center.y(), 0.05 * kScale, "rfid");
    s.text(s.x(d.footprint.pose.x), s.y(d.footprint.pose.y) + 3.5, d.name, "dev-label");
    o << "</g>\n";
  }
  for (const planner::NamedBox& b : map.obstacles) {
    o << "<g id=\"obstacle-" << core::xml_escape(b.name) << "\" data-x=\"" << m2(b.box.pose.x)
      << "\" data-y=\"" << m2(b.box.pose.y) << "\">\n";
    s.polygon(b.box.corners(), "obstacle");
    s.text(s.x(b.box.pose.x), s.y(b.box.pose.y) - b.box.half_extents.y() * kScale - 5, b.name,
           "obstacle-label");
    o << "</g>\n";
  }
  for (const planner::Place& p : planner.places()) {
    const bool input = p.kind == planner::PlaceKind::kDeviceInput;
    o << "<g id=\"place-" << core::xml_escape(p.name) << "\" data-x=\"" << m2(p.pose.x)
      << "\" data-y=\"" << m2(p.pose.y) << "\" data-ori-deg=\"" << deg(p.pose.theta) << "\">\n";
    s.pose(p.pose, 9.0, input ? "place-input" : "place");
    // The label behind the pose (away from where it looks), clear of the device.
    const double lx = s.x(p.pose.x) - 10.0 * std::cos(p.pose.theta);
    const double ly = s.y(p.pose.y) + 10.0 * std::sin(p.pose.theta) + 2.5;
    s.text(lx, ly, place_label(p), "place-label");
    o << "</g>\n";
  }

  // Pucks at their start (not in the hackathon: its layout is drawn from each seed).
  if (hackathon == nullptr) {
    for (const kinematic::PuckPlacement& p : c.world.pucks) {
      s.circle(p.position.x(), p.position.y(), c.world.puck.radius_m * kScale, "puck");
    }
  }
  // Robots at their start.
  for (const kinematic::RobotStart& rb : c.world.robots) {
    o << "<g id=\"robot-" << core::xml_escape(rb.name) << "\" data-x=\"" << m2(rb.pose.x)
      << "\" data-y=\"" << m2(rb.pose.y) << "\" data-ori-deg=\"" << deg(rb.pose.theta) << "\">\n";
    s.circle(rb.pose.x, rb.pose.y, c.world.robot.radius_m * kScale, "robot");
    s.pose(rb.pose, c.world.robot.radius_m * kScale, "robot-heading");
    s.text(s.x(rb.pose.x), s.y(rb.pose.y) - c.world.robot.radius_m * kScale - 3, rb.name,
           "robot-label");
    o << "</g>\n";
  }

  // The coordinate list beside the field.
  const double px = kLeft + f.width_m * kScale + 24.0;
  double py = kTop + 10;
  auto line = [&](const std::string& t, const std::string& cls) {
    s.text(px, py, t, cls, "start");
    py += cls == "panel-h" ? 15.0 : 12.5;
  };
  line("Devices: pose (x, y) m, facing deg", "panel-h");
  for (const planner::FieldDevice& d : map.devices) {
    const planner::Place* in = planner.place(d.name + "_input");
    line(fmt::format("{:<4}({:>4}, {:>4}) {:>3}  in ({}, {})", d.name, m2(d.pose.x), m2(d.pose.y),
                     deg(d.pose.theta), in != nullptr ? m2(in->pose.x) : "-",
                     in != nullptr ? m2(in->pose.y) : "-"),
         "panel");
  }
  py += 6;
  if (!map.obstacles.empty()) {
    line("Obstacles: centre (x, y), size m", "panel-h");
    for (const planner::NamedBox& b : map.obstacles) {
      line(fmt::format("{:<5}({}, {})  {} x {}", b.name, m2(b.box.pose.x), m2(b.box.pose.y),
                       m2(2.0 * b.box.half_extents.x()), m2(2.0 * b.box.half_extents.y())),
           "panel");
    }
    py += 6;
  }
  if (hackathon != nullptr) {
    const kinematic::Rect& a = hackathon->safe_area;
    line("Safe area", "panel-h");
    line(fmt::format("x {}..{}, y {}..{}", m2(a.lo.x()), m2(a.hi.x()), m2(a.lo.y()), m2(a.hi.y())),
         "panel");
    if (const planner::Place* p = planner.place(hackathon->safe_place)) {
      line(fmt::format("{} ({}, {}) {}", p->name, m2(p->pose.x), m2(p->pose.y), deg(p->pose.theta)),
           "panel");
    }
    py += 6;
  }
  line("Robots at the start", "panel-h");
  for (const kinematic::RobotStart& rb : c.world.robots) {
    line(fmt::format("{} ({}, {}) {}", rb.name, m2(rb.pose.x), m2(rb.pose.y), deg(rb.pose.theta)),
         "panel");
  }
  py += 6;
  line("Navigator clearance (dashed red)", "panel-h");
  line(fmt::format("robot {:.3f} + margin {:.3f} = {:.3f} m", planner.config().robot_radius_m,
                   planner.config().safety_margin_m, r),
       "panel");
  line("a goal whose centre lies inside is", "panel");
  line("refused: navigator INVALID_GOAL", "panel");
  line("green dots: grid points that are", "panel");
  line("valid goals (drive_to{x=, y=})", "panel");
  py += 6;
  line("Places (blue: pose + heading)", "panel-h");
  line("green = <device>_input, in: puck in", "panel");
  line("the RFID zone (blue circle); L/R:", "panel");
  line("consumed pucks; <device>_look", "panel");
  line("llsfsim field-map --table: all", "panel");

  std::ostringstream doc;
  doc << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << px1(s.width()) << "\" height=\""
      << px1(s.height()) << "\" viewBox=\"0 0 " << px1(s.width()) << " " << px1(s.height())
      << "\">\n"
      << "<!-- Generated by `llsfsim field-map` from the configuration; do not edit "
         "(docs/field.md). -->\n"
      << kStyle << "<rect x=\"0\" y=\"0\" width=\"" << px1(s.width()) << "\" height=\""
      << px1(s.height()) << "\" fill=\"#ffffff\"/>\n"
      << o.str() << "</svg>\n";
  return doc.str();
}

/// The same content as Markdown tables (docs/field.md embeds it).
std::string draw_table(const MapSource& src, const planner::Planner& planner) {
  const sim::GameConfig& c = src.config;
  const sim::HackathonConfig* hackathon = sim::hackathon_config(c);
  const planner::FieldMap& map = planner.field();
  std::ostringstream o;
  o << "Field " << m2(map.width_m) << " x " << m2(map.height_m) << " m (" << src.title
    << "); navigator clearance " << fmt::format("{:.3f}", planner.config().inflated_radius_m())
    << " m.\n\n";
  o << "| device | x | y | facing (deg) |\n|---|---|---|---|\n";
  for (const planner::FieldDevice& d : map.devices) {
    o << "| " << d.name << " | " << m2(d.pose.x) << " | " << m2(d.pose.y) << " | "
      << deg(d.pose.theta) << " |\n";
  }
  if (!map.obstacles.empty()) {
    o << "\n| obstacle | x | y | size x | size y | ori (deg) |\n|---|---|---|---|---|---|\n";
    for (const planner::NamedBox& b : map.obstacles) {
      o << "| " << b.name << " | " << m2(b.box.pose.x) << " | " << m2(b.box.pose.y) << " | "
        << m2(2.0 * b.box.half_extents.x()) << " | " << m2(2.0 * b.box.half_extents.y()) << " | "
        << deg(b.box.pose.theta) << " |\n";
    }
  }
  o << "\n| area | x min | y min | x max | y max |\n|---|---|---|---|---|\n";
  auto area = [&](const char* name, const std::pair<core::Vec2, core::Vec2>& a) {
    o << "| " << name << " | " << m2(a.first.x()) << " | " << m2(a.first.y()) << " | "
      << m2(a.second.x()) << " | " << m2(a.second.y()) << " |\n";
  };
  area("insertion area", {map.insertion_area.lo, map.insertion_area.hi});
  area("input storage", {map.input_storage.lo, map.input_storage.hi});
  area("late-order area", {map.late_order_area.lo, map.late_order_area.hi});
  area("delivery zone", {map.delivery_zone.lo, map.delivery_zone.hi});
  if (hackathon != nullptr) area("safe area", {hackathon->safe_area.lo, hackathon->safe_area.hi});
  o << "\n| robot | x | y | heading (deg) |\n|---|---|---|---|\n";
  for (const kinematic::RobotStart& rb : c.world.robots) {
    o << "| " << rb.name << " | " << m2(rb.pose.x) << " | " << m2(rb.pose.y) << " | "
      << deg(rb.pose.theta) << " |\n";
  }
  o << "\n| place | x | y | heading (deg) |\n|---|---|---|---|\n";
  for (const planner::Place& p : planner.places()) {
    o << "| `" << p.name << "` | " << m2(p.pose.x) << " | " << m2(p.pose.y) << " | "
      << deg(p.pose.theta) << " |\n";
  }
  return o.str();
}

/// Writes `text` to `path` through a temporary file beside it: nothing half-written.
void write_file(const std::string& path, const std::string& text) {
  const std::string tmp = path + ".tmp";
  {
    std::ofstream f(tmp, std::ios::binary | std::ios::trunc);
    f << text;
    f.close();
    if (!f) {
      std::error_code ec;
      fs::remove(tmp, ec);
      throw core::UserError("cannot write " + path);
    }
  }
  std::error_code ec;
  fs::rename(tmp, path, ec);
  if (ec) {
    fs::remove(tmp, ec);
    throw core::UserError("cannot write " + path + ": " + ec.message());
  }
}

int run_field_map(const FieldMapOptions& o, std::ostream& out, std::ostream& err) {
  MapSource src;
  try {
    src = read_source(o);
  } catch (const core::ConfigError& e) {
    err << "llsfsim field-map: " << e.what() << "\n";
    return kExitBadInput;
  }
  const planner::Planner planner(sim::field_map_from_world(src.config.world), src.config.planner);
  const std::string text = o.table ? draw_table(src, planner) : draw_svg(src, planner);
  if (o.output.empty() || o.output == "-") {
    out << text;
  } else {
    write_file(o.output, text);
    out << "wrote " << o.output << "\n";
  }
  return kExitOk;
}

}  // namespace

Action add_field_map_command(CLI::App& app) {
  auto o = std::make_shared<FieldMapOptions>();
  app.add_option("scenario", o->scenario,
                 "A scenario file (its first variant); default: config/world-2013.yaml of the "
                 "data directory");
  app.add_option("--exercise", o->exercise,
                 "An exercise's world instead: its name, a unique prefix (02) or its directory");
  app.add_option("--exercises", o->exercises_root,
                 "Where the exercises are (default: $LLSF_EXERCISES_DIR, else exercises/ of the "
                 "data directory)");
  app.add_option("--world", o->world, "A world file (docs/world-config.md) instead");
  app.add_option("-o,--output", o->output, "Write to FILE (default: stdout)");
  app.add_flag("--table", o->table,
               "Markdown tables (devices, obstacles, areas, robots, every named place) instead "
               "of the SVG");
  app.footer(
      "Examples:\n"
      "  llsfsim field-map -o field-map.svg\n"
      "  llsfsim field-map scenarios/hackathon.yaml -o hackathon-map.svg\n"
      "  llsfsim field-map --exercise 02 --table\n"
      "The dashed red lines are the navigator's clearance: a goal whose centre lies inside is "
      "refused (docs/field.md).");
  return [o](std::ostream& out, std::ostream& err) { return run_field_map(*o, out, err); };
}

}  // namespace llsf::app
