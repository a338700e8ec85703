// SPDX-License-Identifier: MIT
// The 2013 referee-box rules engine: game states and phases, machines, recycling, delivery
// gates, the test station, lights, pucks, orders, points, exploration reports and robots.
// Driven only by the simulated time passed to step(); never reads the wall clock.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "llsf/core/rng.h"
#include "llsf/refbox/config.h"
#include "llsf/refbox/io.h"
#include "llsf/refbox/params.h"
#include "llsf/refbox/report.h"
#include "llsf/refbox/rules_variant.h"
#include "llsf/refbox/types.h"

namespace llsf::refbox {

/// Most pucks one RFID zone can hold at once (more are ignored until one leaves).
inline constexpr int kMaxPucksInZone = 4;

/// One of the 16 devices as the refbox sees it (the MachineInfo controller view).
struct Machine {
  DeviceId id;
  /// True type. M1..M10 hold a T1 placeholder until the game is parameterised (use shown_type()
  /// for what the controller may see).
  MachineType type = MachineType::kTest;
  MachineState state = MachineState::kIdle;
  /// The state to return to when a down time ends (valid while state == DOWN).
  MachineState state_before_down = MachineState::kIdle;
  /// The puck registered under the RFID reader (the one the machine works on), if any.
  PuckId puck_under_rfid;
  /// Inputs consumed but not yet finished, lying in the machine space (at most 2 + the last).
  std::array<PuckId, 3> loaded{};
  int loaded_count = 0;
  Lights lights;
  /// Exploration: unset until the first report of this machine, then right/wrong.
  std::optional<bool> correctly_reported;
  /// Game time at which PROCESSING ends (pushed back by down times).
  SimTime processing_end;
  /// Delivery gates: active (green) or not (DOWN, red); when it last turned inactive.
  bool gate_active = false;
  SimTime gate_inactive_since;
  /// Delivery gates: a delivery completed and the puck still lies there (all lamps on).
  bool delivered = false;
  /// Delivery gates: a puck lies at the inactive gate that it rejected (red + yellow blink).
  bool gate_rejected = false;
  /// Pucks currently in the RFID zone, in arrival order (what the reader senses is the first).
  std::array<PuckId, kMaxPucksInZone> in_zone{};
  int in_zone_count = 0;

  /// The loaded pucks.
  std::span<const PuckId> loaded_with() const { return {loaded.data(), std::size_t(loaded_count)}; }
  /// The puck the reader senses (first in the zone), if any.
  PuckId sensed() const { return in_zone_count > 0 ? in_zone[0] : PuckId(); }
};

/// One order of the production plan.
struct Order {
  OrderId id;
  PuckState product = PuckState::kP1;  ///< P1, P2 or P3
  int quantity_requested = 0;
  int quantity_delivered = 0;
  int window_begin_s = 0;  ///< delivery window in PRODUCTION game time, seconds
  int window_end_s = 0;
  bool late = false;
  bool active = false;  ///< visible in OrderInfo
  int points_per_unit = 10;
  int points_per_extra_unit = 1;
};

/// One puck the refbox knows.
struct Puck {
  PuckId id;
  PuckState state = PuckState::kS0;
};

/// A robot known from its beacons, keyed by (host, port).
struct Robot {
  std::string team;
  std::string name;
  int number = 0;
  std::string host;
  int port = 0;
  SimTime last_seen;  ///< simulated receive time of the last beacon
  std::optional<core::Pose2D> pose;
  /// Last overhead-camera pose (StepInput::robot_poses), if any (Robot.vision_pose).
  std::optional<core::Pose2D> vision_pose;
  RobotState state = RobotState::kActive;
  bool lost = false;  ///< no beacon for robot_lost_after (warned once)
  int maintenance_cycles = 0;
  SimTime maintenance_elapsed;  ///< running game time spent in the current maintenance
  bool maintenance_warned = false;
  bool clock_warned = false;
  /// Seconds of maintenance left (negative when overdue), as in Robot.maintenance_time_remaining.
  double maintenance_time_remaining_s(const RulesVariant& rules) const;
};

/// ExplorationInfo content: the light code of each type and the machines to explore.
struct ExplorationSignal {
  MachineType type = MachineType::kT1;
  Lights lights;
};

/// What Refbox::sync_from() did with a master's plan.
struct SyncResult {
  enum class Status : std::uint8_t {
    kApplied,               ///< the slave will play this plan
    kNotSlave,              ///< only a SLAVE takes a master's plan; nothing changed
    kAlreadyParameterised,  ///< the game has its plan already (it left PRE_GAME); nothing changed
    kInvalid,  ///< the plan breaks the spec's structure (see `reason`); nothing changed
  };
  Status status = Status::kApplied;
  std::string reason;  ///< for kInvalid: the validation message
  bool ok() const { return status == Status::kApplied; }
};

/// The referee box. Copyable (a copy continues identically), so snapshots are plain copies.
class Refbox {
 public:
  /// Validates `config` (throws core::ConfigError) and takes the stream "refbox" of `rng`.
  Refbox(RefboxConfig config, const core::Rng& rng);

