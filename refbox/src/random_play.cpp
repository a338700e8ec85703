// SPDX-License-Identifier: MIT
// The random-play driver (see random_play.h).
#include "llsf/refbox/random_play.h"

#include <algorithm>

namespace llsf::refbox {

using Kind = PlayPuckPlace::Kind;

RandomPlay::RandomPlay(core::RandomStream stream, int robots, double rule_bias, double min_pause_s,
                       double max_pause_s)
    : rng_(stream),
      rule_bias_(rule_bias),
      min_pause_s_(min_pause_s),
      max_pause_s_(max_pause_s),
      robots_(static_cast<std::size_t>(robots)) {
  places_.reserve(64);
  candidates_.reserve(64);
}

PlayPuckPlace& RandomPlay::at(PuckId id) {
  if (id.value() >= static_cast<int>(places_.size())) {
    places_.resize(static_cast<std::size_t>(id.value()) + 1);
  }
  return places_[static_cast<std::size_t>(id.value())];
}

PlayPuckPlace RandomPlay::place_of(PuckId id) const {
  if (!id.valid() || id.value() >= static_cast<int>(places_.size())) return {Kind::kGone, {}};
  return places_[static_cast<std::size_t>(id.value())];
}

bool RandomPlay::insertion_slot_occupied() const {
  return std::any_of(places_.begin(), places_.end(),
                     [](const PlayPuckPlace& p) { return p.kind == Kind::kSlot; });
}

void RandomPlay::act(const Refbox& rb, const StepOutput& last, SimTime now,
                     std::vector<RfidEvent>& rfid, std::vector<MachineReport>& reports) {
  rfid.clear();
  reports.clear();
  // The referee: delivered pucks leave the field, late-order pucks arrive.
  for (const RefereeAction& a : last.actions) {
    PlayPuckPlace& p = at(a.puck);
    if (a.kind == RefereeAction::Kind::kRemovePuck) {
      if (p.kind == Kind::kZone) rfid.push_back({p.device, a.puck, false});
      for (RobotPlan& r : robots_) {
        if (r.carried == a.puck) r.carried = PuckId();
      }
      p = {Kind::kGone, {}};
    } else {
      p = {a.place == RefereeAction::Place::kInsertionSlot ? Kind::kSlot : Kind::kStorage, {}};
    }
  }
  // Exploration: a report of one to three machines every few seconds, mostly right.
  if (rb.phase() == GamePhase::kExploration && now >= next_report_) {
    next_report_ = now + SimTime::from_seconds(rng_.uniform(1.5, 3.0));
    MachineReport r;
    const int n = static_cast<int>(rng_.uniform_int(1, 3));
    for (int i = 0; i < n; ++i) {
      const DeviceId d(static_cast<int>(rng_.uniform_int(0, kProductionMachineCount - 1)));
      const MachineType t = rng_.bernoulli(0.6) ? rb.machine(d).type
                                                : static_cast<MachineType>(rng_.uniform_int(0, 4));
      r.machines.push_back({std::string(device_name(d)), std::string(to_string(t))});
    }
    reports.push_back(std::move(r));
  }
  if (rb.phase() != GamePhase::kProduction || rb.state() != GameState::kRunning) return;
  for (RobotPlan& r : robots_) {
    if (now < r.next_action) continue;
    r.next_action = now + SimTime::from_seconds(rng_.uniform(min_pause_s_, max_pause_s_));
    if (r.carried.valid()) {
      put_down(rb, r, rfid);
    } else {
      pick_up(rb, r, rfid);
    }
  }
}

void RandomPlay::pick_up(const Refbox& rb, RobotPlan& r, std::vector<RfidEvent>& rfid) {
  const bool by_rules = rng_.bernoulli(rule_bias_);
  candidates_.clear();
  for (const Puck& pk : rb.pucks()) {
    const PlayPuckPlace& p = at(pk.id);
    if (p.kind == Kind::kGone || p.kind == Kind::kCarried || pk.state == PuckState::kFinished) {
      continue;
    }
    bool useful = true;
    if (by_rules) {
      if (p.kind == Kind::kZone) {
        // Take finished outputs and rejected inputs; leave running machines alone.
        const Machine& m = rb.machine(p.device);
        useful = m.state == MachineState::kIdle || m.state == MachineState::kInvalid;
        useful = useful && !(is_gate(p.device));
      } else if (p.kind == Kind::kSpace) {
        useful = pk.state == PuckState::kConsumed;
      }
    }
    if (useful) candidates_.push_back(pk.id);
  }
  if (candidates_.empty()) return;
  const PuckId id = candidates_[static_cast<std::size_t>(
      rng_.uniform_int(0, static_cast<std::int64_t>(candidates_.size()) - 1))];
  PlayPuckPlace& p = at(id);
  if (p.kind == Kind::kZone) rfid.push_back({p.device, id, false});
  p = {Kind::kCarried, {}};
  r.carried = id;
}

DeviceId RandomPlay::target_for(const Refbox& rb, PuckState s) {
  candidates_.clear();  // reused for device ids (as PuckId values)
  if (s == PuckState::kConsumed) {
    for (int d : {kR1, kR2}) {
      if (rb.machine(DeviceId(d)).state == MachineState::kIdle) candidates_.push_back(PuckId(d));
    }
  } else if (is_product(s)) {
    if (const auto g = rb.active_gate()) {
      if (rb.machine(*g).state == MachineState::kIdle) candidates_.push_back(PuckId(g->value()));
    }
  } else if (s == PuckState::kS0 || s == PuckState::kS1 || s == PuckState::kS2) {
    for (int d = 0; d < kProductionMachineCount; ++d) {
      const Machine& m = rb.machine(DeviceId(d));
      if (m.state != MachineState::kIdle && m.state != MachineState::kWaiting) continue;
      if (m.sensed().valid()) continue;
      const TypeInputs in = inputs_of(m.type);
      bool needs = std::find(in.states.begin(), in.states.begin() + in.count, s) !=
                   in.states.begin() + in.count;
      for (PuckId l : m.loaded_with()) needs = needs && rb.puck_state(l) != s;
      if (needs) candidates_.push_back(PuckId(d));
    }
  }
  if (candidates_.empty()) return DeviceId();
  return DeviceId(candidates_[static_cast<std::size_t>(rng_.uniform_int(
                                  0, static_cast<std::int64_t>(candidates_.size()) - 1))]
                      .value());
}

void RandomPlay::put_down(const Refbox& rb, RobotPlan& r, std::vector<RfidEvent>& rfid) {
  const PuckId id = r.carried;
  r.carried = PuckId();
  const auto state = rb.puck_state(id);
  DeviceId target;
  if (state && rng_.bernoulli(rule_bias_)) target = target_for(rb, *state);
  if (!target.valid()) target = DeviceId(static_cast<int>(rng_.uniform_int(0, kDeviceCount - 1)));
  // Whatever lies under the reader is pushed aside into the machine space.
  for (std::size_t i = 0; i < places_.size(); ++i) {
    PlayPuckPlace& p = places_[i];
    if (p.kind == Kind::kZone && p.device == target) {
      rfid.push_back({target, PuckId(static_cast<int>(i)), false});
      p.kind = Kind::kSpace;
    }
  }
  rfid.push_back({target, id, true});
  at(id) = {Kind::kZone, target};
}

}  // namespace llsf::refbox
