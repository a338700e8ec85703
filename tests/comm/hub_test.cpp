// SPDX-License-Identifier: MIT
// The in-process hub: loss models (rates over 100,000 messages, correlation across receivers,
// burst lengths), delays and reordering, outages, channels, determinism and counters.
//
// Statistical tolerances: with n = 100,000 Bernoulli draws of p = 0.3 the standard deviation of
// the observed rate is sqrt(p (1 - p) / n) = 0.00145; the tests allow 0.01 (about 7 sigma, a
// spurious failure is out of the question for a fixed seed, and a wrong model is off by far more).
#include <doctest/doctest.h>
#include <llsf_agent_msgs/LockMessage.pb.h>
#include <llsf_agent_msgs/Worldmodel.pb.h>

#include <cmath>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "llsf/comm/hub.h"
#include "llsf/core/assert.h"
#include "llsf/core/error.h"

using namespace llsf::comm;
using llsf::core::Rng;

namespace {

using Outcome = TraceEntry::Outcome;

MessageRegistry registry() {
  MessageRegistry r;
  add_agent_messages(r);
  return r;
}

llsf_agent_msgs::LockMessage lock(const std::string& agent, int n) {
  llsf_agent_msgs::LockMessage m;
  m.set_type(llsf_agent_msgs::LockMessage::GET);
  m.set_agent(agent);
  std::string resource = "M";
  resource += std::to_string(n);
  m.set_resource(resource);
  return m;
}

/// Three robots and the refbox on one team channel, in that order.
struct Team {
  explicit Team(HubConfig cfg, std::uint64_t seed = 1) : hub(std::move(cfg), reg, Rng(seed)) {
    r1 = hub.add_peer("robot1");
    r2 = hub.add_peer("robot2");
    r3 = hub.add_peer("robot3");
    refbox = hub.add_peer("refbox", std::string(kAllChannels));
  }
  MessageRegistry reg = registry();
  Hub hub;
  PeerId r1, r2, r3, refbox;
};

HubConfig loss(LossModel m, double p, SimTime fixed = SimTime::from_ms(0)) {
  HubConfig c;
  c.loss_model = m;
  c.loss_probability = p;
  c.delay.fixed = fixed;
  return c;
}

/// Outcomes of message i for each receiver, from a trace of robot1 broadcasts.
std::vector<std::array<bool, 3>> lost_matrix(const Team& t) {
  std::vector<std::array<bool, 3>> m;
  const auto& tr = t.hub.trace();
  REQUIRE(tr.size() % 3 == 0);
  for (std::size_t i = 0; i < tr.size(); i += 3) {
    std::array<bool, 3> row{};
    for (std::size_t k = 0; k < 3; ++k) row[k] = tr[i + k].outcome == Outcome::kLost;
    // Receivers in ascending peer id: robot2, robot3, refbox.
    CHECK(tr[i].to == t.r2);
    CHECK(tr[i + 2].to == t.refbox);
    m.push_back(row);
  }
  return m;
}

constexpr int kMessages = 100000;

void send_many(Team& t, int n) {
  const auto msg = lock("robot1", 1);
  for (int i = 0; i < n; ++i) {
    const SimTime now = SimTime::from_ms(i);
    REQUIRE(t.hub.broadcast(t.r1, msg, now) == FrameError::kNone);
    t.hub.step(now);
  }
}

}  // namespace

TEST_CASE("no loss: every other peer of the channel gets every message, decoded intact") {
  Team t(HubConfig{});
  CHECK(t.hub.broadcast(t.r1, lock("robot1", 7), SimTime::from_ms(0)) == FrameError::kNone);
  CHECK(t.hub.step(SimTime::from_ms(1)) == 0);  // default delay 2 ms
  CHECK(t.hub.step(SimTime::from_ms(2)) == 3);
  CHECK(t.hub.received(t.r1).empty());  // never back to the sender
  for (const PeerId p : {t.r2, t.r3, t.refbox}) {
    REQUIRE(t.hub.received(p).size() == 1);
    const Delivery& d = t.hub.received(p)[0];
    CHECK(d.from == t.r1);
    CHECK(d.sent_at == SimTime::from_ms(0));
    CHECK(d.due == SimTime::from_ms(2));
    const auto m = t.hub.decode(d);
    CHECK(dynamic_cast<const llsf_agent_msgs::LockMessage&>(*m).resource() == "M7");
  }
  CHECK(t.hub.step(SimTime::from_ms(3)) == 0);
  CHECK(t.hub.received(t.r2).empty());  // the inbox holds one step's deliveries
}

