// SPDX-License-Identifier: MIT
// Deterministic JSON rendering of the game report.
#include "llsf/refbox/report.h"

#include <nlohmann/json.hpp>

namespace llsf::refbox {

namespace {

using Json = nlohmann::ordered_json;  // fixed key order: the same report, the same bytes

/// Seconds with (at most) 3 decimals from whole milliseconds: one correctly rounded division,
/// identical everywhere.
Json secs(SimTime t) { return static_cast<double>(t.ns() / 1000000) / 1000.0; }

Json dev(DeviceId d) { return is_valid_device(d) ? Json(device_name(d)) : Json(nullptr); }
Json id_or_null(int v, bool valid) { return valid ? Json(v) : Json(nullptr); }

Json params_json(const GameParams& p) {
  Json types = Json::object();
  for (int i = 0; i < kProductionMachineCount; ++i) {
    types[std::string(kDeviceNames[i])] = to_string(p.machine_types[i]);
  }
  Json proc = Json::object();
  Json lights = Json::object();
  for (int t = 0; t < 5; ++t) {
    proc["T" + std::to_string(t + 1)] = p.proc_time_s[t];
    lights["T" + std::to_string(t + 1)] = light_code_string(p.light_codes[t]);
  }
  Json down = Json::array();
  for (const DownTime& d : p.down_times) {
    down.push_back({{"machine", dev(d.device)}, {"start_s", d.start_s}, {"end_s", d.end_s}});
  }
  Json gates = Json::array();
  for (const GatePeriod& g : p.gate_schedule) {
    gates.push_back({{"gate", dev(g.gate)}, {"start_s", g.start_s}, {"end_s", g.end_s}});
  }
  return {{"machine_types", std::move(types)},          {"proc_time_s", std::move(proc)},
          {"light_codes", std::move(lights)},           {"order_quantities", p.order_quantities},
          {"late_order_start_s", p.late_order_start_s}, {"down_times", std::move(down)},
          {"gate_schedule", std::move(gates)}};
}

}  // namespace

std::string to_json(const GameReport& r) {
  Json totals = Json::array();
  for (const PhaseTotal& t : r.phase_totals) {
    totals.push_back({{"phase", to_string(t.phase)}, {"sum", t.sum}, {"counted", t.counted}});
  }
  Json awards = Json::array();
  for (const PointsAward& a : r.awards) {
    awards.push_back({{"t", secs(a.game_time)},
                      {"phase", to_string(a.phase)},
                      {"points", a.points},
                      {"reason", to_string(a.reason)},
                      {"device", dev(a.device)},
                      {"order", id_or_null(a.order.value(), a.order.valid())},
                      {"puck", id_or_null(a.puck.value(), a.puck.valid())}});
  }
  Json orders = Json::array();
  for (const OrderSummary& s : r.orders) {
    orders.push_back({{"id", s.id.value()},
                      {"product", to_string(s.product)},
                      {"requested", s.requested},
                      {"delivered", s.delivered},
                      {"window", Json::array({s.window_begin_s, s.window_end_s})},
                      {"late", s.late}});
  }
  Json deliveries = Json::array();
  for (const DeliveryRecord& d : r.deliveries) {
    deliveries.push_back({{"t", secs(d.game_time)},
                          {"gate", dev(d.gate)},
                          {"puck", d.puck.value()},
                          {"product", to_string(d.product)},
                          {"order", id_or_null(d.order.value(), d.order.valid())},
                          {"points", d.points}});
  }
  Json history = Json::array();
  for (const MachineHistoryEntry& h : r.machine_history) {
    history.push_back({{"t", secs(h.game_time)},
                       {"phase", to_string(h.phase)},
                       {"device", dev(h.device)},
                       {"from", to_string(h.from)},
                       {"to", to_string(h.to)},
                       {"puck", id_or_null(h.puck.value(), h.puck.valid())}});
  }
  const Json j = {{"rules", r.rules},
                  {"team", r.team},
                  {"seed", r.seed},
                  {"final_state", to_string(r.final_state)},
                  {"final_phase", to_string(r.final_phase)},
                  {"mode", to_string(r.mode)},
                  {"overtime", r.overtime},
                  {"params", r.params ? params_json(*r.params) : Json(nullptr)},
                  {"total_points", r.total_points},
                  {"phase_totals", std::move(totals)},
                  {"awards", std::move(awards)},
                  {"orders", std::move(orders)},
                  {"deliveries", std::move(deliveries)},
                  {"machine_history", std::move(history)}};
  return j.dump(2, ' ', false, Json::error_handler_t::replace) + "\n";
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
