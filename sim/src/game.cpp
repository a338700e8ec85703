// SPDX-License-Identifier: MIT
#include "llsf/sim/game.h"

#include <chrono>

#include <llsf_log_msgs/LogMessage.pb.h>
#include <llsf_msgs/AttentionMessage.pb.h>
#include <llsf_msgs/BeaconSignal.pb.h>
#include <llsf_msgs/ExplorationInfo.pb.h>
#include <llsf_msgs/GameInfo.pb.h>
#include <llsf_msgs/GameState.pb.h>
#include <llsf_msgs/MachineCommands.pb.h>
#include <llsf_msgs/MachineInfo.pb.h>
#include <llsf_msgs/MachineReport.pb.h>
#include <llsf_msgs/OrderInfo.pb.h>
#include <llsf_msgs/PuckInfo.pb.h>
#include <llsf_msgs/RobotCommands.pb.h>
#include <llsf_msgs/RobotInfo.pb.h>
#include <llsf_msgs/Sync.pb.h>
#include <llsf_msgs/VersionInfo.pb.h>

#include <algorithm>
#include <stdexcept>
#include <string>
#include <utility>

#include "llsf/core/assert.h"
#include "llsf/core/error.h"

namespace llsf::sim {

namespace {

kinematic::LampState to_lamp(refbox::LightState s) {
  switch (s) {
    case refbox::LightState::kOff:
      return kinematic::LampState::kOff;
    case refbox::LightState::kOn:
      return kinematic::LampState::kOn;
    case refbox::LightState::kBlink:
      return kinematic::LampState::kBlink;
  }
  return kinematic::LampState::kOff;
}

kinematic::SignalLights to_world(const refbox::Lights& l) {
  return {to_lamp(l.red), to_lamp(l.yellow), to_lamp(l.green)};
}

/// The source address under which the refbox sees robot `index` (robots are keyed by
/// (host, port), spec §10): one host per robot, the 2013 team port.
std::string robot_host(int index) { return "10.0.0." + std::to_string(index + 1); }
constexpr int kRobotPort = 4444;

}  // namespace

void add_refbox_messages(comm::MessageRegistry& r) {
  r.add<llsf_msgs::BeaconSignal>();
  r.add<llsf_msgs::AttentionMessage>();
  r.add<llsf_msgs::VersionInfo>();
  r.add<llsf_msgs::SyncInfo>();
  r.add<llsf_msgs::InitiateSync>();
  r.add<llsf_msgs::GameState>();
  r.add<llsf_msgs::SetGameState>();
  r.add<llsf_msgs::SetGamePhase>();
  r.add<llsf_msgs::MachineInfo>();
  r.add<llsf_msgs::RemovePuckFromMachine>();
  r.add<llsf_msgs::PlacePuckUnderMachine>();
  r.add<llsf_msgs::LoadPuckInMachine>();
  r.add<llsf_msgs::RobotInfo>();
  r.add<llsf_msgs::OrderInfo>();
  r.add<llsf_msgs::PuckInfo>();
  r.add<llsf_msgs::SetPucks>();
  r.add<llsf_msgs::MachineReport>();
  r.add<llsf_msgs::MachineReportInfo>();
  r.add<llsf_msgs::ExplorationInfo>();
  r.add<llsf_msgs::GameInfo>();
  r.add<llsf_msgs::SetTeamName>();
  r.add<llsf_msgs::SetRobotMaintenance>();
  r.add<llsf_log_msgs::LogMessage>();
}

planner::FieldMap field_map_from_world(const kinematic::WorldConfig& w) {
  planner::FieldMap m;
  m.width_m = w.field.width_m;
  m.height_m = w.field.height_m;
  for (int i = 0; i < kinematic::kDeviceCount; ++i) {
    const core::DeviceId id(i);
    const kinematic::DeviceConfig& d = w.devices[static_cast<std::size_t>(i)];
    planner::DeviceRole role = planner::DeviceRole::kProduction;
    switch (kinematic::device_kind(id)) {
      case kinematic::DeviceKind::kProduction:
        role = planner::DeviceRole::kProduction;
        break;
      case kinematic::DeviceKind::kRecycling:
        role = planner::DeviceRole::kRecycling;
        break;
      case kinematic::DeviceKind::kTest:
        role = planner::DeviceRole::kTest;
        break;
      case kinematic::DeviceKind::kDelivery:
        role = planner::DeviceRole::kDelivery;
        break;
    }
    m.devices.push_back(
        {std::string(kinematic::device_name(id)), role, d.pose, d.footprint(), d.rfid_center()});
  }
  auto rect = [](const kinematic::Rect& r) { return planner::AreaRect{r.lo, r.hi}; };
  m.insertion_area = rect(w.field.insertion_area);
  m.input_storage = rect(w.field.input_storage);
  m.late_order_area = rect(w.field.late_order_area);
  m.late_order_slot = w.field.late_order_slot;
  m.delivery_zone = rect(w.field.delivery_zone);
  for (const kinematic::ObstacleConfig& o : w.obstacles)
    m.obstacles.push_back({o.name, o.footprint()});
  return m;
}

// --- construction ----------------------------------------------------------------------------

Game::Game(GameConfig config) : Game(prepare_game(std::move(config))) {}

Game::Game(PreparedGame prepared)
    : extensions_(std::move(prepared.extensions)),
      config_(std::move(prepared.config)),
      rng_(config_.seed) {
  world_ = std::make_unique<kinematic::World>(config_.world, rng_);
  protocol_ = std::make_unique<refbox::RefboxProtocol>(config_.refbox, rng_, config_.protocol);

  // The radio: the refbox hears and is heard by every channel, the robots share "team".
  add_refbox_messages(registry_);
  comm::add_agent_messages(registry_, config_.hub.lock_messages);
  for (const auto& protos : config_.agent_protos) protos->register_in(registry_);
  std::vector<std::string> names;
  names.emplace_back(kRefboxPeer);
  for (const auto& r : config_.world.robots) names.push_back(r.name);
  for (const ExternalPeerConfig& e : config_.external_peers) names.push_back(e.name);
  config_.hub.validate_peer_names(names);
  hub_ = std::make_unique<comm::Hub>(config_.hub, registry_, rng_);
  refbox_peer_ = hub_->add_peer(std::string(kRefboxPeer), std::string(comm::kAllChannels));

  // Navigation and one stack per robot.
  planner_ =
      std::make_unique<planner::Planner>(field_map_from_world(config_.world), config_.planner);
  std::vector<std::string> robot_names;
  for (const auto& r : config_.world.robots) robot_names.push_back(r.name);
  std::vector<DeviceView> devices;
  for (int i = 0; i < kinematic::kDeviceCount; ++i) {
    const kinematic::DeviceConfig& d = config_.world.devices[static_cast<std::size_t>(i)];
    devices.push_back(
        {std::string(kinematic::device_name(core::DeviceId(i))), d.pose, d.rfid_center()});
  }
  const SimTime dt = config_.world.physics.step;
  for (int i = 0; i < world_->robot_count(); ++i) {
    const kinematic::RobotStart& start = config_.world.robots[static_cast<std::size_t>(i)];
    stacks_.push_back(std::make_unique<RobotStack>(start.name, i, start.pose, config_, *planner_,
                                                   robot_names, devices, rng_));
    const comm::PeerId peer = hub_->add_peer(start.name, std::string(kTeamChannel));
    robot_peers_.push_back(peer);
    const auto slot = static_cast<std::size_t>(peer.value());
    if (slot >= robot_of_peer_.size()) robot_of_peer_.resize(slot + 1, -1);
    robot_of_peer_[slot] = i;
    stacks_.back()->radio().attach(*hub_, peer);
    // Beacons staggered by one tick per robot, then every beacon_period.
    next_beacon_.push_back(dt * (i + 1));
    beacon_seq_.push_back(0);
  }
  beacon_ = std::make_unique<llsf_msgs::BeaconSignal>();
  // Peers outside the simulation (served sockets) after the robots, so that a game without
  // them has the same peer ids and draws as ever.
  for (const ExternalPeerConfig& e : config_.external_peers) {
    external_peers_.push_back({hub_->add_peer(e.name, e.channel), "", 0});
  }

  skill_period_ = SimTime::period_of_hz(config_.skill_rate_hz);
  agent_period_ = SimTime::period_of_hz(config_.agent_rate_hz);
  next_skill_ = dt;
  next_agent_ = dt;

  // Per-tick scratch, sized once.
  const std::size_t robots = stacks_.size();
  rfid_.reserve(64);
  discs_.reserve(robots);
  others_.reserve(robots);
  puck_positions_.reserve(config_.world.pucks.size() + 32);
  events_ = &no_events_;

  // The extensions on the built game; what they give the robots' skill API (one each at most).
  for (const auto& e : extensions_) e->on_built(*this);
  for (int i = 0; i < robot_count(); ++i) {
    const GameExtension* giver = nullptr;
    for (const auto& e : extensions_) {
      const RobotAddOn* add_on = e->robot_add_on(i);
      if (add_on == nullptr) continue;
      if (giver != nullptr) {
        throw core::ConfigError("game.extensions: " + std::string(giver->name()) + " and " +
                                std::string(e->name()) + " both give " +
                                std::string(robot(i).name()) + " skill interfaces");
      }
      giver = e.get();
      robot(i).set_add_on(add_on);
    }
  }
}

Game::~Game() = default;

RobotStack* Game::robot(std::string_view name) {
  for (auto& s : stacks_) {
    if (s->name() == name) return s.get();
  }
  return nullptr;
}

void Game::set_brain(int index, RobotBrain* brain) { robot(index).set_brain(brain); }

int Game::robot_of(comm::PeerId peer) const {
  const auto slot = static_cast<std::size_t>(peer.value());
  return peer.valid() && slot < robot_of_peer_.size() ? robot_of_peer_[slot] : -1;
}

refbox::ReceiveResult Game::controller_command(const google::protobuf::Message& message) {
  refbox::ReceiveResult r = protocol_->receive(message, refbox::Origin::stream(0));
  if (r.status == refbox::ReceiveStatus::kRejected) ++controller_rejected_;
  return r;
}

refbox::ReceiveResult Game::controller_command(const google::protobuf::Message& message, int client,
                                               const std::string& host, int port) {
  LLSF_DEMAND(client >= 1);
  refbox::ReceiveResult r = protocol_->receive(message, refbox::Origin::stream(client, host, port));
  if (r.status == refbox::ReceiveStatus::kRejected) ++controller_rejected_;
  return r;
}

void Game::controller_connected(int client) {
  LLSF_DEMAND(client >= 1);
  protocol_->client_connected(client);
}

void Game::controller_disconnected(int client) { protocol_->client_disconnected(client); }

void Game::set_external_origin(int index, std::string host, int port) {
  ExternalPeer& e = external_peers_.at(static_cast<std::size_t>(index));
  e.host = std::move(host);
  e.port = port;
}

void Game::start(refbox::GamePhase phase) {
  auto send = [this](const google::protobuf::Message& m) {
    const refbox::ReceiveResult r = controller_command(m);
    if (r.status != refbox::ReceiveStatus::kAccepted) {
      throw std::logic_error("Game::start: the refbox refused " + m.GetTypeName() + ": " +
                             r.reason);
    }
  };
  if (phase != refbox().phase()) {
    llsf_msgs::SetGamePhase p;
    p.set_phase(refbox::to_msg_phase(phase));
    send(p);
  }
  llsf_msgs::SetGameState s;
  s.set_state(llsf_msgs::GameState::RUNNING);
  send(s);
}

void Game::run_until(SimTime until) {
  while (time() < until) step();
}

// --- the tick --------------------------------------------------------------------------------

std::optional<core::PuckId> Game::puck_in_pocket(int robot) const {
  const core::RobotId id(robot);
  if (const auto held = world_->held_puck(id)) return held;
  // Physical holder (or not yet taken): the puck whose centre is within 2 cm of the pocket.
  const core::Vec2 pocket = world_->robot_pose(id).to_parent({pocket_offset_m(), 0.0});
  std::optional<core::PuckId> best;
  double best_d = 0.02;
  for (const core::PuckId p : world_->pucks()) {
    const double d = (world_->puck_position(p) - pocket).norm();
    if (d <= best_d) {
      best_d = d;
      best = p;
    }
  }
  return best;
}

double Game::pocket_offset_m() const {
  return config_.world.robot.radius_m + config_.world.puck.radius_m;
}

void Game::apply_symbolic(int robot) {
  RobotStack& stack = *stacks_[static_cast<std::size_t>(robot)];
  std::vector<SymbolicRequest>& requests = stack.symbolic_requests();
  if (requests.empty()) return;
  const core::RobotId id(robot);
  for (const SymbolicRequest& r : requests) {
    switch (r.kind) {
      case SymbolicRequest::Kind::kMove: {
        const std::optional<core::PuckId> held = puck_in_pocket(robot);
        const core::Pose2D from = world_->robot_pose(id);
        world_->teleport_robot(id, r.pose);
        if (held) world_->teleport_puck(*held, r.pose.to_parent({pocket_offset_m(), 0.0}));
        stack.on_teleported(from, r.pose);
        break;
      }
      case SymbolicRequest::Kind::kPick: {
        if (puck_in_pocket(robot)) break;  // already holding one
        std::optional<core::PuckId> best;
        double best_d = r.radius_m;
        for (const core::PuckId p : world_->pucks()) {
          bool taken = false;
          for (int o = 0; o < robot_count() && !taken; ++o) {
            taken = o != robot && puck_in_pocket(o) == p;
          }
          const double d = (world_->puck_position(p) - r.point).norm();
          if (!taken && d <= best_d) {
            best_d = d;
            best = p;
          }
        }
        if (best) {
          world_->teleport_puck(*best, world_->robot_pose(id).to_parent({pocket_offset_m(), 0.0}));
        }
        break;
      }
      case SymbolicRequest::Kind::kDrop: {
        if (const auto held = puck_in_pocket(robot)) world_->teleport_puck(*held, r.point);
        break;
      }
    }
  }
  requests.clear();
}

void Game::step() {
  // Optional profile of the tick's steps (steady clock; a measurement, never a game input).
  std::chrono::steady_clock::time_point last;
  std::int64_t last_count = 0;
  if (profiling_) {
    last = std::chrono::steady_clock::now();
    if (profile_counter_ != nullptr) last_count = profile_counter_();
  }
  auto mark = [&](int step) {
    if (!profiling_) return;
    const auto t = std::chrono::steady_clock::now();
    profile_.ns[static_cast<std::size_t>(step)] += (t - last).count();
    last = t;
    if (profile_counter_ != nullptr) {
      const std::int64_t c = profile_counter_();
      profile_.counts[static_cast<std::size_t>(step)] += c - last_count;
      last_count = c;
    }
  };

  // 1. Time advances by the physics step; everything in this tick happens at `now`.
  const SimTime now = world_->time() + config_.world.physics.step;
  const int n = robot_count();
  for (const auto& e : extensions_) e->pre_step(*this, now);

  // 2. Actuators: symbolic skills' changes of the world first; then each stack's navigator or
  //    motor command, with the other robots as discs.
  for (int i = 0; i < n; ++i) apply_symbolic(i);
  discs_.clear();
  const double disc_r = planner_->config().inflated_radius_m();
  for (int i = 0; i < n; ++i) {
    discs_.push_back({i, world_->robot_pose(core::RobotId(i)).position(), disc_r});
  }
  for (int i = 0; i < n; ++i) {
    others_.clear();
    for (const auto& d : discs_) {
      if (d.id != i) others_.push_back(d);
    }
    RobotStack& stack = *stacks_[static_cast<std::size_t>(i)];
    const kinematic::MotorCommand c = stack.actuate(now, others_);
    // An agent's (motor-disable) switches the motors off: the robot stands (Fawkes' motor-switch).
    world_->set_command(core::RobotId(i), stack.motor_enabled() ? c : kinematic::MotorCommand{});
  }

  mark(1);

  // 3. The world steps; collisions are counted, RFID events become the refbox's.
  events_ = &world_->step();
  LLSF_ASSERT(world_->time() == now);
  for (const kinematic::CollisionEvent& c : events_->collisions) {
    ++collisions_[static_cast<std::size_t>(c.kind)];
  }
  rfid_.clear();
  for (const kinematic::RfidEvent& e : events_->rfid) {
    // The world's and the refbox's device ids are the same indices 0..15, puck ids the same.
    rfid_.push_back({e.device, e.puck, e.kind == kinematic::RfidEventKind::kEntered});
  }

  mark(2);

  // 4. Refbox: RFID events and the messages received last tick in; lights, referee actions and
  //    messages out.
  refbox::WorldInputs in;
  in.rfid = rfid_;
  in.insertion_slot_occupied = insertion_slot_occupied();
  const std::span<const refbox::Outgoing> outgoing = protocol_->step(now, in);
  apply_refbox_output(protocol_->engine_output(), now);
  for (const refbox::Outgoing& o : outgoing) {
    // Stream clients (controllers) are not part of the game loop; peers get the UDP messages.
    if (o.to.kind == refbox::Destination::Kind::kAllPeers) {
      hub_->broadcast(refbox_peer_, *o.message, now);
    }
  }

  mark(3);

  // 5. Comm: beacons, then deliveries whose delay has passed.
  for (int i = 0; i < n; ++i) {
    auto& due = next_beacon_[static_cast<std::size_t>(i)];
    if (now < due) continue;
    due += config_.beacon_period;
    auto& b = static_cast<llsf_msgs::BeaconSignal&>(*beacon_);
    const RobotStack& s = *stacks_[static_cast<std::size_t>(i)];
    b.mutable_time()->set_sec(now.ns() / 1000000000);
    b.mutable_time()->set_nsec(now.ns() % 1000000000);
    b.set_seq(++beacon_seq_[static_cast<std::size_t>(i)]);
    b.set_team_name(config_.team.empty() ? config_.refbox.team : config_.team);
    b.set_peer_name(std::string(s.name()));
    b.set_number(
        static_cast<std::uint32_t>(config_.world.robots[static_cast<std::size_t>(i)].jersey_or(i)));
    const lua::PoseEstimate pe = s.pose();
    if (pe.valid) {
      llsf_msgs::Pose2D* p = b.mutable_pose();
      p->mutable_timestamp()->set_sec(pe.stamp.ns() / 1000000000);
      p->mutable_timestamp()->set_nsec(pe.stamp.ns() % 1000000000);
      p->set_x(static_cast<float>(pe.pose.x));
      p->set_y(static_cast<float>(pe.pose.y));
      p->set_ori(static_cast<float>(pe.pose.theta));
    } else {
      b.clear_pose();
    }
    hub_->broadcast(robot_peers_[static_cast<std::size_t>(i)], b, now);
  }
  hub_->step(now);
  for (const comm::Delivery& d : hub_->received(refbox_peer_)) {
    // Only the refbox's own protocol goes to it; the agents' messages are not its business.
    if (d.type_index < 0 ||
        registry_.key_at(d.type_index).component_id != comm::kRefboxComponentId ||
        comm::is_agent_message(registry_, d.type_index)) {
      continue;
    }
    const int from = robot_of(d.from);
    refbox::Origin origin;
    if (from >= 0) {
      origin = refbox::Origin::peer(robot_host(from), kRobotPort);
    } else {
      // A peer outside the simulation (served sockets), once its address is known.
      const ExternalPeer* e = nullptr;
      for (const ExternalPeer& x : external_peers_) {
        if (x.peer == d.from) e = &x;
      }
      if (e == nullptr || e->host.empty()) continue;
      origin = refbox::Origin::peer(e->host, e->port);
    }
    const std::unique_ptr<google::protobuf::Message> msg = hub_->decode(d);
    const refbox::ReceiveResult r = protocol_->receive(*msg, origin);
    if (r.status == refbox::ReceiveStatus::kRejected) {
      ++refbox_rejected_;
    } else {
      ++refbox_accepted_;
    }
  }
  for (int i = 0; i < n; ++i) {
    // Only a robot with a brain reads its messages; decoding them is its agent's cost.
    if (stacks_[static_cast<std::size_t>(i)]->brain() == nullptr) continue;
    RobotRadio& radio = stacks_[static_cast<std::size_t>(i)]->radio();
    for (const comm::Delivery& d : hub_->received(robot_peers_[static_cast<std::size_t>(i)])) {
      if (auto msg = hub_->decode(d)) {
        Received r;
        r.message = std::move(msg);
        r.from = hub_->peer_name(d.from);
        r.from_id = robot_of(d.from) + 1;  // 0 for the refbox
        r.at = now;
        radio.deliver(std::move(r));
      }
    }
  }

  mark(4);

  // 6. Sensors: what each robot perceives, at its abstraction levels.
  const auto lights = world_->all_lights();
  std::copy(lights.begin(), lights.end(), lights_.begin());
  puck_positions_.clear();
  world_->puck_positions(puck_positions_);
  for (int i = 0; i < n; ++i) {
    const core::RobotId id(i);
    RobotPercept p;
    p.now = now;
    p.true_pose = world_->robot_pose(id);
    p.sensors = &world_->sensors(id);
    p.lights = lights_;
    p.pucks = puck_positions_;
    stacks_[static_cast<std::size_t>(i)]->sense(p);
  }
  for (const auto& e : extensions_) e->sense(*this, now);

  mark(5);

  // 7. Skills.
  skills_cycled_ = now >= next_skill_;
  if (skills_cycled_) {
    next_skill_ += skill_period_;
    for (auto& s : stacks_) {
      if (s->brain() != nullptr) s->brain()->on_skill_cycle(*s);
    }
  }

  mark(6);

  // 8. Agents (their inboxes are emptied after each cycle, brain or not).
  if (now >= next_agent_) {
    next_agent_ += agent_period_;
    for (auto& s : stacks_) {
      if (s->brain() != nullptr) s->brain()->on_agent_cycle(*s, s->radio());
      s->radio().clear_inbox();
    }
  }

  mark(7);

  // 9. Extensions, then recorder and statistics.
  ++ticks_;
  for (const auto& e : extensions_) e->post_step(*this, now);
  if (tick_hook_) tick_hook_(*this);
  mark(8);
  if (profiling_) ++profile_.ticks;
}

const char* Game::TickProfile::step_name(int step) {
  static const char* const names[] = {
      "time", "actuators+navigation", "world", "refbox", "radio", "sensors", "skills", "agents",
      "hooks"};
  return step >= 0 && step < kSteps ? names[step] : "?";
}

// --- referee actions -------------------------------------------------------------------------

void Game::apply_refbox_output(const refbox::StepOutput& out, SimTime now) {
  // The referee's removals that are due (in the order asked for).
  while (!pending_removals_.empty() && pending_removals_.front().first <= now) {
    const core::PuckId p = pending_removals_.front().second;
    pending_removals_.erase(pending_removals_.begin());
    if (world_->has_puck(p)) world_->remove_puck(p);
  }
  // The refbox's lamps on the world's devices (all of them once, then the changed ones).
  for (int i = 0; i < kinematic::kDeviceCount; ++i) {
    if (lights_applied_ && (out.lights_changed_mask & (1u << i)) == 0) continue;
    world_->set_lights(core::DeviceId(i), to_world(out.lights[static_cast<std::size_t>(i)]));
  }
  lights_applied_ = true;
  for (const refbox::RefereeAction& a : out.actions) {
    switch (a.kind) {
      case refbox::RefereeAction::Kind::kRemovePuck:
        if (config_.referee_remove_delay > SimTime()) {
          pending_removals_.emplace_back(now + config_.referee_remove_delay, a.puck);
        } else if (world_->has_puck(a.puck)) {
          world_->remove_puck(a.puck);
        }
        break;
      case refbox::RefereeAction::Kind::kPlacePuck:
        if (world_->has_puck(a.puck)) break;
        world_->add_puck(a.puck, a.place == refbox::RefereeAction::Place::kInsertionSlot
                                     ? config_.world.field.late_order_slot
                                     : free_storage_spot());
        break;
    }
  }
}

bool Game::insertion_slot_occupied() const {
  // Occupied if a new puck at the slot would overlap one already there.
  const core::Vec2 slot = config_.world.field.late_order_slot;
  const double clear = 2.0 * config_.world.puck.radius_m;
  return world_->any_puck_within(slot, clear);
}

core::Vec2 Game::free_storage_spot() const {
  // The first spot of a 2.5 cm grid in the input storage where a puck touches no other puck and
  // no robot.
  const kinematic::Rect& s = config_.world.field.input_storage;
  const double r = config_.world.puck.radius_m;
  const double robot_r = config_.world.robot.radius_m;
  constexpr double kGrid = 0.025;
  const double edge = r + 0.005;  // off the walls and the area's border
  const int nx = static_cast<int>((s.hi.x() - s.lo.x() - 2.0 * edge) / kGrid);
  const int ny = static_cast<int>((s.hi.y() - s.lo.y() - 2.0 * edge) / kGrid);
  for (int iy = 0; iy <= ny; ++iy) {
    for (int ix = 0; ix <= nx; ++ix) {
      const core::Vec2 p(s.lo.x() + edge + ix * kGrid, s.lo.y() + edge + iy * kGrid);
      bool free = true;
      for (const core::PuckId q : world_->pucks()) {
        if (world_->has_puck(q) && (world_->puck_position(q) - p).norm() < 2.0 * r + 0.004) {
          free = false;
        }
      }
      for (int i = 0; i < world_->robot_count(); ++i) {
        if ((world_->robot_pose(core::RobotId(i)).position() - p).norm() < robot_r + r + 0.005) {
          free = false;
        }
      }
      if (free) return p;
    }
  }
  return s.center();
}

// --- summary ---------------------------------------------------------------------------------

GameSummary Game::summary() const {
  const refbox::Refbox& rb = refbox();
  GameSummary s;
  s.time = time();
  s.ticks = ticks_;
  s.phase = rb.phase();
  s.state = rb.state();
  s.points = rb.points();
  s.exploration_points = rb.phase_points(refbox::GamePhase::kExploration);
  s.production_points = rb.phase_points(refbox::GamePhase::kProduction);
  s.whack_a_mole_points = rb.phase_points(refbox::GamePhase::kWhackAMoleChallenge);
  s.collisions_robot_robot =
      collisions_[static_cast<std::size_t>(kinematic::CollisionKind::kRobotRobot)];
  s.collisions_robot_wall =
      collisions_[static_cast<std::size_t>(kinematic::CollisionKind::kRobotWall)];
  s.collisions_robot_device =
      collisions_[static_cast<std::size_t>(kinematic::CollisionKind::kRobotDevice)];
  s.comm = hub_->total_counters();
  s.refbox_accepted = refbox_accepted_;
  s.refbox_rejected = refbox_rejected_;
  s.controller_rejected = controller_rejected_;
  s.world_hash = world_->state_hash();
  s.refbox_hash = rb.state_hash();
  return s;
}

}  // namespace llsf::sim