TEST_CASE("global loss: rate matches, and one draw drops a message for every receiver") {
  Team t(loss(LossModel::kGlobal, 0.3));
  t.hub.set_trace(true);
  send_many(t, kMessages);
  const auto m = lost_matrix(t);
  int lost_any = 0, partial = 0;
  for (const auto& row : m) {
    const int n = row[0] + row[1] + row[2];
    lost_any += n > 0;
    partial += n > 0 && n < 3;
  }
  CHECK(partial == 0);  // all or nothing: correlated across receivers
  CHECK(std::abs(lost_any / double(kMessages) - 0.3) < 0.01);
  for (const PeerId p : {t.r2, t.r3, t.refbox}) {
    const TrafficCounters& c = t.hub.link_counters(t.r1, p);
    CHECK(c.sent == kMessages);
    CHECK(c.delivered + c.dropped_by(DropCause::kLoss) == kMessages);
    CHECK(std::abs(c.dropped_by(DropCause::kLoss) / double(kMessages) - 0.3) < 0.01);
  }
}

TEST_CASE("per_link loss: rate matches on every link, drops independent across receivers") {
  Team t(loss(LossModel::kPerLink, 0.3));
  t.hub.set_trace(true);
  send_many(t, kMessages);
  const auto m = lost_matrix(t);
  int both = 0, all3 = 0, partial = 0;
  for (const auto& row : m) {
    both += row[0] && row[1];
    all3 += row[0] && row[1] && row[2];
    const int n = row[0] + row[1] + row[2];
    partial += n > 0 && n < 3;
  }
  // Independence: P(robot2 and robot3 both lose it) = p^2 = 0.09, all three p^3 = 0.027; under
  // the global model these would be 0.3, and `partial` 0.
  CHECK(std::abs(both / double(kMessages) - 0.09) < 0.01);
  CHECK(std::abs(all3 / double(kMessages) - 0.027) < 0.01);
  CHECK(partial > kMessages / 2);
  for (const PeerId p : {t.r2, t.r3, t.refbox}) {
    const TrafficCounters& c = t.hub.link_counters(t.r1, p);
    CHECK(std::abs(c.dropped_by(DropCause::kLoss) / double(kMessages) - 0.3) < 0.01);
  }
}

TEST_CASE("per_link loss with per-link probabilities") {
  HubConfig c = loss(LossModel::kPerLink, 0.1);
  c.links.push_back(LinkConfig{"robot1", "refbox", true, 0.5});
  c.links.push_back(LinkConfig{"robot1", "robot3", false, 0.0});
  Team t(c);
  send_many(t, kMessages);
  const auto rate = [&](PeerId to) {
    return t.hub.link_counters(t.r1, to).dropped_by(DropCause::kLoss) / double(kMessages);
  };
  CHECK(std::abs(rate(t.r2) - 0.1) < 0.01);
  CHECK(rate(t.r3) == 0.0);
  CHECK(std::abs(rate(t.refbox) - 0.5) < 0.01);
  // Symmetric override: refbox -> robot1 also 0.5; robot3 -> robot1 (not symmetric) keeps 0.1.
  const auto msg = lock("x", 1);
  for (int i = 0; i < 20000; ++i) {
    const SimTime now = SimTime::from_ms(kMessages + i);
    t.hub.broadcast(t.refbox, msg, now);
    t.hub.broadcast(t.r3, msg, now);
    t.hub.step(now);
  }
  const auto back = [&](PeerId from) {
    const TrafficCounters& l = t.hub.link_counters(from, t.r1);
    return l.dropped_by(DropCause::kLoss) / double(l.sent);
  };
  CHECK(std::abs(back(t.refbox) - 0.5) < 0.02);
  CHECK(std::abs(back(t.r3) - 0.1) < 0.02);
}

