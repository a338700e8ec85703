// SPDX-License-Identifier: MIT
// The hackathon exercises: exercise.yaml read and validated, found by name, and the temporary
// skill directory (docs/exercises.md).
#include "exercise.h"

#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cstdlib>
#include <filesystem>
#include <regex>

#include "llsf/core/config.h"
#include "llsf/core/data_dir.h"
#include "llsf/core/error.h"
#include "llsf/sim/hackathon_extension.h"

namespace llsf::app {

namespace fs = std::filesystem;

namespace {

bool is_identifier(const std::string& s) {
  static const std::regex re("[A-Za-z_][A-Za-z0-9_]*");
  return std::regex_match(s, re);
}

}  // namespace

Exercise load_exercise(const std::string& dir) {
  Exercise ex;
  ex.dir = dir;
  ex.name = fs::path(dir).lexically_normal().filename().string();
  if (ex.name.empty()) ex.name = fs::path(dir).lexically_normal().parent_path().filename().string();
  ex.file = (fs::path(dir) / "exercise.yaml").string();
  const core::ConfigNode root = core::ConfigNode::load_file(ex.file);
  root.require_map();
  ex.title = root.at("title").as_string();
  ex.skill = root.at("skill").as_string();
  if (!is_identifier(ex.skill)) root["skill"].fail("must be a Lua identifier (the skill's name)");
  root.read("repeat", ex.repeat);
  root.read("progress_s", ex.progress_s, core::positive());
  core::ConfigNode sc = root.at("scenario");
  const core::ConfigNode g = root.at("goal");
  root.no_other_keys();

  // The world: a scenario map (docs/scenarios.md) that must switch on the hackathon.
  sc.require_map();
  if (!sc["name"].defined()) sc.set("name", core::ConfigNode::parse("'" + ex.name + "'", ex.file));
  ex.scenario = study::read_scenario_map(sc, ex.file);
  const sim::HackathonConfig* hackathon = sim::hackathon_config(ex.scenario.game);
  if (hackathon == nullptr) {
    sc.fail("an exercise plays the hackathon variant: add `hackathon: {}` (docs/hackathon.md)");
  }
  for (const study::RobotSpec& r : ex.scenario.robots) {
    if (!r.agent.empty()) sc["robots"].fail("robots of an exercise run the skill, not an agent");
  }

  // The scoring rule.
  g.require_map();
  const core::ConfigNode reach = g["reach"];
  const core::ConfigNode find = g["find"];
  static_cast<void>(g["points_at_least"]);  // asked for: the third known key
  g.no_other_keys();
  if (g.size() != 1) g.fail("give exactly one of reach, find, points_at_least");
  const kinematic::FieldConfig& field = ex.scenario.game.world.field;
  if (reach.defined()) {
    const core::ConfigNode& r = reach;
    r.require_map();
    ex.goal.kind = Goal::Kind::kReach;
    const core::ConfigNode t = r.at("targets");
    if (!t.is_sequence() || t.size() == 0) t.fail("expected a list of {x, y}");
    for (const core::ConfigNode& p : t.elements()) {
      p.require_map();
      const core::Vec2 v(p.at("x").as_double(), p.at("y").as_double());
      p.no_other_keys();
      if (v.x() < 0.0 || v.y() < 0.0 || v.x() > field.width_m || v.y() > field.height_m) {
        p.fail(fmt::format("({:.2f}, {:.2f}) is not on the field", v.x(), v.y()));
      }
      ex.goal.targets.push_back(v);
    }
    r.read("within_m", ex.goal.within_m, core::positive());
    r.no_other_keys();
  } else if (find.defined()) {
    const core::ConfigNode& f = find;
    f.require_map();
    ex.goal.kind = Goal::Kind::kFind;
    ex.goal.colour = f.at("colour").as_string();
    if (hackathon->colour_index(ex.goal.colour) < 0) {
      f["colour"].fail("'" + ex.goal.colour + "' is not a colour of scenario.hackathon.colours");
    }
    ex.goal.within_m = 0.3;
    f.read("within_m", ex.goal.within_m, core::positive());
    f.no_other_keys();
  } else {
    ex.goal.kind = Goal::Kind::kPoints;
    g.read("points_at_least", ex.goal.points, core::non_negative());
  }
  return ex;
}

std::string describe_goal(const Exercise& ex) {
  switch (ex.goal.kind) {
    case Goal::Kind::kReach:
      return fmt::format("end FINAL with the robot within {:.2f} m of the target (x, y)",
                         ex.goal.within_m);
    case Goal::Kind::kFind:
      return fmt::format(
          "end FINAL with self.fsm.result = \"X Y\" within {:.2f} m of a {} puck's centre",
          ex.goal.within_m, ex.goal.colour);
    case Goal::Kind::kPoints:
      return fmt::format(
          ">= {} points in {:.0f} s (a puck of a counted colour released in the "
          "safe area: +{}, a decoy: -{}); the skill must not fail",
          ex.goal.points, ex.scenario.duration.seconds(),
          sim::hackathon_config(ex.scenario.game)->points_per_puck,
          sim::hackathon_config(ex.scenario.game)->decoy_penalty);
  }
  return "";
}

std::string exercises_root(const std::string& option) {
  if (!option.empty()) return option;
  const char* env = std::getenv("LLSF_EXERCISES_DIR");
  if (env != nullptr && *env != '\0') return env;
  return core::data_dir() + "/exercises";
}

std::vector<std::string> exercise_names(const std::string& root) {
  std::vector<std::string> names;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(root, ec)) {
    if (e.is_directory() && fs::exists(e.path() / "exercise.yaml")) {
      names.push_back(e.path().filename().string());
    }
  }
  std::sort(names.begin(), names.end());
  return names;
}

std::string find_exercise(const std::string& name, const std::string& root, std::string& why) {
  if (fs::is_directory(name) && fs::exists(fs::path(name) / "exercise.yaml")) return name;
  std::vector<std::string> hits;
  for (const std::string& n : exercise_names(root)) {
    if (n == name) return (fs::path(root) / n).string();
    if (n.rfind(name, 0) == 0) hits.push_back(n);
  }
  if (hits.size() == 1) return (fs::path(root) / hits.front()).string();
  why = hits.empty() ? "unknown exercise '" + name + "'" : "'" + name + "' names several exercises";
  return "";
}

const char* goal_name(Goal::Kind kind) {
  switch (kind) {
    case Goal::Kind::kReach:
      return "reach";
    case Goal::Kind::kFind:
      return "find";
    case Goal::Kind::kPoints:
      return "points";
  }
  return "";
}

SkillDir::SkillDir(const std::string& source, const std::string& skill) {
  static std::atomic<int> counter{0};  // sweeps make them on several threads
  dir_ = (fs::temp_directory_path() / fmt::format("llsfex-{}-{}", ::getpid(), ++counter)).string();
  fs::create_directories(dir_);
  path_ = (fs::path(dir_) / (skill + ".lua")).string();
  fs::copy_file(source, path_, fs::copy_options::overwrite_existing);
}

SkillDir::~SkillDir() {
  std::error_code ec;
  fs::remove_all(dir_, ec);
}

}  // namespace llsf::app