  /// Advances to simulated time `now` (>= the previous now) and processes `in`. Tick order:
  /// 1. game time advances by the elapsed time if RUNNING, phases end and switch; the peer's
  /// GameState may decide overtime (synchronised mode);
  /// 2. controller commands, in order; 3. beacons and machine reports, vision poses and
  /// whack-a-mole;
  /// 4. RFID events; 5. scheduled rules of PRODUCTION (down times, gates, late orders, pending
  /// deliveries, processing ends); 6. the machines poll their readers; 7. robots (lost,
  /// maintenance); 8. lights. Returns this step's outputs (valid until the next step).
  const StepOutput& step(SimTime now, const StepInput& in);

  // --- master/slave synchronisation (spec §10) -------------------------------------------------
  /// SLAVE: plays `master_params` (the SyncInfo content of the master) instead of drawing a plan.
  /// Accepted until the game leaves PRE_GAME; validated like a config's params (in synchronised
  /// mode the gate schedule must cover kPlanSynchronisedS). Returns what happened.
  SyncResult sync_from(const GameParams& master_params);
  /// The plan to send in SyncInfo (MASTER). Fixes the plan now if the game has none yet: the
  /// same plan the game would draw on leaving PRE_GAME, so calling it changes nothing else.
  const GameParams& sync_params();

  // --- snapshot (everything the 2013 messages need) --------------------------------------------
  const RefboxConfig& config() const { return config_; }
  const RulesVariant& rules() const { return rules_; }
  /// GameState.refbox_mode (from the config).
  RefBoxMode mode() const { return config_.mode; }
  /// True while a synchronised game plays its overtime (PRODUCTION beyond the regular end).
  bool overtime() const { return overtime_; }
  /// True while a synchronised game stands PAUSED at the regular production end, waiting for
  /// the other field's GameState to decide between overtime and POST_GAME.
  bool awaiting_overtime_decision() const;
  /// The machine the robots have to reach (WHACK_A_MOLE_CHALLENGE, while one is lit).
  std::optional<DeviceId> mole() const { return mole_; }
  /// Length of `phase` in game time (0 for untimed phases); PRODUCTION includes the overtime
  /// once it has started.
  SimTime phase_duration(GamePhase p) const;
  SimTime now() const { return now_; }
  GameState state() const { return state_; }
  GamePhase phase() const { return phase_; }
  /// Phase-relative game time (GameState.game_time).
  SimTime game_time() const { return game_time_; }
  const std::string& team() const { return team_; }
  /// GameState.points: sum over phases of max(0, phase sum).
  int points() const;
  /// The raw sum of the awards of `phase` (may be negative).
  int phase_points(GamePhase phase) const;
  /// The parameterisation (drawn, or the config's), once the game has left PRE_GAME.
  const std::optional<GameParams>& params() const { return params_; }
  const std::array<Machine, kDeviceCount>& machines() const { return machines_; }
  const Machine& machine(DeviceId d) const { return machines_.at(std::size_t(d.value())); }
  /// The type string the controller view shows: real type in PRODUCTION and POST_GAME, else "?"
  /// except DELIVER, RECYCLE, TEST.
  std::string_view shown_type(DeviceId d) const;
  /// All 11 orders (check Order::active for OrderInfo), by id; empty before parameterisation.
  const std::vector<Order>& orders() const { return orders_; }
  /// All known pucks, sorted by id.
  const std::vector<Puck>& pucks() const { return pucks_; }
  /// The state of puck `id`, if known.
  std::optional<PuckState> puck_state(PuckId id) const;
  const std::vector<Robot>& robots() const { return robots_; }
  /// ExplorationInfo signals T1..T5 (empty before parameterisation).
  std::span<const ExplorationSignal> exploration_signals() const;
  /// MachineReportInfo: machines reported so far, in report order.
  const std::vector<DeviceId>& reported_machines() const { return reported_; }
  /// Every points award so far, in order.
  const std::vector<PointsAward>& awards() const { return awards_; }
  /// The gate that is active now (PRODUCTION), if any.
  std::optional<DeviceId> active_gate() const;
  /// The game report so far (complete after POST_GAME).
  GameReport report() const;
  /// FNV-1a hash of the rule state (states, time, pucks, machines, orders, points).
  std::uint64_t state_hash() const;

