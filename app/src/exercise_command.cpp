// SPDX-License-Identifier: MIT
// `llsfsim exercise`: the hackathon exercises (exercises/NN-name/ with README.md, skill.lua and
// exercise.yaml; docs/exercises.md). Loads the participant's file as the exercise's skill, plays
// the exercise's hackathon world, prints progress and a score, and judges the game by the
// exercise's rule. Lua errors are shown as `file:line: message` with a hint, never as a dump.
#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <optional>
#include <ostream>
#include <regex>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "commands.h"
#include "exercise_hints.h"
#include "hackathon_client.h"
#include "live.h"
#include "llsf/app/cli.h"
#include "llsf/core/config.h"
#include "llsf/core/data_dir.h"
#include "llsf/core/error.h"
#include "llsf/core/version.h"
#include "llsf/sim/driver.h"
#include "llsf/sim/game.h"
#include "llsf/sim/skill_brain.h"
#include "llsf/study/recording.h"
#include "llsf/study/scenario.h"
#include "llsf/study/stats_store.h"
#include "server.h"

namespace llsf::app {

namespace {

namespace fs = std::filesystem;
using core::SimTime;

// --- The exercise file ----------------------------------------------------------------------

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

bool is_identifier(const std::string& s) {
  static const std::regex re("[A-Za-z_][A-Za-z0-9_]*");
  return std::regex_match(s, re);
}

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
  if (!ex.scenario.game.hackathon) {
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
    if (ex.scenario.game.hackathon->colour_index(ex.goal.colour) < 0) {
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
          ex.scenario.game.hackathon->points_per_puck, ex.scenario.game.hackathon->decoy_penalty);
  }
  return "";
}

// --- Finding exercises ----------------------------------------------------------------------

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

/// The directory of exercise `name`: a directory with an exercise.yaml, or an exercise of
/// `root` by its name or a unique prefix of it ("01", "01-drive"); "" if none.
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

/// A temporary skill directory holding the participant's file as `<skill>.lua`; removed on
/// destruction.
class SkillDir {
 public:
  SkillDir(const std::string& source, const std::string& skill) {
    static int counter = 0;
    dir_ =
        (fs::temp_directory_path() / fmt::format("llsfex-{}-{}", ::getpid(), ++counter)).string();
    fs::create_directories(dir_);
    path_ = (fs::path(dir_) / (skill + ".lua")).string();
    fs::copy_file(source, path_, fs::copy_options::overwrite_existing);
  }
  ~SkillDir() {
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }
  SkillDir(const SkillDir&) = delete;
  SkillDir& operator=(const SkillDir&) = delete;
  const std::string& dir() const { return dir_; }
  const std::string& path() const { return path_; }

