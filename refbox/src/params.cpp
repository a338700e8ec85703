// SPDX-License-Identifier: MIT
// Drawing and checking a game's parameterisation (spec §2.1, §5, §6, §8).
#include "llsf/refbox/params.h"

#include <algorithm>
#include <set>
#include <utility>

#include "llsf/core/assert.h"
#include "llsf/core/error.h"
#include "llsf/refbox/rules_variant.h"

namespace llsf::refbox {

namespace {

using core::RandomStream;

constexpr LightState kOn = LightState::kOn;
constexpr LightState kOff = LightState::kOff;

/// RBX shuffles by 200 random pair swaps (machine-init-randomize); we do the same for every list.
template <class T, std::size_t N>
void shuffle_by_swaps(std::array<T, N>& a, RandomStream& rng) {
  for (int i = 0; i < 200; ++i) {
    const auto x = static_cast<std::size_t>(rng.uniform_int(0, static_cast<std::int64_t>(N) - 1));
    const auto y = static_cast<std::size_t>(rng.uniform_int(0, static_cast<std::int64_t>(N) - 1));
    std::swap(a[x], a[y]);
  }
}

int draw(RandomStream& rng, int lo, int hi) { return static_cast<int>(rng.uniform_int(lo, hi)); }

/// Moves a T5 down period off the start and end of both late-order windows (spec §8). A period
/// that covers a window's start is moved to end at that start; one that covers a window's end is
/// moved to start at that end (clipped to the plan, so it may shrink). If after both windows it
/// still covers a boundary (possible only when the gap between the windows is shorter than the
/// period), it is moved behind the second window. Documented in docs/refbox.md.
void protect_t5(DownTime& dt, const std::array<int, kLateOrderCount>& late_start) {
  auto covers = [&](int ws, int we) {
    return (dt.start_s <= ws && dt.end_s > ws) || (dt.start_s < we && dt.end_s >= we);
  };
  for (int ws : late_start) {
    const int we = ws + kLateOrderWindowS;
    const int dur = dt.end_s - dt.start_s;
    if (dt.start_s <= ws && dt.end_s > ws) {
      dt.end_s = ws;
      dt.start_s = std::max(0, ws - dur);
    } else if (dt.start_s < we && dt.end_s >= we) {
      dt.start_s = we;
      dt.end_s = std::min(kPlanProductionS, we + dur);
    }
  }
  for (int ws : late_start) {
    if (covers(ws, ws + kLateOrderWindowS)) {
      const int dur = dt.end_s - dt.start_s;
      const int last_end = std::max(late_start[0], late_start[1]) + kLateOrderWindowS;
      dt.start_s = last_end;
      dt.end_s = std::min(kPlanProductionS, last_end + dur);
      break;
    }
  }
}

[[noreturn]] void fail(const std::string& path, const std::string& reason) {
  throw core::ConfigError(path + ": " + reason);
}

}  // namespace

const std::array<Lights, 7>& exploration_light_codes() {
  // R, Y, G order in each Lights; RBX lists the codes G, Y, GY, R, RG, RY, RYG.
  static const std::array<Lights, 7> codes = {Lights{kOff, kOff, kOn}, Lights{kOff, kOn, kOff},
                                              Lights{kOff, kOn, kOn},  Lights{kOn, kOff, kOff},
                                              Lights{kOn, kOff, kOn},  Lights{kOn, kOn, kOff},
                                              Lights{kOn, kOn, kOn}};
  return codes;
}

std::string light_code_string(const Lights& code) {
  std::string s;
  if (code.red != kOff) s += 'R';
  if (code.yellow != kOff) s += 'Y';
  if (code.green != kOff) s += 'G';
  return s;
}

GameParams draw_game_params(RandomStream& rng, const RulesVariant& rules) {
  return draw_game_params(rng, rules, kPlanProductionS);
}

GameParams draw_game_params(RandomStream& rng, const RulesVariant& rules, int gate_schedule_end_s) {
  LLSF_DEMAND(gate_schedule_end_s >= kPlanProductionS);
  GameParams p;

  // Machine types: MACHINE-DISTRIBUTION shuffled and dealt to M1..M10.
  std::array<MachineType, kProductionMachineCount> types = {
      MachineType::kT1, MachineType::kT1, MachineType::kT1, MachineType::kT1, MachineType::kT2,
      MachineType::kT2, MachineType::kT2, MachineType::kT3, MachineType::kT4, MachineType::kT5};
  shuffle_by_swaps(types, rng);
  p.machine_types = types;

  // One processing time per type.
  p.proc_time_s = {draw(rng, 3, 8), draw(rng, 15, 25), draw(rng, 40, 60), draw(rng, 40, 60),
                   draw(rng, 20, 40)};

  // Exploration light codes: the 7 codes shuffled, the first five to T1..T5.
  std::array<Lights, 7> codes = exploration_light_codes();
  shuffle_by_swaps(codes, rng);
  for (int i = 0; i < 5; ++i) p.light_codes[i] = codes[i];

  // Late-order windows.
  p.late_order_start_s = {draw(rng, 120, 400), draw(rng, 520, 780)};

  // Down times: 6..8 distinct machines among M1..M10, R1, R2.
  std::array<int, 12> candidates{};
  for (int i = 0; i < 12; ++i) candidates[i] = i;
  shuffle_by_swaps(candidates, rng);
  const int n_down = draw(rng, 6, 8);
  bool t5_down = false;
  for (int i = 0; i < n_down; ++i) {
    DownTime dt;
    dt.device = DeviceId(candidates[i]);
    const int dur = draw(rng, 30, 120);
    dt.start_s = draw(rng, 1, kPlanProductionS - dur);
    dt.end_s = dt.start_s + dur;
    if (candidates[i] < kProductionMachineCount &&
        p.machine_types[candidates[i]] == MachineType::kT5) {
      protect_t5(dt, p.late_order_start_s);
      t5_down = true;
    }
    p.down_times.push_back(dt);
  }

  // Order quantities (0.6.1 quirk 1: only drawn when the T5 got a down time).
  if (!rules.quantities_only_with_t5_down || t5_down) {
    for (int& q : p.order_quantities) q = draw(rng, 3, 10);
  } else {
    p.order_quantities = kDefaultOrderQuantities;
  }

  // Delivery-gate schedule: 60..180 s periods on a gate other than the previous one; a period
  // ending within 60 s of the end (900 s, or 1200 s in synchronised mode) is stretched to it.
  const int gate_end = gate_schedule_end_s;
  int t = 0;
  int prev = -1;
  while (t < gate_end) {
    const int len = draw(rng, 60, 180);
    int gate;
    if (prev < 0) {
      gate = draw(rng, 0, 2);
    } else {
      gate = draw(rng, 0, 1);
      if (gate >= prev) ++gate;
    }
    int end = t + len;
    if (end > gate_end - 60) end = gate_end;
    p.gate_schedule.push_back(GatePeriod{DeviceId(kD1 + gate), t, end});
    prev = gate;
    t = end;
  }
  return p;
}

void validate_game_params(const GameParams& p, const std::string& path) {
  validate_game_params(p, path, kPlanProductionS);
}

void validate_game_params(const GameParams& p, const std::string& path, int gate_schedule_end_s) {
  // Machine types: four T1, three T2, one each of T3..T5.
  std::array<int, 5> count{};
  for (int i = 0; i < kProductionMachineCount; ++i) {
    const int t = static_cast<int>(p.machine_types[i]);
    if (t < 0 || t > 4) {
      fail(path + ".machine_types." + std::string(kDeviceNames[i]),
           "must be one of T1..T5 (got " + std::string(to_string(p.machine_types[i])) + ")");
    }
    ++count[t];
  }
  constexpr std::array<int, 5> kWant = {4, 3, 1, 1, 1};
  for (int t = 0; t < 5; ++t) {
    if (count[t] != kWant[t]) {
      fail(path + ".machine_types", "needs 4 T1, 3 T2 and one each of T3, T4, T5 (got " +
                                        std::to_string(count[t]) + " T" + std::to_string(t + 1) +
                                        ")");
    }
  }
  for (int t = 0; t < 5; ++t) {
    const std::string f = path + ".proc_time_s.T" + std::to_string(t + 1);
    if (p.proc_time_s[t] <= 0)
      fail(f, "must be > 0 (got " + std::to_string(p.proc_time_s[t]) + ")");
  }
  for (int t = 0; t < 5; ++t) {
    const std::string f = path + ".light_codes.T" + std::to_string(t + 1);
    const Lights& c = p.light_codes[t];
    if (c == kAllOff) fail(f, "needs at least one lamp on");
    for (LightState s : {c.red, c.yellow, c.green}) {
      if (s == LightState::kBlink) fail(f, "must be steady (blinking codes are disabled in 2013)");
    }
    for (int u = 0; u < t; ++u) {
      if (p.light_codes[u] == c) {
        fail(f, "same code as T" + std::to_string(u + 1) + " (" + light_code_string(c) + ")");
      }
    }
  }
  for (int i = 0; i < kRegularOrderCount; ++i) {
    if (p.order_quantities[i] < 1) {
      fail(path + ".order_quantities[" + std::to_string(i) + "]",
           "must be >= 1 (got " + std::to_string(p.order_quantities[i]) + ")");
    }
  }
  for (int i = 0; i < kLateOrderCount; ++i) {
    const int s = p.late_order_start_s[i];
    if (s < 0 || s + kLateOrderWindowS > kPlanProductionS) {
      fail(path + ".late_order_start_s[" + std::to_string(i) + "]",
           "window must lie in [0, " + std::to_string(kPlanProductionS) + "] (got start " +
               std::to_string(s) + ")");
    }
  }
  std::set<int> down_devices;
  for (std::size_t i = 0; i < p.down_times.size(); ++i) {
    const DownTime& d = p.down_times[i];
    const std::string f = path + ".down_times[" + std::to_string(i) + "]";
    if (d.device.value() < 0 || d.device.value() > kR2) {
      fail(f + ".machine", "must be one of M1..M10, R1, R2");
    }
    if (!down_devices.insert(d.device.value()).second) {
      fail(f + ".machine", "at most one down time per machine (" +
                               std::string(device_name(d.device)) + " repeats)");
    }
    if (d.start_s < 0 || d.end_s < d.start_s || d.end_s > kPlanProductionS) {
      fail(f, "needs 0 <= start_s <= end_s <= " + std::to_string(kPlanProductionS) + " (got " +
                  std::to_string(d.start_s) + ".." + std::to_string(d.end_s) + ")");
    }
  }
  if (p.gate_schedule.empty()) fail(path + ".gate_schedule", "must not be empty");
  int t = 0;
  for (std::size_t i = 0; i < p.gate_schedule.size(); ++i) {
    const GatePeriod& g = p.gate_schedule[i];
    const std::string f = path + ".gate_schedule[" + std::to_string(i) + "]";
    if (!is_gate(g.gate)) fail(f + ".gate", "must be D1, D2 or D3");
    if (g.start_s != t) {
      fail(f + ".start_s", "periods must be consecutive from 0 (expected " + std::to_string(t) +
                               ", got " + std::to_string(g.start_s) + ")");
    }
    if (g.end_s <= g.start_s) fail(f + ".end_s", "must be > start_s");
    t = g.end_s;
  }
  if (t < gate_schedule_end_s) {
    fail(path + ".gate_schedule", "must cover production up to " +
                                      std::to_string(gate_schedule_end_s) + " s (ends at " +
                                      std::to_string(t) + ")");
  }
}

}  // namespace llsf::refbox
