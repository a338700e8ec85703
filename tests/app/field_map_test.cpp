// SPDX-License-Identifier: MIT
// `llsfsim field-map`: the committed images of the docs are what the command draws from today's
// configuration, every device, obstacle, robot and place is named at its configured
// coordinates, docs/field.md's tables are the command's, bad input is an error.
#include <doctest/doctest.h>
#include <fmt/format.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "cli_fixture.h"
#include "llsf/core/geometry.h"
#include "llsf/kinematic/world_config.h"
#include "llsf/sim/hackathon_extension.h"
#include "llsf/study/scenario.h"

namespace {

using llsf::test::has;
using llsf::test::llsfsim;

const std::string kSource = LLSF_SOURCE_DIR;

std::string read_text(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  std::ostringstream s;
  s << f.rdbuf();
  return s.str();
}

std::string m2(double v) { return fmt::format("{:.2f}", std::abs(v) < 0.005 ? 0.0 : v); }

/// The SVG group of the element `id` ("device-M1"), from its start tag to its end; "" if none.
std::string group(const std::string& svg, const std::string& id) {
  const std::size_t a = svg.find("<g id=\"" + id + "\"");
  if (a == std::string::npos) return "";
  const std::size_t b = svg.find("</g>", a);
  return svg.substr(a, b - a);
}

/// The group of `id` exists, carries the configured coordinates and shows `label` as text.
void check_named_at(const std::string& svg, const std::string& id, double x, double y,
                    const std::string& label) {
  CAPTURE(id);
  const std::string g = group(svg, id);
  REQUIRE(!g.empty());
  CHECK(has(g, "data-x=\"" + m2(x) + "\" data-y=\"" + m2(y) + "\""));
  if (!label.empty()) CHECK(has(g, ">" + label + "</text>"));
}

}  // namespace

TEST_CASE("field-map: the committed images are what the command draws from the configuration") {
  const std::string dir =
      (std::filesystem::temp_directory_path() / ("llsf_field_map_" + std::to_string(::getpid())))
          .string();
  std::filesystem::create_directories(dir);
  struct Image {
    const char* committed;
    std::vector<std::string> args;
  };
  for (const Image& img : {Image{"docs/images/field-map.svg", {"field-map"}},
                           Image{"docs/images/hackathon-map.svg",
                                 {"field-map", kSource + "/scenarios/hackathon.yaml"}}}) {
    CAPTURE(img.committed);
    std::vector<std::string> args = img.args;
    const std::string out = dir + "/map.svg";
    args.insert(args.end(), {"-o", out});
    const llsf::test::Run r = llsfsim(args);
    REQUIRE(r.code == 0);
    CHECK(r.out == "wrote " + out + "\n");
    const std::string drawn = read_text(out);
    // A difference: the configuration or the drawing changed; regenerate the image with
    // `llsfsim field-map [scenarios/hackathon.yaml] -o docs/images/...svg` and commit it.
    const std::string fix =
        "regenerate it: build/ci/llsfsim " +
        std::string(img.args.size() > 1 ? "field-map scenarios/hackathon.yaml" : "field-map") +
        " -o " + img.committed;
    CHECK_MESSAGE(drawn == read_text(kSource + "/" + img.committed), fix);
    // Deterministic: drawn again, the same bytes (stdout this time).
    const llsf::test::Run again = llsfsim(img.args);
    CHECK(again.out == drawn);
  }
  std::filesystem::remove_all(dir);
}

TEST_CASE("field-map: every device, robot and place of the world file at its coordinates") {
  const llsf::kinematic::WorldConfig w =
      llsf::kinematic::load_world_config_file(kSource + "/config/world-2013.yaml");
  const std::string svg = read_text(kSource + "/docs/images/field-map.svg");
  for (int i = 0; i < llsf::kinematic::kDeviceCount; ++i) {
    const std::string name(llsf::kinematic::device_name(llsf::core::DeviceId(i)));
    const llsf::kinematic::DeviceConfig& d = w.devices[static_cast<std::size_t>(i)];
    check_named_at(svg, "device-" + name, d.pose.x, d.pose.y, name);
    // Its places are drawn, the input place first of all.
    CHECK(!group(svg, "place-" + name + "_input").empty());
  }
  REQUIRE(w.robots.size() == 3);
  for (const llsf::kinematic::RobotStart& rb : w.robots) {
    check_named_at(svg, "robot-" + rb.name, rb.pose.x, rb.pose.y, rb.name);
  }
  for (const char* p : {"INS_1", "INS_5", "LATE_ORDER", "WAIT_INS", "WAIT_DELIVERY"}) {
    CHECK(!group(svg, std::string("place-") + p).empty());
  }
  CHECK(has(svg, "id=\"area-delivery\" data-x-min=\"" + m2(w.field.delivery_zone.lo.x()) +
                     "\" data-y-min=\"" + m2(w.field.delivery_zone.lo.y()) + "\""));
  CHECK(has(svg, "id=\"area-storage\""));
  CHECK(has(svg, "id=\"area-insertion\""));
  // The navigator's clearance: robot radius + safety margin (planner::PlannerConfig).
  CHECK(has(svg, "<g id=\"clearance\" data-m=\"0.260\""));
  CHECK(has(svg, "robot 0.185 + margin 0.075 = 0.260 m"));
  CHECK(!has(svg, "safe-area"));
}

