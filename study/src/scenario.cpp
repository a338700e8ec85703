// SPDX-License-Identifier: MIT
#include "llsf/study/scenario.h"

#include <algorithm>
#include <array>
#include <charconv>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string_view>
#include <system_error>
#include <utility>
#include <vector>

#include "llsf/comm/hub_config.h"
#include "llsf/comm/proto_library.h"
#include "llsf/core/error.h"
#include "llsf/core/input_file.h"
#include "llsf/kinematic/world_config.h"
#include "llsf/planner/config.h"
#include "llsf/refbox/config.h"
#include "llsf/sim/hackathon_extension.h"
#include "llsf/study/profile.h"

namespace llsf::study {

namespace {

namespace fs = std::filesystem;

/// A hackathon run's length unless `duration_s` says otherwise.
constexpr core::SimTime kHackathonDefaultDuration = core::SimTime::from_sec(300);

std::string read_text(const std::string& path) {
  return core::read_input_file(path, core::kMaxSourceBytes, "scenario file");
}

/// A path of the scenario, relative to its directory unless absolute.
std::string resolve(const std::string& dir, const std::string& p) {
  const fs::path path(p);
  if (path.is_absolute() || dir.empty()) return path.lexically_normal().string();
  return (fs::path(dir) / path).lexically_normal().string();
}

std::vector<std::string> string_list(const core::ConfigNode& n) {
  std::vector<std::string> out;
  if (n.is_scalar()) {
    out.push_back(n.as_string());
    return out;
  }
  if (!n.is_sequence()) n.fail("expected a string or a list of strings");
  for (const core::ConfigNode& e : n.elements()) out.push_back(e.as_string());
  return out;
}

void read_levels(const core::ConfigNode& n, sim::RobotLevelsConfig& l) {
  if (!n.defined()) return;
  n.require_map();
  n.read_enum("localization", l.localization.level,
              {{"ground_truth", sim::LocalizationLevel::kGroundTruth},
               {"noisy", sim::LocalizationLevel::kNoisy}},
              "localization level");
  n.read_enum("light", l.light.level,
              {{"ground_truth", sim::DetectionLevel::kGroundTruth},
               {"vision", sim::DetectionLevel::kVision}},
              "detection level");
  n.read_enum("light_view", l.light.view,
              {{"front", sim::LightView::kFront}, {"laser_cluster", sim::LightView::kLaserCluster}},
              "light view");
  n.read_enum("puck", l.puck.level,
              {{"ground_truth", sim::DetectionLevel::kGroundTruth},
               {"vision", sim::DetectionLevel::kVision}},
              "detection level");
  n.read_enum("skill", l.skill,
              {{"physical", sim::SkillLevel::kPhysical}, {"symbolic", sim::SkillLevel::kSymbolic}},
              "skill level");
  n.read_enum("navigation", l.navigation,
              {{"ideal", sim::NavigationLevel::kIdeal},
               {"move_base-2013", sim::NavigationLevel::kMoveBase2013}},
              "navigation level");
  // Bounds: docs/security.md, "Scenario budgets".
  n.read("position_noise_m", l.localization.position_noise_m, core::in_range(0.0, 1.0));
  n.read("heading_noise_rad", l.localization.heading_noise_rad, core::in_range(0.0, core::kPi));
  n.read("light_error_rate", l.light.error_rate, core::probability());
  if (const core::ConfigNode delay = n["light_delay_s"]; delay.defined()) {
    l.light.delay = core::SimTime::from_seconds(delay.as_double(core::in_range(0.0, 60.0)));
  }
  n.read("cruise_speed_mps", l.symbolic.cruise_speed_mps, core::in_range(0.01, 10.0));
  n.no_other_keys();
}

void read_rates(const core::ConfigNode& n, sim::GameConfig& g) {
  if (!n.defined()) return;
  n.require_map();
  using L = ScenarioLimits;  // the bounds' reasons: docs/security.md, "Scenario budgets"
  double physics_hz = 0.0;   // 0: not given
  n.read("physics_hz", physics_hz, core::in_range(L::kMinPhysicsHz, L::kMaxPhysicsHz));
  if (physics_hz > 0.0) g.world.physics.step = core::SimTime::period_of_hz(physics_hz);
  n.read("skill_hz", g.skill_rate_hz, core::in_range(L::kMinCycleHz, L::kMaxPhysicsHz));
  n.read("agent_hz", g.agent_rate_hz, core::in_range(L::kMinCycleHz, L::kMaxPhysicsHz));
  double beacon_period_s = 0.0;  // 0: not given
  n.read("beacon_period_s", beacon_period_s,
         core::in_range(L::kMinBeaconPeriodS, L::kMaxBeaconPeriodS));
  if (beacon_period_s > 0.0) g.beacon_period = core::SimTime::from_seconds(beacon_period_s);
  n.no_other_keys();
}

std::vector<std::uint64_t> read_seeds(const core::ConfigNode& root) {
  const core::ConfigNode seed = root["seed"];
  const core::ConfigNode seeds = root["seeds"];
  if (seed.defined() && seeds.defined()) seeds.fail("give either 'seed' or 'seeds', not both");
  auto one = [](const core::ConfigNode& n) {
    return static_cast<std::uint64_t>(n.as_int(core::non_negative()));
  };
  if (seed.defined()) return {one(seed)};
  if (!seeds.defined()) return {1};
  std::vector<std::uint64_t> out;
  if (seeds.is_map()) {
    std::uint64_t first = 1;
    if (const core::ConfigNode f = seeds["first"]; f.defined()) first = one(f);
    const std::int64_t count =
        seeds.at("count").as_int(core::in_range(1, static_cast<double>(ScenarioLimits::kMaxSeeds)));
    seeds.no_other_keys();
    for (std::int64_t i = 0; i < count; ++i) out.push_back(first + static_cast<std::uint64_t>(i));
    return out;
  }
  if (!seeds.is_sequence() || seeds.size() == 0)
    seeds.fail("expected a list of seeds or {first, count}");
  if (seeds.size() > ScenarioLimits::kMaxSeeds) {
    seeds.fail("a list of " + std::to_string(seeds.size()) + " seeds: at most " +
               std::to_string(ScenarioLimits::kMaxSeeds) + " (docs/security.md)");
  }
  for (const core::ConfigNode& e : seeds.elements()) out.push_back(one(e));
  return out;
}

void merge_config(clips::ConfigEntries& into, const clips::ConfigEntries& over) {
  for (const clips::ConfigEntry& e : over) {
    std::erase_if(into, [&](const clips::ConfigEntry& x) { return x.path == e.path; });
    into.push_back(e);
  }
}

/// Whether the directory `dir` holds a regular `*.clp` file (what an agent directory loads).
bool has_clp_file(const std::string& dir) {
  std::error_code ec;
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
    std::error_code file_ec;
    if (it->path().extension() == ".clp" && it->is_regular_file(file_ec)) return true;
  }
  return false;
}

// " (did you mean 'NEAR'?)" for a missing path `rel` (as the scenario wrote it; `looked` is where
// it was looked for): the near name of that folder, written as the scenario would write it.
std::string near_hint(const std::string& rel, const std::string& looked) {
  const std::optional<std::string> m = core::near_path(looked);
  if (!m) return "";
  const fs::path meant = fs::path(rel).parent_path() / fs::path(*m).filename();
  return " (did you mean '" + meant.string() + "'?)";
}

std::vector<std::string> read_agent(const core::ConfigNode& n, const std::string& dir) {
  std::vector<std::string> out;
  const std::vector<std::string> entries = string_list(n);
  for (std::size_t i = 0; i < entries.size(); ++i) {
    const std::string p = resolve(dir, entries[i]);
    std::error_code ec;
    const core::ConfigNode at = n.is_sequence() ? n.at(static_cast<int>(i)) : n;
    if (!fs::exists(p, ec)) {
      at.fail("agent file or directory '" + entries[i] + "' not found (looked at " + p + ")" +
              near_hint(entries[i], p));
    }
    if (fs::is_directory(p, ec) && !has_clp_file(p)) {
      at.fail("agent directory '" + entries[i] + "' has no .clp files (looked at " + p + ")");
    }
    out.push_back(p);
  }
  return out;
}

// A path inside `root` (relative to it), or a failure at `at`.
std::string inside(const core::ConfigNode& at, const std::string& root, const std::string& rel,
                   const char* what) {
  std::error_code ec;
  const fs::path r = fs::weakly_canonical(root, ec);
  const fs::path p = fs::weakly_canonical(r / rel, ec);
  const auto [end, it] = std::mismatch(r.begin(), r.end(), p.begin(), p.end());
  if (ec || end != r.end() || fs::path(rel).is_absolute()) {
    at.fail(std::string(what) + " '" + rel + "' is outside the agent directory " + r.string() +
            " (an agent reads only its own directory: docs/security.md)");
  }
  if (!fs::exists(p, ec))
    at.fail(std::string(what) + " '" + rel + "' not found (looked at " + p.string() + ")" +
            near_hint(rel, p.string()));
  return p.string();
}

// robots.agent as a map: a Fawkes-style agent {fawkes: DIR, entry: FILE, protos: [DIRS]}.
void read_fawkes_agent(const core::ConfigNode& n, const std::string& dir, RobotSpec& spec) {
  const core::ConfigNode d = n.at("fawkes");
  spec.agent_dir = resolve(dir, d.as_string());
  std::error_code ec;
  if (!fs::is_directory(spec.agent_dir, ec)) {
    d.fail("agent directory '" + d.as_string() + "' not found (looked at " + spec.agent_dir + ")" +
           near_hint(d.as_string(), spec.agent_dir));
  }
  const core::ConfigNode e = n.at("entry");
  std::string entry = e.as_string();
  if (!entry.ends_with(".clp")) entry += ".clp";  // as Fawkes' /clips-agent/agent
  spec.agent = {inside(e, spec.agent_dir, entry, "entry file")};
  spec.proto_dirs.clear();
  if (const core::ConfigNode p = n["protos"]; p.defined()) {
    const std::vector<std::string> dirs = string_list(p);
    for (std::size_t i = 0; i < dirs.size(); ++i) {
      const core::ConfigNode at = p.is_sequence() ? p.at(static_cast<int>(i)) : p;
      spec.proto_dirs.push_back(inside(at, spec.agent_dir, dirs[i], "proto directory"));
    }
  }
  n.no_other_keys();
  spec.fawkes = true;
  std::erase_if(spec.config,
                [](const clips::ConfigEntry& c) { return c.path == "/clips-agent/agent"; });
  spec.config.push_back(
      clips::ConfigEntry::of("/clips-agent/agent", entry.substr(0, entry.size() - 4)));
}

// robots.agent / each[i].agent: files and directories, or a Fawkes-style agent (a map).
void read_agent_spec(const core::ConfigNode& n, const std::string& dir, RobotSpec& spec) {
  if (n.is_map()) return read_fawkes_agent(n, dir, spec);
  spec.agent = read_agent(n, dir);
  spec.fawkes = false;
  spec.agent_dir.clear();
  spec.proto_dirs.clear();
}

void read_robots(const core::ConfigNode& n, const std::string& dir, Scenario& s) {
  int count = static_cast<int>(s.game.world.robots.size());
  RobotSpec common;
  core::ConfigNode agent_node;
  clips::ConfigEntries config;
  bool locks = false;
  bool sandbox = true;
  core::ConfigNode each;
  if (n.defined()) {
    n.require_map();
    if (const core::ConfigNode c = n["count"]; c.defined()) {
      const std::int64_t v = c.as_int();
      if (v < 1 || v > static_cast<std::int64_t>(s.game.world.robots.size())) {
        c.fail("must be in 1.." + std::to_string(s.game.world.robots.size()) +
               " (the robots of the world)");
      }
      count = static_cast<int>(v);
    }
    if (const core::ConfigNode c = n["config"]; c.defined()) {
      c.require_map();
      config = clips::config_from_node(c, "/clips-agent");
    }
    common.config = config;
    agent_node = n["agent"];
    if (agent_node.defined()) read_agent_spec(agent_node, dir, common);
    n.read("locks", locks);
    n.read("sandbox", sandbox);
    each = n["each"];
    n.no_other_keys();
  }
  common.locks = locks;
  common.sandbox = sandbox;
  s.game.world.robots.resize(static_cast<std::size_t>(count));
  s.robots.assign(static_cast<std::size_t>(count), common);
  if (!each.defined()) return;
  if (!each.is_sequence()) each.fail("expected a list with one entry per robot");
  if (each.size() > count) each.fail("more entries than robots (" + std::to_string(count) + ")");
  for (int i = 0; i < each.size(); ++i) {
    const core::ConfigNode r = each.at(i);
    if (r.is_null()) continue;
    r.require_map();
    RobotSpec& spec = s.robots[static_cast<std::size_t>(i)];
    if (const core::ConfigNode c = r["config"]; c.defined()) {
      c.require_map();
      merge_config(spec.config, clips::config_from_node(c, "/clips-agent"));
    }
    if (const core::ConfigNode a = r["agent"]; a.defined()) read_agent_spec(a, dir, spec);
    if (const core::ConfigNode a = r["agent_start_s"]; a.defined()) {
      spec.agent_start = core::SimTime::from_seconds(a.as_double(core::in_range(0.0, 3600.0)));
    }
    kinematic::RobotStart& start = s.game.world.robots[static_cast<std::size_t>(i)];
    r.read("name", start.name);
    r.read("jersey", start.jersey);
    if (const core::ConfigNode p = r["start"]; p.defined()) {
      p.require_map();
      double x = start.pose.x, y = start.pose.y, ori = start.pose.theta * 180.0 / core::kPi;
      p.read("x", x, core::in_range(-1000.0, 1000.0));  // metres; the world checks the field
      p.read("y", y, core::in_range(-1000.0, 1000.0));
      p.read("ori_deg", ori, core::in_range(-360.0, 360.0));
      p.no_other_keys();
      start.pose = {x, y, ori * core::kPi / 180.0};
    }
    r.no_other_keys();
  }
}

// Fawkes-style agents: their host has no lock protocol (they bring their own lock.clp), and
// their own .proto files are loaded once per directory list (game.agent_protos).
void read_fawkes_protos(const core::ConfigNode& robots, Scenario& s) {
  std::map<std::vector<std::string>, std::shared_ptr<const comm::ProtoLibrary>> loaded;
  for (const RobotSpec& spec : s.robots) {
    if (!spec.fawkes) continue;
    if (spec.locks) {
      robots["locks"].fail(
          "the host's lock protocol is off for a Fawkes-style agent, which brings its own (a "
          "lock.clp with its own lock template and messages): remove robots.locks "
          "(docs/fawkes.md)");
    }
    if (spec.proto_dirs.empty() || loaded.contains(spec.proto_dirs)) continue;
    try {
      loaded[spec.proto_dirs] = comm::ProtoLibrary::load(spec.proto_dirs);
    } catch (const core::ConfigError& e) {
      robots["agent"].fail(std::string("the agent's .proto files: ") + e.what());
    }
  }
  for (auto& [dirs, lib] : loaded) s.game.agent_protos.push_back(lib);
}

void read_tests(const core::ConfigNode& n, Scenario& s) {
  if (!n.defined()) return;
  if (!n.is_sequence()) n.fail("expected a list of test cases");
  for (const core::ConfigNode& t : n.elements()) {
    t.require_map();
    TestCase tc;
    int kinds = 0;
    // The conditions: one per metric with a test case (the metric table, metrics.h), and
    // no_agent_errors.
    for (const Metric& m : metrics()) {
      if (m.test_key.empty()) continue;
      const core::ConfigNode c = t[std::string(m.test_key).c_str()];
      if (!c.defined()) continue;
      ++kinds;
      tc.metric = &m;
      tc.value = c.as_double(core::non_negative());
    }
    if (const core::ConfigNode c = t["no_agent_errors"]; c.defined()) {
      ++kinds;
      tc.metric = nullptr;
      if (!c.as_bool()) c.fail("only 'true' makes sense");
    }
    const core::ConfigNode by = t["by_s"];
    const core::ConfigNode name = t["name"];
    t.no_other_keys();  // before the condition count: a misspelt condition is the likely cause
    if (kinds != 1) t.fail("a test case needs exactly one condition (e.g. points_at_least: 30)");
    if (by.defined()) {
      if (tc.metric == nullptr || !tc.metric->test_by_s) {
        std::string with;
        for (const Metric& m : metrics()) {
          if (m.test_by_s) with += (with.empty() ? "" : " and ") + std::string(m.test_key);
        }
        by.fail("by_s works with " + with);
      }
      tc.by_s = by.as_double(core::positive());
      const double duration_s = static_cast<double>(s.duration.ns()) / 1e9;
      if (*tc.by_s > duration_s) {
        by.fail("must be at most the game's duration " + core::number_text(duration_s) +
                " s (got " + core::number_text(*tc.by_s) + "): the game ends before");
      }
    }
    tc.name = name.defined() ? name.as_string() : describe(tc);
    s.tests.push_back(std::move(tc));
  }
}

/// The node at `dotted` ("rates.skill_hz") if the document has it.
std::optional<core::ConfigNode> find_key(const core::ConfigNode& root, std::string_view dotted) {
  core::ConfigNode n = root;
  while (!dotted.empty()) {
    const std::size_t dot = dotted.find('.');
    if (!n.is_map()) return std::nullopt;
    n = n[dotted.substr(0, dot)];
    if (!n.defined()) return std::nullopt;
    dotted = dot == std::string_view::npos ? std::string_view() : dotted.substr(dot + 1);
  }
  return n;
}

/// The scenario keys that set a field GameConfig::validate() names, most specific first; a
/// field is matched by prefix ("game.levels." covers every level field).
struct GameFieldKeys {
  std::string_view field;
  std::array<std::string_view, 3> keys;
};
constexpr GameFieldKeys kGameFieldKeys[] = {
    {"game.levels.localization.position_noise_m", {"levels.position_noise_m", "profile"}},
    {"game.levels.localization.heading_noise_rad", {"levels.heading_noise_rad", "profile"}},
    {"game.levels.light.error_rate", {"levels.light_error_rate", "profile"}},
    {"game.levels.light.delay", {"levels.light_delay_s", "profile"}},
    {"game.levels.symbolic.cruise_speed_mps", {"levels.cruise_speed_mps"}},
    {"game.levels.", {"levels", "profile"}},
    {"game.skill_rate_hz", {"rates.skill_hz", "rates.physics_hz", "world.physics.step_ms"}},
    {"game.agent_rate_hz", {"rates.agent_hz", "rates.physics_hz", "world.physics.step_ms"}},
    {"game.beacon_period", {"rates.beacon_period_s"}},
    {"game.referee_remove_delay", {"referee.remove_delay_s"}},
    {"game.handling.", {"profile"}},
    {"game.hackathon", {"hackathon"}},
    {"physics.", {"rates.physics_hz", "world.physics", "world"}},
};

/// The node of a world.validate() error about a robot ("robots[1].jersey: duplicate ...",
/// "robots[0]: ... is outside the field") if the scenario sets that robot in `robots.each`:
/// the key named, else its start pose for a position, else the entry.
std::optional<core::ConfigNode> robot_error_node(const core::ConfigNode& root,
                                                 std::string_view what) {
  if (!what.starts_with("robots[")) return std::nullopt;
  const std::size_t close = what.find(']');
  if (close == std::string_view::npos) return std::nullopt;
  int index = -1;
  const std::string_view digits = what.substr(7, close - 7);
  if (std::from_chars(digits.data(), digits.data() + digits.size(), index).ec != std::errc()) {
    return std::nullopt;
  }
  const std::optional<core::ConfigNode> each = find_key(root, "robots.each");
  if (!each || !each->is_sequence() || index < 0 || index >= each->size()) return std::nullopt;
  const core::ConfigNode entry = each->at(index);
  if (!entry.is_map()) return entry;
  std::string_view rest = what.substr(close + 1);
  if (rest.starts_with('.')) {
    rest.remove_prefix(1);
    const std::string_view field = rest.substr(0, rest.find_first_of(".:["));
    if (const core::ConfigNode n = entry[field]; n.defined()) return n;
  } else if (what.find("outside the field") != std::string_view::npos ||
             what.find("overlaps") != std::string_view::npos) {
    if (const core::ConfigNode n = entry["start"]; n.defined()) return n;
  }
  return entry;
}

/// Throws GameConfig::validate()'s error `e` ("game.skill_rate_hz: must not exceed ...") at the
/// scenario key that set the field, or at the top level if the document has none of its keys.
[[noreturn]] void fail_at_game_key(const core::ConfigNode& root, const core::ConfigError& e) {
  const std::string_view what = e.what();
  // The hackathon's own errors name its keys ("hackathon.colours: no free spot ..."): the
  // deepest of them the document has.
  const std::size_t colon = what.find(": ");
  const std::string reason(colon == std::string_view::npos ? what : what.substr(colon + 2));
  const std::string field(what.substr(0, colon));
  std::string_view key = field;
  if (key.starts_with("game.")) key.remove_prefix(5);
  while (key.starts_with("hackathon")) {
    if (const std::optional<core::ConfigNode> n = find_key(root, key)) {
      n->fail(reason + " (" + field + ")");
    }
    const std::size_t dot = key.rfind('.');
    if (dot == std::string_view::npos) break;
    key = key.substr(0, dot);
  }
  if (const std::optional<core::ConfigNode> n = robot_error_node(root, what)) {
    n->fail(reason + " (" + field + ")");
  }
  for (const GameFieldKeys& f : kGameFieldKeys) {
    if (!what.starts_with(f.field)) continue;
    for (const std::string_view k : f.keys) {
      if (k.empty()) continue;
      if (const std::optional<core::ConfigNode> n = find_key(root, k)) {
        n->fail(reason + " (" + field + ")");
      }
    }
  }
  root.fail("the game config is invalid: " + std::string(what));
}

/// duration / physics step within ScenarioLimits::kMaxPhysicsSteps, failing at the key that
/// made it too many: the physics rate, the world's step or the duration.
void check_physics_steps(const core::ConfigNode& root, const Scenario& s) {
  const std::int64_t step = s.game.world.physics.step.ns();
  if (step <= 0) return;  // GameConfig::validate() says it
  const std::int64_t steps = s.duration.ns() / step;
  if (steps <= ScenarioLimits::kMaxPhysicsSteps) return;
  const std::string why = "the game would take " + std::to_string(steps) + " physics steps (" +
                          core::number_text(static_cast<double>(s.duration.ns()) / 1e9) + " s at " +
                          core::number_text(1e9 / static_cast<double>(step)) + " Hz); at most " +
                          std::to_string(ScenarioLimits::kMaxPhysicsSteps) +
                          " (docs/security.md, \"Scenario budgets\")";
  for (const std::string_view key : {"rates.physics_hz", "world.physics.step_ms", "duration_s"}) {
    if (const std::optional<core::ConfigNode> n = find_key(root, key)) n->fail(why);
  }
  root.fail(why);
}

Scenario read_scenario(const core::ConfigNode& root, const std::string& file) {
  root.require_map();
  const std::string dir = fs::path(file).parent_path().string();
  Scenario s;
  s.file = file;
  const core::ConfigNode name = root.at("name");
  s.name = name.as_string();
  if (s.name.empty()) name.fail("must not be empty");
  root.read("description", s.description);
  s.seeds = read_seeds(root);
  if (const core::ConfigNode n = root["refbox"]; n.defined()) {
    // The teams the refbox knows (GameInfo.known_teams: the 2013 shell's team menu), as
    // 0.6.1's llsfrb/game/teams; the protocol's, not the engine's, so read here.
    if (n.is_map() && n["known_teams"].defined()) {
      const core::ConfigNode teams = n["known_teams"];
      if (!teams.is_sequence()) teams.fail("a list of team names, e.g. [Carologistics, Solidus]");
      constexpr int kMaxTeams = 64;
      if (teams.size() > kMaxTeams) {
        teams.fail("at most " + std::to_string(kMaxTeams) + " teams (got " +
                   std::to_string(teams.size()) + ")");
      }
      for (const core::ConfigNode& t : teams.elements()) {
        std::string team = t.as_string();
        if (team.empty() || team.size() > 64) t.fail("a team name has 1 to 64 characters");
        if (std::find(s.game.protocol.known_teams.begin(), s.game.protocol.known_teams.end(),
                      team) != s.game.protocol.known_teams.end()) {
          t.fail("'" + team + "' is listed twice");
        }
        s.game.protocol.known_teams.push_back(std::move(team));
      }
    }
    s.game.refbox = refbox::load_refbox_config(n);
  }
  // The robot profile first: world, navigation and levels keys override its figures.
  RobotProfile profile;
  if (const core::ConfigNode n = root["profile"]; n.defined()) profile = load_profile(n);
  profile.apply(s.game, s.skills);
  if (const core::ConfigNode n = root["world"]; n.defined()) {
    s.game.world = kinematic::load_world_config(n, s.game.world);
  }
  if (const core::ConfigNode n = root["radio"]; n.defined()) s.game.hub = comm::load_hub_config(n);
  if (const core::ConfigNode n = root["navigation"]; n.defined()) {
    planner::NavigationConfig nav{s.game.planner, s.game.controller};
    nav = planner::load_navigation_config(n, nav);
    s.game.planner = nav.planner;
    s.game.controller = nav.controller;
  }
  read_levels(root["levels"], s.game.levels);
  read_rates(root["rates"], s.game);
  root.read("team", s.game.team);
  root.read("strict", s.strict);
  if (const core::ConfigNode n = root["referee"]; n.defined()) {
    n.require_map();
    if (const core::ConfigNode d = n["remove_delay_s"]; d.defined()) {
      s.game.referee_remove_delay =
          core::SimTime::from_seconds(d.as_double(core::in_range(0.0, 60.0)));
    }
    n.no_other_keys();
  }
  if (const core::ConfigNode n = root["hackathon"]; n.defined()) {
    sim::set_hackathon(s.game, sim::load_hackathon_config(n, s.game.world));
    s.start = StartMode::kNone;
  }
  root.read_enum("start", s.start,
                 {{"game", StartMode::kGame},
                  {"exploration", StartMode::kExploration},
                  {"production", StartMode::kProduction},
                  {"none", StartMode::kNone}},
                 "start mode");
  const refbox::RefboxConfig& rb = s.game.refbox;
  double duration = rb.production_duration.seconds();
  if (s.start != StartMode::kProduction) duration += rb.exploration_duration.seconds();
  if (s.start == StartMode::kGame && !rb.team.empty() && !rb.skip_setup) {
    duration += rb.setup_duration.seconds();
  }
  if (sim::hackathon_config(s.game) != nullptr) duration = kHackathonDefaultDuration.seconds();
  root.read("duration_s", duration,
            core::in_range(ScenarioLimits::kMinDurationS, ScenarioLimits::kMaxDurationS));
  s.duration = core::SimTime::from_seconds(duration);
  check_physics_steps(root, s);
  read_robots(root["robots"], dir, s);
  read_fawkes_protos(root["robots"], s);
  if (const core::ConfigNode n = root["skills"]; n.defined()) {
    s.skills = lua::SkillEngineConfig::from_config(n, dir);  // dirs relative to the file
    s.skills.profile = profile.name;
    s.skills.stuck_detection = profile.stuck_detection;
    s.skills.motions = profile.motions;
  }
  read_tests(root["tests"], s);
  // `matrix` is read by the callers (load_scenario, read_scenario_map) on this document.
  root.no_other_keys();
  s.game.seed = s.seeds.front();
  try {
    s.game.validate();
  } catch (const core::ConfigError& e) {
    fail_at_game_key(root, e);
  }
  if (sim::hackathon_config(s.game) != nullptr) {
    // The layout of the first seed: pucks that find no free spot are an error of the file.
    try {
      (void)sim::prepare_game_config(s.game);
    } catch (const core::ConfigError& e) {
      fail_at_game_key(root, e);
    }
  }
  return s;
}

}  // namespace

