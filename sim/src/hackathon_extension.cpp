// SPDX-License-Identifier: MIT
#include "llsf/sim/hackathon_extension.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <utility>

#include "llsf/core/error.h"
#include "llsf/sim/game.h"

namespace llsf::sim {

// --- the hackathon's colour camera -------------------------------------------------------------

ColourCamera::ColourCamera(const ColourCameraConfig& config, std::vector<std::string> colour_names,
                           core::RandomStream rng)
    : c_(config), colour_names_(std::move(colour_names)), rng_(rng) {
  sightings_.reserve(64);
}

// A cone ahead of the robot, one frame every 1/frame_rate_hz; per puck in the cone three draws
// (miss, false colour, which colour) and two for the position noise, whatever the outcome, so
// that one puck's luck does not shift the others'.
void ColourCamera::update(SimTime now, const core::Pose2D& truth, std::span<const core::Vec2> pucks,
                          std::span<const int> puck_colours) {
  if (now < next_frame_) return;
  const SimTime period = SimTime::period_of_hz(c_.frame_rate_hz);
  next_frame_ += period;
  if (next_frame_ <= now) next_frame_ = now + period;
  sightings_.clear();
  frame_time_ = now;
  frame_pose_ = truth;
  ++frames_;
  const double half_fov = 0.5 * c_.fov_rad;
  const int colours = static_cast<int>(colour_names_.size());
  for (std::size_t i = 0; i < pucks.size() && i < puck_colours.size(); ++i) {
    const int colour = puck_colours[i];
    if (colour < 0) continue;
    const core::Vec2 l = truth.to_local(pucks[i]);
    const double d = l.norm();
    if (d > c_.range_m || std::abs(std::atan2(l.y(), l.x())) > half_fov) continue;
    const bool missed = rng_.bernoulli(c_.miss_rate);
    const bool wrong = rng_.bernoulli(c_.false_colour_rate);
    const std::int64_t other = colours > 1 ? rng_.uniform_int(0, colours - 2) : 0;
    const core::Vec2 noise(rng_.normal(0.0, c_.position_noise_m),
                           rng_.normal(0.0, c_.position_noise_m));
    if (missed) continue;
    int seen = colour;
    if (wrong && colours > 1)
      seen =
          static_cast<int>(other) >= colour ? static_cast<int>(other) + 1 : static_cast<int>(other);
    const core::Vec2 at = l + noise;
    sightings_.push_back(
        {at, at.norm(), std::atan2(at.y(), at.x()), colour_names_[static_cast<std::size_t>(seen)]});
  }
}

lua::RescueInfo hackathon_rescue_info(const HackathonConfig& config,
                                      const kinematic::WorldConfig& world) {
  lua::RescueInfo info;
  info.safe_lo = config.safe_area.lo;
  info.safe_hi = config.safe_area.hi;
  info.safe_place = config.safe_place;
  for (const HackathonColour& c : config.colours) {
    (c.decoy ? info.decoys : info.counted).push_back(c.name);
  }
  info.held_puck_offset_m = world.robot.radius_m + world.puck.radius_m;
  return info;
}

namespace {

std::vector<std::string> colour_names(const HackathonConfig& config) {
  std::vector<std::string> names;
  for (const HackathonColour& c : config.colours) names.push_back(c.name);
  return names;
}

}  // namespace

HackathonRobot::HackathonRobot(const HackathonConfig& config, core::RandomStream rng,
                               const lua::RescueInfo* rescue)
    : camera_(config.camera, colour_names(config), rng), rescue_(rescue) {}

HackathonExtension::HackathonExtension(HackathonConfig config) : config_(std::move(config)) {}

HackathonExtension::~HackathonExtension() = default;

void HackathonExtension::setup(GameConfig& config, const core::Rng& rng) {
  // The layout of the seed, into the world; the safe place for the navigator.
  layout_ = generate_hackathon_layout(config_, config.world, rng);
  apply_hackathon_layout(config_, layout_, config.world);
  config.planner.places.extra.push_back(
      {config_.safe_place,
       hackathon_safe_pose(config_, config.world, config.planner.places.held_puck_offset_m)});
  // The colour of every puck of the layout, by puck id.
  for (const HackathonPuck& p : layout_.pucks) {
    const auto id = static_cast<std::size_t>(p.id.value());
    if (id >= colour_by_id_.size()) colour_by_id_.resize(id + 1, -1);
    colour_by_id_[id] = p.colour;
  }
}

void HackathonExtension::on_built(Game& game) {
  const GameConfig& c = game.config();
  rescue_ = hackathon_rescue_info(config_, c.world);
  robots_.clear();
  for (int i = 0; i < game.robot_count(); ++i) {
    const std::string& robot = c.world.robots[static_cast<std::size_t>(i)].name;
    robots_.push_back(std::make_unique<HackathonRobot>(
        config_, game.rng().stream("sim/" + robot + "/colour"), &rescue_));
  }
  puck_positions_.reserve(c.world.pucks.size() + 32);
  puck_colours_.reserve(c.world.pucks.size() + 32);
}

void HackathonExtension::sense(Game& game, SimTime now) {
  const kinematic::World& world = game.world();
  puck_positions_.clear();
  puck_colours_.clear();
  world.puck_positions(puck_positions_);
  for (const core::PuckId p : world.pucks()) {
    const auto id = static_cast<std::size_t>(p.value());
    puck_colours_.push_back(id < colour_by_id_.size() ? colour_by_id_[id] : -1);
  }
  for (int i = 0; i < static_cast<int>(robots_.size()); ++i) {
    robots_[static_cast<std::size_t>(i)]->update(now, world.robot_pose(core::RobotId(i)),
                                                 puck_positions_, puck_colours_);
  }
}

const RobotAddOn* HackathonExtension::robot_add_on(int robot) const {
  return robots_.at(static_cast<std::size_t>(robot)).get();
}

const HackathonRobot& HackathonExtension::robot_at(int robot) const {
  return *robots_.at(static_cast<std::size_t>(robot));
}

HackathonScore HackathonExtension::score(const Game& game) const {
  const kinematic::World& world = game.world();
  std::vector<HackathonPuckState> states;
  std::vector<core::PuckId> held;
  for (int r = 0; r < game.robot_count(); ++r) {
    if (const auto p = game.puck_in_pocket(r)) held.push_back(*p);
  }
  for (const HackathonPuck& p : layout_.pucks) {
    HackathonPuckState s;
    s.id = p.id;
    s.on_field = world.has_puck(p.id);
    if (s.on_field) s.position = world.puck_position(p.id);
    s.held = std::find(held.begin(), held.end(), p.id) != held.end();
    states.push_back(s);
  }
  return score_hackathon(config_, layout_, states);
}

void HackathonVariant::validate(const GameConfig& game) const {
  try {
    config_.validate(game.world);
  } catch (const core::ConfigError& e) {
    throw core::ConfigError("game." + std::string(e.what()));
  }
}

std::unique_ptr<GameExtension> HackathonVariant::make() const {
  return std::make_unique<HackathonExtension>(config_);
}

void set_hackathon(GameConfig& game, HackathonConfig config) {
  auto variant = std::make_shared<const HackathonVariant>(std::move(config));
  for (auto& e : game.extensions) {
    if (dynamic_cast<const HackathonVariant*>(e.get()) != nullptr) {
      e = std::move(variant);
      return;
    }
  }
  game.extensions.push_back(std::move(variant));
}

const HackathonConfig* hackathon_config(const GameConfig& game) {
  for (const auto& e : game.extensions) {
    if (const auto* h = dynamic_cast<const HackathonVariant*>(e.get())) return &h->config();
  }
  return nullptr;
}

const HackathonExtension* hackathon_of(const Game& game) {
  return game.extension<HackathonExtension>();
}

std::optional<HackathonScore> hackathon_score(const Game& game) {
  const HackathonExtension* h = hackathon_of(game);
  if (h == nullptr) return std::nullopt;
  return h->score(game);
}

}  // namespace llsf::sim
