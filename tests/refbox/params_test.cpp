// SPDX-License-Identifier: MIT
// The parameterisation: drawn within the spec's ranges over many seeds, deterministic per seed,
// variant quirk 1, and validate_game_params() on bad plans.
#include <doctest/doctest.h>

#include <algorithm>
#include <set>

#include "llsf/core/error.h"
#include "llsf/refbox/params.h"
#include "llsf/refbox/rules_variant.h"

using namespace llsf;
using namespace llsf::refbox;

namespace {

GameParams draw(std::uint64_t seed, std::string_view rules = kRulesRefbox061) {
  core::RandomStream s = core::Rng(seed).stream("refbox");
  return draw_game_params(s, make_rules_variant(rules));
}

bool t5_has_down(const GameParams& p) {
  for (const DownTime& d : p.down_times) {
    if (d.device.value() < 10 && p.machine_types[d.device.value()] == MachineType::kT5) return true;
  }
  return false;
}

}  // namespace

TEST_CASE("drawn parameterisations stay within the spec's ranges (300 seeds, both variants)") {
  int quantities_default = 0;
  int t5_down_games = 0;
  for (std::string_view rules : {kRulesRefbox061, kRulesRulebook2013}) {
    for (std::uint64_t seed = 1; seed <= 300; ++seed) {
      CAPTURE(seed);
      const GameParams p = draw(seed, rules);
      CHECK_NOTHROW(validate_game_params(p));
      // Types: 4 T1, 3 T2, one each of T3..T5.
      std::array<int, 5> count{};
      for (MachineType t : p.machine_types) ++count[type_index(t)];
      CHECK(count == std::array<int, 5>{4, 3, 1, 1, 1});
      // Processing times per type.
      CHECK(p.proc_time_s[0] >= 3);
      CHECK(p.proc_time_s[0] <= 8);
      CHECK(p.proc_time_s[1] >= 15);
      CHECK(p.proc_time_s[1] <= 25);
      for (int t : {2, 3}) {
        CHECK(p.proc_time_s[t] >= 40);
        CHECK(p.proc_time_s[t] <= 60);
      }
      CHECK(p.proc_time_s[4] >= 20);
      CHECK(p.proc_time_s[4] <= 40);
      // Light codes: five distinct of the seven steady codes.
      std::set<std::string> codes;
      for (const Lights& c : p.light_codes) {
        CHECK(std::find(exploration_light_codes().begin(), exploration_light_codes().end(), c) !=
              exploration_light_codes().end());
        codes.insert(light_code_string(c));
      }
      CHECK(codes.size() == 5);
      // Orders.
      if (p.order_quantities != kDefaultOrderQuantities) {
        for (int q : p.order_quantities) {
          CHECK(q >= 3);
          CHECK(q <= 10);
        }
      }
      CHECK(p.late_order_start_s[0] >= 120);
      CHECK(p.late_order_start_s[0] <= 400);
      CHECK(p.late_order_start_s[1] >= 520);
      CHECK(p.late_order_start_s[1] <= 780);
      // Down times: 6..8 distinct machines among M1..M10, R1, R2, 30..120 s inside production.
      CHECK(p.down_times.size() >= 6);
      CHECK(p.down_times.size() <= 8);
      std::set<int> devices;
      for (const DownTime& d : p.down_times) {
        CHECK(d.device.value() >= 0);
        CHECK(d.device.value() <= kR2);
        devices.insert(d.device.value());
        CHECK(d.start_s >= 0);
        CHECK(d.end_s <= 900);
        const bool t5 =
            d.device.value() < 10 && p.machine_types[d.device.value()] == MachineType::kT5;
        if (!t5) {
          CHECK(d.start_s >= 1);
          CHECK(d.end_s - d.start_s >= 30);
          CHECK(d.end_s - d.start_s <= 120);
        } else {
          // T5 protection: no late window's start or end lies inside the down period.
          CHECK(d.end_s - d.start_s <= 120);
          for (int ws : p.late_order_start_s) {
            const int we = ws + kLateOrderWindowS;
            CHECK_FALSE((d.start_s <= ws && d.end_s > ws));
            CHECK_FALSE((d.start_s < we && d.end_s >= we));
          }
        }
      }
      CHECK(devices.size() == p.down_times.size());
      // Gate schedule: consecutive, 60..180 s (the last may be stretched to < 240 s), the next
      // gate differs from the previous one, ends at 900.
      int t = 0;
      for (std::size_t i = 0; i < p.gate_schedule.size(); ++i) {
        const GatePeriod& g = p.gate_schedule[i];
        CHECK(g.start_s == t);
        CHECK(g.gate.value() >= kD1);
        CHECK(g.gate.value() <= kD3);
        const int len = g.end_s - g.start_s;
        CHECK(len >= 1);
        if (i + 1 < p.gate_schedule.size()) {
          CHECK(len >= 60);
          CHECK(len <= 180);
          CHECK(p.gate_schedule[i + 1].gate != g.gate);
          CHECK(g.end_s <= 840);
        } else {
          CHECK(len < 240);
        }
        t = g.end_s;
      }
      CHECK(t == 900);
      // Quirk 1 (0.6.1 only): without a T5 down time the default quantities are used.
      if (rules == kRulesRefbox061) {
        if (t5_has_down(p)) {
          ++t5_down_games;
        } else {
          CHECK(p.order_quantities == kDefaultOrderQuantities);
          ++quantities_default;
        }
      }
    }
  }
  // Both branches of quirk 1 occur in 300 games.
  CHECK(quantities_default > 0);
  CHECK(t5_down_games > 0);
}

