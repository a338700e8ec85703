// SPDX-License-Identifier: MIT
// WorldConfig: the 2013 default, validate(), and the YAML loader with its error messages.
#include <doctest/doctest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <set>
#include <string>

#include "llsf/kinematic/world_config.h"

using namespace llsf::kinematic;
using llsf::core::ConfigError;
using llsf::core::ConfigNode;
using llsf::core::kPi;
using llsf::core::normalize_angle;

namespace {

const std::string kDefaultFile = std::string(LLSF_SOURCE_DIR) + "/config/world-2013.yaml";

/// A YAML file in the temp directory, removed again at scope exit.
class TempYaml {
 public:
  TempYaml(const std::string& name, const std::string& text)
      : path_((std::filesystem::temp_directory_path() /
               ("llsf_wc_" + std::to_string(::getpid()) + "_" + name))
                  .string()) {
    std::ofstream(path_) << text;
  }
  ~TempYaml() {
    std::error_code ec;
    std::filesystem::remove(path_, ec);
  }
  TempYaml(const TempYaml&) = delete;
  TempYaml& operator=(const TempYaml&) = delete;
  const std::string& path() const { return path_; }

 private:
  std::string path_;
};

/// The message of the ConfigError that loading `text` (as a file) throws, or "" if none.
std::string load_error(const std::string& name, const std::string& text, std::string* file) {
  TempYaml f(name, text);
  *file = f.path();
  try {
    load_world_config_file(f.path());
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "";
}

/// Loads `text` on top of the 2013 default.
WorldConfig load_text(const std::string& text) {
  return load_world_config(ConfigNode::parse(text, "test.yaml"));
}

bool contains(const std::string& s, const std::string& part) {
  return s.find(part) != std::string::npos;
}

void check_same(const WorldConfig& a, const WorldConfig& b) {
  CHECK(a.field.width_m == b.field.width_m);
  CHECK(a.field.height_m == b.field.height_m);
  CHECK(a.field.wall_thickness_m == b.field.wall_thickness_m);
  CHECK(a.field.insertion_area.lo == b.field.insertion_area.lo);
  CHECK(a.field.insertion_area.hi == b.field.insertion_area.hi);
  CHECK(a.field.input_storage.lo == b.field.input_storage.lo);
  CHECK(a.field.input_storage.hi == b.field.input_storage.hi);
  CHECK(a.field.late_order_area.lo == b.field.late_order_area.lo);
  CHECK(a.field.late_order_area.hi == b.field.late_order_area.hi);
  CHECK(a.field.late_order_slot == b.field.late_order_slot);
  CHECK(a.field.delivery_zone.lo == b.field.delivery_zone.lo);
  CHECK(a.field.delivery_zone.hi == b.field.delivery_zone.hi);

  for (int i = 0; i < kDeviceCount; ++i) {
    CAPTURE(kDeviceNames[i]);
    const DeviceConfig& x = a.devices[i];
    const DeviceConfig& y = b.devices[i];
    CHECK(x.pose == y.pose);
    CHECK(x.body_depth_m == y.body_depth_m);
    CHECK(x.body_width_m == y.body_width_m);
    CHECK(x.body_offset_m == y.body_offset_m);
    CHECK(x.rfid_offset_m == y.rfid_offset_m);
    CHECK(x.rfid_radius_m == y.rfid_radius_m);
  }

  CHECK(a.puck.radius_m == b.puck.radius_m);
  CHECK(a.puck.mass_kg == b.puck.mass_kg);
  CHECK(a.puck.floor_friction == b.puck.floor_friction);
  CHECK(a.puck.contact_friction == b.puck.contact_friction);
  CHECK(a.puck.restitution == b.puck.restitution);
  REQUIRE(a.pucks.size() == b.pucks.size());
  for (std::size_t i = 0; i < a.pucks.size(); ++i) {
    CAPTURE(i);
    CHECK(a.pucks[i].id == b.pucks[i].id);
    CHECK(a.pucks[i].position == b.pucks[i].position);
  }

  const RobotModelConfig& r = a.robot;
  const RobotModelConfig& s = b.robot;
  CHECK(r.radius_m == s.radius_m);
  CHECK(r.mass_kg == s.mass_kg);
  CHECK(r.max_speed_mps == s.max_speed_mps);
  CHECK(r.max_omega_rps == s.max_omega_rps);
  CHECK(r.max_accel_mps2 == s.max_accel_mps2);
  CHECK(r.max_alpha_rps2 == s.max_alpha_rps2);
  CHECK(r.contact_friction == s.contact_friction);
  CHECK(r.holder.mode == s.holder.mode);
  CHECK(r.holder.inner_width_m == s.holder.inner_width_m);
  CHECK(r.holder.arm_length_m == s.holder.arm_length_m);
  CHECK(r.holder.arm_thickness_m == s.holder.arm_thickness_m);
  CHECK(r.holder.arm_friction == s.holder.arm_friction);
  CHECK(r.holder.release_backing_speed_mps == s.holder.release_backing_speed_mps);
  REQUIRE(a.robots.size() == b.robots.size());
  for (std::size_t i = 0; i < a.robots.size(); ++i) {
    CAPTURE(i);
    CHECK(a.robots[i].name == b.robots[i].name);
    CHECK(a.robots[i].pose == b.robots[i].pose);
  }

  const SensorsConfig& p = a.sensors;
  const SensorsConfig& q = b.sensors;
  CHECK(p.odometry.rate_hz == q.odometry.rate_hz);
  CHECK(p.odometry.trans_noise_per_m == q.odometry.trans_noise_per_m);
  CHECK(p.odometry.rot_noise_per_rad == q.odometry.rot_noise_per_rad);
  CHECK(p.odometry.accel_noise_per_mps == q.odometry.accel_noise_per_mps);
  CHECK(p.odometry.accel_rot_noise_per_rps == q.odometry.accel_rot_noise_per_rps);
  CHECK(p.gyro.rate_hz == q.gyro.rate_hz);
  CHECK(p.gyro.noise_std_rps == q.gyro.noise_std_rps);
  CHECK(p.gyro.bias_rps == q.gyro.bias_rps);
  CHECK(p.ir.rate_hz == q.ir.rate_hz);
  CHECK(p.ir.range_m == q.ir.range_m);
  CHECK(p.ir.noise_std_m == q.ir.noise_std_m);
  CHECK(p.ir.threshold_m == q.ir.threshold_m);
  CHECK(p.optical.rate_hz == q.optical.rate_hz);
  CHECK(p.optical.range_m == q.optical.range_m);
  CHECK(p.optical.miss_probability == q.optical.miss_probability);
  CHECK(p.ground_truth.rate_hz == q.ground_truth.rate_hz);
  CHECK(p.laser.enabled == q.laser.enabled);
  CHECK(p.laser.beams == q.laser.beams);
  CHECK(p.laser.rate_hz == q.laser.rate_hz);
  CHECK(p.laser.min_range_m == q.laser.min_range_m);
  CHECK(p.laser.max_range_m == q.laser.max_range_m);
  CHECK(p.laser.noise_std_m == q.laser.noise_std_m);
  CHECK(p.laser.mount_x_m == q.laser.mount_x_m);
  CHECK(p.laser.mount_y_m == q.laser.mount_y_m);

  CHECK(a.physics.step == b.physics.step);
  CHECK(a.physics.velocity_iterations == b.physics.velocity_iterations);
  CHECK(a.physics.position_iterations == b.physics.position_iterations);
}

}  // namespace

TEST_CASE("the 2013 default world") {
  const WorldConfig c = WorldConfig::default_2013();
  CHECK_NOTHROW(c.validate());

  SUBCASE("16 devices at the rule-book poses, headings normalised") {
    CHECK(c.devices.size() == 16);
    const auto& m1 = c.devices[device_by_name("M1")->value()];
    CHECK(m1.pose.x == doctest::Approx(3.92));
    CHECK(m1.pose.y == doctest::Approx(1.68));
    CHECK(m1.pose.theta == doctest::Approx(-kPi / 2));
    const auto& tst = c.devices[device_by_name("TST")->value()];
    CHECK(tst.pose.theta == doctest::Approx(normalize_angle(5 * kPi / 4)));
    const auto& r2 = c.devices[device_by_name("R2")->value()];
    CHECK(r2.pose.theta == doctest::Approx(-kPi / 4));
    for (const auto& d : c.devices) {
      CHECK(d.pose.theta > -kPi);
      CHECK(d.pose.theta <= kPi);
      CHECK(d.body_depth_m > 0.0);
      CHECK(d.rfid_radius_m > 0.0);
    }
    // Delivery slots are in the delivery zone and their bodies behind them against the wall.
    for (const char* g : {"D1", "D2", "D3"}) {
      const auto& d = c.devices[device_by_name(g)->value()];
      CHECK(c.field.delivery_zone.contains(d.pose.position()));
      CHECK(c.field.delivery_zone.contains(d.rfid_center()));
      CHECK(d.footprint().pose.x > d.pose.x);
    }
  }

  SUBCASE("20 pucks with unique ids in the input storage") {
    REQUIRE(c.pucks.size() == 20);
    std::set<int> ids;
    for (const auto& p : c.pucks) {
      ids.insert(p.id);
      const double r = c.puck.radius_m;
      CHECK(c.field.input_storage.contains(p.position + Vec2(r, r)));
      CHECK(c.field.input_storage.contains(p.position - Vec2(r, r)));
    }
    CHECK(ids.size() == 20);
    CHECK(*ids.begin() == 1);
    CHECK(*ids.rbegin() == 20);
  }

  SUBCASE("3 robots in the insertion area") {
    REQUIRE(c.robots.size() == 3);
    CHECK(c.robots[0].name == "robot1");
    CHECK(c.robots[2].name == "robot3");
    for (const auto& r : c.robots) {
      const double rad = c.robot.radius_m;
      CHECK(c.field.insertion_area.contains(r.pose.position() + Vec2(rad, rad)));
      CHECK(c.field.insertion_area.contains(r.pose.position() - Vec2(rad, rad)));
    }
  }
}

TEST_CASE("config/world-2013.yaml is the default world") {
  const WorldConfig loaded = load_world_config_file(kDefaultFile);
  check_same(loaded, WorldConfig::default_2013());
}

TEST_CASE("an empty document is the base unchanged") {
  check_same(load_text(""), WorldConfig::default_2013());
  check_same(load_text("# only a comment\n"), WorldConfig::default_2013());
  WorldConfig base = WorldConfig::default_2013();
  base.robots.pop_back();
  CHECK(load_world_config(ConfigNode::parse("", "empty.yaml"), base).robots.size() == 2);
}

TEST_CASE("overrides change only what they name") {
  SUBCASE("move M1, radians and degrees") {
    const WorldConfig c = load_text("devices:\n  M1: {x: 4.2, y: 1.0, ori: 3.14159}\n");
    const auto& m1 = c.devices[0];
    CHECK(m1.pose.x == 4.2);
    CHECK(m1.pose.y == 1.0);
    CHECK(m1.pose.theta == doctest::Approx(3.14159));
    CHECK(m1.body_width_m == 0.3);  // untouched
    WorldConfig expected = WorldConfig::default_2013();
    expected.devices[0] = m1;  // everything else is the default
    check_same(c, expected);
    const WorldConfig d = load_text("devices: {M2: {ori_deg: -90}}\n");
    CHECK(d.devices[1].pose.theta == doctest::Approx(-kPi / 2));
    CHECK(d.devices[1].pose.x == 3.92);
    const WorldConfig e = load_text("devices: {M2: {ori_deg: 450}}\n");
    CHECK(e.devices[1].pose.theta == doctest::Approx(kPi / 2));
  }
  SUBCASE("holder mode and robot model") {
    const WorldConfig c = load_text("robot:\n  max_speed_mps: 0.5\n  holder: {mode: physical}\n");
    CHECK(c.robot.holder.mode == HolderMode::kPhysical);
    CHECK(c.robot.max_speed_mps == 0.5);
    CHECK(c.robot.holder.inner_width_m == 0.09);
    CHECK(c.robot.radius_m == 0.185);
  }
  SUBCASE("pucks and robots lists are replaced") {
    const WorldConfig c = load_text(
        "pucks:\n  - {id: 7, x: 1.0, y: 1.0}\n  - {id: 42, x: 1.2, y: 1.0}\n"
        "robots:\n  - {name: solo, x: 0.2, y: 1.0, ori_deg: 90}\n");
    REQUIRE(c.pucks.size() == 2);
    CHECK(c.pucks[0].id == 7);
    CHECK(c.pucks[1].id == 42);
    CHECK(c.pucks[1].position == Vec2(1.2, 1.0));
    REQUIRE(c.robots.size() == 1);
    CHECK(c.robots[0].name == "solo");
    CHECK(c.robots[0].pose.theta == doctest::Approx(kPi / 2));
    CHECK(load_text("pucks: []\n").pucks.empty());
    CHECK(load_text("robots:\n").robots.empty());
  }
  SUBCASE("sensors and physics") {
    const WorldConfig c = load_text(
        "sensors: {laser: {enabled: false, beams: 720}, gyro: {bias_rps: -0.001}}\n"
        "physics: {step_ms: 2.5, velocity_iterations: 10}\n");
    CHECK_FALSE(c.sensors.laser.enabled);
    CHECK(c.sensors.laser.beams == 720);
    CHECK(c.sensors.laser.rate_hz == 5.0);
    CHECK(c.sensors.gyro.bias_rps == -0.001);
    CHECK(c.physics.step == llsf::core::SimTime::from_us(2500));
    CHECK(c.physics.velocity_iterations == 10);
    CHECK(c.physics.position_iterations == 3);
  }
}

TEST_CASE("validate() names the field") {
  auto message = [](const WorldConfig& c) -> std::string {
    try {
      c.validate();
    } catch (const ConfigError& e) {
      return e.what();
    }
    return "";
  };
  WorldConfig c = WorldConfig::default_2013();
  c.devices[2].body_width_m = -0.2;
  CHECK(message(c) == "devices.M3.body_width_m: must be in (0, 100] (got -0.2)");

  c = WorldConfig::default_2013();
  c.devices[3].pose = c.devices[7].pose;
  CHECK(message(c) == "devices.M4: footprint overlaps devices.M8");

  c = WorldConfig::default_2013();
  c.pucks[3].position = Vec2(6.0, 1.0);
  CHECK(contains(message(c), "pucks[3]: puck 4 at (6.00, 1.00) is outside the field"));

  c = WorldConfig::default_2013();
  c.robots[1].name = "robot1";
  CHECK(contains(message(c), "robots[1].name: duplicate robot name 'robot1'"));

  c = WorldConfig::default_2013();
  c.devices[0].rfid_radius_m = 0.2;
  CHECK(contains(message(c), "devices.M1.rfid_radius_m: must be > 0 and <= 0.115"));

  c = WorldConfig::default_2013();
  c.pucks.push_back(PuckPlacement{99, c.devices[4].rfid_center() + Vec2(0.05, 0.0)});
  CHECK(contains(message(c),
                 "pucks[20]: puck 99 at (2.71, 2.80) overlaps the footprint of "
                 "devices.M5"));

  c = WorldConfig::default_2013();
  c.pucks.push_back(PuckPlacement{99, Vec2(0.15, 2.35)});
  CHECK(contains(message(c),
                 "pucks[20]: puck 99 at (0.15, 2.35) overlaps puck 1 (pucks[0], "
                 "puck.radius_m = 0.0375)"));

  c = WorldConfig::default_2013();
  c.robots[2].pose.y = 2.2;
  CHECK(contains(message(c), "robots[2]: robot 'robot3' at (0.20, 2.20) overlaps puck 1"));

  c = WorldConfig::default_2013();
  c.robots[1].pose.y = 0.6;
  CHECK(contains(message(c), "robots[1]: robot 'robot2' at (0.20, 0.60) overlaps robot 'robot1'"));

  c = WorldConfig::default_2013();
  c.robot.holder.inner_width_m = 0.07;
  CHECK(contains(message(c), "robot.holder.inner_width_m: must be wider than the puck diameter"));

  c = WorldConfig::default_2013();
  c.sensors.ir.threshold_m = 0.2;
  CHECK(contains(message(c), "sensors.ir.threshold_m: must be <= sensors.ir.range_m"));

  c = WorldConfig::default_2013();
  c.sensors.laser.min_range_m = 6.0;
  CHECK(contains(message(c), "sensors.laser.min_range_m: must be < sensors.laser.max_range_m"));

  c = WorldConfig::default_2013();
  c.sensors.optical.miss_probability = 1.5;
  CHECK(message(c) == "sensors.optical.miss_probability: must be in [0, 1] (got 1.5)");

  c = WorldConfig::default_2013();
  c.physics.step = llsf::core::SimTime::from_ms(200);
  CHECK(message(c) == "physics.step_ms: must be > 0 and <= 100 (got 200)");

  c = WorldConfig::default_2013();
  c.physics.position_iterations = 0;
  CHECK(message(c) == "physics.position_iterations: must be in [1, 1000] (got 0)");

  c = WorldConfig::default_2013();
  c.robot.max_speed_mps = 1e300;
  CHECK(message(c) == "robot.max_speed_mps: must be in (0, 10] (got 1e+300)");
  c = WorldConfig::default_2013();
  c.sensors.laser.max_range_m = 1e300;
  CHECK(message(c) == "sensors.laser.max_range_m: must be in (0, 100] (got 1e+300)");
}

TEST_CASE("every world figure has an upper bound, reported at its key") {
  const auto error_of = [](const std::string& text) -> std::string {
    try {
      load_text(text);
    } catch (const ConfigError& e) {
      return e.what();
    }
    return "(no error)";
  };
  // Each of these used to load (or fail far from the key).
  CHECK(error_of("robot:\n  max_speed_mps: 1e300\n") ==
        "test.yaml:2:18: robot.max_speed_mps: must be in (0, 10] (got 1e+300)");
  CHECK(error_of("robot:\n  max_omega_rps: 21\n") ==
        "test.yaml:2:18: robot.max_omega_rps: must be in (0, 20] (got 21)");
  CHECK(error_of("robot:\n  max_accel_mps2: 1e300\n") ==
        "test.yaml:2:19: robot.max_accel_mps2: must be in (0, 100] (got 1e+300)");
  CHECK(error_of("robot:\n  holder: {release_backing_speed_mps: 1e300}\n") ==
        "test.yaml:2:39: robot.holder.release_backing_speed_mps: must be in [0, 10] (got 1e+300)");
  CHECK(error_of("sensors:\n  laser:\n    max_range_m: 1e300\n") ==
        "test.yaml:3:18: sensors.laser.max_range_m: must be in (0, 100] (got 1e+300)");
  CHECK(error_of("sensors:\n  laser:\n    rate_hz: 1e300\n") ==
        "test.yaml:3:14: sensors.laser.rate_hz: must be in [0.01, 1000] (got 1e+300)");
  CHECK(error_of("sensors:\n  laser:\n    noise_std_m: 1e300\n") ==
        "test.yaml:3:18: sensors.laser.noise_std_m: must be in [0, 100] (got 1e+300)");
  CHECK(error_of("sensors:\n  laser:\n    mount_x_m: -1e300\n") ==
        "test.yaml:3:16: sensors.laser.mount_x_m: must be in [-100, 100] (got -1e+300)");
  CHECK(error_of("sensors:\n  odometry:\n    rate_hz: 1e-300\n") ==
        "test.yaml:3:14: sensors.odometry.rate_hz: must be in [0.01, 1000] (got 1e-300)");
  CHECK(error_of("puck:\n  mass_kg: 1e300\n") ==
        "test.yaml:2:12: puck.mass_kg: must be in (0, 1000] (got 1e+300)");
  CHECK(error_of("field:\n  width_m: 1e300\n") ==
        "test.yaml:2:12: field.width_m: must be in (0, 100] (got 1e+300)");
  CHECK(error_of("robots:\n  - {name: r, x: 1e300, y: 1}\n") ==
        "test.yaml:2:18: robots[0].x: must be in [-1000, 1000] (got 1e+300)");
  CHECK(error_of("devices:\n  M1: {ori_deg: 1e300}\n") ==
        "test.yaml:2:17: devices.M1.ori_deg: must be in [-720, 720] (got 1e+300)");
  CHECK(error_of("physics:\n  velocity_iterations: 1000000000\n") ==
        "test.yaml:2:24: physics.velocity_iterations: must be in [1, 1000] (got 1000000000)");
  // The bounds themselves load.
  CHECK(error_of("robot:\n  max_speed_mps: 10\n  max_omega_rps: 20\n"
                 "sensors:\n  laser: {rate_hz: 1000, max_range_m: 100}\n") == "(no error)");
}

TEST_CASE("bad config files fail with file, line, field path and reason") {
  std::string file;

  SUBCASE("unknown device") {
    const std::string m =
        load_error("dev.yaml", "devices:\n  M1: {x: 4.0}\n  M11: {x: 1.0}\n", &file);
    CHECK(contains(m, file + ":3:"));
    CHECK(contains(m,
                   "devices.M11: unknown device 'M11' (expected one of M1..M10, R1, R2, TST, "
                   "D1, D2, D3)"));
  }
  SUBCASE("unknown key (typo)") {
    const std::string m =
        load_error("typo.yaml", "robot:\n  radius_m: 0.2\n  max_sped_mps: 1.0\n", &file);
    CHECK(contains(m, file + ":3:"));
    CHECK(contains(m, "robot.max_sped_mps: unknown key 'max_sped_mps'"));
  }
  SUBCASE("unknown top-level key") {
    const std::string m = load_error("top.yaml", "field: {width_m: 5.6}\nphysic: {}\n", &file);
    CHECK(contains(m, file + ":2:"));
    CHECK(contains(m, "physic: unknown key 'physic'"));
  }
  SUBCASE("overlapping devices") {
    const std::string m = load_error(
        "overlap.yaml", "# move M4 onto M8\ndevices:\n  M4: {x: 1.68, y: 1.68}\n", &file);
    CHECK(contains(m, file + ":3:"));
    CHECK(contains(m, "devices.M4: footprint overlaps devices.M8"));
  }
  SUBCASE("overlap reported at the device that was moved") {
    const std::string m =
        load_error("overlap2.yaml", "devices:\n  M8:\n    x: 2.80\n    y: 1.68\n", &file);
    CHECK(contains(m, file + ":3:"));
    CHECK(contains(m, "devices.M4: footprint overlaps devices.M8"));
  }
  SUBCASE("a larger puck is reported at puck.radius_m") {
    const std::string m =
        load_error("big_puck.yaml", "puck:\n  mass_kg: 0.2\n  radius_m: 0.06\n", &file);
    CHECK(contains(m, file + ":3:"));
    CHECK(contains(m,
                   "pucks[1]: puck 2 at (0.12, 2.45) overlaps puck 1 (pucks[0], "
                   "puck.radius_m = 0.06)"));
  }
  SUBCASE("a smaller field is reported at field.width_m") {
    const std::string m = load_error("small.yaml", "field:\n  width_m: 3\n", &file);
    CHECK(contains(m, file + ":2:"));
    CHECK(contains(m, "devices.M1: footprint at (3.92, 1.68) is not entirely inside the field"));
  }
  SUBCASE("negative device size") {
    const std::string m =
        load_error("size.yaml", "devices:\n  M3:\n    x: 2.8\n    body_width_m: -0.2\n", &file);
    CHECK(contains(m, file + ":4:"));
    CHECK(contains(m, "devices.M3.body_width_m: must be in (0, 100] (got -0.2)"));
  }
  SUBCASE("negative robot radius") {
    const std::string m =
        load_error("radius.yaml", "robot:\n  mass_kg: 20\n  radius_m: -1\n", &file);
    CHECK(contains(m, file + ":3:"));
    CHECK(contains(m, "robot.radius_m: must be in (0, 100] (got -1)"));
  }
  SUBCASE("puck outside the field") {
    const std::string m = load_error("puck_out.yaml",
                                     "pucks:\n"
                                     "  - {id: 1, x: 1.0, y: 1.0}\n"
                                     "  - {id: 2, x: 1.1, y: 1.0}\n"
                                     "  - {id: 3, x: 1.2, y: 1.0}\n"
                                     "  - {id: 4, x: 6.0, y: 1.0}\n",
                                     &file);
    CHECK(contains(m, file + ":5:"));
    CHECK(contains(m, "pucks[3]: puck 4 at (6.00, 1.00) is outside the field"));
  }
  SUBCASE("duplicate puck id") {
    const std::string m =
        load_error("puck_dup.yaml",
                   "pucks:\n  - {id: 5, x: 1.0, y: 1.0}\n  - {id: 5, x: 1.2, y: 1.0}\n", &file);
    CHECK(contains(m, file + ":3:"));
    CHECK(contains(m, "pucks[1].id: duplicate puck id 5 (also used by pucks[0])"));
  }
  SUBCASE("missing puck key") {
    const std::string m = load_error("puck_key.yaml", "pucks:\n  - {id: 5, x: 1.0}\n", &file);
    CHECK(contains(m, file + ":2:"));
    CHECK(contains(m, "pucks[0]: missing required key 'y'"));
  }
  SUBCASE("robot outside the field") {
    const std::string m = load_error(
        "robot_out.yaml", "robots:\n  - {name: robot1, x: 5.5, y: 1.0, ori_deg: 0}\n", &file);
    CHECK(contains(m, file + ":2:"));
    CHECK(contains(m, "robots[0]: robot 'robot1' at (5.50, 1.00) is outside the field"));
  }
  SUBCASE("duplicate robot name") {
    const std::string m = load_error("robot_dup.yaml",
                                     "robots:\n  - {name: robot1, x: 0.2, y: 0.4}\n"
                                     "  - name: robot1\n    x: 0.2\n    y: 1.0\n",
                                     &file);
    CHECK(contains(m, file + ":3:"));
    CHECK(contains(m, "robots[1].name: duplicate robot name 'robot1'"));
  }
  SUBCASE("bad holder mode") {
    const std::string m =
        load_error("holder.yaml", "robot:\n  holder:\n    mode: magnetic\n", &file);
    CHECK(contains(m, file + ":3:"));
    CHECK(contains(m,
                   "robot.holder.mode: unknown holder mode 'magnetic' (expected one of: "
                   "physical, assisted)"));
  }
  SUBCASE("holder too narrow") {
    const std::string m =
        load_error("holder_w.yaml", "robot:\n  holder: {inner_width_m: 0.05}\n", &file);
    CHECK(contains(m, file + ":2:"));
    CHECK(contains(m,
                   "robot.holder.inner_width_m: must be wider than the puck diameter "
                   "2 * puck.radius_m = 0.075 (got 0.05)"));
  }
  SUBCASE("non-number value") {
    const std::string m = load_error("nan.yaml", "field:\n  width_m: wide\n", &file);
    CHECK(contains(m, file + ":2:"));
    CHECK(contains(m, "field.width_m: expected a number, got 'wide'"));
  }
  SUBCASE("laser beams 0") {
    const std::string m =
        load_error("beams.yaml", "sensors:\n  laser:\n    rate_hz: 5\n    beams: 0\n", &file);
    CHECK(contains(m, file + ":4:"));
    CHECK(contains(m, "sensors.laser.beams: must be in [1, 10000] (got 0)"));
  }
  SUBCASE("both ori and ori_deg") {
    const std::string m =
        load_error("ori.yaml", "devices:\n  M2:\n    ori: 1.0\n    ori_deg: 90\n", &file);
    CHECK(contains(m, file + ":4:"));
    CHECK(contains(m,
                   "devices.M2.ori_deg: give either 'ori' (radians) or 'ori_deg' (degrees), "
                   "not both"));
  }
  SUBCASE("physics step out of range") {
    const std::string m = load_error("step.yaml", "physics:\n  step_ms: 250\n", &file);
    CHECK(contains(m, file + ":2:"));
    CHECK(contains(m, "physics.step_ms: must be > 0 and <= 100 (got 250)"));
  }
  SUBCASE("wrong type for a section") {
    const std::string m = load_error("section.yaml", "robot: fast\n", &file);
    CHECK(contains(m, file + ":1:"));
    CHECK(contains(m, "robot: expected a map, got 'fast'"));
  }
  SUBCASE("YAML syntax error") {
    const std::string m =
        load_error("syntax.yaml", "field:\n  width_m: 5.6\n  height_m: [5.6\n", &file);
    CHECK(contains(m, file + ":"));
    CHECK(contains(m, "YAML syntax error"));
    CHECK_FALSE(contains(m, file + ":1:"));  // points at the broken part, not the start
  }
  SUBCASE("missing file") {
    CHECK_THROWS_WITH_AS(load_world_config_file("/nonexistent/world.yaml"),
                         doctest::Contains("/nonexistent/world.yaml: cannot open file"),
                         ConfigError);
  }
}
