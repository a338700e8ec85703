// SPDX-License-Identifier: MIT
// Locks feature: the Fawkes-style lock facts over three agent hosts wired through a comm::Hub,
// the lock-role fact, lock messages consumed by the feature, a one-robot team, and locks off by
// default.
#include <doctest/doctest.h>
#include <llsf_agent_msgs/LockMessage.pb.h>

#include <map>
#include <memory>
#include <string>
#include <vector>

#include "llsf/clips/testing.h"
#include "llsf/comm/hub.h"

using namespace llsf;
using namespace llsf::clips;
using core::SimTime;

namespace {

comm::MessageRegistry agent_registry() {
  comm::MessageRegistry r;
  comm::add_agent_messages(r);
  return r;
}

// Records what the tests look for: RELEASE_RVCD facts (retracted in their cycle) and lock
// messages that reached CLIPS as protobuf-msg facts (they must not).
constexpr const char* kProbeRvcd =
    "(defrule probe-rvcd (lock (type RELEASE_RVCD) (resource ?r)) => (assert (released ?r)))\n";
constexpr const char* kProbeMsg =
    "(defrule probe-lock-msg (protobuf-msg (type ?t&:(str-index \"llsf_agent_msgs.Lock\" ?t)))\n"
    "  => (assert (saw-lock-msg)))\n";

/// Three agent hosts with locks on ("robot1".."robot3") on one hub, cycled at 10 Hz.
struct Team {
  explicit Team(comm::HubConfig cfg = {}) : reg(agent_registry()), hub(cfg, reg, core::Rng(5)) {
    for (int i = 0; i < 3; ++i) {
      const std::string name = "robot" + std::to_string(i + 1);
      const comm::PeerId peer = hub.add_peer(name);
      peers.push_back(peer);
      AgentConfig c;
      c.robot_name = name;
      c.robot_number = i + 1;
      c.seed = static_cast<std::uint64_t>(100 + i);
      c.locks = true;
      AgentIo io;
      io.messages = &reg;
      io.broadcast = [this, peer](const google::protobuf::Message& m) {
        hub.broadcast(peer, m, now);
      };
      io.log = [this](const LogRecord& r) { log.push_back(std::string(r.text)); };
      io.lock_events = [this, name](const LockEvent& e) {
        CHECK(e.time == now);
        lock_events[name].push_back(std::string(e.resource) + " " + to_string(e.from) + ">" +
                                    to_string(e.to));
      };
      hosts.push_back(std::make_unique<AgentHost>(c, io));
      hosts.back()->load_string(kProbeRvcd, "probe-rvcd.clp");
      hosts.back()->load_string(kProbeMsg, "probe-msg.clp");
      hosts.back()->set_pose({});
    }
  }
  void tick() {
    now += SimTime::from_ms(100);
    hub.step(now);
    for (std::size_t i = 0; i < hosts.size(); ++i) {
      for (const comm::Delivery& d : hub.received(peers[i]))
        hosts[i]->receive(hub.decode(d), hub.peer_name(d.from), static_cast<int>(d.from.value()),
                          now);
      hosts[i]->cycle(now);
    }
  }
  template <class Pred>
  bool run_until(Pred pred, SimTime limit) {
    const SimTime end = now + limit;
    while (now < end) {
      tick();
      if (pred()) return true;
    }
    return false;
  }
  bool has_lock(std::size_t i, const char* type, const char* resource) const {
    return !hosts[i]
                ->find_facts("lock", {{"type", Value::symbol(type)},
                                      {"agent", Value::symbol(hosts[i]->config().robot_name)},
                                      {"resource", Value::symbol(resource)}})
                .empty();
  }
  bool has(std::size_t i, const char* expr) const { return hosts[i]->eval(expr).is_symbol("TRUE"); }
  std::string role(std::size_t i) const {
    auto f = hosts[i]->facts("lock-role");
    return f.size() == 1 ? f[0].fields().at(0).text : "";
  }
  void assert_lock(std::size_t i, const char* type, const char* resource) {
    hosts[i]->assert_fact(std::string("(lock (type ") + type + ") (agent " +
                          hosts[i]->config().robot_name + ") (resource " + resource + "))");
  }

  comm::MessageRegistry reg;
  comm::Hub hub;
  std::vector<comm::PeerId> peers;
  std::vector<std::unique_ptr<AgentHost>> hosts;
  std::vector<std::string> log;
  std::map<std::string, std::vector<std::string>> lock_events;  ///< per robot, in order
  SimTime now;
};

}  // namespace

