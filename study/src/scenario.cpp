// SPDX-License-Identifier: MIT
#include "llsf/study/scenario.h"

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <utility>

#include "llsf/comm/hub_config.h"
#include "llsf/core/error.h"
#include "llsf/kinematic/world_config.h"
#include "llsf/planner/config.h"
#include "llsf/refbox/config.h"
#include "llsf/study/profile.h"

namespace llsf::study {

namespace {

namespace fs = std::filesystem;

/// A hackathon run's length unless `duration_s` says otherwise.
constexpr core::SimTime kHackathonDefaultDuration = core::SimTime::from_sec(300);

std::string read_text(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw core::ConfigError(path + ": cannot read the scenario file");
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
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

template <class E>
E enum_of(const core::ConfigNode& n, std::initializer_list<std::pair<const char*, E>> values) {
  const std::string s = n.as_string();
  std::string allowed;
  for (const auto& [name, v] : values) {
    if (s == name) return v;
    allowed += allowed.empty() ? "" : ", ";
    allowed += name;
  }
  n.fail("'" + s + "' is not one of " + allowed);
}

double positive(const core::ConfigNode& n) {
  const double v = n.as_double();
  if (!(v > 0.0)) n.fail("must be > 0");
  return v;
}

void read_levels(const core::ConfigNode& n, sim::RobotLevelsConfig& l) {
  if (!n.defined()) return;
  n.require_map();
  n.check_keys({"localization", "light", "puck", "skill", "position_noise_m", "heading_noise_rad",
                "light_error_rate", "light_delay_s", "cruise_speed_mps"});
  if (n["localization"].defined()) {
    l.localization.level = enum_of<sim::LocalizationLevel>(
        n["localization"], {{"ground_truth", sim::LocalizationLevel::kGroundTruth},
                            {"noisy", sim::LocalizationLevel::kNoisy}});
  }
  auto detection = [](const core::ConfigNode& c) {
    return enum_of<sim::DetectionLevel>(c, {{"ground_truth", sim::DetectionLevel::kGroundTruth},
                                            {"vision", sim::DetectionLevel::kVision}});
  };
  if (n["light"].defined()) l.light.level = detection(n["light"]);
  if (n["puck"].defined()) l.puck.level = detection(n["puck"]);
  if (n["skill"].defined()) {
    l.skill = enum_of<sim::SkillLevel>(n["skill"], {{"physical", sim::SkillLevel::kPhysical},
                                                    {"symbolic", sim::SkillLevel::kSymbolic}});
  }
  n.read("position_noise_m", l.localization.position_noise_m);
  n.read("heading_noise_rad", l.localization.heading_noise_rad);
  n.read("light_error_rate", l.light.error_rate);
  if (n["light_delay_s"].defined()) {
    l.light.delay = core::SimTime::from_seconds(n["light_delay_s"].as_double());
  }
  n.read("cruise_speed_mps", l.symbolic.cruise_speed_mps);
}

void read_rates(const core::ConfigNode& n, sim::GameConfig& g) {
  if (!n.defined()) return;
  n.require_map();
  n.check_keys({"physics_hz", "skill_hz", "agent_hz", "beacon_period_s"});
  if (n["physics_hz"].defined()) {
    g.world.physics.step = core::SimTime::period_of_hz(positive(n["physics_hz"]));
  }
  if (n["skill_hz"].defined()) g.skill_rate_hz = positive(n["skill_hz"]);
  if (n["agent_hz"].defined()) g.agent_rate_hz = positive(n["agent_hz"]);
  if (n["beacon_period_s"].defined()) {
    g.beacon_period = core::SimTime::from_seconds(positive(n["beacon_period_s"]));
  }
}

std::vector<std::uint64_t> read_seeds(const core::ConfigNode& root) {
  const core::ConfigNode seed = root["seed"];
  const core::ConfigNode seeds = root["seeds"];
  if (seed.defined() && seeds.defined()) seeds.fail("give either 'seed' or 'seeds', not both");
  auto one = [](const core::ConfigNode& n) {
    const std::int64_t v = n.as_int();
    if (v < 0) n.fail("a seed must be >= 0");
    return static_cast<std::uint64_t>(v);
  };
  if (seed.defined()) return {one(seed)};
  if (!seeds.defined()) return {1};
  std::vector<std::uint64_t> out;
  if (seeds.is_map()) {
    seeds.check_keys({"first", "count"});
    const std::uint64_t first = seeds["first"].defined() ? one(seeds["first"]) : 1;
    const std::int64_t count = seeds.at("count").as_int();
    if (count < 1 || count > 100000) seeds["count"].fail("must be in 1..100000");
    for (std::int64_t i = 0; i < count; ++i) out.push_back(first + static_cast<std::uint64_t>(i));
    return out;
  }
  if (!seeds.is_sequence() || seeds.size() == 0)
    seeds.fail("expected a list of seeds or {first, count}");
  for (const core::ConfigNode& e : seeds.elements()) out.push_back(one(e));
  return out;
}

void merge_config(clips::ConfigEntries& into, const clips::ConfigEntries& over) {
  for (const clips::ConfigEntry& e : over) {
    std::erase_if(into, [&](const clips::ConfigEntry& x) { return x.path == e.path; });
    into.push_back(e);
  }
}

std::vector<std::string> read_agent(const core::ConfigNode& n, const std::string& dir) {
  std::vector<std::string> out;
  const std::vector<std::string> entries = string_list(n);
  for (std::size_t i = 0; i < entries.size(); ++i) {
    const std::string p = resolve(dir, entries[i]);
    std::error_code ec;
    if (!fs::exists(p, ec)) {
      (n.is_sequence() ? n.at(static_cast<int>(i)) : n)
          .fail("agent file or directory '" + entries[i] + "' not found (looked at " + p + ")");
    }
    out.push_back(p);
  }
  return out;
}

void read_robots(const core::ConfigNode& n, const std::string& dir, Scenario& s) {
  int count = static_cast<int>(s.game.world.robots.size());
  std::vector<std::string> agent;
  clips::ConfigEntries config;
  if (n.defined()) {
    n.require_map();
    n.check_keys({"count", "agent", "config", "locks", "each"});
    if (n["count"].defined()) {
      const std::int64_t c = n["count"].as_int();
      if (c < 1 || c > static_cast<std::int64_t>(s.game.world.robots.size())) {
        n["count"].fail("must be in 1.." + std::to_string(s.game.world.robots.size()) +
                        " (the robots of the world)");
      }
      count = static_cast<int>(c);
    }
    if (n["agent"].defined()) agent = read_agent(n["agent"], dir);
    if (n["config"].defined()) {
      n["config"].require_map();
      config = clips::config_from_node(n["config"], "/clips-agent");
    }
  }
  bool locks = false;
  if (n.defined()) n.read("locks", locks);
  s.game.world.robots.resize(static_cast<std::size_t>(count));
  s.robots.assign(static_cast<std::size_t>(count), RobotSpec{agent, config, locks});
  const core::ConfigNode each = n.defined() ? n["each"] : core::ConfigNode();
  if (!each.defined()) return;
  if (!each.is_sequence()) each.fail("expected a list with one entry per robot");
  if (each.size() > count) each.fail("more entries than robots (" + std::to_string(count) + ")");
  for (int i = 0; i < each.size(); ++i) {
    const core::ConfigNode r = each.at(i);
    if (r.is_null()) continue;
    r.require_map();
    r.check_keys({"agent", "config", "name", "jersey", "start"});
    RobotSpec& spec = s.robots[static_cast<std::size_t>(i)];
    if (r["agent"].defined()) spec.agent = read_agent(r["agent"], dir);
    if (r["config"].defined()) {
      r["config"].require_map();
      merge_config(spec.config, clips::config_from_node(r["config"], "/clips-agent"));
    }
    kinematic::RobotStart& start = s.game.world.robots[static_cast<std::size_t>(i)];
    r.read("name", start.name);
    r.read("jersey", start.jersey);
    if (r["start"].defined()) {
      const core::ConfigNode p = r["start"];
      p.require_map();
      p.check_keys({"x", "y", "ori_deg"});
      double x = start.pose.x, y = start.pose.y, ori = start.pose.theta * 180.0 / core::kPi;
      p.read("x", x);
      p.read("y", y);
      p.read("ori_deg", ori);
      start.pose = {x, y, ori * core::kPi / 180.0};
    }
  }
}

void read_tests(const core::ConfigNode& n, Scenario& s) {
  if (!n.defined()) return;
  if (!n.is_sequence()) n.fail("expected a list of test cases");
  for (const core::ConfigNode& t : n.elements()) {
    t.require_map();
    t.check_keys({"name", "points_at_least", "exploration_points_at_least",
                  "production_points_at_least", "deliveries_at_least", "collisions_at_most",
                  "no_agent_errors", "skill_failure_streak_at_most", "lock_hold_at_most_s",
                  "by_s"});
    TestCase tc;
    int kinds = 0;
    auto kind = [&](const char* key, TestCase::Kind k) {
      if (!t[key].defined()) return;
      ++kinds;
      tc.kind = k;
      if (k == TestCase::Kind::kNoAgentErrors) {
        if (!t[key].as_bool()) t[key].fail("only 'true' makes sense");
      } else {
        tc.value = t[key].as_double();
        if (tc.value < 0.0) t[key].fail("must be >= 0");
      }
    };
    kind("points_at_least", TestCase::Kind::kPointsAtLeast);
    kind("exploration_points_at_least", TestCase::Kind::kExplorationPointsAtLeast);
    kind("production_points_at_least", TestCase::Kind::kProductionPointsAtLeast);
    kind("deliveries_at_least", TestCase::Kind::kDeliveriesAtLeast);
    kind("collisions_at_most", TestCase::Kind::kCollisionsAtMost);
    kind("no_agent_errors", TestCase::Kind::kNoAgentErrors);
    kind("skill_failure_streak_at_most", TestCase::Kind::kSkillFailureStreakAtMost);
    kind("lock_hold_at_most_s", TestCase::Kind::kLockHoldAtMost);
    if (kinds != 1) t.fail("a test case needs exactly one condition (e.g. points_at_least: 30)");
    if (t["by_s"].defined()) {
      if (tc.kind != TestCase::Kind::kPointsAtLeast &&
          tc.kind != TestCase::Kind::kDeliveriesAtLeast) {
        t["by_s"].fail("by_s works with points_at_least and deliveries_at_least");
      }
      tc.by_s = t["by_s"].as_double();
      if (*tc.by_s <= 0.0) t["by_s"].fail("must be > 0");
    }
    tc.name = t["name"].defined() ? t["name"].as_string() : describe(tc);
    s.tests.push_back(std::move(tc));
  }
}

Scenario read_scenario(const core::ConfigNode& root, const std::string& file) {
  root.require_map();
  root.check_keys({"name", "description", "seed", "seeds", "start", "duration_s", "refbox", "world",
                   "radio", "navigation", "levels", "rates", "team", "robots", "skills", "tests",
                   "matrix", "hackathon", "profile"});
  const std::string dir = fs::path(file).parent_path().string();
  Scenario s;
  s.file = file;
  s.name = root.at("name").as_string();
  if (s.name.empty()) root["name"].fail("must not be empty");
  root.read("description", s.description);
  s.seeds = read_seeds(root);
  if (root["refbox"].defined()) s.game.refbox = refbox::load_refbox_config(root["refbox"]);
  // The robot profile first: world, navigation and levels keys override its figures.
  RobotProfile profile;
  if (root["profile"].defined()) profile = load_profile(root["profile"]);
  profile.apply(s.game, s.skills);
  if (root["world"].defined()) {
    s.game.world = kinematic::load_world_config(root["world"], s.game.world);
  }
  if (root["radio"].defined()) s.game.hub = comm::load_hub_config(root["radio"]);
  if (root["navigation"].defined()) {
    planner::NavigationConfig nav{s.game.planner, s.game.controller};
    nav = planner::load_navigation_config(root["navigation"], nav);
    s.game.planner = nav.planner;
    s.game.controller = nav.controller;
  }
  read_levels(root["levels"], s.game.levels);
  read_rates(root["rates"], s.game);
  root.read("team", s.game.team);
  if (root["hackathon"].defined()) {
    s.game.hackathon = sim::load_hackathon_config(root["hackathon"], s.game.world);
    s.start = StartMode::kNone;
  }
  if (root["start"].defined()) {
    s.start = enum_of<StartMode>(root["start"], {{"game", StartMode::kGame},
                                                 {"exploration", StartMode::kExploration},
                                                 {"production", StartMode::kProduction},
                                                 {"none", StartMode::kNone}});
  }
  const refbox::RefboxConfig& rb = s.game.refbox;
  double duration = rb.production_duration.seconds();
  if (s.start != StartMode::kProduction) duration += rb.exploration_duration.seconds();
  if (s.start == StartMode::kGame && !rb.team.empty() && !rb.skip_setup) {
    duration += rb.setup_duration.seconds();
  }
  if (s.game.hackathon) duration = kHackathonDefaultDuration.seconds();
  if (root["duration_s"].defined()) duration = positive(root["duration_s"]);
  s.duration = core::SimTime::from_seconds(duration);
  read_robots(root["robots"], dir, s);
  if (root["skills"].defined()) {
    s.skills = lua::SkillEngineConfig::from_config(root["skills"]);
    for (std::string& d : s.skills.skill_dirs) d = resolve(dir, d);
    s.skills.profile = profile.name;
    s.skills.stuck_detection = profile.stuck_detection;
  }
  read_tests(root["tests"], s);
  s.game.seed = s.seeds.front();
  try {
    s.game.validate();
  } catch (const core::ConfigError& e) {
    root.fail(std::string("the game config is invalid: ") + e.what());
  }
  return s;
}

}  // namespace

std::string describe(const TestCase& t) {
  std::ostringstream ss;
  switch (t.kind) {
    case TestCase::Kind::kPointsAtLeast:
      ss << ">= " << t.value << " points";
      break;
    case TestCase::Kind::kExplorationPointsAtLeast:
      ss << ">= " << t.value << " exploration points";
      break;
    case TestCase::Kind::kProductionPointsAtLeast:
      ss << ">= " << t.value << " production points";
      break;
    case TestCase::Kind::kDeliveriesAtLeast:
      ss << ">= " << t.value << " deliveries";
      break;
    case TestCase::Kind::kCollisionsAtMost:
      ss << "<= " << t.value << " collisions";
      break;
    case TestCase::Kind::kNoAgentErrors:
      ss << "no agent runtime errors";
      break;
    case TestCase::Kind::kSkillFailureStreakAtMost:
      ss << "<= " << t.value << " failures of one skill in a row";
      break;
    case TestCase::Kind::kLockHoldAtMost:
      ss << "no lock held longer than " << t.value << " s";
      break;
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
  const core::ConfigNode matrix = first["matrix"];
  if (!matrix.defined()) {
    out.variants.push_back(read_scenario(first, path));
    return out;
  }
  matrix.require_map();
  if (matrix.size() == 0) matrix.fail("an empty matrix: give at least one axis or remove it");
  // Axes and their values, in file order.
  std::vector<std::vector<std::string>> values;
  for (const std::string& axis : matrix.keys()) {
    const core::ConfigNode a = matrix[axis];
    a.require_map();
    if (a.size() == 0) a.fail("an axis needs at least one value");
    out.axes.push_back(axis);
    values.push_back(a.keys());
    for (const std::string& v : values.back()) a[v].require_map();
  }
  // The cartesian product, last axis fastest; each cell re-parses the file and applies its
  // overrides (errors then point at the override's line).
  std::vector<std::size_t> idx(values.size(), 0);
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
    Scenario s = read_scenario(root, path);
    s.variant = variant;
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