TEST_CASE("the same seed gives the same plan, different seeds differ") {
  CHECK(draw(7) == draw(7));
  CHECK_FALSE(draw(7) == draw(8));
  // The rule book always draws quantities, so its quantities differ from the defaults mostly.
  int differ = 0;
  for (std::uint64_t s = 1; s <= 50; ++s)
    differ += draw(s, kRulesRulebook2013).order_quantities != kDefaultOrderQuantities;
  CHECK(differ >= 45);
}

TEST_CASE("validate_game_params names the bad field") {
  GameParams ok = draw(3);
  auto error_of = [](const GameParams& p) -> std::string {
    try {
      validate_game_params(p);
    } catch (const core::ConfigError& e) {
      return e.what();
    }
    return "";
  };
  CHECK(error_of(ok).empty());
  GameParams p = ok;
  p.machine_types[0] = p.machine_types[0] == MachineType::kT5 ? MachineType::kT1 : MachineType::kT5;
  CHECK(error_of(p).find("params.machine_types") == 0);
  p = ok;
  p.proc_time_s[2] = 0;
  CHECK(error_of(p).find("params.proc_time_s.T3: must be > 0") == 0);
  p = ok;
  p.light_codes[4] = p.light_codes[1];
  CHECK(error_of(p).find("params.light_codes.T5: same code as T2") == 0);
  p = ok;
  p.light_codes[0] = kAllOff;
  CHECK(error_of(p).find("params.light_codes.T1") == 0);
  p = ok;
  p.order_quantities[8] = 0;
  CHECK(error_of(p).find("params.order_quantities[8]") == 0);
  p = ok;
  p.late_order_start_s[1] = 850;
  CHECK(error_of(p).find("params.late_order_start_s[1]") == 0);
  p = ok;
  p.down_times.push_back({DeviceId(kD1), 10, 20});
  CHECK(error_of(p).find(".machine: must be one of M1..M10, R1, R2") != std::string::npos);
  p = ok;
  p.down_times.push_back(p.down_times[0]);
  CHECK(error_of(p).find("at most one down time per machine") != std::string::npos);
  p = ok;
  REQUIRE(p.gate_schedule.size() >= 2);
  p.gate_schedule.pop_back();
  CHECK(error_of(p).find("params.gate_schedule: must cover production") == 0);
  p = ok;
  p.gate_schedule[1].start_s += 1;
  CHECK(error_of(p).find("params.gate_schedule[1].start_s") == 0);
}
