// SPDX-License-Identifier: MIT
// The hackathon exercises (exercises/NN-name/exercise.yaml; docs/exercises.md): reading and
// finding them, and the temporary skill directory a participant's file is played from. Used by
// `llsfsim exercise` (exercise_command.cpp) for one game and for a sweep over seeds.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "llsf/core/geometry.h"
#include "llsf/study/scenario.h"

namespace llsf::app {

/// How an exercise is judged (exactly one kind per exercise).
struct Goal {
  enum class Kind : std::uint8_t {
    kReach,   ///< the skill ends FINAL with the robot within `within_m` of the target
    kFind,    ///< the skill ends FINAL reporting (fsm.result) a puck of `colour` within `within_m`
    kPoints,  ///< the hackathon points reach `points` (the skill must not fail)
  };
  Kind kind = Kind::kPoints;
  std::vector<core::Vec2> targets;  ///< kReach: the seed picks one (stream "exercise/target")
  double within_m = 0.2;
  std::string colour;  ///< kFind
  int points = 0;      ///< kPoints
};

/// One exercise: exercise.yaml read and validated.
struct Exercise {
  std::string name;   ///< the directory name, e.g. "01-drive-to-point"
  std::string title;  ///< "Drive to a point"
  std::string dir;
  std::string file;     ///< .../exercise.yaml
  std::string skill;    ///< the skill name the participant's file is loaded as
  bool repeat = false;  ///< call the skill again after FINAL until the time is up
  double progress_s = 10.0;
  Goal goal;
  study::Scenario scenario;
};

/// Reads `dir`/exercise.yaml; throws core::ConfigError naming file, line and key.
Exercise load_exercise(const std::string& dir);

/// The goal in one line ("end FINAL with the robot within 0.20 m of the target (x, y)").
std::string describe_goal(const Exercise& ex);

/// "reach", "find" or "points": the goal's kind as `--json` names it.
const char* goal_name(Goal::Kind kind);

/// Where the exercises are: `option` if given, else $LLSF_EXERCISES_DIR, else the data
/// directory's exercises/.
std::string exercises_root(const std::string& option);

/// The names of the exercise directories of `root` (those with an exercise.yaml), sorted.
std::vector<std::string> exercise_names(const std::string& root);

/// The directory of exercise `name`: a directory with an exercise.yaml, or an exercise of
/// `root` by its name or a unique prefix of it ("01", "01-drive"); "" if none, with `why` set.
std::string find_exercise(const std::string& name, const std::string& root, std::string& why);

/// A temporary skill directory holding the participant's file as `<skill>.lua`; removed on
/// destruction. Each object has its own directory (safe to make on several threads at once).
class SkillDir {
 public:
  SkillDir(const std::string& source, const std::string& skill);
  ~SkillDir();
  SkillDir(const SkillDir&) = delete;
  SkillDir& operator=(const SkillDir&) = delete;
  SkillDir(SkillDir&&) = delete;
  SkillDir& operator=(SkillDir&&) = delete;
  const std::string& dir() const { return dir_; }
  const std::string& path() const { return path_; }

 private:
  std::string dir_;
  std::string path_;
};

}  // namespace llsf::app
