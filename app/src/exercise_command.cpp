// SPDX-License-Identifier: MIT
// `llsfsim exercise`: the hackathon exercises (exercises/NN-name/ with README.md, skill.lua and
// exercise.yaml; docs/exercises.md). Loads the participant's file as the exercise's skill, plays
// the exercise's hackathon world, prints progress and a score, and judges the game by the
// exercise's rule. Lua errors are shown as `file:line: message` with a hint, never as a dump.
#include <fmt/format.h>
#include <fmt/ranges.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <ostream>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "batch_progress.h"
#include "cli_checks.h"
#include "commands.h"
#include "exercise.h"
#include "exercise_hints.h"
#include "hackathon_client.h"
#include "live.h"
#include "llsf/app/cli.h"
#include "llsf/core/config.h"
#include "llsf/core/data_dir.h"
#include "llsf/core/error.h"
#include "llsf/core/input_file.h"
#include "llsf/core/version.h"
#include "llsf/sim/game.h"
#include "llsf/sim/hackathon_extension.h"
#include "llsf/sim/skill_brain.h"
#include "llsf/study/batch.h"
#include "llsf/study/player.h"
#include "llsf/study/pool.h"
#include "llsf/study/recording.h"
#include "llsf/study/scenario.h"
#include "llsf/study/stats_store.h"
#include "server.h"

