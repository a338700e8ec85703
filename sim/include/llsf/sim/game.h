// SPDX-License-Identifier: MIT
// Game: the game loop. Owns the world, the refbox (behind its protocol adapter), the radio hub,
// the planner and one RobotStack per robot, and steps them in the tick order of
// docs/architecture.md ("One tick"), written in Game::step(). Knows no file formats and no CLI: the
// scenario runner builds a GameConfig and drives this loop.
#pragma once

#include <google/protobuf/message.h>

#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "llsf/comm/hub.h"
#include "llsf/comm/registry.h"
#include "llsf/core/rng.h"
#include "llsf/kinematic/world.h"
#include "llsf/planner/planner.h"
#include "llsf/refbox/protocol.h"
#include "llsf/refbox/refbox.h"
#include "llsf/sim/extension.h"
#include "llsf/sim/game_config.h"
#include "llsf/sim/robot_stack.h"

namespace llsf::sim {

/// The hub peer name of the refbox (channel "*": hears and is heard by every channel).
inline constexpr std::string_view kRefboxPeer = "refbox";
/// The hub channel of the robots.
inline constexpr std::string_view kTeamChannel = "team";

/// Registers the 2013 refbox messages (llsf_msgs, component 2000, and llsf_log_msgs.LogMessage)
/// in `registry`.
void add_refbox_messages(comm::MessageRegistry& registry);

/// A summary of the game so far (the RunResult of a scenario run takes it).
struct GameSummary {
  SimTime time;
  std::int64_t ticks = 0;
  refbox::GamePhase phase = refbox::GamePhase::kPreGame;
  refbox::GameState state = refbox::GameState::kInit;
  int points = 0;              ///< GameState.points: sum of the phases' sums floored at 0
  int exploration_points = 0;  ///< raw sum of the phase's awards
  int production_points = 0;
  int whack_a_mole_points = 0;
  int collisions_robot_robot = 0;  ///< contacts that started, from the world's events
  int collisions_robot_wall = 0;
  int collisions_robot_device = 0;
  comm::TrafficCounters comm;        ///< everything the hub carried
  std::int64_t refbox_accepted = 0;  ///< messages the refbox took from the radio
  std::int64_t refbox_rejected = 0;
  std::int64_t controller_rejected = 0;  ///< controller commands the refbox refused
  std::uint64_t world_hash = 0;
  std::uint64_t refbox_hash = 0;
};

/// The game loop. Not copyable or movable (stacks and the adapter hold references into it);
/// not thread-safe; games in different threads are independent.
class Game {
 public:
  /// Completes `config` with prepare_game() (validation, the extensions made and set up: the
  /// hackathon layout; throws core::ConfigError), then builds everything from it and never
  /// changes it: world, refbox + protocol adapter (hub peer "refbox" on "*"), hub with the refbox
  /// and agent messages registered, planner, and a RobotStack + hub peer (channel "team") per
  /// world robot; then calls every extension's on_built() and gives the robots their add-ons.
  explicit Game(GameConfig config);
  ~Game();
  Game(const Game&) = delete;
  Game& operator=(const Game&) = delete;

  /// One tick (the extensions' hooks are called in the order of their list):
  /// 1. time advances by the physics step; extensions' pre_step();
  /// 2. actuators: every stack's command (navigator or motor) goes to World::set_command;
  /// 3. the world steps; its RFID and collision events are collected;
  /// 4. refbox: RFID events in (same device and puck ids), insertion-slot occupancy, messages
  ///    received in the previous tick; its lights go to World::set_lights, its referee actions
  ///    are carried out (delivered pucks removed, late-order S0 added), its messages broadcast;
  /// 5. comm: robots' beacons (every beacon_period) broadcast, the hub steps, deliveries go to
  ///    the refbox (llsf_msgs only) and to the inboxes of robots with a brain;
  /// 6. sensors: every stack perceives the world at its abstraction levels; then extensions'
  ///    sense();
  /// 7. skills: brains' on_skill_cycle at skill_rate_hz;
  /// 8. agents: brains' on_agent_cycle at agent_rate_hz (inboxes are then cleared);
  /// 9. extensions' post_step(), then the tick hook, if set.
  void step();
  /// Steps until time() >= `until`.
  void run_until(SimTime until);