TEST_CASE("burst loss: long-run rate and mean burst length match") {
  // Mean run length of a geometric burst with mean 5 over ~4,000 bursts: sd ~0.07; allow 0.4.
  HubConfig c = loss(LossModel::kBurst, 0.2);
  c.mean_burst_length = 5.0;
  Team t(c);
  t.hub.set_trace(true);
  send_many(t, kMessages);
  const auto m = lost_matrix(t);
  for (std::size_t k = 0; k < 3; ++k) {
    int lost = 0, bursts = 0;
    bool in_burst = false;
    for (const auto& row : m) {
      lost += row[k];
      if (row[k] && !in_burst) ++bursts;
      in_burst = row[k];
    }
    CHECK(std::abs(lost / double(kMessages) - 0.2) < 0.02);
    CHECK(std::abs(lost / double(bursts) - 5.0) < 0.4);
  }
  // Bursts are per link: receivers do not lose the same messages (0.2^2 = 0.04 if independent).
  int both = 0;
  for (const auto& row : m) both += row[0] && row[1];
  CHECK(std::abs(both / double(kMessages) - 0.04) < 0.01);

  // Against per_link at the same rate, whose runs are short (mean 1 / (1 - p) = 1.25).
  Team u(loss(LossModel::kPerLink, 0.2));
  u.hub.set_trace(true);
  send_many(u, kMessages);
  int lost = 0, bursts = 0;
  bool in_burst = false;
  for (const auto& row : lost_matrix(u)) {
    lost += row[0];
    if (row[0] && !in_burst) ++bursts;
    in_burst = row[0];
  }
  CHECK(std::abs(lost / double(bursts) - 1.25) < 0.05);
}

TEST_CASE("delay: fixed per link orders deliveries; jitter reorders within its range") {
  SUBCASE("fixed, per link") {
    HubConfig c;
    c.delay.fixed = SimTime::from_ms(10);
    c.links.push_back(LinkConfig{"robot1", "robot3", true, std::nullopt, SimTime::from_ms(50)});
    Team t(c);
    t.hub.broadcast(t.r1, lock("robot1", 1), SimTime::from_ms(0));
    t.hub.broadcast(t.r1, lock("robot1", 2), SimTime::from_ms(5));
    std::map<int, std::vector<std::pair<int, std::string>>> got;  // ms -> (peer, resource)
    for (int ms = 0; ms <= 60; ++ms) {
      t.hub.step(SimTime::from_ms(ms));
      for (const PeerId p : {t.r2, t.r3, t.refbox}) {
        for (const Delivery& d : t.hub.received(p)) {
          const auto m = t.hub.decode(d);
          got[ms].emplace_back(p.value(),
                               dynamic_cast<const llsf_agent_msgs::LockMessage&>(*m).resource());
        }
      }
    }
    using V = std::vector<std::pair<int, std::string>>;
    CHECK(got.size() == 4);
    CHECK(got[10] == V{{t.r2.value(), "M1"}, {t.refbox.value(), "M1"}});
    CHECK(got[15] == V{{t.r2.value(), "M2"}, {t.refbox.value(), "M2"}});
    CHECK(got[50] == V{{t.r3.value(), "M1"}});
    CHECK(got[55] == V{{t.r3.value(), "M2"}});
    const auto& h = t.hub.link_counters(t.r1, t.r3).delay;
    CHECK(h.count == 2);
    CHECK(h.min_ns == 50000000);
    CHECK(h.max_ns == 50000000);
    CHECK(h.counts[6] == 2);  // bucket [50, 100) ms
  }
  SUBCASE("jitter") {
    HubConfig c;
    c.delay.fixed = SimTime::from_ms(2);
    c.delay.jitter = SimTime::from_ms(20);
    Team t(c);
    int reordered = 0, delivered = 0;
    std::int64_t last_sent = -1;
    SimTime max_delay, min_delay = SimTime::from_sec(1);
    for (int ms = 0; ms < 5000; ++ms) {
      const SimTime now = SimTime::from_ms(ms);
      if (ms < 4000) t.hub.broadcast(t.r1, lock("robot1", ms), now);
      t.hub.step(now);
      SimTime last_due;
      for (const Delivery& d : t.hub.received(t.r2)) {
        ++delivered;
        // Delivered at the first step at or after its due time, in due order within a step.
        CHECK(d.due <= now);
        CHECK(d.due > now - SimTime::from_ms(1));
        CHECK(d.due >= last_due);
        last_due = d.due;
        max_delay = std::max(max_delay, d.due - d.sent_at);
        min_delay = std::min(min_delay, d.due - d.sent_at);
        if (d.sent_at.ns() < last_sent) ++reordered;
        last_sent = std::max(last_sent, d.sent_at.ns());
      }
    }
    CHECK(delivered == 4000);
    CHECK(reordered > 1000);  // a message sent 1 ms later often overtakes
    CHECK(min_delay >= SimTime::from_ms(2));
    CHECK(max_delay <= SimTime::from_ms(22));
    CHECK(max_delay > SimTime::from_ms(21));
    const auto& h = t.hub.link_counters(t.r1, t.r2).delay;
    CHECK(std::abs(h.mean_ms() - 12.5) < 0.5);  // 2 + U[0, 20] ms, observed at 1 ms ticks
  }
  SUBCASE("without jitter, FIFO per link even with equal due times") {
    Team t(HubConfig{});
    for (int i = 0; i < 10; ++i) t.hub.broadcast(t.r1, lock("robot1", i), SimTime::from_ms(0));
    t.hub.step(SimTime::from_ms(5));
    REQUIRE(t.hub.received(t.r2).size() == 10);
    for (int i = 0; i < 10; ++i) {
      const auto m = t.hub.decode(t.hub.received(t.r2)[static_cast<std::size_t>(i)]);
      CHECK(dynamic_cast<const llsf_agent_msgs::LockMessage&>(*m).resource() ==
            std::string("M").append(std::to_string(i)));
    }
  }
}