namespace llsf::app {

namespace {

namespace fs = std::filesystem;
using core::SimTime;

// --- Running --------------------------------------------------------------------------------

struct ExerciseOptions {
  std::string exercise;
  std::string skill_file;
  std::optional<std::uint64_t> seed;
  std::string seeds;  ///< --seeds LIST: a sweep
  int jobs = 0;       ///< games at once in a sweep; 0: one per core
  bool json = false;
  std::string root;
  LiveOptions live;  ///< --speed, --realtime, --serve, --port, --serve-exit
  std::string record;
  bool quiet = false;
  bool list = false;
  bool trace = false;  ///< --trace: each state change with the transition that made it
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

/// A seed's result, and a sweep's verdict.
enum class Outcome : std::uint8_t { kPass, kFail, kNotRun };

const char* outcome_name(Outcome r) {
  switch (r) {
    case Outcome::kPass:
      return "PASS";
    case Outcome::kFail:
      return "FAIL";
    case Outcome::kNotRun:
      return "NOT RUN";
  }
  return "";
}

/// Warnings kept per seed (SeedRun::warnings).
constexpr std::size_t kMaxWarnings = 5;

/// What one seed's game came to: the verdict's parts (a row of the table, a `runs` entry of
/// `--json`).
struct SeedRun {
  std::uint64_t seed = 0;
  Outcome result = Outcome::kNotRun;
  std::optional<double> value;  ///< reach/find: the distance in m; points: the points
  std::string score;            ///< the `score` line's text
  std::string why;              ///< the `why` line's text (when not passed)
  std::string error;            ///< the skill's error as `file:line: message`
  std::string hint;             ///< the hint for `error`
  /// The skill's warnings (lines logged at warn level: the engine's hints such as a state
  /// machine that keeps switching, and print_warn), distinct, the first kMaxWarnings of them.
  std::vector<std::string> warnings;
  double game_time_s = 0.0;
  int code = kExitBadInput;  ///< the exit code of this seed alone
};

/// Prints the engine error `message` in the participant's terms (print_friendly) on `out` and
/// keeps its `error` and `hint` lines in `run`.
void friendly(const std::string& message, const std::string& tmp, const std::string& user,
              const std::string& skill, std::ostream& out, SeedRun& run) {
  std::ostringstream block;
  // The engine shows `user` (display_paths), which Lua shortens to "...tail" beyond 59
  // characters: user_paths() with `user` as the path to find gives the whole path back.
  print_friendly(user_paths(message, user, user), tmp, user, skill, block);
  out << block.str();
  // "error    ...", "in       ...", "hint     ...": a line without such a prefix continues the
  // field before it.
  std::string* field = nullptr;
  std::istringstream lines(block.str());
  for (std::string line; std::getline(lines, line);) {
    const std::string tag = line.substr(0, 9);
    if (tag == "error    ") {
      field = &run.error;
    } else if (tag == "hint     ") {
      field = &run.hint;
    } else if (tag == "in       ") {
      field = nullptr;
      continue;
    } else if (field != nullptr) {
      *field += "\n" + line;
      continue;
    } else {
      continue;
    }
    if (!field->empty()) *field += "\n";
    *field += line.substr(9);
  }
}

/// Why a reported find position `p` of robot `robot` is not the goal colour's puck, by what lies
/// there: another colour's puck (the camera's false colour, or the wrong sighting taken), the
/// puck in the robot's holder or the robot itself, or the goal puck's position in the robot's
/// frame (the sighting not turned into field coordinates); else the general advice.
std::string find_why_not(const sim::Game& game, const Exercise& ex, int robot, core::Vec2 p,
                         int goal_puck) {
  const kinematic::World& w = game.world();
  const sim::HackathonConfig& h = *sim::hackathon_config(ex.scenario.game);
  const double within = ex.goal.within_m;
  const core::RobotId rid = w.robot_by_name(game.robot(robot).name());
  const core::Pose2D pose = w.robot_pose(rid);
  const std::optional<core::PuckId> held = w.held_puck(rid);
  // The held puck or the robot's own position.
  if (held && (w.puck_position(*held) - p).norm() <= within) {
    return fmt::format(
        "the position is the puck in the robot's holder (puck {}), not a {} puck on the field: "
        "report the sighting's position, before taking a puck",
        held->value(), ex.goal.colour);
  }
  if ((pose.position() - p).norm() <= within) {
    return "the position is the robot's own (pose:get()), not the puck's: add the sighting "
           "(robot frame) turned into field coordinates";
  }
  // Another colour's puck.
  for (const sim::HackathonPuck& k : sim::hackathon_of(game)->layout().pucks) {
    if (k.colour == h.colour_index(ex.goal.colour) || !w.has_puck(k.id)) continue;
    if ((w.puck_position(k.id) - p).norm() > within) continue;
    return fmt::format(
        "the position is a {} puck's (puck {}), not a {} one: the camera reports a wrong colour "
        "now and then (false_colour_rate), so wait for the colour in two or more sightings, and "
        "ask puck_detector:nearest(\"{}\") for that colour only",
        h.colours.at(static_cast<std::size_t>(k.colour)).name, k.id.value(), ex.goal.colour,
        ex.goal.colour);
  }
  // The goal puck's position in the robot's frame at the end: not turned into field coordinates.
  if (goal_puck >= 0) {
    const core::Vec2 in_robot = pose.to_local(w.puck_position(core::PuckId(goal_puck)));
    if ((in_robot - p).norm() <= within) {
      return "the position is the " + ex.goal.colour +
             " puck's in the robot's frame (ahead, left): turn the sighting into field "
             "coordinates with pose:get() (see the README's hints)";
    }
  }
  return "the position is no " + ex.goal.colour +
         " puck's: turn the sighting (robot frame) into field coordinates with pose:get() (see "
         "the README's hints), and report it when the colour is sure";
}

/// Plays exercise `ex` with the participant's file `o.skill_file` on `seed` (a study::Player of
/// the exercise's scenario, the file's skill engine plugged into every robot, an observer that
/// stops the game when the skills end), printing what happens on `out` (progress, log lines, the
/// verdict) as a single run does, and returns the outcome. Thread-safe for distinct `out`/`err`
/// streams when `o` asks for no server and no recording.
SeedRun play_seed(const Exercise& ex, const ExerciseOptions& o, std::uint64_t seed,
                  std::ostream& out, std::ostream& err) {
  SeedRun run;
  run.seed = seed;
  // The game and one skill engine per robot, each with the library plus the participant's file.
  study::Player player(ex.scenario, seed);
  sim::Game& game = player.game();
  const SkillDir skill_dir(o.skill_file, ex.skill);
  lua::SkillEngineConfig ec = ex.scenario.skills;
  if (ec.skill_dirs.empty()) ec.skill_dirs = sim::skill_library_dirs(ex.scenario.game.levels.skill);
  ec.skill_dirs.push_back(skill_dir.dir());
  ec.hot_reload = false;
  ec.display_paths[skill_dir.path()] = o.skill_file;  // messages name the participant's file
  std::vector<sim::SkillBrain*> brains;               // owned by the player's driver
  for (int i = 0; i < game.robot_count(); ++i) brains.push_back(&player.plug_skills(i, ec));
  const std::string& user = o.skill_file;
  for (const lua::SkillInfo& s : brains.front()->engine().skills()) {
    if (s.name != ex.skill || s.load_error.empty()) continue;
    out << "exercise " << ex.name << ": " << user << " does not load\n";
    friendly(s.load_error, skill_dir.path(), user, ex.skill, out, run);
    out << "result   NOT RUN (fix the file and run again)\n";
    run.code = kExitBadInput;
    return run;
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
    run.error = e.what();
    run.code = kExitBadInput;
    return run;
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
      run.error = e.what();
      run.code = kExitBadInput;
      return run;
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
      if (recorder) recorder->log(game.time(), name, level, text);
      if (level == lua::LogLevel::kWarn && run.warnings.size() < kMaxWarnings &&
          std::find(run.warnings.begin(), run.warnings.end(), text) == run.warnings.end())
        run.warnings.emplace_back(text);
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
    // Every state the skill passes, also within one skill cycle (START -> DRIVE in one step);
    // with --trace, from where and what took it there.
    b.set_state_listener(
        [&](const sim::SkillStateChange& c) {
          if (recorder) {
            sim::SkillStateChange r = c;
            r.via = user_paths(r.via, skill_dir.path(), user);
            recorder->skill_state(r);
          }
          if (o.quiet || c.to.empty()) return;
          if (!o.trace && (c.to == "FINAL" || c.to == "FAILED")) return;  // the status line says it
          out << stamp(c.time) << " " << c.robot << "   " << c.skill << ": ";
          if (o.trace && !c.from.empty()) out << c.from << " -> ";
          out << c.to;
          if (!c.via.empty()) out << "  (" << user_paths(c.via, skill_dir.path(), user) << ")";
          out << "\n";
        },
        o.trace);
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
        const sim::HackathonScore s = *sim::hackathon_score(game);
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
      run.error = r.error;
      run.code = kExitBadInput;
      return run;
    }
  }
  player.start();   // as the scenario says: the hackathon world's refbox stays in PRE_GAME
  int failed = -1;  // the robot whose skill failed
  bool ended = false;
  player.observe([&](const sim::Game&) {
    if (recorder) recorder->frame(game);
    pacer.wait(game.time().seconds());
    if (!game.skills_cycled()) return false;  // skill states change only in the skill cycle
    bool running = false;
    for (std::size_t i = 0; i < brains.size(); ++i) {
      lua::SkillEngine& e = brains[i]->engine();
      states[i] = e.skill_state(ex.skill);  // for the progress lines (the listener prints)
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
  player.play_until(end);

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
      run.value = d;
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
        const int colour = sim::hackathon_config(ex.scenario.game)->colour_index(ex.goal.colour);
        for (const sim::HackathonPuck& k : sim::hackathon_of(game)->layout().pucks) {
          if (k.colour != colour || !game.world().has_puck(k.id)) continue;
          const double d = (game.world().puck_position(k.id) - *p).norm();
          if (d < best) best = d, best_id = k.id.value();
        }
        score = fmt::format("reported ({:.2f}, {:.2f}): {:.2f} m from {} puck {}, need <= {:.2f} m",
                            p->x(), p->y(), best, ex.goal.colour, best_id, ex.goal.within_m);
        passed = best <= ex.goal.within_m;
        if (best_id >= 0) run.value = best;
        if (!passed) why_not = find_why_not(game, ex, 0, *p, best_id);
      }
      break;
    }
    case Goal::Kind::kPoints: {
      const sim::HackathonScore s = *sim::hackathon_score(game);
      score = fmt::format("{} points: {} of {} rescued, {} decoys, need >= {}", s.points, s.rescued,
                          s.rescuable, s.decoys, ex.goal.points);
      passed = failed < 0 && s.points >= ex.goal.points;
      run.value = s.points;
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
    friendly(e.error(), skill_dir.path(), user, ex.skill, out, run);
  } else if (!ended && ex.goal.kind != Goal::Kind::kPoints) {
    why_not = fmt::format("the skill was still running after {:.0f} s", end.seconds());
    // Where it waits and for what (the first robot whose skill still runs).
    for (const auto& b : brains) {
      const std::string wait = b->engine().skill_wait(ex.skill);
      if (wait.empty()) continue;
      why_not += ": " + user_paths(wait, skill_dir.path(), user);
      break;
    }
  }
  out << "score    " << score << "\n";
  if (!why_not.empty()) out << "why      " << why_not << "\n";
  out << "result   " << (passed ? "PASS" : "FAIL") << "\n";
  if (recorder) {  // the verdict is the recording's last line (the viewer's banner)
    const std::string error =
        failed >= 0 ? user_paths(brains[static_cast<std::size_t>(failed)]->engine().error(),
                                 skill_dir.path(), user)
                    : "";
    recorder->verdict(game.time(), passed ? "PASS" : "FAIL", score,
                      why_not.empty() ? error : why_not);
    recorder->close();
  }
  feed.finish();
  serve_until_stopped(o.live, server, out);
  run.result = passed ? Outcome::kPass : Outcome::kFail;
  run.score = score;
  run.why = why_not;
  run.game_time_s = game.time().seconds();
  run.code = passed ? kExitOk : kExitFailed;
  return run;
}

// --- Sweeps: several seeds, a table or JSON ---------------------------------------------------

/// Plays `seeds` of `ex` on study's worker pool (study::play_on_pool, as `batch` plays its
/// games) with up to `o.jobs` threads (default: one per core). Games are independent (each its
/// own player and skill engines), so each seed's run is the same whatever the number of
/// threads. Returns the runs in the order of
/// `seeds`. Progress on `err` as seeds end: a bar when `err` is std::cerr on a terminal, else one
/// line per seed; nothing with -q or --json.
std::vector<SeedRun> play_seeds(const Exercise& ex, const ExerciseOptions& o,
                                const std::vector<std::uint64_t>& seeds, std::ostream& err,
                                bool& interrupted) {
  // The first Ctrl-C: no new game starts, the running ones end (a game is short) and their
  // temporary skill directories go; the runs played so far are returned.
  const SigintGuard sigint;
  std::vector<char> ended_ok(seeds.size(), 0);  // the seeds whose run is in `runs`
  ExerciseOptions quiet = o;  // the games' own output is not shown, only the table
  quiet.quiet = true;
  std::vector<SeedRun> runs(seeds.size());
  const int total = static_cast<int>(seeds.size());

  // The pool's workers take seeds in order; this thread prints the progress as each run ends,
  // so that nothing interleaves.
  const bool bar =
      &err == &std::cerr && isatty(STDERR_FILENO) != 0 && !o.quiet && !o.json && total > 1;
  const bool lines = !bar && !o.quiet && !o.json;
  int played = 0;
  int not_passed = 0;
  if (bar) err << fmt::format("\r{} 0/{} seeds", progress_bar(0, total), total) << std::flush;
  study::play_on_pool<SeedRun>(
      seeds.size(), o.jobs,
      [&](std::size_t i) {
        std::ostringstream game_out;
        std::ostringstream game_err;
        return play_seed(ex, quiet, seeds[i], game_out, game_err);
      },
      [&](std::size_t i, SeedRun& run) {
        runs[i] = std::move(run);
        ended_ok[i] = 1;
        const SeedRun& r = runs[i];
        ++played;
        if (r.result != Outcome::kPass) ++not_passed;
        if (bar) {
          err << fmt::format("\r{} {}/{} seeds, {} not passed", progress_bar(played, total), played,
                             total, not_passed)
              << (played == total ? "\n" : "") << std::flush;
        } else if (lines) {
          err << fmt::format("[{}/{}] seed {}: {}, {:.2f} s of game time\n", played, total, r.seed,
                             outcome_name(r.result), r.game_time_s)
              << std::flush;
        }
      },
      [] { return SigintGuard::interrupted().load(); });
  // (a Ctrl-C while the last games ran, with every seed played, leaves a whole sweep)
  interrupted = SigintGuard::interrupted() &&
                std::count(ended_ok.begin(), ended_ok.end(), 1) < static_cast<long>(seeds.size());
  if (interrupted) {
    std::vector<SeedRun> ran;
    for (std::size_t i = 0; i < runs.size(); ++i) {
      if (ended_ok[i] != 0) ran.push_back(std::move(runs[i]));
    }
    return ran;
  }
  return runs;
}

/// The sweep's verdict: NOT RUN if the file did not load, PASS if every seed passed, else FAIL.
Outcome sweep_verdict(const std::vector<SeedRun>& runs) {
  Outcome v = Outcome::kPass;
  for (const SeedRun& r : runs) {
    if (r.result == Outcome::kNotRun) return Outcome::kNotRun;
    if (r.result == Outcome::kFail) v = Outcome::kFail;
  }
  return v;
}

int verdict_code(Outcome v) {
  switch (v) {
    case Outcome::kPass:
      return kExitOk;
    case Outcome::kFail:
      return kExitFailed;
    case Outcome::kNotRun:
      return kExitBadInput;
  }
  return kExitInternalError;
}

std::string first_line(const std::string& text) { return text.substr(0, text.find('\n')); }

/// The sweep as a table in seed order, then the verdict: "PASS 20/20", or FAIL with the
/// counts and the seeds not passed, or NOT RUN with the load error.
void print_sweep(const Exercise& ex, const ExerciseOptions& o, const std::vector<SeedRun>& runs,
                 bool interrupted, std::size_t asked, std::ostream& out) {
  out << fmt::format("exercise {}: {}  ({} seed(s))\n", ex.name, ex.title, runs.size());
  out << fmt::format("goal     {}\n", describe_goal(ex));
  out << fmt::format("skill    {} as {}\n", o.skill_file, ex.skill);
  const Outcome verdict = sweep_verdict(runs);
  if (verdict == Outcome::kNotRun && !runs.empty()) {  // the same file on every seed: once
    const SeedRun& r = runs.front();
    out << o.skill_file << " does not load\n";
    if (!r.error.empty()) out << "error    " << r.error << "\n";
    if (!r.hint.empty()) out << "hint     " << r.hint << "\n";
    out << "verdict  NOT RUN (fix the file and run again)\n";
    return;
  }
  std::size_t seed_w = 4;
  std::size_t score_w = 5;
  for (const SeedRun& r : runs) {
    seed_w = std::max(seed_w, std::to_string(r.seed).size());
    score_w = std::max(score_w, r.score.size());
  }
  auto row = [&](const std::string& seed, const std::string& result, const std::string& score,
                 const std::string& time, const std::string& note) {
    std::string line = fmt::format("{:>{}}  {:<7}  {:<{}}  {:>10}  {}", seed, seed_w, result, score,
                                   score_w, time, note);
    while (!line.empty() && line.back() == ' ') line.pop_back();
    out << line << "\n";
  };
  row("seed", "result", "score", "game time", "error / why");
  std::vector<std::uint64_t> failed;
  for (const SeedRun& r : runs) {
    row(std::to_string(r.seed), outcome_name(r.result), r.score,
        fmt::format("{:.2f} s", r.game_time_s), first_line(r.error.empty() ? r.why : r.error));
    if (r.result != Outcome::kPass) failed.push_back(r.seed);
  }
  // Each warning once, with the seeds that gave it (in seed order).
  std::vector<std::pair<std::string, std::vector<std::uint64_t>>> warnings;
  for (const SeedRun& r : runs) {
    for (const std::string& w : r.warnings) {
      auto it = std::find_if(warnings.begin(), warnings.end(),
                             [&](const auto& x) { return x.first == w; });
      if (it == warnings.end()) {
        warnings.emplace_back(w, std::vector<std::uint64_t>{});
        it = std::prev(warnings.end());
      }
      it->second.push_back(r.seed);
    }
  }
  for (std::size_t i = 0; i < warnings.size() && i < kMaxWarnings; ++i) {
    out << fmt::format("warning  {} (seed(s) {})\n", first_line(warnings[i].first),
                       fmt::join(warnings[i].second, ", "));
  }
  if (warnings.size() > kMaxWarnings)
    out << fmt::format("warning  ... and {} more (--json lists each seed's)\n",
                       warnings.size() - kMaxWarnings);
  const std::size_t passed = runs.size() - failed.size();
  if (interrupted) {
    out << fmt::format("verdict  INTERRUPTED (Ctrl-C): {} of {} seed(s) played, {} passed\n",
                       runs.size(), asked, passed);
    return;
  }
  if (failed.empty()) {
    out << fmt::format("verdict  PASS {}/{}\n", passed, runs.size());
    return;
  }
  out << fmt::format("verdict  FAIL {}/{} passed, {} failed: seed(s) {}\n", passed, runs.size(),
                     failed.size(), fmt::join(failed, ", "));
  out << fmt::format("details  llsfsim exercise {} --skill {} --seed {}\n", ex.name, o.skill_file,
                     failed.front());
}

/// The sweep as one JSON object (the `--json` contract of docs/exercises.md).
void print_json(const Exercise& ex, const ExerciseOptions& o, const std::vector<SeedRun>& runs,
                bool interrupted, std::ostream& out) {
  using Json = nlohmann::ordered_json;
  const bool points = ex.goal.kind == Goal::Kind::kPoints;
  Json j;
  j["exercise"] = ex.name;
  j["skill"] = ex.skill;
  j["skill_file"] = o.skill_file;
  j["goal"] = goal_name(ex.goal.kind);
  j["better"] = points ? "higher" : "lower";
  Json list = Json::array();
  int passed = 0;
  for (const SeedRun& r : runs) {
    Json e;
    e["seed"] = r.seed;
    e["result"] = outcome_name(r.result);
    if (!r.value) {
      e["value"] = nullptr;
    } else if (points) {
      e["value"] = std::lround(*r.value);
    } else {
      e["value"] = *r.value;
    }
    e["score"] = r.score;
    e["why"] = r.why;
    e["error"] = r.error;
    e["hint"] = r.hint;
    e["warnings"] = r.warnings;
    e["game_time_s"] = std::round(r.game_time_s * 1000.0) / 1000.0;
    list.push_back(std::move(e));
    if (r.result == Outcome::kPass) ++passed;
  }
  j["runs"] = std::move(list);
  j["passed"] = passed;
  j["total"] = runs.size();
  j["verdict"] = interrupted ? "INTERRUPTED" : outcome_name(sweep_verdict(runs));
  // A participant's file may hold any bytes; invalid UTF-8 in a message becomes U+FFFD.
  out << j.dump(-1, ' ', false, Json::error_handler_t::replace) << "\n";
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
    err << "llsfsim exercise: no such skill file: " << o.skill_file
        << core::near_path_hint(o.skill_file) << "\n";
    return kExitBadInput;
  }
  // Which seeds: --seeds LIST is a sweep; else --seed N or the exercise's first.
  const bool sweep = !o.seeds.empty();
  std::vector<std::uint64_t> seeds;
  if (sweep) {
    try {
      seeds = study::parse_seed_list(o.seeds);
    } catch (const core::ConfigError& e) {
      err << "llsfsim exercise: " << e.what() << "\n";
      return kExitBadInput;
    }
    if (o.live.serve || o.live.pace() > 0.0 || !o.record.empty()) {
      err << "llsfsim exercise: --serve, --record, --realtime and --speed watch one game: give "
             "--seed N instead of --seeds\n";
      return kExitBadInput;
    }
  } else {
    seeds.push_back(o.seed.value_or(ex.scenario.seeds.front()));
  }
  if (o.json && o.live.serve) {
    err << "llsfsim exercise: --json prints only the JSON object; --serve does not go with it\n";
    return kExitBadInput;
  }

