// SPDX-License-Identifier: MIT
// RobotStack: one simulated Robotino as its skills and agent see it -- the Fawkes blackboard
// (lua::RobotApi) at the game's abstraction levels, its navigator and its radio. The stack never
// touches the World: the Game hands it what its sensors perceive (RobotPercept, tick step 6) and
// takes its motor command (tick step 2).
#pragma once

#include <google/protobuf/message.h>

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "llsf/comm/hub.h"
#include "llsf/core/rng.h"
#include "llsf/kinematic/sensors.h"
#include "llsf/kinematic/world.h"
#include "llsf/lua/robot_api.h"
#include "llsf/planner/navigator.h"
#include "llsf/sim/extension.h"
#include "llsf/sim/game_config.h"
#include "llsf/sim/perception.h"

namespace llsf::sim {

/// What one robot's sensors perceive in one tick. Borrowed views, valid during sense().
struct RobotPercept {
  SimTime now;
  core::Pose2D true_pose;                            ///< for ground truth and the AMCL stand-in
  const kinematic::RobotSensors* sensors = nullptr;  ///< the world's readings of this robot
  /// Lamps of the 16 devices (DeviceId order), as the world shows them.
  std::span<const kinematic::SignalLights> lights;
  /// Field positions of every puck on the field.
  std::span<const core::Vec2> pucks;
};

/// A change of the world a symbolic skill asked for (lua::RobotApi::symbolic_*); the Game
/// carries it out at the start of the next tick.
struct SymbolicRequest {
  enum class Kind : std::uint8_t { kMove, kPick, kDrop };
  Kind kind = Kind::kMove;
  core::Pose2D pose;           ///< kMove: where the robot goes
  core::Vec2 point{0.0, 0.0};  ///< kPick: near where; kDrop: where the puck goes
  double radius_m = 0.0;       ///< kPick: how far from `point` a puck may be
};

/// A navigation that ended without arriving: the navigator refused the goal (kInvalidGoal: inside
/// an obstacle, too close to one, an unknown place) or gave up (kNoPath, kBlocked, kStuck). Aborts
/// (a new goal, stop()) are not failures.
struct NavFailure {
  SimTime time;
  planner::NavOutcome outcome = planner::NavOutcome::kIdle;
  std::string message;     ///< the navigator's reason
  core::Pose2D goal;       ///< the goal pose (the place's pose for goto_place)
  std::string place;       ///< goto_place's name; empty for goto_pose
  bool goal_known = true;  ///< false for an unknown place (`goal` means nothing then)
};

/// A message a robot received, with its sender.
struct Received {
  std::unique_ptr<google::protobuf::Message> message;
  std::string from;  ///< the sender's hub peer name ("refbox", "robot2", ...)
  int from_id = 0;   ///< the sender's robot number (index + 1); 0 for the refbox and others
  SimTime at;        ///< when it arrived
  const google::protobuf::Message* operator->() const { return message.get(); }
  const google::protobuf::Message* get() const { return message.get(); }
};

/// Messages a robot received and a way to send: the agent's side of the radio.
class RobotRadio {
 public:
  /// Messages received since the last agent cycle, in delivery order (cleared after it). An
  /// agent may move the messages out (e.g. into its CLIPS environment).
  std::span<Received> inbox() { return inbox_; }
  std::span<const Received> inbox() const { return inbox_; }
  /// Broadcasts `message` to the robot's channel (the team and the refbox) at the current time.
  /// Returns what the hub said (kNone = accepted). Requires the stack to be attached to a hub.
  comm::FrameError broadcast(const google::protobuf::Message& message);

  // The game's side (tick steps 5, 6 and 8).
  /// Connects the radio to `hub` as `peer` (the game, when it builds the robot).
  void attach(comm::Hub& hub, comm::PeerId peer) {
    hub_ = &hub;
    peer_ = peer;
  }
  comm::PeerId peer() const { return peer_; }
  /// Sets the time stamp of the robot's broadcasts (the stack, when it senses).
  void set_time(SimTime now) { now_ = now; }
  /// Appends a message the robot received to the inbox.
  void deliver(Received message) { inbox_.push_back(std::move(message)); }
  /// Empties the inbox (after the agent cycle, brain or not).
  void clear_inbox() { inbox_.clear(); }