  /// Simulated time (of the last tick).
  SimTime time() const { return world_->time(); }
  /// True if the last step() ran the robots' skill cycle (skill states can only change then).
  bool skills_cycled() const { return skills_cycled_; }
  std::int64_t ticks() const { return ticks_; }
  const GameConfig& config() const { return config_; }
  /// The scenario seed's random streams (components draw from named streams of it).
  const core::Rng& rng() const { return rng_; }

  kinematic::World& world() { return *world_; }
  const kinematic::World& world() const { return *world_; }
  /// The world's events of the last tick.
  const kinematic::WorldEvents& last_events() const { return *events_; }
  const refbox::Refbox& refbox() const { return protocol_->refbox(); }
  refbox::RefboxProtocol& refbox_protocol() { return *protocol_; }
  comm::Hub& hub() { return *hub_; }
  const comm::Hub& hub() const { return *hub_; }
  comm::PeerId refbox_peer() const { return refbox_peer_; }
  /// The messages the radio knows (refbox and agent messages).
  const comm::MessageRegistry& registry() const { return registry_; }
  planner::Planner& planner() { return *planner_; }

  int robot_count() const { return static_cast<int>(stacks_.size()); }
  RobotStack& robot(int index) { return *stacks_.at(static_cast<std::size_t>(index)); }
  const RobotStack& robot(int index) const { return *stacks_.at(static_cast<std::size_t>(index)); }
  /// The stack of the robot called `name`, or nullptr.
  RobotStack* robot(std::string_view name);
  /// The hub peer of robot `index`.
  comm::PeerId robot_peer(int index) const { return robot_peers_.at(std::size_t(index)); }
  /// The index of the robot that is hub peer `peer`, or -1 (the refbox, an unknown peer).
  int robot_of(comm::PeerId peer) const;

  /// Plugs `brain` (borrowed; must outlive the game or be unset with nullptr) into robot `index`.
  void set_brain(int index, RobotBrain* brain);
  /// A controller command (as if sent over the refbox's TCP port): applied at the next tick's
  /// refbox step. Returns the adapter's verdict.
  refbox::ReceiveResult controller_command(const google::protobuf::Message& message);

  // --- The outside world (served sockets; call between ticks) ----------------------------------
  /// A command of stream client `client` (>= 1; 0 is the game's own start()) from `host`:`port`,
  /// checked with the 2013 channel rules and applied at the next tick's refbox step.
  refbox::ReceiveResult controller_command(const google::protobuf::Message& message, int client,
                                           const std::string& host, int port);
  /// Stream client `client` (>= 1) connected: VersionInfo and GameInfo go to it at the next
  /// tick, the stream messages' timers restart (RefboxProtocol::client_connected).
  void controller_connected(int client);
  /// Stream client `client` went away.
  void controller_disconnected(int client);
  /// The refbox's messages of the last tick (those for stream clients included; the game itself
  /// only broadcasts the peers' ones on the hub). Valid until the next step().
  std::span<const refbox::Outgoing> refbox_outgoing() const { return protocol_->outgoing(); }
  /// The hub peer of GameConfig::external_peers[index].
  comm::PeerId external_peer(int index) const {
    return external_peers_.at(static_cast<std::size_t>(index)).peer;
  }
  /// Where the refbox sees external peer `index` come from (robots are keyed by (host, port),
  /// spec §10): its socket's source address. Until set, the refbox ignores its messages (the
  /// robots and other peers still hear them).
  void set_external_origin(int index, std::string host, int port);
  /// Starts the game as a controller would: SetGamePhase(`phase`) unless the refbox is in that
  /// phase already, then SetGameState(RUNNING); they take effect at the next tick's refbox step
  /// (kPreGame: the refbox runs from PRE_GAME through the setup as in a real game). Throws
  /// std::logic_error if the refbox refuses (a bug: both commands are valid before a game).
  void start(refbox::GamePhase phase);
  /// Called at the end of every tick (step 9), e.g. by a recorder.
  void set_tick_hook(std::function<void(const Game&)> hook) { tick_hook_ = std::move(hook); }

  GameSummary summary() const;

  /// The game's first extension of type T (e.g. HackathonExtension), or nullptr.
  template <class T>
  T* extension() {
    for (const auto& e : extensions_) {
      if (auto* t = dynamic_cast<T*>(e.get())) return t;
    }
    return nullptr;
  }
  template <class T>
  const T* extension() const {
    for (const auto& e : extensions_) {
      if (const auto* t = dynamic_cast<const T*>(e.get())) return t;
    }
    return nullptr;
  }
  /// How many extensions the game has (prepare_game's order).
  int extension_count() const { return static_cast<int>(extensions_.size()); }

