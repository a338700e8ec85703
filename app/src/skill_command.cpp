// SPDX-License-Identifier: MIT
// `llsfsim skill`: the hackathon's first tool. Builds a fresh game (2013 field, refbox in the
// chosen phase), plugs the skill library into one robot and runs the given skill strings one
// after another, printing every status change with its simulated time stamp.
#include <fmt/format.h>
#include <llsf_msgs/GameState.pb.h>

#include <map>
#include <memory>
#include <ostream>
#include <string>
#include <vector>

#include "cli_checks.h"
#include "commands.h"
#include "llsf/app/cli.h"
#include "llsf/refbox/protocol.h"
#include "llsf/sim/game.h"
#include "llsf/sim/skill_brain.h"
#include "llsf/study/player.h"
#include "llsf/study/recording.h"

namespace llsf::app {

namespace {

using core::SimTime;

struct SkillOptions {
  std::vector<std::string> skill_strings;
  int robot = 1;
  int robots = 1;
  std::uint64_t seed = 1;
  std::string phase = "production";
  std::string level = "physical";
  std::string localization = "ground_truth";
  std::string light = "ground_truth";
  std::string puck = "ground_truth";
  std::vector<std::string> skill_dirs;
  std::vector<std::string> module_dirs;    ///< --modules: where require finds helper modules
  std::vector<std::string> cfg_dirs;       ///< --cfg: Fawkes' cfg directories (navgraphs)
  std::vector<std::string> fawkes_config;  ///< --fawkes-config /path=value
  std::string library_dir;
  double timeout_s = 300.0;
  double after_s = 0.0;
  std::string record;  ///< --record FILE: the game's recording
  bool trace = false;
  bool quiet = false;
  bool list = false;
};

std::string stamp(SimTime t) { return fmt::format("[{:8.2f} s]", t.seconds()); }

const char* status_name(lua::SkillStatus s) { return lua::to_string(s); }

refbox::GamePhase phase_of(const std::string& name) {
  static const std::map<std::string, refbox::GamePhase> phases{
      {"pre_game", refbox::GamePhase::kPreGame},
      {"setup", refbox::GamePhase::kSetup},
      {"exploration", refbox::GamePhase::kExploration},
      {"production", refbox::GamePhase::kProduction},
  };
  return phases.at(name);
}

void print_skills(const sim::SkillBrain& brain, std::ostream& out) {
  for (const lua::SkillInfo& s : brain.engine().skills()) {
    out << s.name << "  (" << s.path << ")\n";
    if (!s.load_error.empty()) {
      out << "  LOAD ERROR: " << s.load_error << "\n";
      continue;
    }
    std::string doc = s.documentation;
    while (!doc.empty() && doc.back() == '\n') doc.pop_back();
    std::size_t pos = 0;
    while (pos <= doc.size()) {
      const std::size_t nl = doc.find('\n', pos);
      out << "  " << doc.substr(pos, nl == std::string::npos ? std::string::npos : nl - pos)
          << "\n";
      if (nl == std::string::npos) break;
      pos = nl + 1;
    }
  }
}

int run_skill(const SkillOptions& o, std::ostream& out, std::ostream& err) {
  sim::GameConfig config;
  config.seed = o.seed;
  config.world.robots.resize(static_cast<std::size_t>(o.robots));
  config.levels.skill =
      o.level == "symbolic" ? sim::SkillLevel::kSymbolic : sim::SkillLevel::kPhysical;
  config.levels.localization.level = o.localization == "noisy"
                                         ? sim::LocalizationLevel::kNoisy
                                         : sim::LocalizationLevel::kGroundTruth;
  config.levels.light.level =
      o.light == "vision" ? sim::DetectionLevel::kVision : sim::DetectionLevel::kGroundTruth;
  config.levels.puck.level =
      o.puck == "vision" ? sim::DetectionLevel::kVision : sim::DetectionLevel::kGroundTruth;
  if (o.robot > o.robots) {
    err << "llsfsim skill: --robot " << o.robot << " but only " << o.robots
        << " robot(s) on the field (--robots)\n";
    return kExitBadInput;
  }
  // The game as a scenario without robot entries: the skill engine is plugged by hand.
  study::Scenario scenario;
  scenario.name = "skill";
  scenario.game = config;
  study::Player player(scenario, o.seed);
  sim::Game& game = player.game();
  const int index = o.robot - 1;

  lua::SkillEngineConfig ec;
  ec.skill_dirs = sim::skill_library_dirs(config.levels.skill, o.library_dir);
  for (const std::string& d : o.skill_dirs) ec.skill_dirs.push_back(d);
  ec.module_dirs = o.module_dirs;
  ec.cfg_dirs = o.cfg_dirs;
  for (const std::string& kv : o.fawkes_config) {
    const std::size_t eq = kv.find('=');
    if (eq == std::string::npos || eq == 0 || kv[0] != '/') {
      err << "llsfsim skill: --fawkes-config '" << kv
          << "': expected /path=value, e.g. /skills/take_puck_to/front_sensor_dist=0.05\n";
      return kExitBadInput;
    }
    ec.fawkes_config[kv.substr(0, eq)] = kv.substr(eq + 1);
  }
  sim::SkillBrain& brain = player.plug_skills(index, ec);
  if (o.list) {
    print_skills(brain, out);
    return kExitOk;
  }
  // A skill file that does not load is bad input (exit 2), as for `llsfsim exercise`.
  const std::vector<std::string> load_errors = brain.engine().load_errors();
  for (const std::string& e : load_errors) err << "skill file error: " << e << "\n";
  if (!load_errors.empty()) {
    err << "llsfsim skill: " << load_errors.size()
        << " skill file(s) do not load; fix them and run again (nothing was run)\n";
    return kExitBadInput;
  }

  // --record: the game as the viewer replays it, with the skill's states and log lines.
  std::unique_ptr<study::Recorder> recorder;
  if (!o.record.empty()) {
    try {
      recorder = std::make_unique<study::Recorder>(
          o.record, game, study::RecordingInfo{"skill", "", o.seed, std::string(core::kVersion)},
          10.0, study::LineSink{});
    } catch (const core::UserError& e) {  // the recording cannot be written
      err << "llsfsim skill: " << e.what() << "\n";
      return kExitBadInput;
    }
    brain.set_state_listener(
        [&recorder](const sim::SkillStateChange& c) { recorder->skill_state(c); });
  }

  const std::string robot_name(game.robot(index).name());
  brain.engine().set_log_sink([&](lua::LogLevel level, std::string_view text) {
    if (recorder) recorder->log(game.time(), robot_name, level, text);
    if (o.quiet && level < lua::LogLevel::kWarn) return;
    static const char* const names[] = {"debug", "info", "warn", "error"};
    out << stamp(game.time()) << " " << robot_name << " " << names[static_cast<int>(level)] << ": "
        << text << "\n";
  });
  brain.set_listener([&](const sim::SkillStatusChange& c) {
    if (recorder) recorder->skill(c);
    out << stamp(c.time) << " " << c.robot << " " << status_name(c.status) << "  "
        << c.skill_string;
    if (!c.result.empty()) out << "  -> " << c.result;
    if (!c.error.empty()) out << "\n             error: " << c.error;
    out << "\n";
  });

  // Trace: FSM state changes of every skill of the library.
  std::map<std::string, std::string> states;
  std::vector<std::string> names;
  for (const lua::SkillInfo& s : brain.engine().skills()) names.push_back(s.name);

  // After every tick: the recording's frame; while a skill string runs, the trace, and the end
  // of the string stops the game.
  bool in_string = false;
  player.observe([&recorder](const sim::Game& g) {
    if (recorder) recorder->frame(g);
    return false;
  });
  player.observe([&](const sim::Game&) {
    if (!in_string) return false;
    if (o.trace) {
      for (const std::string& n : names) {
        const std::string st = brain.engine().skill_state(n);
        std::string& last = states[n];
        if (st == last) continue;
        if (!st.empty())
          out << stamp(game.time()) << " " << robot_name << "   " << n << ": " << st << "\n";
        last = st;
      }
    }
    return brain.engine().status() != lua::SkillStatus::kRunning;
  });

  // The refbox: the chosen phase, running.
  player.start(o.phase == "pre_game" ? std::nullopt
                                     : std::optional<refbox::GamePhase>(phase_of(o.phase)));
  player.play_until(game.time() + SimTime::from_seconds(o.after_s));
  if (!o.quiet) {
    out << stamp(game.time()) << " game: seed " << o.seed << ", " << o.robots << " robot(s), "
        << o.phase << ", skills " << o.level << ", robot " << robot_name << "\n";
  }

  int code = kExitOk;
  for (const std::string& s : o.skill_strings) {
    const lua::ExecResult r = brain.exec(s);
    if (!r.ok) {
      err << "llsfsim skill: " << r.error << "\n";
      return kExitBadInput;
    }
    const SimTime end = game.time() + SimTime::from_seconds(o.timeout_s);
    if (brain.engine().status() == lua::SkillStatus::kRunning) {
      in_string = true;
      player.play_until(end);
      in_string = false;
    }
    if (brain.engine().status() == lua::SkillStatus::kRunning) {
      out << stamp(game.time()) << " " << robot_name << " TIMEOUT  " << s << " still running after "
          << o.timeout_s << " s\n";
      brain.engine().stop();
      code = kExitFailed;
      break;
    }
    if (brain.engine().status() == lua::SkillStatus::kFailed) {
      code = kExitFailed;
      break;
    }
  }
  if (recorder) recorder->close();  // throws if the file could not be finished
  const sim::GameSummary sum = game.summary();
  if (!o.quiet) {
    const auto held = game.puck_in_pocket(index);
    out << stamp(game.time()) << " end: " << sum.points << " points (production "
        << sum.production_points << ", exploration " << sum.exploration_points << "), holder: ";
    if (held) {
      const auto state = game.refbox().puck_state(*held);
      out << "puck " << held->value() << " ("
          << (state ? refbox::to_string(*state) : std::string_view("unknown")) << ")";
    } else {
      out << "empty";
    }
    out << ", collisions "
        << (sum.collisions_robot_device + sum.collisions_robot_wall + sum.collisions_robot_robot)
        << "\n";
  }
  return code;
}

}  // namespace

Action add_skill_command(CLI::App& app) {
  auto o = std::make_shared<SkillOptions>();
  app.footer(
      "Examples:\n"
      "  llsfsim skill 'get_s0{}' 'finish_puck_at{place=\"M3\"}'\n"
      "  llsfsim skill --level symbolic --trace 'explore_machine{place=\"M5\"}' --phase "
      "exploration\n"
      "  llsfsim skill --skills my_skills 'my_first_skill{}'\n"
      "  llsfsim skill --list\n"
      "Status lines: [game time] robot STATUS skill-string  -> result; the skill library is "
      "documented in docs/skills.md.\n"
      "Exit code: 0 every skill succeeded, 1 one failed (also: stopped by a budget of the "
      "sandbox), 2 bad input (options, skill string, a skill file that does not load), 3 "
      "internal error (a bug: please report it).");
  app.add_option("skill_strings", o->skill_strings,
                 "Skill strings to run in turn, e.g. 'drive_to{place=\"M3\"}'; stops at the "
                 "first failure");
  app.add_option("--robot", o->robot, "Which robot runs the skills (1-based)")
      ->capture_default_str()
      ->check(CLI::Range(1, 3));
  app.add_option("--robots", o->robots, "Robots on the field (the others stand still)")
      ->capture_default_str()
      ->check(CLI::Range(1, 3));
  app.add_option("--seed", o->seed, "Scenario seed (game plan, noise)")
      ->capture_default_str()
      ->check(kSeed);
  app.add_option("--phase", o->phase, "Refbox phase to run in")
      ->capture_default_str()
      ->check(CLI::IsMember({"pre_game", "setup", "exploration", "production"}));
  app.add_option("--level", o->level, "Skill level: physical (drive) or symbolic (estimate)")
      ->capture_default_str()
      ->check(CLI::IsMember({"physical", "symbolic"}));
  app.add_option("--localization", o->localization, "Localization level")
      ->capture_default_str()
      ->check(CLI::IsMember({"ground_truth", "noisy"}));
  app.add_option("--light", o->light, "Light-signal detection level")
      ->capture_default_str()
      ->check(CLI::IsMember({"ground_truth", "vision"}));
  app.add_option("--puck", o->puck, "Puck detection level")
      ->capture_default_str()
      ->check(CLI::IsMember({"ground_truth", "vision"}));
  app.add_option("--skills", o->skill_dirs,
                 "Extra skill directory (repeatable); its skills replace library skills of the "
                 "same name")
      ->check(CLI::ExistingDirectory)
      ->allow_extra_args(false);  // one directory per --skills: skill strings follow
  app.add_option("--modules", o->module_dirs,
                 "Directory where require() finds Lua helper modules besides the skill "
                 "directories (repeatable; skills written for Fawkes: docs/fawkes.md)")
      ->check(CLI::ExistingDirectory)
      ->allow_extra_args(false);
  app.add_option("--cfg", o->cfg_dirs,
                 "Fawkes cfg directory where fawkes.load_yaml_navgraph finds navgraph files "
                 "(repeatable)")
      ->check(CLI::ExistingDirectory)
      ->allow_extra_args(false);
  app.add_option("--fawkes-config", o->fawkes_config,
                 "A Fawkes configuration value skills read with config:get_*(path), as "
                 "/path=value (repeatable)")
      ->allow_extra_args(false);
  app.add_option("--library", o->library_dir,
                 "The skill library directory (default: lua/skills of the data directory)")
      ->check(CLI::ExistingDirectory);
  app.add_option("--timeout", o->timeout_s, "Seconds of game time each skill string may run")
      ->capture_default_str()
      ->check(kPositive);
  app.add_option("--after", o->after_s, "Seconds of game time to play before the first string")
      ->capture_default_str()
      ->check(kNonNegative);
  app.add_flag("--trace", o->trace, "Also print every state change of every skill's FSM");
  app.add_option("--record", o->record,
                 "Also write the game's recording to FILE (gzip JSON lines: poses, events, the "
                 "skill's states and log lines); replay it with llsfsim serve --recordings DIR "
                 "at http://127.0.0.1:8080/#/file/FILE");
  app.add_flag("-q,--quiet", o->quiet, "Only status changes, warnings and errors");
  app.add_flag("--list", o->list, "List the skills with their documentation and exit");
  return [o](std::ostream& out, std::ostream& err) {
    if (o->skill_strings.empty() && !o->list) {
      err << "llsfsim skill: give a skill string, e.g. llsfsim skill 'get_s0{}' (or --list)\n";
      return kExitBadInput;
    }
    return run_skill(*o, out, err);
  };
}

}  // namespace llsf::app