TEST_CASE("outages drop exactly the messages sent in their window") {
  HubConfig c;
  c.delay.fixed = SimTime::from_ms(0);
  c.outages.push_back(OutageConfig{"robot2", "", SimTime::from_sec(1), SimTime::from_sec(2)});
  c.outages.push_back(
      OutageConfig{"robot1", "robot3", SimTime::from_ms(2500), SimTime::from_ms(2600)});
  c.outages.push_back(OutageConfig{"refbox", "", SimTime::from_ms(500), SimTime::from_ms(700)});
  Team t(c);
  t.hub.set_trace(true);
  // Every peer broadcasts every 10 ms for 3 s.
  for (int ms = 0; ms < 3000; ms += 10) {
    const SimTime now = SimTime::from_ms(ms);
    for (const PeerId p : {t.r1, t.r2, t.r3, t.refbox}) t.hub.broadcast(p, lock("x", ms), now);
    t.hub.step(now);
  }
  int outage_drops = 0;
  for (const TraceEntry& e : t.hub.trace()) {
    const std::int64_t ms = e.sent_at.ns() / 1000000;
    const bool r2_cut = (e.from == t.r2 || e.to == t.r2) && ms >= 1000 && ms < 2000;
    const bool pair_cut = ((e.from == t.r1 && e.to == t.r3) || (e.from == t.r3 && e.to == t.r1)) &&
                          ms >= 2500 && ms < 2600;
    const bool refbox_cut = (e.from == t.refbox || e.to == t.refbox) && ms >= 500 && ms < 700;
    const bool cut = r2_cut || pair_cut || refbox_cut;
    CHECK((e.outcome == Outcome::kOutage) == cut);
    if (!cut) CHECK(e.outcome == Outcome::kQueued);
    outage_drops += cut;
  }
  // robot2: 100 sends x 3 receivers + 3 senders x 100 sends; pair: 2 x 10; refbox: 20 x 6 minus
  // nothing shared (the windows do not overlap).
  CHECK(outage_drops == 600 + 20 + 120);
  CHECK(t.hub.link_counters(t.r1, t.r2).dropped_by(DropCause::kOutage) == 100);
  CHECK(t.hub.link_counters(t.r2, t.r1).dropped_by(DropCause::kOutage) == 100);
  CHECK(t.hub.link_counters(t.r1, t.r3).dropped_by(DropCause::kOutage) == 10);
  CHECK(t.hub.link_counters(t.r3, t.r2).dropped_by(DropCause::kOutage) == 100);
  CHECK(t.hub.link_counters(t.refbox, t.r3).dropped_by(DropCause::kOutage) == 20);
  CHECK(t.hub.link_counters(t.r3, t.r1).delivered == 300 - 10);
}