  // One game as it is played, or a sweep's table, or JSON.
  if (!sweep && !o.json) return play_seed(ex, o, seeds.front(), out, err).code;
  bool interrupted = false;
  const std::vector<SeedRun> runs = play_seeds(ex, o, seeds, err, interrupted);
  if (interrupted)
    err << fmt::format("llsfsim exercise: interrupted (Ctrl-C) after {} of {} seed(s)\n",
                       runs.size(), seeds.size());
  if (o.json) {
    print_json(ex, o, runs, interrupted, out);
  } else {
    print_sweep(ex, o, runs, interrupted, seeds.size(), out);
  }
  return interrupted ? kExitInterrupted : verdict_code(sweep_verdict(runs));
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
  auto* seed = app.add_option("--seed", o->seed, "Seed to play (default: the exercise's first)")
                   ->check(kSeed);
  auto* seeds =
      app.add_option("--seeds", o->seeds,
                     "Play these seeds and print a table and the verdict over them (PASS only when "
                     "every seed passes): a list of seeds and ranges, e.g. 1-20 or 3,5,9-12")
          ->excludes(seed);
  app.add_option("--jobs,-j", o->jobs,
                 "Games played at once by --seeds (default: the number of cores)")
      ->check(kPositive)
      ->needs(seeds);
  app.add_flag("--json", o->json,
               "Print only one JSON object on stdout: the exercise, each seed's result, value, "
               "score, error, hint and warnings, and the verdict (docs/exercises.md)");
  app.add_option("--exercises", o->root,
                 "Where the exercises are (default: $LLSF_EXERCISES_DIR, else exercises/ of the "
                 "data directory)");
  add_live_options(app, o->live,
                   "Serve the browser viewer with the game live at http://127.0.0.1:PORT/#/live "
                   "(best with --realtime or --speed)");
  app.add_option("--record", o->record,
                 "Also write the game's recording to FILE (gzip JSON lines)");
  app.add_flag("-q,--quiet", o->quiet,
               "Only the score, errors and the verdict (--seeds: no progress lines)");
  app.add_flag("--list", o->list, "List the exercises with their goals and exit");
  app.add_flag("--trace", o->trace,
               "Print each state change as FROM -> TO with the transition that made it and its "
               "file:line (every state a step passes through, also within one skill cycle); the "
               "recording's skill_state lines get it too (via)");
  app.footer(
      "Examples:\n"
      "  llsfsim exercise --list\n"
      "  cp exercises/01-drive-to-point/skill.lua my_drive.lua   # edit the TODOs\n"
      "  llsfsim exercise 01 --skill my_drive.lua\n"
      "  llsfsim exercise 04 --skill my_rescue.lua --seed 7 --realtime --serve\n"
      "  llsfsim exercise 01 --skill my_drive.lua --seeds 1-20        # all seeds, a table\n"
      "  llsfsim exercise 01 --skill my_drive.lua --seeds 1-20 --json # the same as JSON\n"
      "With --seeds, progress goes to stderr: a bar on a terminal, else one line per seed.\n"
      "Exit code: 0 PASS (with --seeds: every seed), 1 not passed (also a skill that fails, "
      "crashes or loops forever), 2 bad "
      "input (unknown exercise, missing file, a skill file that does not load), 3 internal error "
      "(a bug: please report it). docs/exercises.md");
  const std::shared_ptr<SubmitOptions> submit = add_submit_options(app);
  return [o, submit](std::ostream& out, std::ostream& err) {
    if (!submit->url.empty()) return submit_skill(*submit, o->exercise, o->skill_file, out, err);
    return run_exercise(*o, out, err);
  };
}

}  // namespace llsf::app
