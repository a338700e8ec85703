// SPDX-License-Identifier: MIT
// The hackathon variant as a game extension (extension.h): it draws the layout and puts it into
// the world before the game is built, gives every robot the colour camera and the rescue
// interface, takes the camera frames in tick step 6 and scores the safe area. All its state
// lives here, not in Game or GameConfig (docs/hackathon.md).
#pragma once

#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "llsf/core/geometry.h"
#include "llsf/sim/extension.h"
#include "llsf/sim/hackathon.h"

namespace llsf::sim {

/// The hackathon's flashlight camera (ColourCameraConfig): coloured pucks in a cone ahead, with
/// seeded misses, false colours and position noise.
class ColourCamera {
 public:
  ColourCamera(const ColourCameraConfig& config, std::vector<std::string> colour_names,
               core::RandomStream rng);
  /// Tick step 6. `colours`: the colour index of each entry of `pucks` (-1 none).
  void update(SimTime now, const core::Pose2D& truth, std::span<const core::Vec2> pucks,
              std::span<const int> colours);
  std::span<const lua::ColourPuckSighting> sightings() const { return sightings_; }
  /// When the current sightings were taken (the last frame; zero before the first) and the true
  /// pose they are relative to: `frame_pose().to_parent(s.position)` is a sighting's field
  /// position (recordings, the viewer).
  SimTime frame_time() const { return frame_time_; }
  const core::Pose2D& frame_pose() const { return frame_pose_; }
  /// Frames taken so far (a new frame changes it, even with the same sightings).
  std::int64_t frames() const { return frames_; }
  const ColourCameraConfig& config() const { return c_; }

 private:
  ColourCameraConfig c_;
  std::vector<std::string> colour_names_;
  core::RandomStream rng_;
  SimTime next_frame_;
  SimTime frame_time_;
  core::Pose2D frame_pose_;
  std::int64_t frames_ = 0;
  std::vector<lua::ColourPuckSighting> sightings_;
};

/// What a rescue skill knows about the task of `config` on `world` (lua::RobotApi::rescue).
lua::RescueInfo hackathon_rescue_info(const HackathonConfig& config,
                                      const kinematic::WorldConfig& world);

/// One robot's part of the hackathon as its skill API sees it: its colour camera and the rescue
/// task (borrowed; must outlive this).
class HackathonRobot final : public RobotAddOn {
 public:
  /// A camera of `config.camera` and `config.colours` drawing from `rng` (the game's stream
  /// "sim/<robot>/colour").
  HackathonRobot(const HackathonConfig& config, core::RandomStream rng,
                 const lua::RescueInfo* rescue);
  /// The camera's frame, if one is due (tick step 6): `pucks` the field positions of the pucks
  /// on the field, `colours` their colour indices (-1 none), `truth` the robot's true pose.
  void update(SimTime now, const core::Pose2D& truth, std::span<const core::Vec2> pucks,
              std::span<const int> colours) {
    camera_.update(now, truth, pucks, colours);
  }
  const ColourCamera& camera() const { return camera_; }
  std::span<const lua::ColourPuckSighting> colour_pucks() const override {
    return camera_.sightings();
  }
  const lua::RescueInfo* rescue() const override { return rescue_; }

 private:
  ColourCamera camera_;
  const lua::RescueInfo* rescue_;
};

/// The hackathon world of one game (made from the game config's HackathonVariant).
class HackathonExtension final : public GameExtension {
 public:
  explicit HackathonExtension(HackathonConfig config);
  ~HackathonExtension() override;
  HackathonExtension(const HackathonExtension&) = delete;
  HackathonExtension& operator=(const HackathonExtension&) = delete;

  std::string_view name() const override { return "hackathon"; }
  /// Draws the layout (generate_hackathon_layout, stream "sim/hackathon/layout"), puts it into
  /// the world (boxes added, pucks replaced) and the safe place into the planner's places.
  void setup(GameConfig& config, const core::Rng& rng) override;
  /// One colour camera per robot (stream "sim/<robot>/colour") and the rescue task.
  void on_built(Game& game) override;
  /// The colour cameras' frames of this tick (from the world's pucks and the robots' true
  /// poses).
  void sense(Game& game, SimTime now) override;
  const RobotAddOn* robot_add_on(int robot) const override;

  const HackathonConfig& config() const { return config_; }
  /// The puck layout of this game.
  const HackathonLayout& layout() const { return layout_; }
  /// The score now (pucks released in the safe area; a puck in a robot's pocket does not count).
  HackathonScore score(const Game& game) const;
  /// Robot `robot`'s colour camera (its sightings, frame time and pose).
  const ColourCamera& camera(int robot) const { return robot_at(robot).camera(); }
  /// What a rescue skill knows about the task (lua::RobotApi::rescue).
  const lua::RescueInfo& rescue_info() const { return rescue_; }

 private:
  const HackathonRobot& robot_at(int robot) const;

  HackathonConfig config_;
  HackathonLayout layout_;
  std::vector<int> colour_by_id_;  // indexed by puck id; -1: no colour
  lua::RescueInfo rescue_;
  std::vector<std::unique_ptr<HackathonRobot>> robots_;  // by robot index
  // Per-tick scratch (reserved in on_built; the steady tick does not grow them).
  std::vector<core::Vec2> puck_positions_;
  std::vector<int> puck_colours_;  // colour index per entry of puck_positions_
};

/// The hackathon variant's entry in GameConfig::extensions (a scenario's `hackathon:` section):
/// its configuration, validated against the game's world, and the factory of its extension.
class HackathonVariant final : public GameExtensionFactory {
 public:
  explicit HackathonVariant(HackathonConfig config) : config_(std::move(config)) {}
  const HackathonConfig& config() const { return config_; }
  /// Throws core::ConfigError "game.hackathon.<field>: reason" (HackathonConfig::validate).
  void validate(const GameConfig& game) const override;
  std::unique_ptr<GameExtension> make() const override;

 private:
  HackathonConfig config_;
};

/// Makes `game` a hackathon game of `config`: its HackathonVariant entry in `game.extensions`,
/// replacing an earlier one in its place or added at the end.
void set_hackathon(GameConfig& game, HackathonConfig config);
/// The hackathon configuration of `game` (its HackathonVariant), or nullptr outside the variant.
const HackathonConfig* hackathon_config(const GameConfig& game);

/// The hackathon extension of `game`, or nullptr outside the variant.
const HackathonExtension* hackathon_of(const Game& game);
/// The hackathon score of `game` now, or nullopt outside the variant.
std::optional<HackathonScore> hackathon_score(const Game& game);

}  // namespace llsf::sim