TEST_CASE("an outage added while running") {
  Team t(HubConfig{});
  const auto msg = lock("x", 1);
  int got = 0;
  for (int ms = 0; ms < 100; ++ms) {
    const SimTime now = SimTime::from_ms(ms);
    if (ms == 40) t.hub.add_outage(OutageConfig{"refbox", "", now, now + SimTime::from_ms(20)});
    t.hub.broadcast(t.r1, msg, now);
    t.hub.step(now);
    got += static_cast<int>(t.hub.received(t.refbox).size());
  }
  CHECK(t.hub.link_counters(t.r1, t.refbox).dropped_by(DropCause::kOutage) == 20);
  CHECK(got == 100 - 20 - 2);  // and the last 2 ms are still in flight
  CHECK_THROWS_AS(t.hub.add_outage(OutageConfig{"refbox", "", SimTime::from_ms(5), SimTime()}),
                  llsf::core::ConfigError);
}

TEST_CASE("an outage under a loss model does not change the other links' draws") {
  HubConfig c = loss(LossModel::kPerLink, 0.3);
  Team a(c, 5);
  c.outages.push_back(OutageConfig{"robot2", "", SimTime::from_ms(100), SimTime::from_ms(300)});
  Team b(c, 5);
  a.hub.set_trace(true);
  b.hub.set_trace(true);
  send_many(a, 1000);
  send_many(b, 1000);
  REQUIRE(a.hub.trace().size() == b.hub.trace().size());
  int differ = 0;
  for (std::size_t i = 0; i < a.hub.trace().size(); ++i) {
    const TraceEntry& x = a.hub.trace()[i];
    const TraceEntry& y = b.hub.trace()[i];
    if (x == y) continue;
    ++differ;
    CHECK(y.to == b.r2);
    CHECK(y.outcome == Outcome::kOutage);
  }
  CHECK(differ > 100);
}

TEST_CASE("changing one link's loss probability changes only that link's outcomes") {
  HubConfig c = loss(LossModel::kPerLink, 0.3);
  Team a(c, 8);
  c.links.push_back(LinkConfig{"robot1", "robot3", false, 0.9});
  Team b(c, 8);
  a.hub.set_trace(true);
  b.hub.set_trace(true);
  send_many(a, 2000);
  send_many(b, 2000);
  REQUIRE(a.hub.trace().size() == b.hub.trace().size());
  int changed = 0;
  for (std::size_t i = 0; i < a.hub.trace().size(); ++i) {
    const TraceEntry& x = a.hub.trace()[i];
    const TraceEntry& y = b.hub.trace()[i];
    if (x == y) continue;
    ++changed;
    CHECK(y.to == b.r3);
  }
  CHECK(changed > 500);  // about 2000 x (0.9 - 0.3)
}

TEST_CASE("same seed = same drop and delay sequence; another seed differs") {
  HubConfig c = loss(LossModel::kBurst, 0.25, SimTime::from_ms(3));
  c.delay.jitter = SimTime::from_ms(7);
  const auto run = [&](std::uint64_t seed) {
    Team t(c, seed);
    t.hub.set_trace(true);
    std::vector<std::pair<int, std::int64_t>> deliveries;  // (peer, sent_ns) in delivery order
    for (int ms = 0; ms < 3000; ++ms) {
      const SimTime now = SimTime::from_ms(ms);
      const PeerId from = PeerId(ms % 4);
      t.hub.broadcast(from, lock("x", ms), now);
      t.hub.step(now);
      for (int p = 0; p < 4; ++p) {
        for (const Delivery& d : t.hub.received(PeerId(p)))
          deliveries.emplace_back(p, d.sent_at.ns());
      }
    }
    return std::make_pair(t.hub.trace(), deliveries);
  };
  const auto a = run(42);
  const auto b = run(42);
  const auto other = run(43);
  CHECK(a.first == b.first);
  CHECK(a.second == b.second);
  CHECK(a.first != other.first);

  // The delay draws come from their own stream: changing the jitter keeps the drop sequence.
  HubConfig c2 = c;
  c2.delay.jitter = SimTime::from_ms(1);
  Team t(c2, 42);
  t.hub.set_trace(true);
  for (int ms = 0; ms < 3000; ++ms) {
    t.hub.broadcast(PeerId(ms % 4), lock("x", ms), SimTime::from_ms(ms));
    t.hub.step(SimTime::from_ms(ms));
  }
  REQUIRE(t.hub.trace().size() == a.first.size());
  for (std::size_t i = 0; i < a.first.size(); ++i) {
    CHECK(t.hub.trace()[i].outcome == a.first[i].outcome);
  }
}

