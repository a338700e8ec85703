// SPDX-License-Identifier: MIT
// The hackathon keys of a scenario file: defaults, start none, and errors with file:line.
#include <doctest/doctest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "llsf/core/error.h"
#include "llsf/sim/hackathon_extension.h"
#include "llsf/study/scenario.h"

using namespace llsf;
using namespace llsf::study;

namespace {

std::string write_temp(const std::string& name, const std::string& text) {
  const auto path = std::filesystem::temp_directory_path() / name;
  std::ofstream(path) << text;
  return path.string();
}

}  // namespace

TEST_CASE("hackathon scenario: defaults, start none, and errors with file:line") {
  const std::string ok = write_temp("llsf_hack_ok.yaml", R"(name: hack
hackathon:
  colours: [{name: red, count: 2}, {name: yellow, count: 1, decoy: true}]
  camera: {range_m: 0.5, fov_deg: 60}
)");
  const ScenarioFile f = load_scenario(ok);
  const Scenario& s = f.variants.at(0);
  const sim::HackathonConfig* hackathon = sim::hackathon_config(s.game);
  REQUIRE(hackathon != nullptr);
  CHECK(s.start == StartMode::kNone);
  CHECK(s.duration == core::SimTime::from_sec(300));
  CHECK(hackathon->camera.range_m == 0.5);
  CHECK(hackathon->camera.fov_rad == doctest::Approx(60.0 * core::kPi / 180.0));
  CHECK(hackathon->obstacles.size() == 4);

  auto error_of = [](const std::string& name, const std::string& text) {
    try {
      load_scenario(write_temp(name, text));
    } catch (const core::ConfigError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  std::string e = error_of("llsf_hack_e1.yaml", "name: x\nhackathon:\n  camera: {rnage_m: 1}\n");
  CHECK(e.find("llsf_hack_e1.yaml:3:") != std::string::npos);
  CHECK(e.find("rnage_m") != std::string::npos);
  e = error_of("llsf_hack_e2.yaml",
               "name: x\nhackathon:\n  obstacles:\n    - {name: a, x: 1, y: 4, size_x_m: 0.3, "
               "size_y_m: 0.3}\n    - {name: b, x: 5.5, y: 1, size_x_m: 0.4, size_y_m: 0.3}\n");
  CHECK(e.find("llsf_hack_e2.yaml:5:") != std::string::npos);
  CHECK(e.find("hackathon.obstacles[1]") != std::string::npos);
  CHECK(e.find("inside the field") != std::string::npos);
  e = error_of("llsf_hack_e3.yaml", "name: x\nhackathon:\n  camera:\n    miss_rate: 1.5\n");
  CHECK(e.find("llsf_hack_e3.yaml:4:") != std::string::npos);
  CHECK(e.find("hackathon.camera.miss_rate") != std::string::npos);
  e = error_of("llsf_hack_e4.yaml",
               "name: x\nhackathon:\n  safe_area: {x_min: 2.6, y_min: 2.6, x_max: 3.0, y_max: "
               "3.0}\n");
  CHECK(e.find("llsf_hack_e4.yaml:3:") != std::string::npos);
  CHECK(e.find("overlaps the footprint of device M5") != std::string::npos);
  e = error_of("llsf_hack_e5.yaml",
               "name: x\nhackathon:\n  colours:\n    - {name: red, count: 2}\n    - {name: red, "
               "count: 1}\n");
  CHECK(e.find("llsf_hack_e5.yaml:5:") != std::string::npos);
  CHECK(e.find("duplicate colour 'red'") != std::string::npos);
}