 private:
  std::string dir_;
  std::string path_;
};

// --- Running --------------------------------------------------------------------------------

struct ExerciseOptions {
  std::string exercise;
  std::string skill_file;
  std::optional<std::uint64_t> seed;
  std::string root;
  LiveOptions live;  ///< --speed, --realtime, --serve, --port, --serve-exit
  std::string record;
  bool quiet = false;
  bool list = false;
};

std::string stamp(SimTime t) { return fmt::format("[{:8.2f} s]", t.seconds()); }

/// Two numbers in `text` ("1.20 3.40", "(1.2, 3.4)", "x=1.2 y=3.4"), or nullopt.
std::optional<core::Vec2> two_numbers(const std::string& text) {
  static const std::regex number(R"([-+]?(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?)");
  std::vector<double> v;
  for (auto it = std::sregex_iterator(text.begin(), text.end(), number);
       it != std::sregex_iterator() && v.size() < 2; ++it) {
    v.push_back(std::stod(it->str()));
  }
  if (v.size() < 2) return std::nullopt;
  return core::Vec2(v[0], v[1]);
}

int list_exercises(const std::string& root, std::ostream& out, std::ostream& err) {
  const std::vector<std::string> names = exercise_names(root);
  if (names.empty()) {
    err << "llsfsim exercise: no exercises in " << root << "\n";
    return kExitBadInput;
  }
  for (const std::string& n : names) {
    try {
      const Exercise ex = load_exercise((fs::path(root) / n).string());
      out << fmt::format("{:22} {}\n{:22} skill {}, {:.0f} s, seeds {}..{} ({}): {}\n", n, ex.title,
                         "", ex.skill, ex.scenario.duration.seconds(), ex.scenario.seeds.front(),
                         ex.scenario.seeds.back(), ex.scenario.seeds.size(), describe_goal(ex));
    } catch (const core::ConfigError& e) {
      out << fmt::format("{:22} BAD: {}\n", n, e.what());
    }
  }
  out << "Run one: llsfsim exercise NAME --skill FILE (start from NAME/skill.lua; "
         "docs/exercises.md)\n";
  return kExitOk;
}

int run_exercise(const ExerciseOptions& o, std::ostream& out, std::ostream& err) {
  const std::string root = exercises_root(o.root);
  if (o.list) return list_exercises(root, out, err);
  if (o.exercise.empty()) {
    err << "llsfsim exercise: name an exercise (llsfsim exercise --list shows them)\n";
    return kExitBadInput;
  }
  std::string why;
  const std::string dir = find_exercise(o.exercise, root, why);
  if (dir.empty()) {
    err << "llsfsim exercise: " << why << "; the exercises (" << root << "):\n";
    for (const std::string& n : exercise_names(root)) err << "  " << n << "\n";
    return kExitBadInput;
  }
  Exercise ex;
  try {
    ex = load_exercise(dir);
  } catch (const core::ConfigError& e) {
    err << "llsfsim exercise: " << e.what() << "\n";
    return kExitBadInput;
  }
  if (o.skill_file.empty()) {
    err << "llsfsim exercise: give your skill file with --skill FILE (start from a copy of "
        << (fs::path(dir) / "skill.lua").string() << ")\n";
    return kExitBadInput;
  }
  if (!fs::is_regular_file(o.skill_file)) {
    err << "llsfsim exercise: no such skill file: " << o.skill_file << "\n";
    return kExitBadInput;
  }
  const std::uint64_t seed = o.seed.value_or(ex.scenario.seeds.front());

  // The game and one skill engine per robot, each with the library plus the participant's file.
  sim::GameConfig config = ex.scenario.game;
  config.seed = seed;
  sim::GameDriver driver(config);
  sim::Game& game = driver.game();
  const SkillDir skill_dir(o.skill_file, ex.skill);
  lua::SkillEngineConfig ec = ex.scenario.skills;
  if (ec.skill_dirs.empty()) ec.skill_dirs = sim::skill_library_dirs(config.levels.skill);
  ec.skill_dirs.push_back(skill_dir.dir());
  ec.hot_reload = false;
  std::vector<sim::SkillBrain*> brains;  // owned by the driver
  for (int i = 0; i < game.robot_count(); ++i) brains.push_back(&driver.plug_skills(i, ec));
  const std::string& user = o.skill_file;
  for (const lua::SkillInfo& s : brains.front()->engine().skills()) {
    if (s.name != ex.skill || s.load_error.empty()) continue;
    out << "exercise " << ex.name << ": " << user << " does not load\n";
    print_friendly(s.load_error, skill_dir.path(), user, ex.skill, out);
    out << "result   NOT RUN (fix the file and run again)\n";
    return kExitBadInput;
  }

  // What the skill is called with.
  std::string call = ex.skill + "{}";
  core::Vec2 target(0.0, 0.0);
  if (ex.goal.kind == Goal::Kind::kReach) {
    core::RandomStream pick = game.rng().stream("exercise/target");
    target = ex.goal.targets.at(static_cast<std::size_t>(
        pick.uniform_int(0, static_cast<std::int64_t>(ex.goal.targets.size()) - 1)));
    call = fmt::format("{}{{x={:.2f}, y={:.2f}}}", ex.skill, target.x(), target.y());
  }

  // Recording (--record, --serve) and the live viewer.
  LiveFeed feed;
  std::unique_ptr<Server> server;
  try {
    ServerOptions so;
    so.db = "";
    so.recordings = default_recordings_dir(std::string(study::StatsStore::kDefaultPath));
    server = start_live_server(o.live, so, feed, out);
  } catch (const core::UserError& e) {  // cannot listen
    err << "llsfsim exercise: " << e.what() << "\n";
    return kExitBadInput;
  }
  std::unique_ptr<study::Recorder> recorder;
  if (o.live.serve || !o.record.empty()) {
    study::LineSink sink;
    if (o.live.serve) sink = [&feed](std::string_view line) { feed.publish(line); };
    try {
      recorder = std::make_unique<study::Recorder>(
          o.record, game, study::RecordingInfo{ex.name, "", seed, std::string(core::kVersion)},
          10.0, sink);
    } catch (const core::UserError& e) {  // the recording cannot be written
      err << "llsfsim exercise: " << e.what() << "\n";
      return kExitBadInput;
    }
  }

  if (!o.quiet) {
    out << fmt::format("exercise {}: {}  (seed {})\n", ex.name, ex.title, seed);
    out << fmt::format("goal     {}\n", describe_goal(ex));
    out << fmt::format("skill    {} as {}, {} robot(s), called as {}{}\n", user, ex.skill,
                       game.robot_count(), call, ex.repeat ? " (again after each FINAL)" : "");
  }
  for (std::size_t i = 0; i < brains.size(); ++i) {
    sim::SkillBrain& b = *brains[i];
    const std::string name(game.robot(static_cast<int>(i)).name());
    b.engine().set_log_sink([&, name](lua::LogLevel level, std::string_view text) {
      if (o.quiet && level < lua::LogLevel::kWarn) return;
      static const char* const names[] = {"debug", "info", "warn", "error"};
      out << stamp(game.time()) << " " << name << " " << names[static_cast<int>(level)] << ": "
          << text << "\n";
    });
    b.set_listener([&](const sim::SkillStatusChange& c) {
      if (recorder) recorder->skill(c);
      if (o.quiet || c.status == lua::SkillStatus::kFailed) return;
      out << stamp(c.time) << " " << c.robot << " " << lua::to_string(c.status) << "  "
          << c.skill_string;
      if (!c.result.empty()) out << "  -> " << c.result;
      out << "\n";
    });
  }

  // Paced mode (the wall clock only paces the loop; it never enters the game).
  const Pacer pacer(o.live.pace());

  // Score so far, for progress lines and the verdict.
  auto robot_pose = [&](int i) {
    return game.world().robot_pose(game.world().robot_by_name(game.robot(i).name()));
  };
  auto score_now = [&]() -> std::string {
    switch (ex.goal.kind) {
      case Goal::Kind::kReach:
        return fmt::format("{:.2f} m from the target", (robot_pose(0).position() - target).norm());
      case Goal::Kind::kFind:
        return "searching";
      case Goal::Kind::kPoints: {
        const sim::HackathonScore s = *game.hackathon_score();
        return fmt::format("{} points ({} of {} rescued, {} decoys)", s.points, s.rescued,
                           s.rescuable, s.decoys);
      }
    }
    return "";
  };

  // Play: until the time is up, the skill failed, or (without repeat) every robot's skill ended.
  const SimTime end = ex.scenario.duration;
  SimTime next_progress = SimTime::from_seconds(ex.progress_s);
  std::vector<std::string> states(brains.size());
  std::vector<int> calls(brains.size(), 1);
  for (auto& b : brains) {
    if (const lua::ExecResult r = b->exec(call); !r) {
      err << "llsfsim exercise: " << r.error << "\n";
      return kExitBadInput;
    }
  }
  int failed = -1;  // the robot whose skill failed
  bool ended = false;
  driver.run_until(end, [&](const sim::Game&) {
    if (recorder) recorder->frame(game);
    pacer.wait(game.time().seconds());
    if (!game.skills_cycled()) return false;  // skill states change only in the skill cycle
    bool running = false;
    for (std::size_t i = 0; i < brains.size(); ++i) {
      lua::SkillEngine& e = brains[i]->engine();
      const std::string st = e.skill_state(ex.skill);
      if (st != states[i]) {
        if (!st.empty() && !o.quiet) {
          out << stamp(game.time()) << " " << game.robot(static_cast<int>(i)).name() << "   "
              << ex.skill << ": " << st << "\n";
        }
        states[i] = st;
      }
      const lua::SkillStatus s = e.status();
      if (s == lua::SkillStatus::kFailed) {
        failed = static_cast<int>(i);
        break;
      }
      if (s == lua::SkillStatus::kFinal && ex.repeat) {
        brains[i]->exec(call);
        ++calls[i];
      }
      if (e.status() == lua::SkillStatus::kRunning) running = true;
    }
    if (failed >= 0) return true;
    if (!running) {
      ended = true;
      return true;
    }
    if (game.time() >= next_progress) {
      if (!o.quiet) {
        out << stamp(game.time()) << " progress:";
        for (std::size_t i = 0; i < brains.size(); ++i) {
          out << " " << game.robot(static_cast<int>(i)).name() << " "
              << (states[i].empty() ? "-" : states[i]);
        }
        out << " | " << score_now() << "\n";
      }
      next_progress += SimTime::from_seconds(ex.progress_s);
    }
    return false;
  });
  if (recorder) recorder->close();
  feed.finish();

  // The verdict.
  bool passed = false;
  std::string score;
  std::string why_not;
  const bool final =
      ended && brains.front()->engine().status() == lua::SkillStatus::kFinal && failed < 0;
  switch (ex.goal.kind) {
    case Goal::Kind::kReach: {
      const double d = (robot_pose(0).position() - target).norm();
      score = fmt::format("{:.2f} m from the target ({:.2f}, {:.2f}), need <= {:.2f} m", d,
                          target.x(), target.y(), ex.goal.within_m);
      passed = final && d <= ex.goal.within_m;
      if (final && !passed) why_not = "the skill ended FINAL too far from the target";
      break;
    }
    case Goal::Kind::kFind: {
      const std::string result = brains.front()->engine().result();
      const std::optional<core::Vec2> p = two_numbers(result);
      if (!final) {
        score = "no position reported";
      } else if (!p) {
        score = "fsm.result is \"" + result + "\": no position";
        why_not =
            "set self.fsm.result = string.format(\"%.2f %.2f\", x, y) (field coordinates) "
            "before FINAL";
      } else {
        double best = 1e9;
        int best_id = -1;
        const int colour = ex.scenario.game.hackathon->colour_index(ex.goal.colour);
        for (const sim::HackathonPuck& k : game.hackathon_layout()->pucks) {
          if (k.colour != colour || !game.world().has_puck(k.id)) continue;
          const double d = (game.world().puck_position(k.id) - *p).norm();
          if (d < best) best = d, best_id = k.id.value();
        }
        score = fmt::format("reported ({:.2f}, {:.2f}): {:.2f} m from {} puck {}, need <= {:.2f} m",
                            p->x(), p->y(), best, ex.goal.colour, best_id, ex.goal.within_m);
        passed = best <= ex.goal.within_m;
        if (!passed) {
          why_not = "the position is not a " + ex.goal.colour +
                    " puck's: turn the sighting (robot frame) into field coordinates with "
                    "pose:get() (see the README's hints)";
        }
      }
      break;
    }
    case Goal::Kind::kPoints: {
      const sim::HackathonScore s = *game.hackathon_score();
      score = fmt::format("{} points: {} of {} rescued, {} decoys, need >= {}", s.points, s.rescued,
                          s.rescuable, s.decoys, ex.goal.points);
      passed = failed < 0 && s.points >= ex.goal.points;
      if (failed < 0 && !passed) {
        why_not = ended ? "the skill ended before the time was up (FINAL without repeat)"
                        : "not enough points when the time was up";
      }
      break;
    }
  }
  out << fmt::format("{} end after {:.2f} s of game time", stamp(game.time()),
                     game.time().seconds());
  if (ex.repeat) {
    out << ", " << calls.front() << " call(s)";
    for (std::size_t i = 1; i < calls.size(); ++i) out << " / " << calls[i];
  }
  out << "\n";
  if (failed >= 0) {
    const lua::SkillEngine& e = brains[static_cast<std::size_t>(failed)]->engine();
    out << game.robot(failed).name() << "   FAILED  " << e.skill_string() << "\n";
    print_friendly(e.error(), skill_dir.path(), user, ex.skill, out);
  } else if (!ended && ex.goal.kind != Goal::Kind::kPoints) {
    why_not = fmt::format("the skill was still running after {:.0f} s", end.seconds());
  }
  out << "score    " << score << "\n";
  if (!why_not.empty()) out << "why      " << why_not << "\n";
  out << "result   " << (passed ? "PASS" : "FAIL") << "\n";
  serve_until_stopped(o.live, server, out);
  return passed ? kExitOk : kExitFailed;
}

}  // namespace

