// SPDX-License-Identifier: MIT
// A small game driver for the refbox rule tests: a fixed plan, queued inputs, 10 ms steps, and
// every output of every step collected.
#pragma once

#include <doctest/doctest.h>

#include <string>
#include <vector>

#include "llsf/refbox/refbox.h"

namespace llsf::refbox::test {

inline constexpr SimTime kStep = SimTime::from_ms(10);

/// M1 T1, M2 T2, M3 T3, M4 T4, M5 T5, M6 T1, M7 T2, M8 T1, M9 T2, M10 T1; T1 4 s, T2 20 s,
/// T3 50 s, T4 45 s, T5 30 s; the default light codes; default quantities; late orders at 200 s
/// and 600 s; no down times; D1 0-300, D2 300-600, D3 600-900.
inline GameParams test_params() {
  using T = MachineType;
  GameParams p;
  p.machine_types = {T::kT1, T::kT2, T::kT3, T::kT4, T::kT5,
                     T::kT1, T::kT2, T::kT1, T::kT2, T::kT1};
  p.proc_time_s = {4, 20, 50, 45, 30};
  const auto& c = exploration_light_codes();  // G, Y, GY, R, RG, RY, RYG
  p.light_codes = {c[0], c[1], c[3], c[4], c[5]};
  p.order_quantities = kDefaultOrderQuantities;
  p.late_order_start_s = {200, 600};
  p.gate_schedule = {{DeviceId(kD1), 0, 300}, {DeviceId(kD2), 300, 600}, {DeviceId(kD3), 600, 900}};
  return p;
}

/// test_params() with the gate schedule extended to 1200 s (D1 900-1200) for synchronised games.
inline GameParams test_params_synchronised() {
  GameParams p = test_params();
  p.gate_schedule.push_back({DeviceId(kD1), 900, 1200});
  return p;
}

inline RefboxConfig test_config(std::string_view rules = kRulesRefbox061) {
  RefboxConfig c;
  c.rules = std::string(rules);
  c.team = "Carologistics";
  c.params = test_params();
  return c;
}

constexpr DeviceId dev(int i) { return DeviceId(i); }
inline DeviceId M(int n) { return DeviceId(n - 1); }
inline PuckId puck(int id) { return PuckId(id); }
inline constexpr Lights L(LightState r, LightState y, LightState g) { return {r, y, g}; }
inline constexpr LightState kOff = LightState::kOff;
inline constexpr LightState kOn = LightState::kOn;
inline constexpr LightState kBlink = LightState::kBlink;

/// Drives one Refbox with queued inputs and keeps everything it outputs.
class Game {
 public:
  explicit Game(RefboxConfig cfg, std::uint64_t seed = 1) : rb(std::move(cfg), core::Rng(seed)) {
    step();
  }

  void enter(DeviceId d, int p) { rfid_.push_back({d, PuckId(p), true}); }
  void leave(DeviceId d, int p) { rfid_.push_back({d, PuckId(p), false}); }
  /// Queues a controller command (constructed in place: GCC 12 warns about moving variants).
  template <class C>
  void command(const C& c) {
    cmds_.emplace_back(std::in_place_type<C>, c);
  }
  void beacon(Beacon b) { beacons_.push_back(std::move(b)); }
  void report(MachineReport r) { reports_.push_back(std::move(r)); }
  /// Queues an overhead-camera pose of robot `number` for the next step.
  void vision(int number, double x, double y) { poses_.push_back({number, {x, y, 0.0}}); }
  /// Passes the other field's GameState with the next step (synchronised mode).
  void peer(GamePhase phase, GameState state, double game_time_s, int points) {
    peer_ = PeerGameState{phase, state, SimTime::from_seconds(game_time_s), points};
  }

  /// One step of `dt` with everything queued.
  const StepOutput& step(SimTime dt = kStep) {
    now += dt;
    StepInput in;
    in.rfid = rfid_;
    in.commands = cmds_;
    in.beacons = beacons_;
    in.reports = reports_;
    in.insertion_slot_occupied = slot_occupied;
    in.robot_poses = poses_;
    in.peer_game_state = peer_;
    const StepOutput& out = rb.step(now, in);
    poses_.clear();
    peer_.reset();
    rfid_.clear();
    cmds_.clear();
    beacons_.clear();
    reports_.clear();
    awards.insert(awards.end(), out.awards.begin(), out.awards.end());
    actions.insert(actions.end(), out.actions.begin(), out.actions.end());
    attention.insert(attention.end(), out.attention.begin(), out.attention.end());
    activated.insert(activated.end(), out.orders_activated.begin(), out.orders_activated.end());
    return out;
  }
  /// Steps for `d` of simulated time.
  void run(SimTime d) {
    const SimTime end = now + d;
    while (now < end) step();
  }
  void run_s(double s) { run(SimTime::from_seconds(s)); }

  /// Jumps straight into PRODUCTION, RUNNING.
  void start_production() {
    command(command::SetGamePhase{GamePhase::kProduction});
    command(command::SetGameState{GameState::kRunning});
    step();
  }
  /// Runs production up to game time `s` seconds.
  void run_to_game_time(double s) {
    while (rb.game_time() < SimTime::from_seconds(s)) step();
  }

  const Machine& m(DeviceId d) const { return rb.machine(d); }
  PuckState state_of(int p) const { return *rb.puck_state(PuckId(p)); }
  bool attention_contains(const std::string& s) const {
    for (const auto& a : attention) {
      if (a.text.find(s) != std::string::npos) return true;
    }
    return false;
  }
  int award_sum() const {
    int s = 0;
    for (const auto& a : awards) s += a.points;
    return s;
  }

  Refbox rb;
  SimTime now;
  bool slot_occupied = false;
  std::vector<PointsAward> awards;
  std::vector<RefereeAction> actions;
  std::vector<AttentionMessage> attention;
  std::vector<OrderId> activated;

 private:
  std::vector<RfidEvent> rfid_;
  std::vector<Command> cmds_;
  std::vector<Beacon> beacons_;
  std::vector<MachineReport> reports_;
  std::vector<RobotPose> poses_;
  std::optional<PeerGameState> peer_;
};

}  // namespace llsf::refbox::test