TEST_CASE("channels: teams do not hear each other; '*' hears and is heard by all") {
  MessageRegistry reg = registry();
  Hub hub(HubConfig{}, reg, Rng(1));
  const PeerId c1 = hub.add_peer("cyan1", "cyan");
  const PeerId c2 = hub.add_peer("cyan2", "cyan");
  const PeerId m1 = hub.add_peer("magenta1", "magenta");
  const PeerId rb = hub.add_peer("refbox", "*");
  const PeerId obs = hub.add_peer("observer", "*");
  hub.broadcast(c1, lock("c", 1), SimTime::from_ms(0));
  hub.broadcast(rb, lock("r", 1), SimTime::from_ms(0));
  hub.step(SimTime::from_ms(10));
  CHECK(hub.received(c2).size() == 2);
  CHECK(hub.received(m1).size() == 1);  // only the refbox
  CHECK(hub.received(rb).size() == 1);
  CHECK(hub.received(obs).size() == 2);
  CHECK(hub.link_counters(c1, m1).sent == 0);
}

TEST_CASE("refused messages are counted per peer and do not block other traffic") {
  Team t(HubConfig{});
  llsf_agent_msgs::LockMessage incomplete;
  incomplete.set_agent("robot1");
  CHECK(t.hub.broadcast(t.r1, incomplete, SimTime::from_ms(0)) == FrameError::kBadPayload);
  CHECK(t.hub.broadcast(t.r1, llsf_agent_msgs::Incoming(), SimTime::from_ms(0)) ==
        FrameError::kUnknownType);
  CHECK(t.hub.broadcast(t.r1, lock(std::string(2000, 'x'), 1), SimTime::from_ms(0)) ==
        FrameError::kOversized);
  const std::vector<std::uint8_t> garbage{0x08, 0x34, 0x00, 0x63, 0x00, 0x00, 0x00, 0x02, 1, 2};
  CHECK(t.hub.broadcast_frame(t.r2, garbage, SimTime::from_ms(0)) == FrameError::kUnknownType);
  CHECK(t.hub.broadcast_frame(t.r2, std::span(garbage.data(), 3), SimTime::from_ms(0)) ==
        FrameError::kShortHeader);
  CHECK(t.hub.broadcast(t.r1, lock("robot1", 1), SimTime::from_ms(0)) == FrameError::kNone);
  const auto good = t.reg.encode(lock("robot2", 2));
  CHECK(t.hub.broadcast_frame(t.r2, good, SimTime::from_ms(0)) == FrameError::kNone);
  t.hub.step(SimTime::from_ms(5));
  CHECK(t.hub.received(t.r3).size() == 2);
  const PeerCounters& p1 = t.hub.peer_counters(t.r1);
  CHECK(p1.broadcasts == 1);
  CHECK(p1.malformed_by(FrameError::kBadPayload) == 1);
  CHECK(p1.malformed_by(FrameError::kUnknownType) == 1);
  CHECK(p1.malformed_by(FrameError::kOversized) == 1);
  const PeerCounters& p2 = t.hub.peer_counters(t.r2);
  CHECK(p2.broadcasts == 1);
  CHECK(p2.malformed_total() == 2);
}

TEST_CASE("forward_unregistered relays frames of unknown types unparsed") {
  HubConfig c;
  c.forward_unregistered = true;
  Team t(c);
  // A frame of (2000, 1) (a refbox BeaconSignal, say) that this registry does not know.
  const std::vector<std::uint8_t> beacon{0x07, 0xd0, 0x00, 0x01, 0x00,
                                         0x00, 0x00, 0x02, 0x20, 0x01};
  CHECK(t.hub.broadcast_frame(t.refbox, beacon, SimTime::from_ms(0)) == FrameError::kNone);
  // Framing is still checked.
  CHECK(t.hub.broadcast_frame(t.refbox, std::span(beacon.data(), 9), SimTime::from_ms(0)) ==
        FrameError::kSizeMismatch);
  t.hub.step(SimTime::from_ms(2));
  REQUIRE(t.hub.received(t.r1).size() == 1);
  const Delivery& d = t.hub.received(t.r1)[0];
  CHECK(d.type_index == kUnregistered);
  CHECK(std::vector<std::uint8_t>(d.frame.begin(), d.frame.end()) == beacon);
  CHECK(t.hub.decode(d) == nullptr);
  CHECK(t.hub.type_counters(kUnregistered).delivered == 3);
  CHECK(t.hub.total_counters().delivered == 3);
  CHECK(nlohmann::json::parse(t.hub.counters_json())["types"].back()["type"] == "(unregistered)");
  // Registered types are still validated.
  auto bad = t.reg.encode(lock("a", 1));
  bad.back() ^= 0xff;
  bad[9] = 0xff;
  CHECK(t.hub.broadcast_frame(t.r1, bad, SimTime::from_ms(3)) == FrameError::kBadPayload);
}

