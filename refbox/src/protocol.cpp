// SPDX-License-Identifier: MIT
// The refbox protocol adapter (docs/refbox-protocol.md): spec §9.7 for what comes in, §9.6 for
// what goes out and when.
#include "llsf/refbox/protocol.h"

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
#include <cmath>
#include <limits>
#include <utility>

#include "llsf/core/assert.h"
#include "llsf/core/error.h"

namespace llsf::refbox {

namespace {

using google::protobuf::Message;
using Level = ProtocolLogLine::Level;

constexpr std::int64_t kNsPerSec = 1000000000;
/// Largest |Time.sec| that fits SimTime's int64 nanoseconds (with room for nsec).
constexpr std::int64_t kMaxTimeSec = std::numeric_limits<std::int64_t>::max() / kNsPerSec - 1;

/// (sec, nsec) of `time`, floored, so that nsec is always in [0, 1e9) as Time expects.
std::pair<std::int64_t, std::int64_t> split_time(SimTime time) {
  std::int64_t sec = time.ns() / kNsPerSec;
  std::int64_t nsec = time.ns() % kNsPerSec;
  if (nsec < 0) {
    nsec += kNsPerSec;
    --sec;
  }
  return {sec, nsec};
}

void set_time(llsf_msgs::Time* t, SimTime time) {
  const auto [sec, nsec] = split_time(time);
  t->set_sec(sec);
  t->set_nsec(nsec);
}

void set_pose(llsf_msgs::Pose2D* p, const core::Pose2D& pose, SimTime stamp) {
  set_time(p->mutable_timestamp(), stamp);
  p->set_x(static_cast<float>(pose.x));
  p->set_y(static_cast<float>(pose.y));
  p->set_ori(static_cast<float>(pose.theta));
}

llsf_msgs::LightState to_msg(LightState s) {
  switch (s) {
    case LightState::kOff:
      return llsf_msgs::OFF;
    case LightState::kOn:
      return llsf_msgs::ON;
    case LightState::kBlink:
      return llsf_msgs::BLINK;
  }
  return llsf_msgs::OFF;
}

llsf_msgs::PuckState to_msg(PuckState s) {
  switch (s) {
    case PuckState::kS0:
      return llsf_msgs::S0;
    case PuckState::kS1:
      return llsf_msgs::S1;
    case PuckState::kS2:
      return llsf_msgs::S2;
    case PuckState::kP1:
      return llsf_msgs::P1;
    case PuckState::kP2:
      return llsf_msgs::P2;
    case PuckState::kP3:
      return llsf_msgs::P3;
    case PuckState::kConsumed:
      return llsf_msgs::CONSUMED;
    case PuckState::kFinished:
      return llsf_msgs::FINISHED;
  }
  return llsf_msgs::S0;
}

llsf_msgs::RobotState to_msg(RobotState s) {
  switch (s) {
    case RobotState::kActive:
      return llsf_msgs::ACTIVE;
    case RobotState::kMaintenance:
      return llsf_msgs::MAINTENANCE;
    case RobotState::kDisqualified:
      return llsf_msgs::DISQUALIFIED;
  }
  return llsf_msgs::ACTIVE;
}

llsf_msgs::Order::ProductType to_msg_product(PuckState s) {
  switch (s) {
    case PuckState::kP1:
      return llsf_msgs::Order::P1;
    case PuckState::kP2:
      return llsf_msgs::Order::P2;
    default:
      return llsf_msgs::Order::P3;
  }
}

/// The three LightSpecs R, Y, G of `l`.
template <class M>
void add_lights(M* m, const Lights& l) {
  const std::array<std::pair<llsf_msgs::LightColor, LightState>, 3> lamps = {
      {{llsf_msgs::RED, l.red}, {llsf_msgs::YELLOW, l.yellow}, {llsf_msgs::GREEN, l.green}}};
  for (const auto& [color, state] : lamps) {
    llsf_msgs::LightSpec* s = m->add_lights();
    s->set_color(color);
    s->set_state(to_msg(state));
  }
}

/// `msg` as a T: the generated class itself, or (for a DynamicMessage of the same type) a copy
/// made through the wire format into `scratch`. Null if `msg` is of another type.
template <class T>
const T* as(const Message& msg, T& scratch) {
  if (const T* t = dynamic_cast<const T*>(&msg)) return t;
  if (msg.GetDescriptor()->full_name() != T::descriptor()->full_name()) return nullptr;
  scratch.Clear();
  if (!scratch.ParsePartialFromString(msg.SerializePartialAsString())) return nullptr;
  return &scratch;
}

std::string origin_label(const Origin& from) {
  if (from.channel == Origin::Channel::kStream) {
    return "stream client " + std::to_string(from.client) + " (" + from.host + ")";
  }
  return "host " + from.host + ":" + std::to_string(from.port);
}

bool fits_int(std::uint64_t v) { return v <= std::uint64_t(std::numeric_limits<int>::max()); }

}  // namespace

// ---------------------------------------------------------------------------------------------
// Enum conversions (spec §9.4)
// ---------------------------------------------------------------------------------------------

llsf_msgs::GameState::Phase to_msg_phase(GamePhase p) {
  switch (p) {
    case GamePhase::kPreGame:
      return llsf_msgs::GameState::PRE_GAME;
    case GamePhase::kSetup:
      return llsf_msgs::GameState::SETUP;
    case GamePhase::kExploration:
      return llsf_msgs::GameState::EXPLORATION;
    case GamePhase::kProduction:
      return llsf_msgs::GameState::PRODUCTION;
    case GamePhase::kPostGame:
      return llsf_msgs::GameState::POST_GAME;
    case GamePhase::kOpenChallenge:
      return llsf_msgs::GameState::OPEN_CHALLENGE;
    case GamePhase::kNavigationChallenge:
      return llsf_msgs::GameState::NAVIGATION_CHALLENGE;
    case GamePhase::kWhackAMoleChallenge:
      return llsf_msgs::GameState::WHACK_A_MOLE_CHALLENGE;
  }
  LLSF_DEMAND_MSG(false, "to_msg_phase: unknown GamePhase");
  return llsf_msgs::GameState::PRE_GAME;
}

std::optional<GamePhase> from_msg_phase(int phase) {
  if (!llsf_msgs::GameState::Phase_IsValid(phase)) return std::nullopt;
  switch (static_cast<llsf_msgs::GameState::Phase>(phase)) {
    case llsf_msgs::GameState::PRE_GAME:
      return GamePhase::kPreGame;
    case llsf_msgs::GameState::SETUP:
      return GamePhase::kSetup;
    case llsf_msgs::GameState::EXPLORATION:
      return GamePhase::kExploration;
    case llsf_msgs::GameState::PRODUCTION:
      return GamePhase::kProduction;
    case llsf_msgs::GameState::POST_GAME:
      return GamePhase::kPostGame;
    case llsf_msgs::GameState::OPEN_CHALLENGE:
      return GamePhase::kOpenChallenge;
    case llsf_msgs::GameState::NAVIGATION_CHALLENGE:
      return GamePhase::kNavigationChallenge;
    case llsf_msgs::GameState::WHACK_A_MOLE_CHALLENGE:
      return GamePhase::kWhackAMoleChallenge;
  }
  return std::nullopt;
}

llsf_msgs::GameState::RefBoxMode to_msg_mode(RefBoxMode m) {
  switch (m) {
    case RefBoxMode::kStandalone:
      return llsf_msgs::GameState::STANDALONE;
    case RefBoxMode::kMaster:
      return llsf_msgs::GameState::MASTER;
    case RefBoxMode::kSlave:
      return llsf_msgs::GameState::SLAVE;
  }
  LLSF_DEMAND_MSG(false, "to_msg_mode: unknown RefBoxMode");
  return llsf_msgs::GameState::STANDALONE;
}

llsf_msgs::GameState::State to_msg_state(GameState s) {
  switch (s) {
    case GameState::kInit:
      return llsf_msgs::GameState::INIT;
    case GameState::kWaitStart:
      return llsf_msgs::GameState::WAIT_START;
    case GameState::kRunning:
      return llsf_msgs::GameState::RUNNING;
    case GameState::kPaused:
      return llsf_msgs::GameState::PAUSED;
  }
  LLSF_DEMAND_MSG(false, "to_msg_state: unknown GameState");
  return llsf_msgs::GameState::INIT;
}

std::optional<GameState> from_msg_state(int state) {
  if (!llsf_msgs::GameState::State_IsValid(state)) return std::nullopt;
  switch (static_cast<llsf_msgs::GameState::State>(state)) {
    case llsf_msgs::GameState::INIT:
      return GameState::kInit;
    case llsf_msgs::GameState::WAIT_START:
      return GameState::kWaitStart;
    case llsf_msgs::GameState::RUNNING:
      return GameState::kRunning;
    case llsf_msgs::GameState::PAUSED:
      return GameState::kPaused;
  }
  return std::nullopt;
}

// ---------------------------------------------------------------------------------------------
// Configuration
// ---------------------------------------------------------------------------------------------

void ProtocolConfig::validate() const {
  const auto positive = [](SimTime t, const char* field) {
    if (t <= SimTime()) {
      throw core::ConfigError(std::string("protocol.") + field + ": must be > 0");
    }
  };
  const auto non_negative = [](int v, const char* field) {
    if (v < 0) throw core::ConfigError(std::string("protocol.") + field + ": must be >= 0");
  };
  positive(beacon_period, "beacon_period");
  positive(game_state_period, "game_state_period");
  positive(version_burst_period, "version_burst_period");
  positive(exploration_info_period, "exploration_info_period");
  positive(machine_report_info_period, "machine_report_info_period");
  positive(machine_info_robot_burst_period, "machine_info_robot_burst_period");
  positive(machine_info_robot_period, "machine_info_robot_period");
  positive(machine_info_controller_period, "machine_info_controller_period");
  positive(order_info_burst_period, "order_info_burst_period");
  positive(order_info_period, "order_info_period");
  positive(robot_info_stream_period, "robot_info_stream_period");
  positive(robot_info_peer_period, "robot_info_peer_period");
  positive(puck_info_period, "puck_info_period");
  non_negative(version_burst_count, "version_burst_count");
  non_negative(machine_info_robot_burst_count, "machine_info_robot_burst_count");
  non_negative(order_info_burst_count, "order_info_burst_count");
  non_negative(version_major, "version_major");
  non_negative(version_minor, "version_minor");
  non_negative(version_micro, "version_micro");
}

// ---------------------------------------------------------------------------------------------
// Message pools
// ---------------------------------------------------------------------------------------------

namespace {
/// Pools keep at most this many messages per type; beyond it a message still held elsewhere is
/// forgotten by the pool (its holder keeps it alive) and replaced.
constexpr std::size_t kMaxPoolSlots = 16;
}  // namespace

template <class T>
std::shared_ptr<T> RefboxProtocol::Pool<T>::acquire() {
  for (auto& s : slots_) {
    if (s.use_count() == 1) {
      s->Clear();
      return s;
    }
  }
  if (slots_.size() < kMaxPoolSlots) {
    slots_.push_back(std::make_shared<T>());
    return slots_.back();
  }
  auto& s = slots_[next_replace_];
  next_replace_ = (next_replace_ + 1) % kMaxPoolSlots;
  s = std::make_shared<T>();
  return s;
}

struct RefboxProtocol::Pools {
  Pool<llsf_msgs::BeaconSignal> beacon;
  Pool<llsf_msgs::VersionInfo> version;
  Pool<llsf_msgs::GameInfo> game_info;
  Pool<llsf_msgs::GameState> game_state;
  Pool<llsf_msgs::ExplorationInfo> exploration;
  Pool<llsf_msgs::MachineReportInfo> report_info;
  Pool<llsf_msgs::MachineInfo> machine_info;
  Pool<llsf_msgs::OrderInfo> order_info;
  Pool<llsf_msgs::RobotInfo> robot_info;
  Pool<llsf_msgs::PuckInfo> puck_info;
  Pool<llsf_msgs::AttentionMessage> attention;
  Pool<llsf_log_msgs::LogMessage> log;
  // Scratch copies for messages that arrive as DynamicMessage.
  llsf_msgs::BeaconSignal in_beacon;
  llsf_msgs::MachineReport in_report;
  llsf_msgs::SetGameState in_set_state;
  llsf_msgs::SetGamePhase in_set_phase;
  llsf_msgs::SetTeamName in_set_team;
  llsf_msgs::SetRobotMaintenance in_maintenance;
  llsf_msgs::PlacePuckUnderMachine in_place;
  llsf_msgs::RemovePuckFromMachine in_remove;
  llsf_msgs::LoadPuckInMachine in_load;
  llsf_msgs::SetPucks in_set_pucks;
  llsf_msgs::InitiateSync in_initiate_sync;
  llsf_msgs::SyncInfo in_sync_info;
  llsf_msgs::GameState in_game_state;
};

// ---------------------------------------------------------------------------------------------
// Construction and clients
// ---------------------------------------------------------------------------------------------

RefboxProtocol::RefboxProtocol(RefboxConfig config, const core::Rng& rng, ProtocolConfig protocol)
    : config_(std::move(protocol)),
      refbox_(std::move(config), rng),
      pools_(std::make_unique<Pools>()) {
  config_.validate();
  commands_.reserve(8);
  beacons_.reserve(8);
  reports_.reserve(4);
  out_.reserve(32);
  log_pending_.reserve(8);
  log_out_.reserve(8);
  // A refbox that has not stepped yet has no output; an empty one stands in.
  static const StepOutput kNoOutput{};
  engine_out_ = &kNoOutput;
}

RefboxProtocol::~RefboxProtocol() = default;

void RefboxProtocol::client_connected(int client) {
  if (std::find(clients_.begin(), clients_.end(), client) != clients_.end()) return;
  clients_.push_back(client);
  new_clients_.push_back(client);
  // Spec §9.6: the periodic messages a controller needs go out at once; the peers-only ones
  // (RobotInfo and MachineInfo to robots) keep their rhythm, as in 0.6.1 (a controller
  // reconnecting in a loop must not flood the robots).
  for (Timer* t :
       {&game_state_, &robot_info_stream_, &machine_info_controller_, &puck_info_, &order_info_}) {
    t->due = std::min(t->due, now_);
    t->restart = true;
  }
}

void RefboxProtocol::client_disconnected(int client) {
  std::erase(clients_, client);
  std::erase(new_clients_, client);
  std::erase(sync_requests_, client);
}

void RefboxProtocol::master_connected() {
  master_link_ = true;
  send_initiate_sync_ = true;
  game_state_.due = std::min(game_state_.due, now_);
  game_state_.restart = true;
}

void RefboxProtocol::master_disconnected() {
  master_link_ = false;
  send_initiate_sync_ = false;
}

// ---------------------------------------------------------------------------------------------
// Incoming messages (spec §9.7)
// ---------------------------------------------------------------------------------------------

void RefboxProtocol::log(Level level, std::string text) {
  log_pending_.push_back({now_, level, std::move(text)});
}

ReceiveResult RefboxProtocol::reject(std::string reason) {
  log(Level::kWarn, "Rejected: " + reason);
  return {ReceiveStatus::kRejected, std::move(reason)};
}

ReceiveResult RefboxProtocol::illegal(const char* what, const Origin& from, bool applied) {
  std::string reason = std::string("Illegal ") + what + " message received from " +
                       origin_label(from) +
                       (applied ? " (applied anyway, as refbox 0.6.1 does)"
                                : " (controller messages only via stream)");
  log(Level::kWarn, reason);
  return {applied ? ReceiveStatus::kAcceptedIllegal : ReceiveStatus::kRejected, std::move(reason)};
}

ReceiveResult RefboxProtocol::receive(const Message& msg, const Origin& from) {
  Pools& p = *pools_;
  const bool stream = from.channel == Origin::Channel::kStream;
  const std::string& type = msg.GetDescriptor()->full_name();
  if (!msg.IsInitialized()) {
    return reject(type + " lacks required fields: " + msg.InitializationErrorString());
  }
  const GamePhase phase = refbox_.phase();
  const GameState state = refbox_.state();
  const auto phase_text = [&] {
    return std::string(to_string(phase)) + ", " + std::string(to_string(state));
  };

  // Refbox-to-refbox synchronisation (spec §10): InitiateSync and GameState from a slave
  // (stream client of a MASTER), SyncInfo and GameState from the master (link of a SLAVE).
  const RefBoxMode mode = refbox_.mode();
  if (as(msg, p.in_initiate_sync)) {
    if (!stream || mode != RefBoxMode::kMaster) {
      return reject("InitiateSync is only accepted by a MASTER from a stream client (this is " +
                    std::string(to_string(mode)) + ", message from " + origin_label(from) + ")");
    }
    if (std::find(sync_requests_.begin(), sync_requests_.end(), from.client) ==
        sync_requests_.end()) {
      sync_requests_.push_back(from.client);
    }
    return {};
  }
  if (const auto* m = as(msg, p.in_sync_info)) {
    if (from.channel != Origin::Channel::kMaster || mode != RefBoxMode::kSlave) {
      return reject("SyncInfo is only accepted by a SLAVE from its master (this is " +
                    std::string(to_string(mode)) + ", message from " + origin_label(from) + ")");
    }
    std::string error;
    const auto params = from_sync_info(*m, error);
    if (!params) return reject("SyncInfo: " + error);
    const SyncResult r = refbox_.sync_from(*params);
    switch (r.status) {
      case SyncResult::Status::kApplied:
        log(Level::kInfo, "Game plan taken from the master");
        return {};
      case SyncResult::Status::kNotSlave:
        return reject("SyncInfo: this refbox is no SLAVE");
      case SyncResult::Status::kAlreadyParameterised:
        return reject("SyncInfo: the game already has its plan (it left PRE_GAME)");
      case SyncResult::Status::kInvalid:
        return reject("SyncInfo: " + r.reason);
    }
    return reject("SyncInfo: not applied");
  }
  if (const auto* m = as(msg, p.in_game_state)) {
    const bool from_slave = stream && mode == RefBoxMode::kMaster;
    const bool from_master = from.channel == Origin::Channel::kMaster && mode == RefBoxMode::kSlave;
    if (!from_slave && !from_master) {
      return reject("GameState is only accepted between a MASTER and its SLAVE (this is " +
                    std::string(to_string(mode)) + ", message from " + origin_label(from) + ")");
    }
    const auto ph = from_msg_phase(m->phase());
    const auto st = from_msg_state(m->state());
    if (!ph || !st) return reject("GameState: invalid phase or state");
    if (m->game_time().nsec() < 0 || m->game_time().nsec() >= kNsPerSec ||
        std::abs(m->game_time().sec()) > kMaxTimeSec) {
      return reject("GameState.game_time out of range");
    }
    PeerGameState g;
    g.phase = *ph;
    g.state = *st;
    g.game_time = SimTime::from_ns(m->game_time().sec() * kNsPerSec + m->game_time().nsec());
    g.points = fits_int(m->points()) ? static_cast<int>(m->points()) : 0;
    peer_game_state_ = g;
    return {};
  }
  if (from.channel == Origin::Channel::kMaster) {
    return reject(type + ": only SyncInfo and GameState are accepted from the master");
  }

  // Robots: beacons (UDP only) and exploration reports (any channel).
  if (const auto* m = as(msg, p.in_beacon)) {
    if (stream)
      return reject("BeaconSignal is only accepted via UDP (from " + origin_label(from) + ")");
    if (!fits_int(m->number())) {
      return reject("BeaconSignal.number " + std::to_string(m->number()) + " out of range");
    }
    if (m->time().nsec() < 0 || m->time().nsec() >= kNsPerSec ||
        std::abs(m->time().sec()) > kMaxTimeSec) {
      return reject("BeaconSignal.time out of range (sec " + std::to_string(m->time().sec()) +
                    ", nsec " + std::to_string(m->time().nsec()) + ")");
    }
    Beacon b;
    b.time = SimTime::from_ns(m->time().sec() * kNsPerSec + m->time().nsec());
    b.team = m->team_name();
    b.peer_name = m->peer_name();
    b.number = static_cast<int>(m->number());
    b.host = from.host;
    b.port = from.port;
    ReceiveResult result;
    if (m->has_pose()) {
      const auto& q = m->pose();
      if (std::isfinite(q.x()) && std::isfinite(q.y()) && std::isfinite(q.ori())) {
        b.pose = core::Pose2D{q.x(), q.y(), q.ori()};
      } else {
        result.reason = "BeaconSignal.pose is not finite; pose dropped";
        log(Level::kWarn, result.reason + " (" + origin_label(from) + ")");
      }
    }
    // A beacon from a new (host, port) starts the VersionInfo burst (not for other refboxes,
    // which the engine never registers).
    const bool refbox_beacon = b.team == "LLSF" && b.peer_name == "RefBox";
    const auto same = [&](const std::string& h, int port) {
      return h == from.host && port == from.port;
    };
    const bool known = std::any_of(refbox_.robots().begin(), refbox_.robots().end(),
                                   [&](const Robot& r) { return same(r.host, r.port); }) ||
                       std::any_of(pending_sources_.begin(), pending_sources_.end(),
                                   [&](const auto& s) { return same(s.first, s.second); });
    if (!known && !refbox_beacon) {
      pending_sources_.emplace_back(from.host, from.port);
      version_burst_requested_ = true;
    }
    beacons_.push_back(std::move(b));
    return result;
  }
  if (const auto* m = as(msg, p.in_report)) {
    if (phase != GamePhase::kExploration) {
      return reject("MachineReport is only scored in EXPLORATION (now " + phase_text() + ")");
    }
    MachineReport r;
    std::string bad;
    for (const auto& e : m->machines()) {
      const auto d = device_by_name(e.name());
      if (!d || !is_production_machine(*d)) {
        bad += (bad.empty() ? "" : ", ") + ("'" + e.name() + "'");
        continue;
      }
      r.machines.push_back({e.name(), e.type()});
    }
    if (r.machines.empty()) {
      return reject("MachineReport names no machine M1..M10" +
                    (bad.empty() ? std::string() : " (unknown: " + bad + ")"));
    }
    reports_.push_back(std::move(r));
    if (bad.empty()) return {};
    std::string reason = "MachineReport entries for unknown machines ignored: " + bad;
    log(Level::kWarn, reason);
    return {ReceiveStatus::kAccepted, std::move(reason)};
  }

  // Controller commands: channel rules of §9.7.
  if (const auto* m = as(msg, p.in_set_state)) {
    if (!stream) return illegal("SetGameState", from, false);
    const auto s = from_msg_state(m->state());
    if (!s) return reject("SetGameState.state " + std::to_string(m->state()) + " is invalid");
    queue_command(command::SetGameState{*s});
    return {};
  }
  if (const auto* m = as(msg, p.in_set_phase)) {
    const auto ph = from_msg_phase(m->phase());
    if (!ph) return reject("SetGamePhase.phase " + std::to_string(m->phase()) + " is invalid");
    queue_command(command::SetGamePhase{*ph});
    // 0.6.1 logs a UDP copy as illegal, but its handler applies it all the same.
    if (!stream) return illegal("SetGamePhase", from, true);
    return {};
  }
  if (const auto* m = as(msg, p.in_set_team)) {
    if (!stream) return illegal("SetTeamName", from, false);
    queue_command(command::SetTeamName{m->team_name()});
    return {};
  }
  if (const auto* m = as(msg, p.in_maintenance)) {
    if (!stream) return illegal("SetRobotMaintenance", from, false);
    if (!fits_int(m->robot_number())) {
      return reject("SetRobotMaintenance.robot_number " + std::to_string(m->robot_number()) +
                    " out of range");
    }
    queue_command(
        command::SetRobotMaintenance{static_cast<int>(m->robot_number()), m->maintenance()});
    return {};
  }

  // Puck commands: name and id checks shared by Place, Remove and Load.
  const auto resolve = [&](const char* what, const std::string& name, std::uint32_t puck_id,
                           std::optional<DeviceId>& device, std::string& error) {
    device = device_by_name(name);
    if (!device) {
      error = std::string(what) + ": unknown machine '" + name + "'";
    } else if (puck_id == 0 || !fits_int(puck_id)) {
      error = std::string(what) + ": invalid puck id " + std::to_string(puck_id);
    } else if (phase != GamePhase::kProduction) {
      error = std::string(what) + " only in PRODUCTION (now " + phase_text() + ")";
    }
    return error.empty();
  };
  std::optional<DeviceId> device;
  std::string error;
  if (const auto* m = as(msg, p.in_place)) {
    if (!stream) return illegal("PlacePuckUnderMachine", from, false);
    if (!resolve("PlacePuckUnderMachine", m->machine_name(), m->puck_id(), device, error)) {
      return reject(error);
    }
    if (state != GameState::kRunning) {
      return reject("PlacePuckUnderMachine only while RUNNING (now " + phase_text() + ")");
    }
    queue_command(command::PlacePuck{*device, PuckId(static_cast<int>(m->puck_id()))});
    return {};
  }
  if (const auto* m = as(msg, p.in_remove)) {
    if (!resolve("RemovePuckFromMachine", m->machine_name(), m->puck_id(), device, error)) {
      return reject(error);
    }
    queue_command(command::RemovePuck{*device, PuckId(static_cast<int>(m->puck_id()))});
    // 0.6.1 only logs a UDP copy as illegal.
    if (!stream) return illegal("RemovePuckFromMachine", from, true);
    return {};
  }
  if (const auto* m = as(msg, p.in_load)) {
    if (!stream) return illegal("LoadPuckInMachine", from, false);
    if (!resolve("LoadPuckInMachine", m->machine_name(), m->puck_id(), device, error)) {
      return reject(error);
    }
    if (!is_production_machine(*device)) {
      return reject("LoadPuckInMachine: " + m->machine_name() + " is no production machine");
    }
    queue_command(command::LoadPuck{*device, PuckId(static_cast<int>(m->puck_id()))});
    return {};
  }
  if (const auto* m = as(msg, p.in_set_pucks)) {
    command::SetPucks c;
    c.ids.reserve(std::size_t(m->ids_size()));
    for (std::uint32_t id : m->ids()) {
      if (id == 0 || !fits_int(id))
        return reject("SetPucks: invalid puck id " + std::to_string(id));
      if (std::find(c.ids.begin(), c.ids.end(), int(id)) != c.ids.end()) {
        return reject("SetPucks: puck id " + std::to_string(id) + " given twice");
      }
      c.ids.push_back(static_cast<int>(id));
    }
    queue_command(c);
    return {};
  }

  return reject(type + " is not accepted by the refbox (from " + origin_label(from) + ")");
}

// ---------------------------------------------------------------------------------------------
// The step
// ---------------------------------------------------------------------------------------------

std::span<const Outgoing> RefboxProtocol::step(SimTime now, const WorldInputs& world) {
  out_.clear();
  log_out_.clear();
  LLSF_DEMAND_MSG(!stepped_ || now >= now_, "RefboxProtocol::step: time went backwards");
  now_ = now;
  stepped_ = true;

  // 1. The engine, with everything received since the last step.
  StepInput in;
  in.rfid = world.rfid;
  in.commands = commands_;
  in.beacons = beacons_;
  in.reports = reports_;
  in.insertion_slot_occupied = world.insertion_slot_occupied;
  in.robot_poses = world.robot_poses;
  in.peer_game_state = peer_game_state_;
  const StepOutput& eo = refbox_.step(now, in);
  engine_out_ = &eo;
  commands_.clear();
  beacons_.clear();
  reports_.clear();
  pending_sources_.clear();
  peer_game_state_.reset();

  // 2. Bursts started by this step's events.
  if (version_burst_requested_) {
    version_burst_requested_ = false;
    version_.burst_left = config_.version_burst_count;
    version_.due = now;
  }
  if (eo.phase_changed && refbox_.phase() == GamePhase::kProduction) {
    machine_info_robot_.burst_left = config_.machine_info_robot_burst_count;
    machine_info_robot_.due = now;
  }
  if (!eo.orders_activated.empty()) {
    order_info_.burst_left = config_.order_info_burst_count;
    order_info_.due = now;
  }

  // 3. Greetings of new stream clients: VersionInfo first, then GameInfo (spec §9.6).
  for (int c : new_clients_) {
    build_version_info({Destination::Kind::kClient, c});
    build_game_info(c);
  }
  new_clients_.clear();
  // Synchronisation: the slave asks its master for the plan; the master answers.
  if (send_initiate_sync_ && master_link_) {
    send_initiate_sync_ = false;
    emit({Destination::Kind::kMaster, -1}, std::make_shared<const llsf_msgs::InitiateSync>());
  }
  for (int c : sync_requests_) build_sync_info(c);
  sync_requests_.clear();

  // 4. Periodic messages, then event messages.
  emit_periodic();
  if (!clients_.empty()) {
    for (const AttentionMessage& a : eo.attention) {
      auto m = pools_->attention.acquire();
      m->set_message(a.text);
      m->set_time_to_show(static_cast<float>(a.time_to_show_s));
      emit_all_clients(std::move(m));
    }
  }
  log_out_.swap(log_pending_);
  if (config_.send_log_messages && !clients_.empty()) {
    for (const ProtocolLogLine& l : log_out_) {
      auto m = pools_->log.acquire();
      const auto [sec, nsec] = split_time(l.time);
      m->set_ts_sec(sec);
      m->set_ts_nsec(nsec);
      m->set_log_level(static_cast<llsf_log_msgs::LogMessage::LogLevel>(l.level));
      m->set_component("refbox");
      m->set_message(l.text);
      emit_all_clients(std::move(m));
    }
  }
  return out_;
}

bool RefboxProtocol::fire(Timer& t, SimTime period, SimTime burst_period) {
  if (now_ < t.due) return false;
  if (t.burst_left > 0) --t.burst_left;
  if (t.restart) t.due = now_;
  t.restart = false;
  t.due += t.burst_left > 0 ? burst_period : period;
  // A step longer than the period sends once, not a catch-up series.
  if (t.due <= now_) t.due = now_ + (t.burst_left > 0 ? burst_period : period);
  return true;
}

void RefboxProtocol::emit(Destination to, std::shared_ptr<const Message> msg) {
  out_.push_back({to, std::move(msg)});
}

void RefboxProtocol::emit_all_clients(std::shared_ptr<const Message> msg) {
  emit({Destination::Kind::kAllClients, -1}, std::move(msg));
}

void RefboxProtocol::emit_periodic() {
  const ProtocolConfig& c = config_;
  const GamePhase phase = refbox_.phase();
  const bool has_clients = !clients_.empty();
  if (fire(beacon_, c.beacon_period, c.beacon_period)) build_beacon();
  if (version_.burst_left > 0 && now_ >= version_.due) {
    --version_.burst_left;
    version_.due += c.version_burst_period;
    if (version_.due <= now_) version_.due = now_ + c.version_burst_period;
    build_version_info({Destination::Kind::kAllPeers, -1});
  }
  if (fire(game_state_, c.game_state_period, c.game_state_period)) build_game_state();
  // Phase-bound messages: outside their phase the rhythm pauses and restarts with the first
  // message of the next occasion.
  const bool exploration = phase == GamePhase::kExploration;
  const bool production = phase == GamePhase::kProduction;
  for (Timer* t : {&exploration_info_, &machine_report_info_}) t->restart |= !exploration;
  for (Timer* t : {&machine_info_robot_, &order_info_}) t->restart |= !production;
  if (exploration) {
    if (fire(exploration_info_, c.exploration_info_period, c.exploration_info_period)) {
      build_exploration_info();
    }
    if (fire(machine_report_info_, c.machine_report_info_period, c.machine_report_info_period)) {
      build_machine_report_info();
    }
  }
  if (production &&
      fire(machine_info_robot_, c.machine_info_robot_period, c.machine_info_robot_burst_period)) {
    build_machine_info_robot();
  }
  if (fire(machine_info_controller_, c.machine_info_controller_period,
           c.machine_info_controller_period) &&
      has_clients) {
    build_machine_info_controller();
  }
  if (production && fire(order_info_, c.order_info_period, c.order_info_burst_period)) {
    build_order_info();
  }
  if (fire(robot_info_stream_, c.robot_info_stream_period, c.robot_info_stream_period) &&
      has_clients) {
    build_robot_info(true);
  }
  if (fire(robot_info_peer_, c.robot_info_peer_period, c.robot_info_peer_period)) {
    build_robot_info(false);
  }
  if (fire(puck_info_, c.puck_info_period, c.puck_info_period) && has_clients) build_puck_info();
}

// ---------------------------------------------------------------------------------------------
// Outgoing messages (spec §9.5, §9.6), built from the engine's snapshot
// ---------------------------------------------------------------------------------------------

void RefboxProtocol::build_beacon() {
  auto m = pools_->beacon.acquire();
  set_time(m->mutable_time(), now_);
  m->set_seq(++beacon_seq_);
  m->set_team_name("LLSF");
  m->set_peer_name("RefBox");
  m->set_number(0);
  emit({Destination::Kind::kAllPeers, -1}, std::move(m));
}

void RefboxProtocol::build_version_info(Destination to) {
  auto m = pools_->version.acquire();
  m->set_version_major(static_cast<std::uint32_t>(config_.version_major));
  m->set_version_minor(static_cast<std::uint32_t>(config_.version_minor));
  m->set_version_micro(static_cast<std::uint32_t>(config_.version_micro));
  m->set_version_string(config_.version_string);
  emit(to, std::move(m));
}

void RefboxProtocol::build_game_info(int client) {
  auto m = pools_->game_info.acquire();
  for (const std::string& t : config_.known_teams) m->add_known_teams(t);
  emit({Destination::Kind::kClient, client}, std::move(m));
}

void RefboxProtocol::build_game_state() {
  const auto fill = [&](llsf_msgs::GameState& m) {
    set_time(m.mutable_game_time(), refbox_.game_time());
    m.set_state(to_msg_state(refbox_.state()));
    m.set_phase(to_msg_phase(refbox_.phase()));
    m.set_points(static_cast<std::uint32_t>(std::max(0, refbox_.points())));
    if (!refbox_.team().empty()) m.set_team(refbox_.team());
  };
  auto peer = pools_->game_state.acquire();
  fill(*peer);
  emit({Destination::Kind::kAllPeers, -1}, std::move(peer));
  if (clients_.empty() && !master_link_) return;
  auto stream = pools_->game_state.acquire();
  fill(*stream);
  stream->set_refbox_mode(to_msg_mode(refbox_.mode()));
  // A slave tells its master how its game stands (the overtime decision needs both).
  std::shared_ptr<const Message> shared = std::move(stream);
  if (master_link_) emit({Destination::Kind::kMaster, -1}, shared);
  if (!clients_.empty()) emit_all_clients(std::move(shared));
}

void RefboxProtocol::build_exploration_info() {
  auto m = pools_->exploration.acquire();
  for (const ExplorationSignal& s : refbox_.exploration_signals()) {
    llsf_msgs::ExplorationSignal* sig = m->add_signals();
    sig->set_type(std::string(to_string(s.type)));
    add_lights(sig, s.lights);
  }
  const auto& poses = refbox_.config().device_poses;
  for (int i = 0; i < kProductionMachineCount; ++i) {
    llsf_msgs::ExplorationMachine* em = m->add_machines();
    em->set_name(std::string(kDeviceNames[std::size_t(i)]));
    set_pose(em->mutable_pose(), poses[std::size_t(i)], now_);
  }
  emit({Destination::Kind::kAllPeers, -1}, std::move(m));
}

void RefboxProtocol::build_machine_report_info() {
  auto m = pools_->report_info.acquire();
  for (DeviceId d : refbox_.reported_machines()) {
    m->add_reported_machines(std::string(device_name(d)));
  }
  emit({Destination::Kind::kAllPeers, -1}, std::move(m));
}

void RefboxProtocol::build_machine_info_robot() {
  auto m = pools_->machine_info.acquire();
  const auto& poses = refbox_.config().device_poses;
  for (const Machine& mach : refbox_.machines()) {
    llsf_msgs::Machine* x = m->add_machines();
    x->set_name(std::string(device_name(mach.id)));
    x->set_type(std::string(to_string(mach.type)));
    const TypeInputs in = inputs_of(mach.type);
    for (int i = 0; i < in.count; ++i) x->add_inputs(to_msg(in.states[std::size_t(i)]));
    if (const auto out = output_of(mach.type)) x->set_output(to_msg(*out));
    set_pose(x->mutable_pose(), poses[std::size_t(mach.id.value())], now_);
  }
  emit({Destination::Kind::kAllPeers, -1}, std::move(m));
}

void RefboxProtocol::build_machine_info_controller() {
  auto m = pools_->machine_info.acquire();
  const auto& poses = refbox_.config().device_poses;
  for (const Machine& mach : refbox_.machines()) {
    llsf_msgs::Machine* x = m->add_machines();
    x->set_name(std::string(device_name(mach.id)));
    x->set_type(std::string(refbox_.shown_type(mach.id)));
    for (PuckId p : mach.loaded_with()) {
      llsf_msgs::Puck* pk = x->add_loaded_with();
      pk->set_id(static_cast<std::uint32_t>(p.value()));
      pk->set_state(to_msg(refbox_.puck_state(p).value_or(PuckState::kS0)));
    }
    if (mach.puck_under_rfid.valid()) {
      llsf_msgs::Puck* pk = x->mutable_puck_under_rfid();
      pk->set_id(static_cast<std::uint32_t>(mach.puck_under_rfid.value()));
      pk->set_state(to_msg(refbox_.puck_state(mach.puck_under_rfid).value_or(PuckState::kS0)));
    }
    add_lights(x, mach.lights);
    set_pose(x->mutable_pose(), poses[std::size_t(mach.id.value())], now_);
    if (mach.correctly_reported) x->set_correctly_reported(*mach.correctly_reported);
  }
  emit_all_clients(std::move(m));
}

void RefboxProtocol::build_order_info() {
  auto m = pools_->order_info.acquire();
  // orders() is sorted by id; only the active ones are shown.
  for (const Order& o : refbox_.orders()) {
    if (!o.active) continue;
    llsf_msgs::Order* x = m->add_orders();
    x->set_id(static_cast<std::uint32_t>(o.id.value()));
    x->set_product(to_msg_product(o.product));
    x->set_quantity_requested(static_cast<std::uint32_t>(o.quantity_requested));
    x->set_quantity_delivered(static_cast<std::uint32_t>(o.quantity_delivered));
    x->set_delivery_period_begin(static_cast<std::uint32_t>(o.window_begin_s));
    x->set_delivery_period_end(static_cast<std::uint32_t>(o.window_end_s));
    x->set_delivery_gate(llsf_msgs::Order::ANY);
  }
  std::shared_ptr<const Message> shared = std::move(m);
  emit({Destination::Kind::kAllPeers, -1}, shared);
  if (!clients_.empty()) emit_all_clients(std::move(shared));
}

void RefboxProtocol::build_robot_info(bool stream) {
  auto m = pools_->robot_info.acquire();
  for (const Robot& r : refbox_.robots()) {
    llsf_msgs::Robot* x = m->add_robots();
    x->set_name(r.name);
    x->set_team(r.team);
    x->set_host(r.host);
    set_time(x->mutable_last_seen(), r.last_seen);
    x->set_number(static_cast<std::uint32_t>(std::max(0, r.number)));
    x->set_state(to_msg(r.state));
    x->set_maintenance_time_remaining(
        static_cast<float>(r.maintenance_time_remaining_s(refbox_.rules())));
    x->set_maintenance_cycles(static_cast<std::uint32_t>(r.maintenance_cycles));
    if (stream && r.pose) set_pose(x->mutable_pose(), *r.pose, r.last_seen);
    if (stream && r.vision_pose) set_pose(x->mutable_vision_pose(), *r.vision_pose, now_);
  }
  if (stream) {
    emit_all_clients(std::move(m));
  } else {
    emit({Destination::Kind::kAllPeers, -1}, std::move(m));
  }
}

void RefboxProtocol::build_puck_info() {
  auto m = pools_->puck_info.acquire();
  for (const Puck& p : refbox_.pucks()) {
    llsf_msgs::Puck* x = m->add_pucks();
    x->set_id(static_cast<std::uint32_t>(p.id.value()));
    x->set_state(to_msg(p.state));
  }
  emit_all_clients(std::move(m));
}

void RefboxProtocol::build_sync_info(int client) {
  auto m = std::make_shared<llsf_msgs::SyncInfo>();
  to_sync_info(refbox_.sync_params(), *m);
  emit({Destination::Kind::kClient, client}, std::move(m));
}

// ---------------------------------------------------------------------------------------------
// SyncInfo <-> GameParams (spec §9.5, §10)
// ---------------------------------------------------------------------------------------------

namespace {
/// Delivery window of regular order i (0..8) in production game time (spec §6).
std::pair<int, int> regular_window(int i) {
  const int third = i / 3;
  return {third * 300, third == 2 ? kPlanProductionS : third * 300 + 299};
}
}  // namespace

void to_sync_info(const GameParams& params, llsf_msgs::SyncInfo& out) {
  out.Clear();
  for (int i = 0; i < kProductionMachineCount; ++i) {
    auto* x = out.add_machines();
    x->set_name(std::string(kDeviceNames[std::size_t(i)]));
    x->set_type(std::string(to_string(params.machine_types[std::size_t(i)])));
  }
  for (int i = 0; i < kRegularOrderCount; ++i) {
    auto* o = out.add_orders();
    o->set_id(static_cast<std::uint32_t>(i + 1));
    o->set_product(i % 3 == 0   ? llsf_msgs::Order::P1
                   : i % 3 == 1 ? llsf_msgs::Order::P2
                                : llsf_msgs::Order::P3);
    o->set_quantity_requested(static_cast<std::uint32_t>(params.order_quantities[std::size_t(i)]));
    o->set_quantity_delivered(0);
    const auto [begin, end] = regular_window(i);
    o->set_delivery_period_begin(static_cast<std::uint32_t>(begin));
    o->set_delivery_period_end(static_cast<std::uint32_t>(end));
    o->set_delivery_gate(llsf_msgs::Order::ANY);
    o->set_late_order(false);
  }
  for (int k = 0; k < kLateOrderCount; ++k) {
    auto* o = out.add_orders();
    const int begin = params.late_order_start_s[std::size_t(k)];
    o->set_id(static_cast<std::uint32_t>(kRegularOrderCount + k + 1));
    o->set_product(llsf_msgs::Order::P3);
    o->set_quantity_requested(1);
    o->set_quantity_delivered(0);
    o->set_delivery_period_begin(static_cast<std::uint32_t>(std::max(0, begin)));
    o->set_delivery_period_end(static_cast<std::uint32_t>(std::max(0, begin + kLateOrderWindowS)));
    o->set_delivery_gate(llsf_msgs::Order::ANY);
    o->set_late_order(true);
  }
  for (const DownTime& d : params.down_times) {
    auto* x = out.add_down_times();
    x->set_machine_name(std::string(device_name(d.device)));
    x->set_gt_from(static_cast<float>(d.start_s));
    x->set_gt_to(static_cast<float>(d.end_s));
  }
  for (const GatePeriod& g : params.gate_schedule) {
    auto* x = out.add_delivery_gates();
    x->set_machine_name(std::string(device_name(g.gate)));
    x->set_gt_from(static_cast<float>(g.start_s));
    x->set_gt_to(static_cast<float>(g.end_s));
  }
  for (int t = 0; t < 5; ++t) {
    auto* x = out.add_proc_times();
    x->set_machine_type(std::string(to_string(static_cast<MachineType>(t))));
    x->set_proc_time(static_cast<std::uint32_t>(std::max(0, params.proc_time_s[std::size_t(t)])));
    auto* l = out.add_exploration_lights();
    l->set_machine_type(std::string(to_string(static_cast<MachineType>(t))));
    add_lights(l, params.light_codes[std::size_t(t)]);
  }
}

std::optional<GameParams> from_sync_info(const llsf_msgs::SyncInfo& in, std::string& error) {
  GameParams p;
  const auto fail = [&](std::string e) {
    error = std::move(e);
    return std::nullopt;
  };
  const auto production_type = [](const std::string& s) -> std::optional<MachineType> {
    const auto t = machine_type_from_string(s);
    if (!t || static_cast<int>(*t) > 4) return std::nullopt;
    return t;
  };
  const auto whole_seconds = [](float v) -> std::optional<int> {
    if (!std::isfinite(v) || v < 0.0f || v > 1e6f || v != std::floor(v)) return std::nullopt;
    return static_cast<int>(v);
  };
  // Machine types: each of M1..M10 exactly once.
  std::array<bool, kProductionMachineCount> have_machine{};
  for (const auto& m : in.machines()) {
    const auto d = device_by_name(m.name());
    if (!d || !is_production_machine(*d)) return fail("unknown machine '" + m.name() + "'");
    const auto t = production_type(m.type());
    if (!t) return fail("machine " + m.name() + ": unknown type '" + m.type() + "'");
    if (have_machine[std::size_t(d->value())]) return fail("machine " + m.name() + " given twice");
    have_machine[std::size_t(d->value())] = true;
    p.machine_types[std::size_t(d->value())] = *t;
  }
  for (int i = 0; i < kProductionMachineCount; ++i) {
    if (!have_machine[std::size_t(i)]) {
      return fail("no type for " + std::string(kDeviceNames[std::size_t(i)]));
    }
  }
  // Processing times and light codes: each of T1..T5 exactly once.
  std::array<bool, 5> have_time{}, have_light{};
  for (const auto& x : in.proc_times()) {
    const auto t = production_type(x.machine_type());
    if (!t) return fail("proc_times: unknown type '" + x.machine_type() + "'");
    if (!fits_int(x.proc_time())) return fail("proc_times: " + x.machine_type() + " out of range");
    have_time[std::size_t(type_index(*t))] = true;
    p.proc_time_s[std::size_t(type_index(*t))] = static_cast<int>(x.proc_time());
  }
  for (const auto& x : in.exploration_lights()) {
    const auto t = production_type(x.machine_type());
    if (!t) return fail("exploration_lights: unknown type '" + x.machine_type() + "'");
    Lights l;
    for (const auto& spec : x.lights()) {
      const LightState st = static_cast<LightState>(spec.state());
      switch (spec.color()) {
        case llsf_msgs::RED:
          l.red = st;
          break;
        case llsf_msgs::YELLOW:
          l.yellow = st;
          break;
        case llsf_msgs::GREEN:
          l.green = st;
          break;
      }
    }
    have_light[std::size_t(type_index(*t))] = true;
    p.light_codes[std::size_t(type_index(*t))] = l;
  }
  for (int t = 0; t < 5; ++t) {
    const std::string name(to_string(static_cast<MachineType>(t)));
    if (!have_time[std::size_t(t)]) return fail("no processing time for " + name);
    if (!have_light[std::size_t(t)]) return fail("no light code for " + name);
  }
  // Orders: quantities of 1..9, window starts of the late orders 10 and 11.
  std::array<bool, kOrderCount> have_order{};
  for (const auto& o : in.orders()) {
    if (o.id() < 1 || o.id() > std::uint32_t(kOrderCount)) {
      return fail("unknown order id " + std::to_string(o.id()));
    }
    const int i = static_cast<int>(o.id()) - 1;
    have_order[std::size_t(i)] = true;
    if (i < kRegularOrderCount) {
      if (!fits_int(o.quantity_requested())) return fail("order quantity out of range");
      p.order_quantities[std::size_t(i)] = static_cast<int>(o.quantity_requested());
    } else {
      if (!fits_int(o.delivery_period_begin())) return fail("late order window out of range");
      p.late_order_start_s[std::size_t(i - kRegularOrderCount)] =
          static_cast<int>(o.delivery_period_begin());
    }
  }
  for (int i = 0; i < kOrderCount; ++i) {
    if (!have_order[std::size_t(i)]) return fail("order " + std::to_string(i + 1) + " missing");
  }
  // Down times and the gate schedule.
  for (const auto& d : in.down_times()) {
    const auto dev = device_by_name(d.machine_name());
    const auto from = whole_seconds(d.gt_from());
    const auto to = whole_seconds(d.gt_to());
    if (!dev) return fail("down_times: unknown machine '" + d.machine_name() + "'");
    if (!from || !to) return fail("down_times: " + d.machine_name() + ": bad game times");
    p.down_times.push_back({*dev, *from, *to});
  }
  for (const auto& g : in.delivery_gates()) {
    const auto dev = device_by_name(g.machine_name());
    const auto from = whole_seconds(g.gt_from());
    const auto to = whole_seconds(g.gt_to());
    if (!dev || !is_gate(*dev))
      return fail("delivery_gates: unknown gate '" + g.machine_name() + "'");
    if (!from || !to) return fail("delivery_gates: " + g.machine_name() + ": bad game times");
    p.gate_schedule.push_back({*dev, *from, *to});
  }
  return p;
}

}  // namespace llsf::refbox
