// SPDX-License-Identifier: MIT
// The hub's steady state does not allocate: after a warm-up, broadcasting (from messages and from
// raw frames) and stepping with loss, jitter and an outage make no heap allocation. Counted with
// a replaced global operator new that only counts while a test switches it on.
#include <doctest/doctest.h>
#include <llsf_agent_msgs/LockMessage.pb.h>
#include <llsf_agent_msgs/Worldmodel.pb.h>

#include <atomic>
#include <cstdlib>
#include <new>

#include "llsf/comm/hub.h"

namespace {
std::atomic<bool> g_counting{false};
std::atomic<long> g_allocations{0};
}  // namespace

void* operator new(std::size_t n) {
  if (g_counting.load(std::memory_order_relaxed)) g_allocations.fetch_add(1);
  if (void* p = std::malloc(n == 0 ? 1 : n)) return p;
  throw std::bad_alloc();
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }

using namespace llsf::comm;

TEST_CASE("steady-state broadcast and step do not allocate") {
  MessageRegistry reg;
  add_agent_messages(reg);
  HubConfig cfg;
  cfg.loss_model = LossModel::kBurst;
  cfg.loss_probability = 0.2;
  cfg.delay.jitter = SimTime::from_ms(5);
  cfg.outages.push_back(OutageConfig{"robot2", "", SimTime::from_ms(3000), SimTime::from_ms(3500)});
  Hub hub(cfg, reg, llsf::core::Rng(11));
  PeerId peers[4] = {hub.add_peer("robot1"), hub.add_peer("robot2"), hub.add_peer("robot3"),
                     hub.add_peer("refbox", "*")};
  llsf_agent_msgs::LockMessage lock;
  lock.set_type(llsf_agent_msgs::LockMessage::ACCEPT);
  lock.set_agent("robot1");
  lock.set_resource("M4");
  llsf_agent_msgs::WorldmodelChange change;
  change.set_id(5);
  change.set_agent("robot3");
  change.set_change(llsf_agent_msgs::WorldmodelChange::SET_NUM_CO);
  change.set_value(2);
  const auto raw = reg.encode(change);

  long delivered = 0;
  const auto run = [&](int from_ms, int to_ms) {
    for (int ms = from_ms; ms < to_ms; ++ms) {
      const SimTime now = SimTime::from_ms(ms);
      hub.broadcast(peers[ms % 4], lock, now);
      hub.broadcast_frame(peers[(ms + 1) % 4], raw, now);
      delivered += hub.step(now);
      for (const PeerId p : peers) {
        for (const Delivery& d : hub.received(p)) delivered += d.frame[0] == 0x08 ? 0 : 1000000;
      }
    }
  };
  run(0, 2000);  // warm-up: pool, heap and inboxes reach their working size
  g_counting = true;
  run(2000, 6000);
  g_counting = false;
  CHECK(g_allocations.load() == 0);
  CHECK(delivered > 10000);
  CHECK(delivered < 1000000);  // every frame started with component 2100's high byte
  CHECK(hub.link_counters(peers[0], peers[1]).dropped_by(DropCause::kOutage) > 0);
}