std::string describe(const TestCase& t) {
  std::ostringstream ss;
  if (t.metric == nullptr) {
    ss << "no agent runtime errors";
  } else {
    // The metric's condition text ("<= {} collisions") with the limit as a stream prints it.
    std::ostringstream limit;
    limit << t.value;
    const std::string_view need = t.metric->test_need;
    const std::size_t field = need.find("{}");
    ss << need.substr(0, field) << limit.str()
       << (field == std::string_view::npos ? std::string_view() : need.substr(field + 2));
  }
  if (t.by_s) ss << " by " << *t.by_s << " s";
  return ss.str();
}

Scenario read_scenario_map(const core::ConfigNode& root, const std::string& file) {
  root.require_map();
  if (root["matrix"].defined()) root["matrix"].fail("a matrix is not allowed here");
  return read_scenario(root, file);
}

ScenarioFile load_scenario(const std::string& path) {
  const std::string text = read_text(path);
  // A test hook, not for users: a deliberate bug (std::logic_error) when LLSF_TEST_INTERNAL_ERROR
  // is set, so that tests/app/exit_code_test.cpp sees llsfsim tell a bug (exit code 3) from bad
  // input (2) through every command that loads a scenario.
  if (const char* hook = std::getenv("LLSF_TEST_INTERNAL_ERROR"); hook != nullptr && *hook != 0) {
    throw std::logic_error("LLSF_TEST_INTERNAL_ERROR is set (a test hook)");
  }
  ScenarioFile out;
  out.file = path;
  const core::ConfigNode first = core::ConfigNode::parse(text, path);
  // An experiment file (docs/experiments.md) given where a scenario is expected: say so, not
  // "unknown key 'batches'".
  // (By its keys: looking a key up would mark it as read for the unknown-key check.)
  const auto has_key = [&first](const char* k) {
    const std::vector<std::string> keys = first.keys();
    return std::find(keys.begin(), keys.end(), k) != keys.end();
  };
  if (first.is_map() && has_key("batches") && !has_key("robots")) {
    first["batches"].fail(
        "this is an experiment file (it has `batches`), not a scenario: play it with "
        "`llsfsim experiment " +
        path + "`; `llsfsim check` takes the scenario files its batches name");
  }
  const core::ConfigNode matrix = first["matrix"];
  if (!matrix.defined()) {
    out.variants.push_back(read_scenario(first, path));
    return out;
  }
  matrix.require_map();
  if (matrix.size() == 0) matrix.fail("an empty matrix: give at least one axis or remove it");
  // Axes and their values, in file order; their product counted before any is expanded.
  std::vector<std::vector<std::string>> values;
  std::int64_t variants = 1;
  std::string sizes;
  for (const std::string& axis : matrix.keys()) {
    const core::ConfigNode a = matrix[axis];
    a.require_map();
    if (a.size() == 0) a.fail("an axis needs at least one value");
    out.axes.push_back(axis);
    values.push_back(a.keys());
    for (const std::string& v : values.back()) a[v].require_map();
    sizes += (sizes.empty() ? "" : " x ") + std::to_string(a.size());
    if (variants > ScenarioLimits::kMaxVariants / a.size()) variants = -1;  // over the limit
    if (variants > 0) variants *= a.size();
  }
  if (variants < 0 || variants > ScenarioLimits::kMaxVariants) {
    matrix.fail("more than " + std::to_string(ScenarioLimits::kMaxVariants) +
                " variants (axes of " + sizes + " values): at most " +
                std::to_string(ScenarioLimits::kMaxVariants) +
                " (docs/security.md, \"Scenario budgets\")");
  }
  // The cartesian product, last axis fastest; each cell re-parses the file and applies its
  // overrides (errors then point at the override's line).
  std::vector<std::size_t> idx(values.size(), 0);
  std::map<std::string, std::vector<std::size_t>> named;  // variant name -> its value indices
  std::int64_t games = 0;
  while (true) {
    core::ConfigNode root = core::ConfigNode::parse(text, path);
    std::string variant;
    for (std::size_t a = 0; a < values.size(); ++a) {
      const std::string& v = values[a][idx[a]];
      const core::ConfigNode over = root["matrix"][out.axes[a]][v];
      for (const std::string& key : over.keys()) {
        if (key == "matrix" || key.rfind("matrix.", 0) == 0)
          over[key].fail("cannot override the matrix");
        root.set(key, over[key]);
      }
      variant += (variant.empty() ? "" : ",") + out.axes[a] + "=" + v;
    }
    // Names identify variants in `run --variant` and in the statistics store: unique. Values
    // with ',' or '=' can give two variants one name.
    if (const auto [it, fresh] = named.emplace(variant, idx); !fresh) {
      std::size_t a = 0;
      while (a + 1 < idx.size() && it->second[a] == idx[a]) ++a;
      const core::ConfigNode mine = matrix[out.axes[a]][values[a][idx[a]]];
      const core::ConfigNode other = matrix[out.axes[a]][values[a][it->second[a]]];
      mine.fail("two variants are named '" + variant + "': this one and the one of " +
                other.location() + " (a value with ',' or '=' makes names ambiguous)");
    }
    Scenario s = read_scenario(root, path);
    s.variant = variant;
    games += static_cast<std::int64_t>(s.seeds.size());
    if (games > ScenarioLimits::kMaxGames) {
      matrix.fail("more than " + std::to_string(ScenarioLimits::kMaxGames) +
                  " games (the variants' seeds summed): at most " +
                  std::to_string(ScenarioLimits::kMaxGames) +
                  " (docs/security.md, \"Scenario budgets\")");
    }
    out.variants.push_back(std::move(s));
    std::size_t a = values.size();
    while (a > 0) {
      --a;
      if (++idx[a] < values[a].size()) break;
      idx[a] = 0;
      if (a == 0) return out;
    }
  }
}

}  // namespace llsf::study
