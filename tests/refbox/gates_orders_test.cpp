// SPDX-License-Identifier: MIT
// Delivery gates, orders, late orders and delivery points (spec §2.4, §6, §7, §8), both variants.
#include <doctest/doctest.h>

#include "fixture.h"

using namespace llsf;
using namespace llsf::refbox;
using namespace llsf::refbox::test;

namespace {

void make(Game& g, DeviceId m, int p, double s) {
  g.enter(m, p);
  g.step();
  g.run_s(s);
  g.leave(m, p);
  g.step();
}
void make_p3(Game& g, int p) {
  make(g, M(5), p, 30.1);
  REQUIRE(g.state_of(p) == PuckState::kP3);
}
/// P1 in puck `b` from S0 pucks a, b, c, d (a, b -> S1; c + b -> S2; d + a + b -> P1).
void make_p1(Game& g, int a, int b, int c, int d) {
  make(g, M(1), a, 4.1);
  make(g, M(6), b, 4.1);
  make(g, M(2), c, 2.05);
  make(g, M(2), b, 20.1);
  make(g, M(3), d, 2.05);
  make(g, M(3), a, 2.05);
  make(g, M(3), b, 50.1);
  REQUIRE(g.state_of(b) == PuckState::kP1);
}
/// Puts `p` at gate `d` and waits for the 1 s delivery (the puck is not taken away).
void put(Game& g, DeviceId d, int p, double wait_s = 1.05) {
  g.enter(d, p);
  g.step();
  g.run_s(wait_s);
}
const DeviceId D1 = dev(kD1), D2 = dev(kD2), D3 = dev(kD3);

/// The test plan with late-order windows 120-240 and 700-820 (none around 300 s).
RefboxConfig early_late_orders(std::string_view rules) {
  RefboxConfig c = test_config(rules);
  c.params->late_order_start_s = {120, 700};
  return c;
}

bool has_action(const Game& g, RefereeAction::Kind k, int p) {
  for (const auto& a : g.actions) {
    if (a.kind == k && a.puck == puck(p)) return true;
  }
  return false;
}

}  // namespace

TEST_CASE("delivery at the active gate: 1 s processing, all lamps, FINISHED, +10, remove puck") {
  Game g(test_config());
  g.start_production();
  CHECK(g.rb.active_gate() == D1);
  CHECK(g.m(D1).lights == L(kOff, kOff, kOn));
  CHECK(g.m(D2).lights == L(kOn, kOff, kOff));
  CHECK(g.m(D2).state == MachineState::kDown);
  make_p3(g, 1);
  g.enter(D1, 1);
  g.step();
  CHECK(g.m(D1).state == MachineState::kProcessing);
  CHECK(g.m(D1).lights == L(kOff, kOn, kOn));
  g.run_s(1.05);
  CHECK(g.state_of(1) == PuckState::kFinished);
  CHECK(g.m(D1).lights == kAllOn);
  CHECK(has_action(g, RefereeAction::Kind::kRemovePuck, 1));
  REQUIRE(!g.awards.empty());
  const PointsAward& a = g.awards.back();
  CHECK(a.points == 10);
  CHECK(a.reason == AwardReason::kDelivery);
  CHECK(a.order == OrderId(3));
  CHECK(a.device == D1);
  CHECK(g.rb.orders()[2].quantity_delivered == 1);
  g.leave(D1, 1);
  g.step();
  CHECK(g.m(D1).lights == L(kOff, kOff, kOn));
  // An intermediate at the active gate: yellow blinking, 0 points, puck unchanged.
  g.enter(D1, 2);
  g.step();
  CHECK(g.m(D1).state == MachineState::kInvalid);
  CHECK(g.m(D1).lights == L(kOff, kBlink, kOff));
  CHECK(g.state_of(2) == PuckState::kS0);
  CHECK(g.awards.back().reason == AwardReason::kDeliveryIntermediate);
  CHECK(g.awards.back().points == 0);
  // ... and at an inactive gate: red + yellow blinking.
  g.enter(D3, 3);
  g.step();
  CHECK(g.m(D3).lights == L(kOn, kBlink, kOff));
  g.leave(D3, 3);
  g.step();
  CHECK(g.m(D3).lights == L(kOn, kOff, kOff));
  const GameReport r = g.rb.report();
  REQUIRE(r.deliveries.size() == 1);
  CHECK(r.deliveries[0].order == OrderId(3));
  CHECK(r.deliveries[0].points == 10);
}

