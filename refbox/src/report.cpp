// SPDX-License-Identifier: MIT
// Deterministic JSON rendering of the game report.
#include "llsf/refbox/report.h"

#include <cstdio>

namespace llsf::refbox {

namespace {

/// Seconds with 3 decimals from integer nanoseconds (no floating point: identical everywhere).
std::string secs(SimTime t) {
  const std::int64_t ms = t.ns() / 1000000;
  const std::int64_t a = ms < 0 ? -ms : ms;
  char buf[40];
  std::snprintf(buf, sizeof buf, "%s%lld.%03lld", ms < 0 ? "-" : "",
                static_cast<long long>(a / 1000), static_cast<long long>(a % 1000));
  return buf;
}

std::string quote(std::string_view s) {
  std::string r = "\"";
  for (char c : s) {
    if (c == '"' || c == '\\') {
      r += '\\';
      r += c;
    } else if (static_cast<unsigned char>(c) < 0x20) {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\u%04x", static_cast<unsigned>(c));
      r += buf;
    } else {
      r += c;
    }
  }
  return r + "\"";
}

std::string dev(DeviceId d) { return is_valid_device(d) ? quote(device_name(d)) : "null"; }
std::string id_or_null(int v, bool valid) { return valid ? std::to_string(v) : "null"; }

void params_json(std::string& o, const GameParams& p) {
  o += "{\"machine_types\": {";
  for (int i = 0; i < kProductionMachineCount; ++i) {
    if (i) o += ", ";
    o += quote(kDeviceNames[i]) + ": " + quote(to_string(p.machine_types[i]));
  }
  o += "}, \"proc_time_s\": {";
  for (int t = 0; t < 5; ++t) {
    if (t) o += ", ";
    o += "\"T" + std::to_string(t + 1) + "\": " + std::to_string(p.proc_time_s[t]);
  }
  o += "}, \"light_codes\": {";
  for (int t = 0; t < 5; ++t) {
    if (t) o += ", ";
    o += "\"T" + std::to_string(t + 1) + "\": " + quote(light_code_string(p.light_codes[t]));
  }
  o += "}, \"order_quantities\": [";
  for (int i = 0; i < kRegularOrderCount; ++i) {
    if (i) o += ", ";
    o += std::to_string(p.order_quantities[i]);
  }
  o += "], \"late_order_start_s\": [" + std::to_string(p.late_order_start_s[0]) + ", " +
       std::to_string(p.late_order_start_s[1]) + "], \"down_times\": [";
  for (std::size_t i = 0; i < p.down_times.size(); ++i) {
    const DownTime& d = p.down_times[i];
    if (i) o += ", ";
    o += "{\"machine\": " + dev(d.device) + ", \"start_s\": " + std::to_string(d.start_s) +
         ", \"end_s\": " + std::to_string(d.end_s) + "}";
  }
  o += "], \"gate_schedule\": [";
  for (std::size_t i = 0; i < p.gate_schedule.size(); ++i) {
    const GatePeriod& g = p.gate_schedule[i];
    if (i) o += ", ";
    o += "{\"gate\": " + dev(g.gate) + ", \"start_s\": " + std::to_string(g.start_s) +
         ", \"end_s\": " + std::to_string(g.end_s) + "}";
  }
  o += "]}";
}

}  // namespace

std::string to_json(const GameReport& r) {
  std::string o;
  o.reserve(4096 + 160 * (r.awards.size() + r.machine_history.size() + r.deliveries.size()));
  o += "{\n  \"rules\": " + quote(r.rules) + ",\n  \"team\": " + quote(r.team) +
       ",\n  \"seed\": " + std::to_string(r.seed) +
       ",\n  \"final_state\": " + quote(to_string(r.final_state)) +
       ",\n  \"final_phase\": " + quote(to_string(r.final_phase)) +
       ",\n  \"mode\": " + quote(to_string(r.mode)) +
       ",\n  \"overtime\": " + (r.overtime ? "true" : "false") + ",\n  \"params\": ";
  if (r.params) {
    params_json(o, *r.params);
  } else {
    o += "null";
  }
  o += ",\n  \"total_points\": " + std::to_string(r.total_points) + ",\n  \"phase_totals\": [";
  for (std::size_t i = 0; i < r.phase_totals.size(); ++i) {
    const PhaseTotal& t = r.phase_totals[i];
    o += std::string(i ? ", " : "") + "{\"phase\": " + quote(to_string(t.phase)) +
         ", \"sum\": " + std::to_string(t.sum) + ", \"counted\": " + std::to_string(t.counted) +
         "}";
  }
  o += "],\n  \"awards\": [";
  for (std::size_t i = 0; i < r.awards.size(); ++i) {
    const PointsAward& a = r.awards[i];
    o += std::string(i ? ",\n    " : "\n    ") + "{\"t\": " + secs(a.game_time) +
         ", \"phase\": " + quote(to_string(a.phase)) + ", \"points\": " + std::to_string(a.points) +
         ", \"reason\": " + quote(to_string(a.reason)) + ", \"device\": " + dev(a.device) +
         ", \"order\": " + id_or_null(a.order.value(), a.order.valid()) +
         ", \"puck\": " + id_or_null(a.puck.value(), a.puck.valid()) + "}";
  }
  o += "],\n  \"orders\": [";
  for (std::size_t i = 0; i < r.orders.size(); ++i) {
    const OrderSummary& s = r.orders[i];
    o += std::string(i ? ",\n    " : "\n    ") + "{\"id\": " + std::to_string(s.id.value()) +
         ", \"product\": " + quote(to_string(s.product)) +
         ", \"requested\": " + std::to_string(s.requested) +
         ", \"delivered\": " + std::to_string(s.delivered) + ", \"window\": [" +
         std::to_string(s.window_begin_s) + ", " + std::to_string(s.window_end_s) +
         "], \"late\": " + (s.late ? "true" : "false") + "}";
  }
  o += "],\n  \"deliveries\": [";
  for (std::size_t i = 0; i < r.deliveries.size(); ++i) {
    const DeliveryRecord& d = r.deliveries[i];
    o += std::string(i ? ",\n    " : "\n    ") + "{\"t\": " + secs(d.game_time) +
         ", \"gate\": " + dev(d.gate) + ", \"puck\": " + std::to_string(d.puck.value()) +
         ", \"product\": " + quote(to_string(d.product)) +
         ", \"order\": " + id_or_null(d.order.value(), d.order.valid()) +
         ", \"points\": " + std::to_string(d.points) + "}";
  }
  o += "],\n  \"machine_history\": [";
  for (std::size_t i = 0; i < r.machine_history.size(); ++i) {
    const MachineHistoryEntry& h = r.machine_history[i];
    o += std::string(i ? ",\n    " : "\n    ") + "{\"t\": " + secs(h.game_time) +
         ", \"phase\": " + quote(to_string(h.phase)) + ", \"device\": " + dev(h.device) +
         ", \"from\": " + quote(to_string(h.from)) + ", \"to\": " + quote(to_string(h.to)) +
         ", \"puck\": " + id_or_null(h.puck.value(), h.puck.valid()) + "}";
  }
  o += "]\n}\n";
  return o;
}

std::string_view to_string(AwardReason r) {
  switch (r) {
    case AwardReason::kExplorationCorrect:
      return "EXPLORATION_CORRECT";
    case AwardReason::kExplorationWrong:
      return "EXPLORATION_WRONG";
    case AwardReason::kMachineCompleted:
      return "MACHINE_COMPLETED";
    case AwardReason::kRecycled:
      return "RECYCLED";
    case AwardReason::kDelivery:
      return "DELIVERY";
    case AwardReason::kDeliveryExtra:
      return "DELIVERY_EXTRA";
    case AwardReason::kDeliveryOutOfWindow:
      return "DELIVERY_OUT_OF_WINDOW";
    case AwardReason::kDeliveryPendingCredited:
      return "DELIVERY_PENDING_CREDITED";
    case AwardReason::kDeliveryIntermediate:
      return "DELIVERY_INTERMEDIATE";
    case AwardReason::kPenaltyMinor:
      return "PENALTY_MINOR";
    case AwardReason::kPenaltyMajor:
      return "PENALTY_MAJOR";
    case AwardReason::kMoleReached:
      return "MOLE_REACHED";
    case AwardReason::kMoleReachedReferee:
      return "MOLE_REACHED_REFEREE";
  }
  return "?";
}

}  // namespace llsf::refbox