Action add_exercise_command(CLI::App& app) {
  auto o = std::make_shared<ExerciseOptions>();
  app.add_option("exercise", o->exercise,
                 "The exercise: its name or a unique prefix (01, 02-find-red-puck) or its "
                 "directory");
  app.add_option("--skill", o->skill_file,
                 "Your skill file (start from a copy of the exercise's skill.lua); it is loaded "
                 "as the exercise's skill, next to the skill library");
  app.add_option("--seed", o->seed, "Seed to play (default: the exercise's first)");
  app.add_option("--exercises", o->root,
                 "Where the exercises are (default: $LLSF_EXERCISES_DIR, else exercises/ of the "
                 "data directory)");
  add_live_options(app, o->live,
                   "Serve the browser viewer with the game live at http://127.0.0.1:PORT/#/live "
                   "(best with --realtime or --speed)");
  app.add_option("--record", o->record,
                 "Also write the game's recording to FILE (gzip JSON lines)");
  app.add_flag("-q,--quiet", o->quiet, "Only the score, errors and the verdict");
  app.add_flag("--list", o->list, "List the exercises with their goals and exit");
  app.footer(
      "Examples:\n"
      "  llsfsim exercise --list\n"
      "  cp exercises/01-drive-to-point/skill.lua my_drive.lua   # edit the TODOs\n"
      "  llsfsim exercise 01 --skill my_drive.lua\n"
      "  llsfsim exercise 04 --skill my_rescue.lua --seed 7 --realtime --serve\n"
      "Exit code: 0 PASS, 1 not passed (also a skill that fails, crashes or loops forever), 2 bad "
      "input (unknown exercise, missing file, a skill file that does not load), 3 internal error "
      "(a bug: please report it). docs/exercises.md");
  const std::shared_ptr<SubmitOptions> submit = add_submit_options(app);
  return [o, submit](std::ostream& out, std::ostream& err) {
    if (!submit->url.empty()) return submit_skill(*submit, o->exercise, o->skill_file, out, err);
    return run_exercise(*o, out, err);
  };
}

}  // namespace llsf::app
