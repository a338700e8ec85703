// SPDX-License-Identifier: MIT
// A skill's debugging lines in a recording (docs/recording.md, "A skill's debugging lines"): the
// camera's cone in the header, its sightings in the field frame, the skill's states and log
// lines, the navigator's refusals, the verdict; and that recording them changes nothing.
#include <doctest/doctest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "llsf/sim/driver.h"
#include "llsf/sim/skill_brain.h"
#include "llsf/study/recording.h"
#include "llsf/study/scenario.h"
#include "support/temp_dir.h"

using namespace llsf;
using Json = nlohmann::json;

namespace {

std::filesystem::path temp_dir() {
  static const llsf::test::TempDir dir("llsf_recording_skill_test");
  return dir.path;
}

/// A skill that logs, then asks the navigator for a goal inside M1 (refused) and fails.
constexpr const char* kProbe = R"(-- SPDX-License-Identifier: MIT
name               = "probe"
fsm                = SkillHSM:new{name=name, start="DRIVE"}
depends_skills     = {"drive_to"}
depends_interfaces = {}
documentation      = [==[Drives into M1.]==]
fsm:define_states{ export_to=_M,
   {"DRIVE", SkillJumpState, skills={{drive_to}}, final_to="FINAL", fail_to="FAILED"},
}
function DRIVE:init()
   printf("driving to %.2f", 3.92)
   print_warn("careful")
   self.args["drive_to"] = {x = 3.92, y = 1.68, ori = 0}
end
)";

struct Played {
  std::vector<study::RecordingLine> lines;
  std::uint64_t hash = 0;
};

/// Plays `skill_string` on the hackathon scenario (seed 1) for `seconds`, with the skills of
/// `dir` beside the library, recording to `path` (none if empty) with the brains' listeners.
Played play(const std::string& skill_dir, const std::string& skill_string, double seconds,
            const std::string& path) {
  const study::ScenarioFile f = study::load_scenario(LLSF_SOURCE_DIR "/scenarios/hackathon.yaml");
  sim::GameConfig config = f.variants[0].game;
  config.seed = 1;
  sim::GameDriver driver(config);
  sim::Game& game = driver.game();
  lua::SkillEngineConfig ec;
  ec.skill_dirs = sim::skill_library_dirs(config.levels.skill);
  ec.skill_dirs.push_back(skill_dir);
  ec.hot_reload = false;
  sim::SkillBrain& brain = driver.plug_skills(0, ec);
  std::unique_ptr<study::Recorder> rec;
  if (!path.empty()) {
    rec = std::make_unique<study::Recorder>(path, game, study::RecordingInfo{"hackathon", "", 1});
    brain.set_listener([&](const sim::SkillStatusChange& c) { rec->skill(c); });
    brain.set_state_listener([&](const sim::SkillStateChange& c) { rec->skill_state(c); });
    brain.engine().set_log_sink([&](lua::LogLevel level, std::string_view text) {
      rec->log(game.time(), "robot1", level, text);
    });
  }
  REQUIRE(brain.exec(skill_string));
  driver.run_until(core::SimTime::from_seconds(seconds), [&](const sim::Game&) {
    if (rec) rec->frame(game);
    return false;
  });
  Played p;
  p.hash = game.world().state_hash();
  if (rec) {
    rec->verdict(game.time(), "FAIL", "a score", "why not");
    rec->close();
    p.lines = study::read_recording(path);
  }
  return p;
}

}  // namespace