  /// Where a tick's time goes: steady-clock nanoseconds per tick step (1..9 of step()), summed
  /// over the ticks since profiling was enabled. For benchmarks; costs a few clock reads a tick.
  struct TickProfile {
    static constexpr int kSteps = 9;
    std::array<std::int64_t, kSteps> ns{};
    /// With a profile counter set: its increase per tick step, summed (e.g. heap allocations).
    std::array<std::int64_t, kSteps> counts{};
    std::int64_t ticks = 0;
    /// "actuators+navigation", "world", "refbox", "radio", "sensors", "skills", "agents", ...
    static const char* step_name(int step);
  };
  void enable_profile(bool on) { profiling_ = on; }
  /// A monotonic counter read at every tick step boundary while profiling, its increases summed
  /// in TickProfile::counts (tests/study/alloc_test.cpp: a count of heap allocations); nullptr:
  /// none. Must not allocate.
  void set_profile_counter(std::int64_t (*counter)()) { profile_counter_ = counter; }
  const TickProfile& profile() const { return profile_; }

 private:
  explicit Game(PreparedGame prepared);
  void apply_refbox_output(const refbox::StepOutput& out, SimTime now);
  /// Carries out robot `robot`'s symbolic skill requests (tick step 2).
  void apply_symbolic(int robot);
  /// Distance from a robot's centre to the centre of a puck in its pocket.
  double pocket_offset_m() const;

 public:
  /// The puck in robot `robot`'s holder pocket (held by an assisted holder, or lying within
  /// 2 cm of the pocket), if any.
  std::optional<core::PuckId> puck_in_pocket(int robot) const;

 private:
  core::Vec2 free_storage_spot() const;
  bool insertion_slot_occupied() const;

  std::vector<std::unique_ptr<GameExtension>> extensions_;  // called in this order
  const GameConfig config_;  // frozen: prepare_game() before anything is built
  core::Rng rng_;
  std::unique_ptr<kinematic::World> world_;
  std::unique_ptr<refbox::RefboxProtocol> protocol_;
  comm::MessageRegistry registry_;  // before hub_: the hub borrows it
  std::unique_ptr<comm::Hub> hub_;
  comm::PeerId refbox_peer_;
  std::unique_ptr<planner::Planner> planner_;
  std::vector<std::unique_ptr<RobotStack>> stacks_;
  std::vector<comm::PeerId> robot_peers_;
  std::vector<int> robot_of_peer_;  // by PeerId value: robot index, -1 for other peers
  struct ExternalPeer {
    comm::PeerId peer;
    std::string host;  // "": origin not known yet
    int port = 0;
  };
  std::vector<ExternalPeer> external_peers_;  // by GameConfig::external_peers index
  std::function<void(const Game&)> tick_hook_;

  const kinematic::WorldEvents* events_ = nullptr;
  kinematic::WorldEvents no_events_;
  std::int64_t ticks_ = 0;
  bool lights_applied_ = false;
  /// Pucks the referee takes off the field later (GameConfig::referee_remove_delay): when, which.
  std::vector<std::pair<SimTime, core::PuckId>> pending_removals_;
  SimTime next_skill_;
  bool skills_cycled_ = false;
  SimTime next_agent_;
  SimTime skill_period_;
  SimTime agent_period_;
  std::vector<SimTime> next_beacon_;
  std::vector<std::uint64_t> beacon_seq_;
  std::unique_ptr<google::protobuf::Message> beacon_;  // reused BeaconSignal

  // Per-tick scratch (reserved at construction; the steady tick does not grow them).
  std::vector<refbox::RfidEvent> rfid_;
  std::vector<planner::DiscObstacle> discs_;
  std::vector<planner::DiscObstacle> others_;
  std::vector<core::Vec2> puck_positions_;
  std::array<kinematic::SignalLights, kinematic::kDeviceCount> lights_{};

  // Counters.
  std::array<int, 3> collisions_{};  // by kinematic::CollisionKind
  std::int64_t refbox_accepted_ = 0;
  std::int64_t refbox_rejected_ = 0;
  std::int64_t controller_rejected_ = 0;
  bool profiling_ = false;
  std::int64_t (*profile_counter_)() = nullptr;
  TickProfile profile_;
};

/// The planner's map of a world configuration: devices with their footprints and RFID zone
/// centres, and the marked areas, copied one to one.
planner::FieldMap field_map_from_world(const kinematic::WorldConfig& world);

}  // namespace llsf::sim