 private:
  // Phases and time.
  void advance_time(SimTime dt);
  void set_state(GameState s);
  void enter_phase(GamePhase p);
  void parameterise();
  void init_production();
  bool timed(GamePhase p) const { return phase_duration(p) > SimTime(); }
  void handle_peer(const PeerGameState& p);
  // Technical challenges.
  void update_vision(std::span<const RobotPose> poses);
  void update_whack_a_mole(std::span<const RobotPose> poses);
  void next_mole();
  // Inputs.
  void apply(const Command& c);
  void handle_beacon(const Beacon& b);
  void handle_report(const MachineReport& r);
  void handle_rfid(const RfidEvent& e);
  // Production rules.
  void run_schedule();
  void finish_processing(Machine& m);
  void poll_device(Machine& m, bool removals_only);
  void on_removal(Machine& m);
  void on_placement(Machine& m, PuckId p);
  void place_production(Machine& m, PuckId p);
  void place_recycler(Machine& m, PuckId p);
  void place_gate(Machine& m, PuckId p);
  void update_gates();
  void set_gate_active(Machine& g, bool active, SimTime since);
  void complete_delivery(Machine& g);
  bool credit_delivery(PuckState product, DeviceId gate, PuckId puck, AwardReason in_window);
  void activate_late_orders();
  void take_off_other_machines(DeviceId here, PuckId p);
  bool registered_elsewhere(DeviceId here, PuckId p) const;
  void set_machine_state(Machine& m, MachineState s, PuckId puck);
  // Robots.
  void update_robots(SimTime dt);
  void attention(std::string text, double seconds = 5.0);
  // Points and pucks.
  void award(int points, AwardReason reason, DeviceId device, OrderId order, PuckId puck);
  Puck* find_puck(PuckId id);
  Puck* find_or_learn_puck(PuckId id);
  void set_puck_state(PuckId id, PuckState s);
  void reset_pucks(std::span<const int> ids);
  // Lights.
  Lights lights_of(const Machine& m) const;
  void update_lights();
  bool production_running() const {
    return phase_ == GamePhase::kProduction && state_ == GameState::kRunning;
  }

  RefboxConfig config_;
  RulesVariant rules_;
  core::RandomStream rng_;
  std::uint64_t seed_ = 0;

  SimTime now_;
  bool started_ = false;
  GameState state_ = GameState::kInit;
  GamePhase phase_ = GamePhase::kPreGame;
  SimTime game_time_;
  std::string team_;
  bool setup_warned_ = false;
  std::optional<GameParams> params_;
  /// A master's plan taken by sync_from() (SLAVE).
  std::optional<GameParams> synced_params_;
  /// Synchronised mode: the overtime is being played.
  bool overtime_ = false;
  /// Whack-a-mole: the lit machine, and the previous one (never drawn twice in a row).
  std::optional<DeviceId> mole_;
  DeviceId last_mole_;
  std::array<ExplorationSignal, 5> signals_{};
  bool slot_occupied_ = false;
  /// Raw points per phase, indexed by phase_slot().
  std::array<int, 8> phase_sums_{};
  /// (host:port) of other refboxes already warned about.
  std::vector<std::string> warned_refboxes_;

  std::array<Machine, kDeviceCount> machines_{};
  std::vector<Order> orders_;
  std::vector<Puck> pucks_;
  std::vector<Robot> robots_;
  std::vector<DeviceId> reported_;
  std::vector<PointsAward> awards_;
  /// Progress of each params_->down_times entry: 0 = not started, 1 = down, 2 = over.
  std::vector<std::uint8_t> down_phase_;
  int gate_period_ = -1;
  /// 0.6.1: deliveries outside every window, waiting for a window to open.
  struct PendingDelivery {
    PuckState product;
    DeviceId gate;
    PuckId puck;
  };
  std::vector<PendingDelivery> pending_;
  std::vector<MachineHistoryEntry> history_;
  std::vector<DeliveryRecord> deliveries_;

  StepOutput out_;
};

}  // namespace llsf::refbox