TEST_CASE("lock facts: GET -> ACCEPT/REFUSE, RELEASE after 0.5 m -> RELEASE_RVCD") {
  Team t;
  // One master emerges: (lock-role MASTER) on one host, SLAVE on the others, and it may grant.
  std::size_t master = 0;
  REQUIRE(t.run_until(
      [&] {
        int masters = 0;
        for (std::size_t i = 0; i < 3; ++i) {
          if (t.role(i) == "MASTER") {
            ++masters;
            master = i;
          }
        }
        return masters == 1 && t.role((master + 1) % 3) == "SLAVE" &&
               t.role((master + 2) % 3) == "SLAVE";
      },
      SimTime::from_sec(20)));
  t.tick();
  const std::size_t a = (master + 1) % 3, b = (master + 2) % 3;
  const std::string master_name = t.hosts[master]->config().robot_name;
  CHECK(t.hosts[a]->eval("(lock-master)").is_symbol(master_name));

  // a asks for M1 and gets it (after the new master's quiet period); the GET fact goes.
  t.assert_lock(a, "GET", "M1");
  CHECK(t.hosts[a]->eval("(lock-state M1)").is_symbol("NONE"));  // taken up at the next cycle
  REQUIRE(t.run_until([&] { return t.has_lock(a, "ACCEPT", "M1"); }, SimTime::from_sec(10)));
  CHECK_FALSE(t.has_lock(a, "GET", "M1"));
  CHECK(t.hosts[a]->eval("(lock-state M1)").is_symbol("ACCEPTED"));

  // b is refused; its GET goes too.
  t.assert_lock(b, "GET", "M1");
  REQUIRE(t.run_until([&] { return t.has_lock(b, "REFUSE", "M1"); }, SimTime::from_sec(3)));
  CHECK_FALSE(t.has_lock(b, "GET", "M1"));

  // a releases: the ACCEPT goes at once, but the lock is kept until a is 0.5 m away.
  t.assert_lock(a, "RELEASE", "M1");
  t.tick();
  CHECK_FALSE(t.has_lock(a, "ACCEPT", "M1"));
  CHECK(t.hosts[a]->eval("(lock-state M1)").is_symbol("RELEASING"));
  t.run_until([] { return false; }, SimTime::from_sec(3));
  CHECK(t.has_lock(a, "RELEASE", "M1"));
  t.hosts[a]->set_pose({0.0, 0.6, 0.0});
  REQUIRE(t.run_until([&] { return t.has(a, "(any-factp ((?f released)) TRUE)"); },
                      SimTime::from_sec(3)));
  CHECK_FALSE(t.has_lock(a, "RELEASE", "M1"));
  CHECK_FALSE(t.has_lock(a, "RELEASE_RVCD", "M1"));  // retracted in its cycle

  // b asks again: the REFUSE goes, the ACCEPT comes.
  t.assert_lock(b, "GET", "M1");
  t.tick();
  CHECK_FALSE(t.has_lock(b, "REFUSE", "M1"));
  REQUIRE(t.run_until([&] { return t.has_lock(b, "ACCEPT", "M1"); }, SimTime::from_sec(3)));

  // The master's own lock, served without the radio.
  t.assert_lock(master, "GET", "M2");
  REQUIRE(t.run_until([&] { return t.has_lock(master, "ACCEPT", "M2"); }, SimTime::from_sec(1)));

  // Every state change went to AgentIo::lock_events, in order.
  const std::string an = t.hosts[a]->config().robot_name, bn = t.hosts[b]->config().robot_name;
  CHECK(t.lock_events[an] == std::vector<std::string>{"M1 NONE>REQUESTED", "M1 REQUESTED>ACCEPTED",
                                                      "M1 ACCEPTED>RELEASING",
                                                      "M1 RELEASING>NONE"});
  CHECK(t.lock_events[bn] == std::vector<std::string>{"M1 NONE>REQUESTED", "M1 REQUESTED>REFUSED",
                                                      "M1 REFUSED>REQUESTED",
                                                      "M1 REQUESTED>ACCEPTED"});
  CHECK(t.lock_events[master_name] ==
        std::vector<std::string>{"M2 NONE>REQUESTED", "M2 REQUESTED>ACCEPTED"});

  // The lock messages never became protobuf-msg facts; nothing went wrong.
  for (std::size_t i = 0; i < 3; ++i) {
    CHECK_FALSE(t.has(i, "(any-factp ((?f saw-lock-msg)) TRUE)"));
    CHECK(t.hosts[i]->runtime_errors() == 0);
  }
}

TEST_CASE("a one-robot team locks for itself") {
  AgentConfig c;
  c.robot_name = "robot1";
  c.locks = true;
  c.lock_config.team_size = 1;
  const auto reg = agent_registry();
  AgentFixture f(c, &reg);
  f.load(kProbeRvcd, "probe-rvcd.clp");
  f.steps(100);  // master after the timeout and back-off, then the quiet period
  CHECK(f.has("(lock-role MASTER)"));
  f.assert_fact("(lock (type GET) (agent robot1) (resource M5))");
  f.step();
  CHECK(f.find("lock", {{"type", Value::symbol("ACCEPT")}}).size() == 1);
  f.assert_fact("(lock (type RELEASE) (agent robot1) (resource M5))");  // no pose: at once
  f.step();
  f.step();
  CHECK(f.has("(released M5)"));
  CHECK(f.facts("lock").empty());
  CHECK(f.agent().runtime_errors() == 0);
}

TEST_CASE("locks are off by default") {
  const auto reg = agent_registry();
  AgentFixture f({}, &reg);
  f.load(kProbeMsg, "probe-msg.clp");
  f.steps(50);
  CHECK(f.sent().empty());  // no announcements
  CHECK(f.facts("lock-role").empty());
  // A received lock message stays an ordinary protobuf-msg fact.
  auto m = std::make_unique<llsf_agent_msgs::LockMasterAnnounce>();
  m->set_agent("robot2");
  f.agent().receive(std::move(m), "robot2", 2, f.now());
  f.step();
  CHECK(f.has("(saw-lock-msg)"));
  // The lock template is the agent's own (built-in locks.clp is not loaded); the functions
  // report that locks are off.
  f.load("(deftemplate lock (slot owner))", "own-lock.clp");
  f.assert_fact("(lock (owner robot1))");
  f.agent().eval("(lock-request M1)");
  CHECK(f.agent().runtime_errors() == 1);
  CHECK(f.logged("locks are off"));
}