TEST_CASE("ordered product at an inactive gate: 0.6.1 ignores it, the rule book takes it out") {
  SUBCASE("refbox-0.6.1: no reaction; delivered once the gate becomes active") {
    Game g(early_late_orders(kRulesRefbox061));
    g.start_production();
    make_p3(g, 1);
    put(g, D2, 1, 3.0);
    CHECK(g.state_of(1) == PuckState::kP3);
    CHECK(g.m(D2).lights == L(kOn, kOff, kOff));
    CHECK(g.m(D2).state == MachineState::kDown);
    CHECK(g.award_sum() == 0);
    // D2 becomes active at 300 s: the puck lying there is delivered to order 6 (300-599).
    g.run_to_game_time(301.2);
    CHECK(g.state_of(1) == PuckState::kFinished);
    CHECK(g.awards.back().order == OrderId(6));
    CHECK(g.awards.back().points == 10);
  }
  SUBCASE("rulebook-2013: red + yellow blinking, puck out of the game, 0 points") {
    Game g(early_late_orders(kRulesRulebook2013));
    g.start_production();
    make_p3(g, 1);
    put(g, D2, 1);
    CHECK(g.state_of(1) == PuckState::kConsumed);
    CHECK(g.m(D2).lights == L(kOn, kBlink, kOff));
    CHECK(has_action(g, RefereeAction::Kind::kRemovePuck, 1));
    g.run_to_game_time(301.2);
    CHECK(g.award_sum() == 0);
    CHECK(g.rb.orders()[5].quantity_delivered == 0);
  }
}

TEST_CASE("a just-switched gate accepts deliveries for 3 s") {
  for (auto rules : {kRulesRefbox061, kRulesRulebook2013}) {
    CAPTURE(rules);
    Game g(early_late_orders(rules));
    g.start_production();
    make_p3(g, 1);
    make_p3(g, 2);
    g.run_to_game_time(302.5);
    CHECK(g.rb.active_gate() == D2);
    CHECK(g.m(D1).lights == L(kOn, kOff, kOff));
    put(g, D1, 1);  // 2.5 s after the switch: accepted
    CHECK(g.state_of(1) == PuckState::kFinished);
    CHECK(g.awards.back().points == 10);
    CHECK(g.awards.back().order == OrderId(6));
    // Delivered in the grace, the gate is down while holding it: red + yellow blinking.
    CHECK(g.m(D1).lights == L(kOn, kBlink, kOff));
    g.leave(D1, 1);
    g.step();
    CHECK(g.m(D1).lights == L(kOn, kOff, kOff));
    put(g, D1, 2);  // ~4.6 s after the switch: too late
    CHECK(g.state_of(2) != PuckState::kFinished);
    CHECK(g.rb.orders()[5].quantity_delivered == 1);
  }
}

TEST_CASE("a gate that goes down while holding a puck: red + yellow blinking, puck FINISHED") {
  Game g(test_config());
  g.start_production();
  g.run_to_game_time(298);
  g.enter(D1, 5);  // an S0: invalid at the active gate
  g.step();
  CHECK(g.m(D1).state == MachineState::kInvalid);
  g.run_to_game_time(300.05);
  CHECK(g.m(D1).lights == L(kOn, kBlink, kOff));
  CHECK(g.state_of(5) == PuckState::kFinished);
  CHECK(has_action(g, RefereeAction::Kind::kRemovePuck, 5));
  CHECK(g.m(D2).lights == L(kOff, kOff, kOn));
}