TEST_CASE("counters: per link, per type, totals, bytes, JSON") {
  HubConfig c = loss(LossModel::kPerLink, 0.5, SimTime::from_ms(1));
  Team t(c, 9);
  llsf_agent_msgs::LockMasterAnnounce ann;
  ann.set_agent("robot1");
  const auto lock_bytes = static_cast<std::int64_t>(t.reg.encode(lock("robot1", 1)).size());
  const auto ann_bytes = static_cast<std::int64_t>(t.reg.encode(ann).size());
  for (int ms = 0; ms < 1000; ++ms) {
    t.hub.broadcast(t.r1, lock("robot1", 1), SimTime::from_ms(ms));
    t.hub.broadcast(t.r2, ann, SimTime::from_ms(ms));
    t.hub.step(SimTime::from_ms(ms));
  }
  CHECK(t.hub.in_flight() > 0);  // the last millisecond's copies
  t.hub.step(SimTime::from_ms(1000));
  CHECK(t.hub.in_flight() == 0);
  const TrafficCounters lk = t.hub.type_counters(*t.reg.index_of(lock("a", 1)));
  const TrafficCounters an = t.hub.type_counters(*t.reg.index_of(ann));
  CHECK(lk.sent == 3000);
  CHECK(an.sent == 3000);
  CHECK(lk.delivered + lk.dropped_total() == lk.sent);
  CHECK(lk.bytes_sent == 3000 * lock_bytes);
  CHECK(lk.bytes_delivered == lk.delivered * lock_bytes);
  CHECK(an.bytes_delivered == an.delivered * ann_bytes);
  CHECK(lk.delay.count == lk.delivered);
  CHECK(lk.delay.min_ns == 1000000);
  CHECK(lk.delay.max_ns == 1000000);
  const TrafficCounters total = t.hub.total_counters();
  CHECK(total.sent == 6000);
  std::int64_t link_delivered = 0;
  for (int f = 0; f < 4; ++f) {
    for (int to = 0; to < 4; ++to)
      link_delivered += t.hub.link_counters(PeerId(f), PeerId(to)).delivered;
  }
  CHECK(link_delivered == total.delivered);
  CHECK(t.hub.peer_counters(t.r1).bytes == 1000 * lock_bytes);
  const nlohmann::json json = nlohmann::json::parse(t.hub.counters_json());
  auto has = [&](const char* list, const nlohmann::json& want) {
    for (const nlohmann::json& e : json.at(list)) {
      bool all = true;
      for (const auto& [key, value] : want.items())
        all = all && e.value(key, nlohmann::json()) == value;
      if (all) return true;
    }
    return false;
  };
  CHECK(has("links", {{"from", "robot1"}, {"to", "refbox"}}));
  CHECK(has("types", {{"type", "llsf_agent_msgs.LockMasterAnnounce"}}));
  CHECK(has("peers", {{"name", "robot3"}}));
}

TEST_CASE("the steady state reuses frames (pool does not grow)") {
  HubConfig c = loss(LossModel::kPerLink, 0.2, SimTime::from_ms(5));
  Team t(c);
  for (int ms = 0; ms < 20000; ++ms) {
    t.hub.broadcast(t.r1, lock("robot1", 1), SimTime::from_ms(ms));
    t.hub.step(SimTime::from_ms(ms));
  }
  // One frame per message in flight (5 ms at one message per ms) plus the last step's one.
  CHECK(t.hub.frame_pool_size() <= 7);
  CHECK(t.hub.in_flight() <= 3 * 6);
}

TEST_CASE("time must not go backwards") {
  Team t(HubConfig{});
  t.hub.step(SimTime::from_ms(10));
  CHECK_THROWS_AS(t.hub.step(SimTime::from_ms(9)), llsf::core::AssertionError);
  CHECK_THROWS_AS(t.hub.broadcast(t.r1, lock("a", 1), SimTime::from_ms(9)),
                  llsf::core::AssertionError);
  CHECK_THROWS_AS(t.hub.add_peer("robot1"), llsf::core::AssertionError);
}
