// SPDX-License-Identifier: MIT
// The 2013 rules engine (spec §2–§8, §10). Section comments follow the tick order of step().
#include "llsf/refbox/refbox.h"

#include <algorithm>
#include <cmath>
#include <utility>

#include "llsf/core/assert.h"
#include "llsf/core/error.h"

namespace llsf::refbox {

namespace {

constexpr LightState kOff = LightState::kOff;
constexpr LightState kOn = LightState::kOn;
constexpr LightState kBlink = LightState::kBlink;

template <class... F>
struct Overloaded : F... {
  using F::operator()...;
};
template <class... F>
Overloaded(F...) -> Overloaded<F...>;

int phase_slot(GamePhase p) {
  switch (p) {
    case GamePhase::kPreGame:
      return 0;
    case GamePhase::kSetup:
      return 1;
    case GamePhase::kExploration:
      return 2;
    case GamePhase::kProduction:
      return 3;
    case GamePhase::kPostGame:
      return 4;
    case GamePhase::kOpenChallenge:
      return 5;
    case GamePhase::kNavigationChallenge:
      return 6;
    case GamePhase::kWhackAMoleChallenge:
      return 7;
  }
  return 0;
}
constexpr std::array<GamePhase, 8> kPhases = {GamePhase::kPreGame,
                                              GamePhase::kSetup,
                                              GamePhase::kExploration,
                                              GamePhase::kProduction,
                                              GamePhase::kPostGame,
                                              GamePhase::kOpenChallenge,
                                              GamePhase::kNavigationChallenge,
                                              GamePhase::kWhackAMoleChallenge};

/// Points when a production machine completes its set (RBX 0.6.1 = RB).
int completion_points(MachineType t) {
  switch (t) {
    case MachineType::kT2:
      return 4;
    case MachineType::kT3:
    case MachineType::kT4:
      return 12;
    default:
      return 0;
  }
}

/// Lamps of the test station for a puck state (spec §2.5).
Lights test_lights(PuckState s) {
  switch (s) {
    case PuckState::kS0:
      return {kOff, kOn, kOff};
    case PuckState::kS1:
      return {kOn, kOn, kOff};
    case PuckState::kS2:
      return {kOn, kOff, kOff};
    case PuckState::kP1:
      return {kOff, kOff, kBlink};
    case PuckState::kP2:
      return {kOff, kBlink, kOff};
    case PuckState::kP3:
      return {kBlink, kOff, kOff};
    case PuckState::kConsumed:
      return kAllOff;
    case PuckState::kFinished:
      return {kBlink, kBlink, kBlink};
  }
  return kAllOff;
}

std::string robot_label(const Robot& r) {
  return r.name + " (" + r.team + " #" + std::to_string(r.number) + ", " + r.host + ":" +
         std::to_string(r.port) + ")";
}

}  // namespace

double Robot::maintenance_time_remaining_s(const RulesVariant& rules) const {
  if (state != RobotState::kMaintenance) return 0.0;
  return (rules.maintenance_allowed - maintenance_elapsed).seconds();
}

// ---------------------------------------------------------------------------------------------
// Construction
// ---------------------------------------------------------------------------------------------

Refbox::Refbox(RefboxConfig config, const core::Rng& rng)
    : config_(std::move(config)), rng_(rng.stream("refbox")), seed_(rng.seed()) {
  config_.validate();
  rules_ = make_rules_variant(config_.rules);
  if (config_.recycle_points) rules_.recycle_points = *config_.recycle_points;
  team_ = config_.team;
  for (int i = 0; i < kDeviceCount; ++i) {
    Machine& m = machines_[i];
    m.id = DeviceId(i);
    if (i < kProductionMachineCount) {
      m.type = MachineType::kT1;  // replaced at parameterisation; shown as "?" until PRODUCTION
    } else if (i == kR1 || i == kR2) {
      m.type = MachineType::kRecycle;
    } else if (i == kTst) {
      m.type = MachineType::kTest;
    } else {
      m.type = MachineType::kDeliver;
    }
  }
  reset_pucks(config_.pucks);
  // Capacity for a whole game, so that steady-state steps do not allocate.
  awards_.reserve(512);
  history_.reserve(4096);
  deliveries_.reserve(128);
  pending_.reserve(32);
  reported_.reserve(kProductionMachineCount);
  robots_.reserve(8);
  out_.awards.reserve(16);
  out_.attention.reserve(16);
  out_.actions.reserve(8);
  out_.orders_activated.reserve(kOrderCount);
  update_lights();
  out_.lights_changed_mask = 0;
}

// ---------------------------------------------------------------------------------------------
// The step
// ---------------------------------------------------------------------------------------------

const StepOutput& Refbox::step(SimTime now, const StepInput& in) {
  out_.awards.clear();
  out_.attention.clear();
  out_.actions.clear();
  out_.orders_activated.clear();
  out_.lights_changed_mask = 0;
  out_.phase_changed = false;
  out_.state_changed = false;
  slot_occupied_ = in.insertion_slot_occupied;

  SimTime dt;
  if (started_) {
    LLSF_DEMAND_MSG(now >= now_, "Refbox::step: time went backwards");
    dt = now - now_;
  }
  now_ = now;
  if (!started_) {
    started_ = true;
    if (state_ == GameState::kInit) set_state(GameState::kWaitStart);
  }

  // 1. Game time and phase ends; in synchronised mode the other field's state may end the
  //    wait at the regular production end (overtime or POST_GAME).
  advance_time(dt);
  if (in.peer_game_state) handle_peer(*in.peer_game_state);
  // 2. Controller commands.
  for (const Command& c : in.commands) apply(c);
  // 3. Beacons and machine reports, then the overhead-camera poses (whack-a-mole).
  for (const Beacon& b : in.beacons) handle_beacon(b);
  for (const MachineReport& r : in.reports) handle_report(r);
  update_vision(in.robot_poses);
  update_whack_a_mole(in.robot_poses);
  // 4. RFID zones.
  for (const RfidEvent& e : in.rfid) handle_rfid(e);
  // 5. Scheduled production rules.
  if (production_running()) run_schedule();
  // 6. Readers: every removal first, so that a puck moving between two readers in one step is
  //    never seen at both.
  for (Machine& m : machines_) poll_device(m, true);
  for (Machine& m : machines_) poll_device(m, false);
  // 7. Robots.
  update_robots(dt);
  // 8. Lights.
  update_lights();
  return out_;
}

// ---------------------------------------------------------------------------------------------
// Phases, states and game time
// ---------------------------------------------------------------------------------------------

SimTime Refbox::phase_duration(GamePhase p) const {
  switch (p) {
    case GamePhase::kSetup:
      return config_.setup_duration;
    case GamePhase::kExploration:
      return config_.exploration_duration;
    case GamePhase::kProduction:
      return overtime_ ? config_.production_duration + config_.overtime_duration
                       : config_.production_duration;
    case GamePhase::kNavigationChallenge:
      return rules_.navigation_challenge_duration;
    case GamePhase::kWhackAMoleChallenge:
      return rules_.whack_a_mole_duration;
    default:
      return SimTime();  // PRE_GAME, POST_GAME, OPEN_CHALLENGE: game time stands still
  }
}

bool Refbox::awaiting_overtime_decision() const {
  return config_.synchronised() && phase_ == GamePhase::kProduction && !overtime_ &&
         game_time_ >= config_.production_duration;
}

void Refbox::advance_time(SimTime dt) {
  // Game time runs only while RUNNING in a timed phase (spec §4).
  if (state_ != GameState::kRunning || !timed(phase_)) return;
  game_time_ += dt;
  if (phase_ == GamePhase::kSetup && !setup_warned_ &&
      game_time_.ns() * 10 >= config_.setup_duration.ns() * 9) {
    setup_warned_ = true;
    attention("Setup phase about to end", 10.0);
  }
  // A phase that ends hands the remaining time to the next one (exact for any step size).
  while (state_ == GameState::kRunning && phase_duration(phase_) > SimTime() &&
         game_time_ >= phase_duration(phase_)) {
    const SimTime end = phase_duration(phase_);
    const SimTime carry = game_time_ - end;
    if (awaiting_overtime_decision()) {
      // Synchronised play-off (spec §10): each field pauses at the regular end and waits for
      // the other one (handle_peer()).
      game_time_ = end;
      set_state(GameState::kPaused);
      attention("Waiting for the synchronised game to end", 15.0);
      break;
    }
    if (phase_ == GamePhase::kProduction || is_challenge(phase_)) {
      // The game or the timed challenge ends; POST_GAME shows the final game time.
      enter_phase(GamePhase::kPostGame);
      game_time_ = end;
      break;
    }
    const GamePhase next =
        phase_ == GamePhase::kSetup ? GamePhase::kExploration : GamePhase::kProduction;
    enter_phase(next);
    game_time_ = carry;
  }
}

void Refbox::handle_peer(const PeerGameState& p) {
  if (!awaiting_overtime_decision()) return;
  const SimTime regular = config_.production_duration;
  // The other field has finished its regular time when it stands paused at (or beyond) the
  // regular end, or is already in POST_GAME; one that already plays overtime decided for both.
  bool start_overtime = false;
  if ((p.phase == GamePhase::kProduction && p.state == GameState::kPaused &&
       p.game_time >= regular) ||
      (p.phase == GamePhase::kPostGame && p.game_time >= regular)) {
    start_overtime = p.points == points() && points() > 0;
  } else if (p.phase == GamePhase::kProduction && p.state == GameState::kRunning &&
             p.game_time > regular) {
    start_overtime = true;
  } else {
    return;  // the other game is still running its regular time
  }
  if (start_overtime) {
    overtime_ = true;
    attention("Entering overtime (" + std::to_string(config_.overtime_duration.ns() / 1000000000) +
                  " s): equal points " + std::to_string(points()),
              15.0);
    set_state(GameState::kRunning);
    return;
  }
  enter_phase(GamePhase::kPostGame);
  game_time_ = regular;
}

void Refbox::set_state(GameState s) {
  if (s == state_) return;
  state_ = s;
  out_.state_changed = true;
}

void Refbox::enter_phase(GamePhase p) {
  if (!params_ && p != GamePhase::kPreGame) parameterise();
  phase_ = p;
  game_time_ = SimTime();
  out_.phase_changed = true;
  mole_.reset();  // only WHACK_A_MOLE lights a mole, drawn when it runs
  last_mole_ = DeviceId();
  attention("Switching to " + std::string(to_string(p)), 5.0);
  switch (p) {
    case GamePhase::kSetup:
      setup_warned_ = false;
      break;
    case GamePhase::kProduction:
      init_production();
      break;
    case GamePhase::kPostGame:
      set_state(GameState::kPaused);
      attention("Game over: " + std::to_string(points()) + " points", 30.0);
      break;
    default:
      break;
  }
}

void Refbox::parameterise() {
  if (synced_params_) {
    params_ = *synced_params_;
  } else if (config_.params) {
    params_ = *config_.params;
  } else {
    if (config_.mode == RefBoxMode::kSlave) {
      attention("Slave refbox has no plan from its master: playing its own", 30.0);
    }
    params_ = draw_game_params(rng_, rules_,
                               config_.synchronised() ? kPlanSynchronisedS : kPlanProductionS);
  }
  const GameParams& p = *params_;
  for (int i = 0; i < kProductionMachineCount; ++i) machines_[i].type = p.machine_types[i];
  for (int t = 0; t < 5; ++t) signals_[t] = {static_cast<MachineType>(t), p.light_codes[t]};
  orders_.clear();
  for (int i = 0; i < kRegularOrderCount; ++i) {
    Order o;
    o.id = OrderId(i + 1);
    o.product = i % 3 == 0 ? PuckState::kP1 : i % 3 == 1 ? PuckState::kP2 : PuckState::kP3;
    o.quantity_requested = p.order_quantities[i];
    o.window_begin_s = (i / 3) * 300;
    o.window_end_s = i / 3 == 2 ? 900 : (i / 3) * 300 + 299;
    orders_.push_back(o);
  }
  for (int i = 0; i < kLateOrderCount; ++i) {
    Order o;
    o.id = OrderId(kRegularOrderCount + i + 1);
    o.product = PuckState::kP3;
    o.quantity_requested = 1;
    o.window_begin_s = p.late_order_start_s[i];
    o.window_end_s = p.late_order_start_s[i] + kLateOrderWindowS;
    o.late = true;
    o.points_per_unit = 20;
    o.points_per_extra_unit = 0;
    orders_.push_back(o);
  }
  down_phase_.assign(p.down_times.size(), 0);
}

SyncResult Refbox::sync_from(const GameParams& master_params) {
  if (config_.mode != RefBoxMode::kSlave) return {SyncResult::Status::kNotSlave, {}};
  if (params_) return {SyncResult::Status::kAlreadyParameterised, {}};
  try {
    validate_game_params(master_params, "sync",
                         config_.synchronised() ? kPlanSynchronisedS : kPlanProductionS);
  } catch (const core::ConfigError& e) {
    return {SyncResult::Status::kInvalid, e.what()};
  }
  synced_params_ = master_params;
  return {SyncResult::Status::kApplied, {}};
}

const GameParams& Refbox::sync_params() {
  if (!params_) parameterise();
  return *params_;
}

void Refbox::init_production() {
  overtime_ = false;
  for (Machine& m : machines_) {
    m.state = MachineState::kIdle;
    m.state_before_down = MachineState::kIdle;
    m.puck_under_rfid = PuckId();
    m.loaded_count = 0;
    m.processing_end = SimTime();
    m.delivered = false;
    m.gate_rejected = false;
    m.gate_active = false;
    m.gate_inactive_since = SimTime::from_sec(-1000000);
  }
  for (Order& o : orders_) {
    o.quantity_delivered = 0;
    o.active = !o.late;
    if (o.active) out_.orders_activated.push_back(o.id);
  }
  std::fill(down_phase_.begin(), down_phase_.end(), std::uint8_t{0});
  gate_period_ = -1;
  pending_.clear();
  update_gates();
}

// ---------------------------------------------------------------------------------------------
// Controller commands
// ---------------------------------------------------------------------------------------------

void Refbox::apply(const Command& c) {
  std::visit(
      Overloaded{
          [&](const command::SetGameState& s) {
            if (s.state == GameState::kRunning && awaiting_overtime_decision()) {
              attention("Waiting for the synchronised game to end", 5.0);
              return;
            }
            if (s.state == GameState::kPaused && phase_ == GamePhase::kWhackAMoleChallenge &&
                state_ == GameState::kRunning && mole_) {
              // The referee pauses when a robot reached the mole (spec §7): +1; the next mole
              // lights up when the game resumes.
              award(1, AwardReason::kMoleReachedReferee, *mole_, OrderId(), PuckId());
              last_mole_ = *mole_;
              mole_.reset();
            }
            if (s.state == GameState::kRunning && phase_ == GamePhase::kPreGame) {
              enter_phase(team_.empty() || config_.skip_setup ? GamePhase::kExploration
                                                              : GamePhase::kSetup);
            }
            set_state(s.state);
          },
          [&](const command::SetGamePhase& s) { enter_phase(s.phase); },
          [&](const command::SetTeamName& s) {
            if (phase_ == GamePhase::kPreGame && s.team != team_) robots_.clear();
            team_ = s.team;
          },
          [&](const command::PlacePuck& s) {
            if (production_running() && is_valid_device(s.device)) {
              handle_rfid({s.device, s.puck, true});
            }
          },
          [&](const command::RemovePuck& s) {
            if (phase_ != GamePhase::kProduction || !is_valid_device(s.device)) return;
            Machine& m = machines_[s.device.value()];
            handle_rfid({s.device, s.puck, false});
            auto* end = m.loaded.data() + m.loaded_count;
            auto* it = std::find(m.loaded.data(), end, s.puck);
            if (it != end) {
              std::copy(it + 1, end, it);
              --m.loaded_count;
              set_puck_state(s.puck, PuckState::kConsumed);
              if (m.loaded_count == 0 && m.state == MachineState::kWaiting) {
                set_machine_state(m, MachineState::kIdle, m.puck_under_rfid);
              } else if (m.loaded_count == 0 && m.state == MachineState::kDown &&
                         m.state_before_down == MachineState::kWaiting) {
                m.state_before_down = MachineState::kIdle;
              }
            }
          },
          [&](const command::LoadPuck& s) {
            if (phase_ != GamePhase::kProduction || !is_production_machine(s.device)) return;
            Machine& m = machines_[s.device.value()];
            const Puck* pk = find_puck(s.puck);
            if (pk == nullptr || registered_elsewhere(m.id, s.puck) ||
                m.puck_under_rfid == s.puck ||
                (m.state != MachineState::kIdle && m.state != MachineState::kWaiting)) {
              attention("Cannot load puck " + std::to_string(s.puck.value()) + " into " +
                        std::string(device_name(m.id)));
              return;
            }
            const TypeInputs in = inputs_of(m.type);
            bool ok = std::find(in.states.begin(), in.states.begin() + in.count, pk->state) !=
                      in.states.begin() + in.count;
            for (PuckId l : m.loaded_with()) ok = ok && find_puck(l)->state != pk->state;
            if (!ok) {
              attention("Puck " + std::to_string(s.puck.value()) + " (" +
                        std::string(to_string(pk->state)) + ") is no valid input of " +
                        std::string(device_name(m.id)));
              return;
            }
            m.loaded[m.loaded_count++] = s.puck;
            if (m.loaded_count < in.count) {
              set_machine_state(m, MachineState::kWaiting, m.puck_under_rfid);
              return;
            }
            // The loaded puck completes the set: it becomes the output.
            set_puck_state(s.puck, *output_of(m.type));
            for (int i = 0; i + 1 < m.loaded_count; ++i) {
              set_puck_state(m.loaded[i], PuckState::kConsumed);
            }
            m.loaded_count = 0;
            set_machine_state(m, MachineState::kIdle, m.puck_under_rfid);
            award(completion_points(m.type), AwardReason::kMachineCompleted, m.id, OrderId(),
                  s.puck);
          },
          [&](const command::SetPucks& s) {
            reset_pucks(s.ids);
            for (Machine& m : machines_) {
              m.puck_under_rfid = PuckId();
              m.loaded_count = 0;
              m.delivered = false;
              m.gate_rejected = false;
              if (m.state == MachineState::kDown) {
                m.state_before_down = MachineState::kIdle;
              } else if (is_gate(m.id) && !m.gate_active) {
                m.state = MachineState::kDown;
              } else {
                m.state = MachineState::kIdle;
              }
            }
          },
          [&](const command::SetRobotMaintenance& s) {
            Robot* r = nullptr;
            for (Robot& x : robots_) {
              if (x.number == s.number && (r == nullptr || (x.team == team_ && r->team != team_))) {
                r = &x;
              }
            }
            if (r == nullptr) {
              attention("No robot with number " + std::to_string(s.number));
              return;
            }
            if (r->state == RobotState::kDisqualified) return;
            if (s.maintenance) {
              if (r->state == RobotState::kMaintenance) return;
              if (r->maintenance_cycles >= 1) {
                r->state = RobotState::kDisqualified;
                attention("Robot " + robot_label(*r) + " disqualified: second maintenance", 15.0);
                return;
              }
              r->state = RobotState::kMaintenance;
              ++r->maintenance_cycles;
              r->maintenance_elapsed = SimTime();
              r->maintenance_warned = false;
              attention("Robot " + robot_label(*r) + " in maintenance", 10.0);
            } else if (r->state == RobotState::kMaintenance) {
              r->state = RobotState::kActive;
              attention("Robot " + robot_label(*r) + " back from maintenance", 10.0);
            }
          },
          [&](const command::Penalty& s) {
            const int total = points();
            const int cut = s.major ? std::max(5, total / 2) : std::max(1, total / 4);
            award(-cut, s.major ? AwardReason::kPenaltyMajor : AwardReason::kPenaltyMinor,
                  DeviceId(), OrderId(), PuckId());
          },
      },
      c);
}

// ---------------------------------------------------------------------------------------------
// Beacons and exploration reports
// ---------------------------------------------------------------------------------------------

void Refbox::handle_beacon(const Beacon& b) {
  if (b.team == "LLSF" && b.peer_name == "RefBox") {
    const std::string where = b.host + ":" + std::to_string(b.port);
    if (std::find(warned_refboxes_.begin(), warned_refboxes_.end(), where) ==
        warned_refboxes_.end()) {
      warned_refboxes_.push_back(where);
      attention("Another refbox is sending beacons from " + where, 10.0);
    }
    return;
  }
  auto it = std::find_if(robots_.begin(), robots_.end(),
                         [&](const Robot& r) { return r.host == b.host && r.port == b.port; });
  if (it == robots_.end()) {
    for (const Robot& r : robots_) {
      if (r.host == b.host) {
        attention("Two beacon sources on host " + b.host + ": " + robot_label(r) + " and " +
                      b.peer_name + " (port " + std::to_string(b.port) + ")",
                  10.0);
      }
      if (b.number != 0 && r.team == b.team && r.number == b.number) {
        attention("Duplicate jersey number " + std::to_string(b.number) + " of team " + b.team +
                      ": " + r.name + " and " + b.peer_name,
                  10.0);
      }
    }
    if (b.number == 0) {
      attention("Robot " + b.peer_name + " of team " + b.team + " sends jersey number 0", 10.0);
    }
    Robot r;
    r.host = b.host;
    r.port = b.port;
    robots_.push_back(std::move(r));
    it = robots_.end() - 1;
  }
  Robot& r = *it;
  if (r.team != b.team) r.team = b.team;
  if (r.name != b.peer_name) r.name = b.peer_name;
  r.number = b.number;
  r.last_seen = now_;
  r.pose = b.pose;
  r.lost = false;
  const SimTime offset = b.time > now_ ? b.time - now_ : now_ - b.time;
  if (offset > rules_.clock_offset_warning) {
    if (!r.clock_warned) {
      r.clock_warned = true;
      attention("Clock of robot " + robot_label(r) + " is off by more than 3 s", 10.0);
    }
  } else {
    r.clock_warned = false;
  }
}

void Refbox::handle_report(const MachineReport& r) {
  if (phase_ != GamePhase::kExploration) return;
  for (const MachineReportEntry& e : r.machines) {
    const auto d = device_by_name(e.name);
    if (!d || !is_production_machine(*d)) continue;
    Machine& m = machines_[d->value()];
    if (m.correctly_reported) continue;  // only the first report of a machine counts
    const bool correct = e.type == to_string(m.type);
    m.correctly_reported = correct;
    reported_.push_back(*d);
    award(correct ? rules_.exploration_correct_points : rules_.exploration_wrong_points,
          correct ? AwardReason::kExplorationCorrect : AwardReason::kExplorationWrong, *d,
          OrderId(), PuckId());
  }
}

// ---------------------------------------------------------------------------------------------
// RFID zones
// ---------------------------------------------------------------------------------------------

void Refbox::handle_rfid(const RfidEvent& e) {
  if (!is_valid_device(e.device) || !e.puck.valid()) return;
  Machine& m = machines_[e.device.value()];
  PuckId* begin = m.in_zone.data();
  PuckId* end = begin + m.in_zone_count;
  PuckId* it = std::find(begin, end, e.puck);
  if (e.entered) {
    if (it == end && m.in_zone_count < kMaxPucksInZone) m.in_zone[m.in_zone_count++] = e.puck;
  } else if (it != end) {
    std::copy(it + 1, end, it);
    --m.in_zone_count;
    m.in_zone[m.in_zone_count] = PuckId();
  }
}

// ---------------------------------------------------------------------------------------------
// Scheduled production rules: down times, gates, late orders, pending deliveries, processing
// ---------------------------------------------------------------------------------------------

void Refbox::run_schedule() {
  const GameParams& p = *params_;
  for (std::size_t i = 0; i < p.down_times.size(); ++i) {
    const DownTime& d = p.down_times[i];
    const SimTime start = SimTime::from_sec(d.start_s);
    const SimTime end = SimTime::from_sec(d.end_s);
    Machine& m = machines_[d.device.value()];
    if (down_phase_[i] == 0 && game_time_ >= start) {
      down_phase_[i] = 1;
      if (end <= start) {
        down_phase_[i] = 2;
        continue;
      }
      // A machine that is processing resumes later: its end moves by the whole down time.
      if (m.state == MachineState::kProcessing) m.processing_end += end - start;
      m.state_before_down = m.state;
      set_machine_state(m, MachineState::kDown, m.puck_under_rfid);
    }
    if (down_phase_[i] == 1 && game_time_ >= end) {
      down_phase_[i] = 2;
      set_machine_state(m, m.state_before_down, m.puck_under_rfid);
    }
  }
  update_gates();
  activate_late_orders();
  if (!pending_.empty()) {
    std::erase_if(pending_, [&](const PendingDelivery& d) {
      return credit_delivery(d.product, d.gate, d.puck, AwardReason::kDeliveryPendingCredited);
    });
  }
  for (Machine& m : machines_) {
    if (m.state == MachineState::kProcessing && game_time_ >= m.processing_end) {
      finish_processing(m);
    }
  }
}

void Refbox::update_gates() {
  const std::vector<GatePeriod>& s = params_->gate_schedule;
  int k = std::max(gate_period_, 0);
  while (k + 1 < static_cast<int>(s.size()) && game_time_ >= SimTime::from_sec(s[k].end_s)) ++k;
  if (k == gate_period_) return;
  gate_period_ = k;
  const SimTime since = SimTime::from_sec(s[k].start_s);
  for (int g = kD1; g <= kD3; ++g) {
    if (g != s[k].gate.value()) set_gate_active(machines_[g], false, since);
  }
  set_gate_active(machines_[s[k].gate.value()], true, since);
}

void Refbox::set_gate_active(Machine& g, bool active, SimTime since) {
  const bool was = g.gate_active;
  g.gate_active = active;
  if (active) {
    if (g.state == MachineState::kDown) {
      set_machine_state(g, g.gate_rejected ? MachineState::kInvalid : MachineState::kIdle,
                        g.puck_under_rfid);
    }
    return;
  }
  if (was) g.gate_inactive_since = since;
  if (g.state == MachineState::kProcessing) return;  // a delivery within the grace completes
  if (g.puck_under_rfid.valid() && was) {
    // A gate that goes down while holding a puck: red + yellow blink, the puck is out.
    const Puck* pk = find_puck(g.puck_under_rfid);
    if (pk != nullptr && pk->state != PuckState::kFinished) {
      set_puck_state(g.puck_under_rfid, PuckState::kFinished);
      out_.actions.push_back(
          {RefereeAction::Kind::kRemovePuck, g.id, g.puck_under_rfid, RefereeAction::Place::kNone});
    }
    g.gate_rejected = true;
  }
  set_machine_state(g, MachineState::kDown, g.puck_under_rfid);
}

void Refbox::activate_late_orders() {
  for (Order& o : orders_) {
    if (!o.late || o.active) continue;
    if (game_time_ + rules_.late_order_lead < SimTime::from_sec(o.window_begin_s)) continue;
    o.active = true;
    out_.orders_activated.push_back(o.id);
    // The referee brings one extra S0 for the late order.
    const int id = pucks_.empty() ? 1 : pucks_.back().id.value() + 1;
    pucks_.push_back({PuckId(id), PuckState::kS0});
    const auto place =
        slot_occupied_ ? RefereeAction::Place::kInputStorage : RefereeAction::Place::kInsertionSlot;
    out_.actions.push_back({RefereeAction::Kind::kPlacePuck, DeviceId(), PuckId(id), place});
    attention("Late order " + std::to_string(o.id.value()) + " (P3, " +
                  std::to_string(o.window_begin_s) + "-" + std::to_string(o.window_end_s) +
                  " s): place puck " + std::to_string(id) +
                  (slot_occupied_ ? " in the input storage" : " at the insertion slot"),
              rules_.late_order_attention_s);
  }
}

bool Refbox::credit_delivery(PuckState product, DeviceId gate, PuckId puck, AwardReason in_window) {
  // RBX order-delivered-in-time: among active orders of the product whose window contains the
  // current time, prefer one that still needs units (higher per-unit points first), then a full
  // one with the higher extra-unit points; ties go to the lower id.
  Order* best = nullptr;
  auto needs = [](const Order& o) { return o.quantity_delivered < o.quantity_requested; };
  for (Order& o : orders_) {
    if (!o.active || o.product != product) continue;
    if (game_time_ < SimTime::from_sec(o.window_begin_s) ||
        game_time_ > SimTime::from_sec(o.window_end_s)) {
      continue;
    }
    if (best == nullptr) {
      best = &o;
    } else if (needs(o) != needs(*best)) {
      if (needs(o)) best = &o;
    } else if (needs(o) ? o.points_per_unit > best->points_per_unit
                        : o.points_per_extra_unit > best->points_per_extra_unit) {
      best = &o;
    }
  }
  if (best == nullptr) return false;
  const bool short_of_units = needs(*best);
  ++best->quantity_delivered;
  const int pts = short_of_units ? best->points_per_unit : best->points_per_extra_unit;
  award(pts, short_of_units ? in_window : AwardReason::kDeliveryExtra, gate, best->id, puck);
  for (auto it = deliveries_.rbegin(); it != deliveries_.rend(); ++it) {
    if (it->puck == puck && !it->order.valid()) {
      it->order = best->id;
      it->points += pts;
      break;
    }
  }
  return true;
}

void Refbox::complete_delivery(Machine& g) {
  const PuckId p = g.puck_under_rfid;
  const PuckState product = find_puck(p)->state;
  set_puck_state(p, PuckState::kFinished);
  g.delivered = true;
  set_machine_state(g, g.gate_active ? MachineState::kIdle : MachineState::kDown, p);
  if (!g.gate_active) g.gate_rejected = true;  // delivered in the grace: went down holding it
  out_.actions.push_back({RefereeAction::Kind::kRemovePuck, g.id, p, RefereeAction::Place::kNone});
  deliveries_.push_back({game_time_, g.id, p, product, OrderId(), 0});
  if (credit_delivery(product, g.id, p, AwardReason::kDelivery)) return;
  // Outside every window of the product.
  award(rules_.out_of_window_points, AwardReason::kDeliveryOutOfWindow, g.id, OrderId(), p);
  deliveries_.back().points = rules_.out_of_window_points;
  if (rules_.out_of_window_pending) pending_.push_back({product, g.id, p});
}

void Refbox::finish_processing(Machine& m) {
  const PuckId p = m.puck_under_rfid;
  if (is_gate(m.id)) {
    complete_delivery(m);
    return;
  }
  if (is_recycler(m.id)) {
    set_puck_state(p, PuckState::kS0);
    set_machine_state(m, MachineState::kIdle, p);
    award(rules_.recycle_points, AwardReason::kRecycled, m.id, OrderId(), p);
    return;
  }
  const TypeInputs in = inputs_of(m.type);
  if (m.loaded_count + 1 < in.count) {
    // An intermediate input: it stays in the machine space until the set is complete.
    m.loaded[m.loaded_count++] = p;
    set_machine_state(m, MachineState::kWaiting, p);
    return;
  }
  set_puck_state(p, *output_of(m.type));
  for (PuckId l : m.loaded_with()) set_puck_state(l, PuckState::kConsumed);
  m.loaded_count = 0;
  set_machine_state(m, MachineState::kIdle, p);
  award(completion_points(m.type), AwardReason::kMachineCompleted, m.id, OrderId(), p);
}

// ---------------------------------------------------------------------------------------------
// Readers: placements and removals
// ---------------------------------------------------------------------------------------------

void Refbox::poll_device(Machine& m, bool removals_only) {
  const bool active = is_test_station(m.id) ? rules_.test_station_all_phases || production_running()
                                            : production_running();
  if (!active) return;
  const PuckId s = m.sensed();
  if (removals_only) {
    if (m.puck_under_rfid.valid() && m.puck_under_rfid != s) on_removal(m);
  } else if (s.valid() && !m.puck_under_rfid.valid()) {
    on_placement(m, s);
  }
}

void Refbox::on_removal(Machine& m) {
  const PuckId p = m.puck_under_rfid;
  m.puck_under_rfid = PuckId();
  if (is_test_station(m.id)) return;
  if (is_gate(m.id)) {
    m.delivered = false;
    m.gate_rejected = false;
    set_machine_state(m, m.gate_active ? MachineState::kIdle : MachineState::kDown, p);
    return;
  }
  // Production machines and recyclers; removal during PROCESSING aborts the step (quirk 5).
  const MachineState next = m.loaded_count > 0 ? MachineState::kWaiting : MachineState::kIdle;
  if (m.state == MachineState::kDown) {
    m.state_before_down = next;
  } else {
    set_machine_state(m, next, p);
  }
}

void Refbox::on_placement(Machine& m, PuckId p) {
  if (find_or_learn_puck(p) == nullptr) return;
  if (is_production_machine(m.id)) {
    if (m.state == MachineState::kIdle || m.state == MachineState::kWaiting) {
      place_production(m, p);
    }
    return;  // DOWN: ignored until it is up again (the reader keeps being polled)
  }
  if (registered_elsewhere(m.id, p)) take_off_other_machines(m.id, p);
  if (is_recycler(m.id)) {
    if (m.state == MachineState::kIdle) place_recycler(m, p);
  } else if (is_gate(m.id)) {
    place_gate(m, p);
  } else {
    m.puck_under_rfid = p;  // test station: the lights show the puck's state
  }
}

void Refbox::place_production(Machine& m, PuckId p) {
  m.puck_under_rfid = p;
  if (registered_elsewhere(m.id, p)) {
    // Junk rule: the puck belongs to another machine; it becomes CONSUMED there and here.
    take_off_other_machines(m.id, p);
    set_machine_state(m, MachineState::kInvalid, p);
    return;
  }
  const PuckState s = find_puck(p)->state;
  const TypeInputs in = inputs_of(m.type);
  bool valid =
      std::find(in.states.begin(), in.states.begin() + in.count, s) != in.states.begin() + in.count;
  for (PuckId l : m.loaded_with()) valid = valid && find_puck(l)->state != s;
  if (!valid) {
    set_machine_state(m, MachineState::kInvalid, p);
    return;
  }
  const bool last = m.loaded_count + 1 >= in.count;
  m.processing_end =
      game_time_ + (last ? SimTime::from_sec(params_->proc_time_s[type_index(m.type)])
                         : rules_.intermediate_time);
  set_machine_state(m, MachineState::kProcessing, p);
}

void Refbox::place_recycler(Machine& m, PuckId p) {
  m.puck_under_rfid = p;
  if (find_puck(p)->state != PuckState::kConsumed) {
    set_machine_state(m, MachineState::kInvalid, p);
    return;
  }
  m.processing_end = game_time_ + rules_.recycle_time;
  set_machine_state(m, MachineState::kProcessing, p);
}

void Refbox::place_gate(Machine& g, PuckId p) {
  const PuckState s = find_puck(p)->state;
  bool ordered = false;
  for (const Order& o : orders_) ordered = ordered || (o.active && o.product == s);
  const bool accepts = g.gate_active || game_time_ - g.gate_inactive_since <= rules_.gate_grace;
  if (ordered && accepts) {
    g.puck_under_rfid = p;
    g.processing_end = game_time_ + rules_.delivery_time;
    set_machine_state(g, MachineState::kProcessing, p);
    return;
  }
  if (ordered) {
    // An ordered product at an inactive gate.
    if (!rules_.inactive_gate_rejects_product) return;  // 0.6.1: no reaction (polled again)
    g.puck_under_rfid = p;
    g.gate_rejected = true;
    set_puck_state(p, PuckState::kConsumed);
    out_.actions.push_back(
        {RefereeAction::Kind::kRemovePuck, g.id, p, RefereeAction::Place::kNone});
    return;
  }
  g.puck_under_rfid = p;
  if (s == PuckState::kS0 || s == PuckState::kS1 || s == PuckState::kS2) {
    award(0, AwardReason::kDeliveryIntermediate, g.id, OrderId(), p);
  }
  if (g.gate_active) {
    set_machine_state(g, MachineState::kInvalid, p);
  } else {
    g.gate_rejected = true;
  }
}

bool Refbox::registered_elsewhere(DeviceId here, PuckId p) const {
  for (const Machine& m : machines_) {
    if (m.id == here) continue;
    if (m.puck_under_rfid == p) return true;
    for (PuckId l : m.loaded_with()) {
      if (l == p) return true;
    }
  }
  return false;
}

void Refbox::take_off_other_machines(DeviceId here, PuckId p) {
  for (Machine& m : machines_) {
    if (m.id == here) continue;
    auto* end = m.loaded.data() + m.loaded_count;
    auto* it = std::find(m.loaded.data(), end, p);
    if (it != end) {
      std::copy(it + 1, end, it);
      --m.loaded_count;
      if (m.loaded_count == 0 && m.state == MachineState::kWaiting) {
        set_machine_state(m, MachineState::kIdle, m.puck_under_rfid);
      } else if (m.loaded_count == 0 && m.state == MachineState::kDown &&
                 m.state_before_down == MachineState::kWaiting) {
        m.state_before_down = MachineState::kIdle;
      }
    }
    if (m.puck_under_rfid == p) on_removal(m);
  }
  set_puck_state(p, PuckState::kConsumed);
}

void Refbox::set_machine_state(Machine& m, MachineState s, PuckId puck) {
  if (m.state == s) return;
  if (phase_ == GamePhase::kProduction) {
    history_.push_back({game_time_, phase_, m.id, m.state, s, puck});
  }
  m.state = s;
}

// ---------------------------------------------------------------------------------------------
// Technical challenges: vision poses and whack-a-mole (spec §4, §7)
// ---------------------------------------------------------------------------------------------

void Refbox::update_vision(std::span<const RobotPose> poses) {
  for (const RobotPose& rp : poses) {
    for (Robot& r : robots_) {
      if (r.number == rp.number && (team_.empty() || r.team == team_)) r.vision_pose = rp.pose;
    }
  }
}

void Refbox::update_whack_a_mole(std::span<const RobotPose> poses) {
  if (phase_ != GamePhase::kWhackAMoleChallenge || state_ != GameState::kRunning) return;
  if (!mole_) next_mole();
  // A robot whose camera pose lies in the box around the mole reaches it: +1, next mole (one
  // per step; the next mole is another machine, at least 1.12 m away).
  const core::Pose2D& mp = config_.device_poses[mole_->value()];
  const double half = rules_.whack_a_mole_box_m / 2.0;
  for (const RobotPose& rp : poses) {
    if (std::abs(rp.pose.x - mp.x) <= half && std::abs(rp.pose.y - mp.y) <= half) {
      award(1, AwardReason::kMoleReached, *mole_, OrderId(), PuckId());
      last_mole_ = *mole_;
      next_mole();
      break;
    }
  }
}

void Refbox::next_mole() {
  // Uniform among M1..M10 except the previous mole (assumption, docs/refbox.md).
  const bool have_last = is_production_machine(last_mole_);
  int k = static_cast<int>(
      rng_.uniform_int(0, have_last ? kProductionMachineCount - 2 : kProductionMachineCount - 1));
  if (have_last && k >= last_mole_.value()) ++k;
  mole_ = DeviceId(k);
}

// ---------------------------------------------------------------------------------------------
// Robots
// ---------------------------------------------------------------------------------------------

void Refbox::update_robots(SimTime dt) {
  for (Robot& r : robots_) {
    if (!r.lost && now_ - r.last_seen > rules_.robot_lost_after) {
      r.lost = true;
      attention("Robot " + robot_label(r) + " lost (no beacon for 5 s)", 10.0);
    }
    if (r.state == RobotState::kMaintenance && state_ == GameState::kRunning) {
      r.maintenance_elapsed += dt;
      if (!r.maintenance_warned && r.maintenance_elapsed >= rules_.maintenance_warning) {
        r.maintenance_warned = true;
        attention("Robot " + robot_label(r) + ": maintenance time almost over", 15.0);
      }
      if (r.maintenance_elapsed > rules_.maintenance_limit) {
        r.state = RobotState::kDisqualified;
        attention("Robot " + robot_label(r) + " disqualified: maintenance took too long", 15.0);
      }
    }
  }
  std::erase_if(robots_,
                [&](const Robot& r) { return now_ - r.last_seen > rules_.robot_removed_after; });
}

void Refbox::attention(std::string text, double seconds) {
  out_.attention.push_back({std::move(text), seconds});
}

// ---------------------------------------------------------------------------------------------
// Points and pucks
// ---------------------------------------------------------------------------------------------

void Refbox::award(int points, AwardReason reason, DeviceId device, OrderId order, PuckId puck) {
  GamePhase phase = phase_;
  if (reason == AwardReason::kPenaltyMinor || reason == AwardReason::kPenaltyMajor) {
    if (phase != GamePhase::kExploration && phase != GamePhase::kWhackAMoleChallenge) {
      phase = GamePhase::kProduction;
    }
  }
  const PointsAward a{game_time_, phase, points, reason, device, order, puck};
  awards_.push_back(a);
  out_.awards.push_back(a);
  phase_sums_[phase_slot(phase)] += points;
}

int Refbox::phase_points(GamePhase phase) const { return phase_sums_[phase_slot(phase)]; }

int Refbox::points() const {
  // Spec §7: the scored phases are EXPLORATION, PRODUCTION and WHACK_A_MOLE_CHALLENGE.
  int total = 0;
  for (GamePhase p :
       {GamePhase::kExploration, GamePhase::kProduction, GamePhase::kWhackAMoleChallenge}) {
    total += std::max(0, phase_sums_[phase_slot(p)]);
  }
  return total;
}

Puck* Refbox::find_puck(PuckId id) {
  auto it = std::lower_bound(pucks_.begin(), pucks_.end(), id,
                             [](const Puck& p, PuckId x) { return p.id < x; });
  return it != pucks_.end() && it->id == id ? &*it : nullptr;
}

std::optional<PuckState> Refbox::puck_state(PuckId id) const {
  auto it = std::lower_bound(pucks_.begin(), pucks_.end(), id,
                             [](const Puck& p, PuckId x) { return p.id < x; });
  if (it != pucks_.end() && it->id == id) return it->state;
  return std::nullopt;
}

Puck* Refbox::find_or_learn_puck(PuckId id) {
  if (Puck* p = find_puck(id)) return p;
  if (!config_.learn_unknown_pucks) return nullptr;
  auto it = std::lower_bound(pucks_.begin(), pucks_.end(), id,
                             [](const Puck& p, PuckId x) { return p.id < x; });
  return &*pucks_.insert(it, Puck{id, PuckState::kS0});
}

void Refbox::set_puck_state(PuckId id, PuckState s) {
  Puck* p = find_puck(id);
  LLSF_DEMAND(p != nullptr);
  p->state = s;
}

void Refbox::reset_pucks(std::span<const int> ids) {
  pucks_.clear();
  for (int id : ids) {
    if (id > 0) pucks_.push_back({PuckId(id), PuckState::kS0});
  }
  std::sort(pucks_.begin(), pucks_.end(), [](const Puck& a, const Puck& b) { return a.id < b.id; });
  pucks_.erase(std::unique(pucks_.begin(), pucks_.end(),
                           [](const Puck& a, const Puck& b) { return a.id == b.id; }),
               pucks_.end());
  pucks_.reserve(pucks_.size() + 8);
}

// ---------------------------------------------------------------------------------------------
// Lights
// ---------------------------------------------------------------------------------------------

Lights Refbox::lights_of(const Machine& m) const {
  // The test station shows a puck's state in every phase (quirk 6).
  if (is_test_station(m.id) && m.puck_under_rfid.valid() &&
      (rules_.test_station_all_phases || production_running())) {
    return test_lights(*puck_state(m.puck_under_rfid));
  }
  switch (phase_) {
    case GamePhase::kPreGame:
      return kAllOn;
    case GamePhase::kSetup: {
      if (!is_production_machine(m.id)) return kAllOn;
      // Running dark spot: 1 s ticks, 0.5 s from 80 % and 0.25 s from 90 % of the phase.
      const std::int64_t d = config_.setup_duration.ns();
      const std::int64_t t = std::min(game_time_.ns(), d);
      const std::int64_t t1 = d / 10 * 8;
      const std::int64_t t2 = d / 10 * 9;
      constexpr std::int64_t kS = 1000000000;
      std::int64_t ticks;
      if (t < t1) {
        ticks = t / kS;
      } else if (t < t2) {
        ticks = t1 / kS + (t - t1) / (kS / 2);
      } else {
        ticks = t1 / kS + (t2 - t1) / (kS / 2) + (t - t2) / (kS / 4);
      }
      return ticks % kProductionMachineCount == m.id.value() ? kAllOff : kAllOn;
    }
    case GamePhase::kExploration:
      if (state_ == GameState::kPaused || !is_production_machine(m.id)) return kAllOff;
      return params_->light_codes[type_index(m.type)];
    case GamePhase::kPostGame:
      return {kBlink, kOff, kOff};
    case GamePhase::kOpenChallenge:
    case GamePhase::kNavigationChallenge:
      return kAllOff;
    case GamePhase::kWhackAMoleChallenge:
      return mole_ && m.id == *mole_ ? kAllOn : kAllOff;
    case GamePhase::kProduction:
      break;
  }
  if (is_test_station(m.id)) return {kOff, kOff, kOn};
  if (is_gate(m.id)) {
    if (m.state == MachineState::kProcessing) return {kOff, kOn, kOn};
    if (!m.gate_active) {
      return m.gate_rejected ? Lights{kOn, kBlink, kOff} : Lights{kOn, kOff, kOff};
    }
    if (m.delivered) return kAllOn;
    if (m.state == MachineState::kInvalid) return {kOff, kBlink, kOff};
    return {kOff, kOff, kOn};
  }
  switch (m.state) {
    case MachineState::kIdle:
      return {kOff, kOff, kOn};
    case MachineState::kProcessing:
      return {kOff, kOn, kOn};
    case MachineState::kWaiting:
      return {kOff, kOn, kOff};
    case MachineState::kDown:
      return {kOn, kOff, kOff};
    case MachineState::kInvalid:
      return {kOff, kBlink, kOff};
  }
  return kAllOff;
}

void Refbox::update_lights() {
  for (int i = 0; i < kDeviceCount; ++i) {
    const Lights l = lights_of(machines_[i]);
    if (!(l == machines_[i].lights)) out_.lights_changed_mask |= 1u << i;
    machines_[i].lights = l;
    out_.lights[i] = l;
  }
}

// ---------------------------------------------------------------------------------------------
// Snapshot helpers and the report
// ---------------------------------------------------------------------------------------------

std::string_view Refbox::shown_type(DeviceId d) const {
  const Machine& m = machine(d);
  if (!is_production_machine(d)) return to_string(m.type);
  if (phase_ == GamePhase::kProduction || phase_ == GamePhase::kPostGame) return to_string(m.type);
  return "?";
}

std::span<const ExplorationSignal> Refbox::exploration_signals() const {
  if (!params_) return {};
  return signals_;
}

std::optional<DeviceId> Refbox::active_gate() const {
  if (phase_ != GamePhase::kProduction) return std::nullopt;
  for (int g = kD1; g <= kD3; ++g) {
    if (machines_[g].gate_active) return DeviceId(g);
  }
  return std::nullopt;
}

GameReport Refbox::report() const {
  GameReport r;
  r.rules = rules_.name;
  r.team = team_;
  r.seed = seed_;
  r.final_state = state_;
  r.final_phase = phase_;
  r.mode = config_.mode;
  r.overtime = overtime_;
  r.params = params_;
  r.awards = awards_;
  for (GamePhase p : kPhases) {
    const int sum = phase_sums_[phase_slot(p)];
    const bool any = std::any_of(awards_.begin(), awards_.end(),
                                 [&](const PointsAward& a) { return a.phase == p; });
    if (p == GamePhase::kExploration || p == GamePhase::kProduction || any) {
      r.phase_totals.push_back({p, sum, std::max(0, sum)});
    }
  }
  r.total_points = points();
  for (const Order& o : orders_) {
    r.orders.push_back({o.id, o.product, o.quantity_requested, o.quantity_delivered,
                        o.window_begin_s, o.window_end_s, o.late});
  }
  r.deliveries = deliveries_;
  r.machine_history = history_;
  return r;
}

std::uint64_t Refbox::state_hash() const {
  std::uint64_t h = core::kFnvOffset;
  auto mix = [&h](std::int64_t v) { h = core::fnv1a(&v, sizeof v, h); };
  mix(static_cast<int>(state_));
  mix(static_cast<int>(phase_));
  mix(game_time_.ns());
  for (const Puck& p : pucks_) {
    mix(p.id.value());
    mix(static_cast<int>(p.state));
  }
  for (const Machine& m : machines_) {
    mix(static_cast<int>(m.type));
    mix(static_cast<int>(m.state));
    mix(m.puck_under_rfid.value());
    for (PuckId l : m.loaded_with()) mix(l.value());
    mix(static_cast<int>(m.lights.red) * 9 + static_cast<int>(m.lights.yellow) * 3 +
        static_cast<int>(m.lights.green));
    mix(m.processing_end.ns());
  }
  for (const Order& o : orders_) mix(o.quantity_delivered * 2 + (o.active ? 1 : 0));
  for (const PointsAward& a : awards_) {
    mix(a.game_time.ns());
    mix(a.points);
  }
  // Only mixed when set, so that hashes of games without them stay as they were.
  if (mole_) mix(1000 + mole_->value());
  if (overtime_) mix(2000);
  return h;
}

}  // namespace llsf::refbox