TEST_CASE(
    "late orders: activation (5 s early in 0.6.1), extra S0, 20 points, matching preference") {
  for (auto rules : {kRulesRefbox061, kRulesRulebook2013}) {
    CAPTURE(rules);
    Game g(test_config(rules));
    g.start_production();
    CHECK(g.activated.size() == 9);  // orders 1..9 at production start
    CHECK_FALSE(g.rb.orders()[9].active);
    const double lead = rules == kRulesRefbox061 ? 5.0 : 0.0;
    g.run_to_game_time(200 - lead - 0.05);
    CHECK_FALSE(g.rb.orders()[9].active);
    g.run_to_game_time(200 - lead + 0.05);
    CHECK(g.rb.orders()[9].active);
    CHECK(g.activated.back() == OrderId(10));
    CHECK(g.attention_contains("Late order 10"));
    REQUIRE(!g.actions.empty());
    const RefereeAction& place = g.actions.back();
    CHECK(place.kind == RefereeAction::Kind::kPlacePuck);
    CHECK(place.place == RefereeAction::Place::kInsertionSlot);
    CHECK(place.puck == puck(21));
    CHECK(g.state_of(21) == PuckState::kS0);
  }
  // With the insertion slot occupied the extra puck goes into the input storage.
  Game g(test_config());
  g.start_production();
  g.slot_occupied = true;
  g.run_to_game_time(196);
  CHECK(g.actions.back().place == RefereeAction::Place::kInputStorage);
}

TEST_CASE("order matching prefers the late order, then an unfulfilled order, then extra points") {
  RefboxConfig cfg = test_config();
  cfg.params->order_quantities[2] = 1;  // order 3: one P3 in 0-299
  Game g(std::move(cfg));
  g.start_production();
  for (int p = 1; p <= 4; ++p) make_p3(g, p);  // ~121 s
  g.run_to_game_time(201);
  // Late order 10 (20/0) and order 3 (10/1) both in window: the late order first.
  put(g, D1, 1);
  CHECK(g.awards.back().order == OrderId(10));
  CHECK(g.awards.back().points == 20);
  CHECK(g.awards.back().reason == AwardReason::kDelivery);
  g.leave(D1, 1);
  // Late order full: the unfulfilled order 3 next.
  put(g, D1, 2);
  CHECK(g.awards.back().order == OrderId(3));
  CHECK(g.awards.back().points == 10);
  g.leave(D1, 2);
  // Both full: higher extra-unit points (order 3: 1, late order: 0).
  put(g, D1, 3);
  CHECK(g.awards.back().order == OrderId(3));
  CHECK(g.awards.back().points == 1);
  CHECK(g.awards.back().reason == AwardReason::kDeliveryExtra);
  CHECK(g.rb.orders()[2].quantity_delivered == 2);
  CHECK(g.rb.orders()[9].quantity_delivered == 1);
  CHECK(g.rb.points() == 31);
}

TEST_CASE("deliveries outside every window: pending in 0.6.1, +1 in the rule book") {
  for (auto rules : {kRulesRefbox061, kRulesRulebook2013}) {
    CAPTURE(rules);
    Game g(test_config(rules));
    g.start_production();
    make_p1(g, 1, 2, 3, 4);
    g.run_to_game_time(298.7);
    put(g, D1, 2, 1.1);  // completes at ~299.8 s: order 1 ended at 299, order 4 starts at 300
    CHECK(g.state_of(2) == PuckState::kFinished);
    const PointsAward a = g.awards.back();
    CHECK(a.reason == AwardReason::kDeliveryOutOfWindow);
    CHECK_FALSE(a.order.valid());
    g.run_to_game_time(300.5);
    if (rules == kRulesRefbox061) {
      CHECK(a.points == 0);
      CHECK(g.awards.back().reason == AwardReason::kDeliveryPendingCredited);
      CHECK(g.awards.back().order == OrderId(4));
      CHECK(g.awards.back().points == 10);
      CHECK(g.rb.orders()[3].quantity_delivered == 1);
      CHECK(g.rb.report().deliveries.back().points == 10);
    } else {
      CHECK(a.points == 1);
      CHECK(g.awards.back().reason == AwardReason::kDeliveryOutOfWindow);
      CHECK(g.rb.orders()[3].quantity_delivered == 0);
    }
    CHECK(g.rb.points() == g.award_sum());
  }
}

TEST_CASE("recycling points differ by variant") {
  for (auto rules : {kRulesRefbox061, kRulesRulebook2013}) {
    Game g(test_config(rules));
    g.start_production();
    make(g, M(2), 1, 2.05);                         // loaded in M2
    g.command(command::RemovePuck{M(2), puck(1)});  // referee takes it out: CONSUMED
    g.step();
    REQUIRE(g.state_of(1) == PuckState::kConsumed);
    make(g, dev(kR2), 1, 2.05);
    CHECK(g.state_of(1) == PuckState::kS0);
    CHECK(g.award_sum() == (rules == kRulesRefbox061 ? 3 : 5));
  }
}