 private:
  comm::Hub* hub_ = nullptr;
  comm::PeerId peer_;
  SimTime now_;
  std::vector<Received> inbox_;
};

/// A robot's skills and agent, plugged into the game loop (the Lua engine and the CLIPS agent
/// implement it). Called on the simulation thread.
class RobotBrain {
 public:
  virtual ~RobotBrain() = default;
  /// Tick step 7, at GameConfig::skill_rate_hz.
  virtual void on_skill_cycle(lua::RobotApi& robot) { static_cast<void>(robot); }
  /// Tick step 8, at GameConfig::agent_rate_hz; `radio.inbox()` holds what arrived since the
  /// previous agent cycle.
  virtual void on_agent_cycle(lua::RobotApi& robot, RobotRadio& radio) {
    static_cast<void>(robot);
    static_cast<void>(radio);
  }
};

/// One robot's interfaces (lua::RobotApi) at the configured abstraction levels. Not copyable;
/// borrows the game's planner (for its navigator), which must outlive it.
class RobotStack final : public lua::RobotApi {
 public:
  /// `index` is the robot's world index (also its id towards other robots' navigators);
  /// `robot_names` names every robot by index (for NavState::blocked_by); `devices` the 16
  /// devices in DeviceId order. Random draws come from rng streams "sim/<name>/localization",
  /// "sim/<name>/light"; the navigator's from "planner/<name>".
  RobotStack(std::string name, int index, const core::Pose2D& start, const GameConfig& config,
             planner::Planner& planner, std::vector<std::string> robot_names,
             std::vector<DeviceView> devices, const core::Rng& rng);
  RobotStack(const RobotStack&) = delete;
  RobotStack& operator=(const RobotStack&) = delete;

  // --- the game loop's side ----------------------------------------------------------------
  /// Tick step 2: the motor command for this tick (navigator or set velocity; zero when idle).
  /// `others`: the other robots as discs (ids = their indices).
  kinematic::MotorCommand actuate(SimTime now, std::span<const planner::DiscObstacle> others);
  /// Tick step 6: updates pose, holder, optical, laser, light and puck views from `percept`.
  void sense(const RobotPercept& percept);
  int index() const { return index_; }
  /// The radio of this robot (agent side).
  RobotRadio& radio() { return radio_; }
  /// The ideal level's navigator (idle at the move_base-2013 level).
  const planner::Navigator& nav() const { return nav_; }
  /// The move_base-2013 level's navigator, nullptr at the ideal level.
  const planner::MoveBaseNavigator* move_base() const {
    return move_base_ ? &*move_base_ : nullptr;
  }
  /// The status and the path of the navigator of this robot's level.
  const planner::NavStatus& nav_status() const {
    return move_base_ ? move_base_->status() : nav_.status();
  }
  const planner::Path& nav_path() const { return move_base_ ? move_base_->path() : nav_.path(); }
  /// Brain plugged into this robot (borrowed), or nullptr.
  RobotBrain* brain() const { return brain_; }
  void set_brain(RobotBrain* brain) { brain_ = brain; }

  // --- lua::RobotApi -----------------------------------------------------------------------
  SimTime now() const override { return now_; }
  std::string_view name() const override { return name_; }
  lua::PoseEstimate pose() const override { return localization_.estimate(); }
  void goto_place(std::string_view place, bool forward_only) override;
  void goto_pose(const core::Pose2D& pose, bool forward_only) override;
  lua::NavState navigator() const override;
  void stop() override;
  void set_velocity(double vx_mps, double vy_mps, double omega_rps) override;
  bool puck_in_holder() const override { return puck_in_holder_; }
  double ir_distance_m() const override { return ir_distance_m_; }
  lua::OpticalSensors optical() const override { return optical_; }
  lua::LightReading light() const override { return light_.reading(); }
  std::span<const lua::PuckSighting> pucks() const override { return puck_vision_.sightings(); }
  lua::LaserView laser() const override { return laser_; }
  std::span<const lua::ColourPuckSighting> colour_pucks() const override {
    return add_on_ != nullptr ? add_on_->colour_pucks()
                              : std::span<const lua::ColourPuckSighting>{};
  }
  const lua::RescueInfo* rescue() const override {
    return add_on_ != nullptr ? add_on_->rescue() : nullptr;
  }
  std::optional<lua::PlaceInfo> place(std::string_view name) const override;
  bool symbolic() const override { return levels_.skill == SkillLevel::kSymbolic; }
  lua::TravelEstimate symbolic_travel(const core::Pose2D& goal) const override;
  void symbolic_move(const core::Pose2D& pose) override;
  void symbolic_pick(const core::Vec2& point, double radius_m) override;
  void symbolic_drop(const core::Vec2& point) override;