TEST_CASE("recording a skill: camera cone, sightings in the field frame, game unchanged") {
  const std::string path = (temp_dir() / "rescue.jsonl.gz").string();
  const std::string dir = LLSF_SOURCE_DIR "/tests/app/exercises";
  const Played p = play(dir, "rescue{}", 40.0, path);
  const Json header = Json::parse(p.lines.at(0).json);
  CHECK(header["hackathon"]["camera"] == Json{{"range_m", 0.6}, {"fov_deg", 50.0}});

  // Every sighting lies in the cone of the robot's pose at that time (the frame of the same
  // tick: camera frames and pose frames both run at 10 Hz from t = 0), as a field position.
  int sightings = 0;
  int frames_with_pucks = 0;
  Json last_frame;
  std::vector<std::pair<double, Json>> pending;  // sightings waiting for their pose frame
  const double half_fov = 25.0 * M_PI / 180.0;
  for (std::size_t i = 1; i < p.lines.size(); ++i) {
    const study::RecordingLine& l = p.lines[i];
    if (l.kind == "sightings") {
      pending.emplace_back(l.t, Json::parse(l.json));
    } else if (l.kind == "frame") {
      const Json f = Json::parse(l.json);
      for (const auto& [t, s] : pending) {
        if (std::abs(t - l.t) > 1e-6) continue;  // not the same tick: skip (checked below)
        const double x = f["r"][0][0], y = f["r"][0][1], th = f["r"][0][2];
        if (!s["pucks"].empty()) ++frames_with_pucks;
        for (const Json& q : s["pucks"]) {
          REQUIRE(q.size() == 3);
          const double dx = q[0].get<double>() - x, dy = q[1].get<double>() - y;
          CHECK(std::hypot(dx, dy) <= 0.6 + 0.05);
          double a = std::atan2(dy, dx) - th;
          while (a > M_PI) a -= 2 * M_PI;
          while (a < -M_PI) a += 2 * M_PI;
          CHECK(std::abs(a) <= half_fov + 0.15);
          CHECK(q[2].is_string());
          ++sightings;
        }
      }
      pending.clear();
    }
  }
  MESSAGE(sightings, " sightings in ", frames_with_pucks, " frames");
  CHECK(frames_with_pucks >= 5);
  // The skill's states, in order, start from none.
  std::vector<std::string> states;
  for (const study::RecordingLine& l : p.lines) {
    if (l.kind == "skill_state") states.push_back(Json::parse(l.json)["to"]);
  }
  REQUIRE(states.size() >= 3);
  CHECK(states[0] == "GO");
  CHECK(Json::parse(p.lines.back().json) == Json{{"t", 40.0},
                                                 {"e", "verdict"},
                                                 {"result", "FAIL"},
                                                 {"score", "a score"},
                                                 {"why", "why not"}});

  // The same game unrecorded ends in the same world.
  CHECK(play(dir, "rescue{}", 40.0, "").hash == p.hash);
}

TEST_CASE("recording a skill: log lines, states, the navigator's refusal") {
  const std::filesystem::path dir = temp_dir() / "probe";
  std::filesystem::create_directories(dir);
  std::ofstream(dir / "probe.lua") << kProbe;
  const std::string path = (temp_dir() / "probe.jsonl.gz").string();
  const Played p = play(dir.string(), "probe{}", 2.0, path);
  std::vector<Json> ev;
  for (const study::RecordingLine& l : p.lines) {
    if (l.kind == "log" || l.kind == "skill_state" || l.kind == "nav") {
      Json j = Json::parse(l.json);
      j.erase("t");
      ev.push_back(j);
    }
  }
  REQUIRE(ev.size() == 5);
  CHECK(ev[0] ==
        Json{{"e", "log"}, {"robot", "robot1"}, {"level", "info"}, {"text", "driving to 3.92"}});
  CHECK(ev[1] == Json{{"e", "log"}, {"robot", "robot1"}, {"level", "warn"}, {"text", "careful"}});
  CHECK(ev[2] == Json{{"e", "skill_state"},
                      {"robot", "robot1"},
                      {"skill", "probe"},
                      {"from", ""},
                      {"to", "DRIVE"}});
  CHECK(ev[3]["e"] == "nav");
  CHECK(ev[3]["kind"] == "refused");
  CHECK(ev[3]["outcome"] == "INVALID_GOAL");
  CHECK(ev[3]["goal"] == Json{3.92, 1.68, 0.0});
  CHECK(ev[3]["message"].get<std::string>().find("inside M1") != std::string::npos);
  CHECK_FALSE(ev[3].contains("place"));
  CHECK(ev[4] == Json{{"e", "skill_state"},
                      {"robot", "robot1"},
                      {"skill", "probe"},
                      {"from", "DRIVE"},
                      {"to", "FAILED"}});
}