TEST_CASE("field-map: the hackathon's obstacles, safe area and SAFE place at their coordinates") {
  const llsf::study::ScenarioFile f =
      llsf::study::load_scenario(kSource + "/scenarios/hackathon.yaml");
  const llsf::sim::GameConfig& c = f.variants.front().game;
  const llsf::sim::HackathonConfig* hackathon = llsf::sim::hackathon_config(c);
  REQUIRE(hackathon != nullptr);
  REQUIRE(!hackathon->obstacles.empty());
  const std::string svg = read_text(kSource + "/docs/images/hackathon-map.svg");
  for (const llsf::kinematic::ObstacleConfig& o : hackathon->obstacles) {
    check_named_at(svg, "obstacle-" + o.name, o.pose.x, o.pose.y, o.name);
  }
  const llsf::kinematic::Rect& a = hackathon->safe_area;
  CHECK(has(svg, "id=\"safe-area\" data-x-min=\"" + m2(a.lo.x()) + "\" data-y-min=\"" +
                     m2(a.lo.y()) + "\" data-x-max=\"" + m2(a.hi.x()) + "\" data-y-max=\"" +
                     m2(a.hi.y()) + "\""));
  CHECK(!group(svg, "place-" + hackathon->safe_place).empty());
  for (const llsf::kinematic::RobotStart& rb : c.world.robots) {
    check_named_at(svg, "robot-" + rb.name, rb.pose.x, rb.pose.y, rb.name);
  }
  for (int i = 0; i < llsf::kinematic::kDeviceCount; ++i) {
    const std::string name(llsf::kinematic::device_name(llsf::core::DeviceId(i)));
    const llsf::kinematic::DeviceConfig& d = c.world.devices[static_cast<std::size_t>(i)];
    check_named_at(svg, "device-" + name, d.pose.x, d.pose.y, name);
  }
}

TEST_CASE("field-map: docs/field.md holds the command's tables of the hackathon field") {
  const llsf::test::Run r =
      llsfsim({"field-map", kSource + "/scenarios/hackathon.yaml", "--table"});
  REQUIRE(r.code == 0);
  CHECK(has(r.out, "| M1 | 3.92 | 1.68 | 270 |"));
  CHECK(has(r.out, "| box1 | 1.00 | 4.20 | 0.30 | 0.30 | 0 |"));
  CHECK(has(r.out, "| `SAFE` |"));
  CHECK(has(r.out, "navigator clearance 0.260 m"));
  const std::string doc = read_text(kSource + "/docs/field.md");
  const std::string begin = "<!-- BEGIN llsfsim field-map scenarios/hackathon.yaml --table -->\n";
  const std::string end = "<!-- END llsfsim field-map -->";
  const std::size_t a = doc.find(begin);
  const std::size_t b = doc.find(end);
  REQUIRE(a != std::string::npos);
  REQUIRE(b != std::string::npos);
  const std::string fix =
      "regenerate the tables in docs/field.md with build/ci/llsfsim field-map "
      "scenarios/hackathon.yaml --table";
  CHECK_MESSAGE(doc.substr(a + begin.size(), b - a - begin.size()) == r.out, fix);
}

TEST_CASE("field-map: an exercise's world; bad input is an error naming it") {
  const std::string ex = kSource + "/exercises";
  const llsf::test::Run r = llsfsim({"field-map", "--exercise", "05", "--exercises", ex});
  REQUIRE(r.code == 0);
  CHECK(has(r.out, "llsfsim field map: exercise 05-two-robots"));
  CHECK(has(r.out, "id=\"robot-robot2\""));
  CHECK(!has(r.out, "id=\"robot-robot3\""));
  CHECK(has(r.out, "id=\"safe-area\""));

  const llsf::test::Run unknown = llsfsim({"field-map", "--exercise", "99", "--exercises", ex});
  CHECK(unknown.code == 2);
  CHECK(has(unknown.err, "llsfsim field-map: unknown exercise '99'"));

  const llsf::test::Run both =
      llsfsim({"field-map", kSource + "/scenarios/hackathon.yaml", "--exercise", "02"});
  CHECK(both.code == 2);
  CHECK(has(both.err, "give one of SCENARIO, --exercise and --world"));

  const std::string dir = (std::filesystem::temp_directory_path() /
                           ("llsf_field_map_bad_" + std::to_string(::getpid())))
                              .string();
  std::filesystem::create_directories(dir);
  {
    std::ofstream(dir + "/bad.yaml") << "name: bad\nhackathon:\n  obstacles:\n"
                                        "    - {name: b, x: 9.0, y: 1.0, size_x_m: 0.3, "
                                        "size_y_m: 0.3}\n";
    std::ofstream(dir + "/world.yaml") << "field:\n  width_m: -1\n";
  }
  const llsf::test::Run bad = llsfsim({"field-map", dir + "/bad.yaml", "-o", dir + "/x.svg"});
  CHECK(bad.code == 2);
  CHECK(has(bad.err, "bad.yaml:4:"));
  CHECK(has(bad.err, "hackathon.obstacles[0]"));
  CHECK(!std::filesystem::exists(dir + "/x.svg"));
  const llsf::test::Run world = llsfsim({"field-map", "--world", dir + "/world.yaml"});
  CHECK(world.code == 2);
  CHECK(has(world.err, "world.yaml:2:"));
  const llsf::test::Run unwritable = llsfsim({"field-map", "-o", dir + "/no/such/dir/x.svg"});
  CHECK(unwritable.code == 2);
  CHECK(has(unwritable.err, "cannot write"));
  std::filesystem::remove_all(dir);
}