  /// Tells the stack that the game moved the robot from true pose `from` to `to` (a symbolic
  /// move): a noisy pose estimate jumps along.
  void on_teleported(const core::Pose2D& from, const core::Pose2D& to);
  /// The symbolic requests since the last call (the Game carries them out in tick step 2).
  std::vector<SymbolicRequest>& symbolic_requests() { return symbolic_requests_; }
  /// Handling (robot profiles): whether the robot is jammed against a device now, the device
  /// (DeviceView index; -1 none), and how many jams it had.
  bool jammed() const { return jam_device_ >= 0; }
  /// The motor switch (an agent's motor-enable / motor-disable): off, the robot stands.
  bool motor_enabled() const { return motor_enabled_; }
  void set_motor_enabled(bool on) { motor_enabled_ = on; }
  int jam_device() const { return jam_device_; }
  int jams() const { return jams_; }
  /// What a game extension gives this robot's skill API (borrowed from the extension; set by
  /// the Game before the first tick), or nullptr.
  const RobotAddOn* add_on() const { return add_on_; }
  void set_add_on(const RobotAddOn* add_on) { add_on_ = add_on; }
  /// How many navigations failed so far (NavFailure), for recordings and tools.
  std::int64_t nav_failures() const { return nav_failure_count_; }
  /// The failure number `n` (0-based, < nav_failures()) if it is among the last
  /// kNavFailureMemory; nullptr otherwise. Valid until the next failure.
  const NavFailure* nav_failure(std::int64_t n) const;
  static constexpr int kNavFailureMemory = 8;

 private:
  enum class Drive : std::uint8_t { kIdle, kNavigator, kMotor };

  std::string name_;
  int index_;
  RobotLevelsConfig levels_;
  std::vector<std::string> robot_names_;
  std::vector<DeviceView> devices_;
  planner::Planner* planner_;
  planner::Navigator nav_;
  std::optional<planner::MoveBaseNavigator> move_base_;
  // The move_base-2013 level's laser input: the newest scan's hits in field coordinates (at the
  // pose estimate), handed to the navigator once; the odometry's velocity.
  std::int64_t laser_seq_ = 0;
  bool scan_new_ = false;
  core::Vec2 scan_origin_{0.0, 0.0};
  core::Vec2 laser_mount_{0.0, 0.0};
  std::vector<core::Vec2> scan_hits_;
  std::vector<int> scan_beam_of_hit_;
  planner::Costmap::Beams scan_beams_;  // their directions (field frame, as estimated; of_hit:
                                        // scan_beam_of_hit_)
  std::vector<core::Vec2> beam_dirs_;   // unit vectors of the laser's beams, robot frame
  planner::VelocityCommand odom_velocity_;
  void nav_abort();
  RobotRadio radio_;
  std::vector<SymbolicRequest> symbolic_requests_;
  mutable std::uint64_t travel_queries_ = 0;
  RobotBrain* brain_ = nullptr;
  SimTime now_;

  // Actuation.
  Drive drive_ = Drive::kIdle;
  kinematic::MotorCommand velocity_;
  std::uint64_t goal_id_ = 0;
  // Handling (robot profiles): alignment after arrival, motor caps, jams.
  HandlingConfig handling_;
  core::RandomStream jam_rng_;
  core::Pose2D true_pose_;
  std::optional<SimTime> arrived_at_;  ///< when the navigator arrived at the current goal
  core::Vec2 goal_from_{0.0, 0.0};     ///< where the robot stood when the goal was given
  SimTime jammed_since_;
  bool motor_started_ = false;  ///< a new run of direct motor commands began
  int jam_device_ = -1;
  bool motor_enabled_ = true;  // set_motor_enabled()
  int jams_ = 0;
  // Navigation failures (a ring of the last kNavFailureMemory) and the current goal's place.
  std::array<NavFailure, kNavFailureMemory> nav_failure_ring_{};
  std::int64_t nav_failure_count_ = 0;
  std::string goal_place_;
  bool goal_known_ = true;
  /// Starts the alignment time (HandlingConfig::align_s) at the navigation's arrival.
  void note_arrival(SimTime now, planner::NavOutcome outcome);
  /// Remembers the navigation's end if it failed (called where the outcome can change).
  void note_nav_end(SimTime now);
  /// Applies the motor caps and the jam to a command; may start or end a jam.
  kinematic::MotorCommand handle(kinematic::MotorCommand c, bool motor);

  // Holder, optical, laser: the world's readings as they are.
  bool puck_in_holder_ = false;
  double ir_distance_m_ = 0.0;
  lua::OpticalSensors optical_;
  lua::LaserView laser_;

  // Perception models (perception.h).
  Localization localization_;
  LightDetection light_;
  PuckVision puck_vision_;
  const RobotAddOn* add_on_ = nullptr;  ///< a game extension's interfaces (the hackathon's)
};

}  // namespace llsf::sim
