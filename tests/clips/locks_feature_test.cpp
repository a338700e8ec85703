// SPDX-License-Identifier: MIT
// Locks feature: the Fawkes-style lock facts over three agent hosts wired through a comm::Hub,
// the lock-role fact, lock messages consumed by the feature, a one-robot team, and locks off by
// default.
#include <doctest/doctest.h>
#include <llsf_agent_msgs/LockMessage.pb.h>

#include <functional>
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
  /// Asserts the lock fact as an agent's rule does; false if an identical fact exists (CLIPS
  /// then asserts nothing and no rule sees it).
  bool assert_lock(std::size_t i, const char* type, const char* resource) {
    return !hosts[i]
                ->eval(std::string("(assert (lock (type ") + type + ") (agent " +
                       hosts[i]->config().robot_name + ") (resource " + resource + ")))")
                .is_symbol("FALSE");
  }

  std::string lock_state(std::size_t i, const char* resource) {
    const Value v = hosts[i]->eval(std::string("(lock-state ") + resource + ")");
    return v.type == Value::Type::kSymbol ? v.text : "?";
  }
  /// Runs until exactly one host has (lock-role MASTER) and the others SLAVE; its index.
  std::size_t elect() {
    std::size_t master = 0;
    const bool one = run_until(
        [&] {
          int masters = 0;
          for (std::size_t i = 0; i < hosts.size(); ++i) {
            if (role(i) == "MASTER") {
              ++masters;
              master = i;
            }
          }
          return masters == 1 && role((master + 1) % 3) == "SLAVE" &&
                 role((master + 2) % 3) == "SLAVE";
        },
        SimTime::from_sec(20));
    REQUIRE(one);
    tick();
    return master;
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
  const std::size_t master = t.elect();
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
  // The agent's GET and RELEASE: facts asserted as such, or by (lock-assert) for code that must
  // also load without the lock template.
  std::function<void(const char*)> request;
  SUBCASE("asserted facts") {
    request = [&f](const char* type) {
      f.assert_fact(std::string("(lock (type ") + type + ") (agent robot1) (resource M5))");
    };
  }
  SUBCASE("lock-assert") {
    request = [&f](const char* type) {
      CHECK(f.agent().eval(std::string("(lock-assert ") + type + " M5)").is_symbol("TRUE"));
    };
  }
  request("GET");
  CHECK(f.find("lock", {{"type", Value::symbol("GET")},
                        {"agent", Value::symbol("robot1")},
                        {"resource", Value::symbol("M5")}})
            .size() == 1);
  f.step();
  CHECK(f.find("lock", {{"type", Value::symbol("ACCEPT")}}).size() == 1);
  request("RELEASE");  // no pose: at once
  f.step();
  f.step();
  CHECK(f.has("(released M5)"));
  CHECK(f.facts("lock").empty());
  CHECK(f.agent().runtime_errors() == 0);
  // lock-assert makes only the robot's own requests: another type is an error naming them.
  f.agent().eval("(lock-assert ACCEPT M5)");
  CHECK(f.agent().runtime_errors() == 1);
  CHECK(f.logged("the type must be GET or RELEASE"));
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
  f.agent().eval("(lock-assert GET M1)");
  CHECK(f.agent().runtime_errors() == 2);
}

// The lock trap (issue #15): CLIPS ignores the assert of a fact identical to an existing one, so
// a (lock (type RELEASE) ...) fact left behind after a GET took the lock back would swallow the
// robot's next RELEASE, and the resource would stay locked for the rest of the game. These tests
// follow the facts an agent asserts, in the orders that could leave a GET or RELEASE behind.
namespace {

// Robot i, standing at `here`, has released resource r (RELEASE pending); it goes away 0.6 m:
// the release must complete, and another robot j must get the resource.
void leave_and_hand_over(Team& t, std::size_t i, std::size_t j, const char* r, core::Pose2D here) {
  CHECK(t.lock_state(i, r) == "RELEASING");
  CHECK(t.has_lock(i, "RELEASE", r));
  t.hosts[i]->set_pose({here.x, here.y + 0.6, 0.0});
  const std::string probe =
      std::string("(any-factp ((?f released)) (eq (nth$ 1 ?f:implied) ") + r + "))";
  const bool released = t.run_until([&] { return t.has(i, probe.c_str()); }, SimTime::from_sec(3));
  CHECK(released);
  CHECK(t.lock_state(i, r) == "NONE");
  CHECK(t.hosts[i]->find_facts("lock", {{"resource", Value::symbol(r)}}).empty());
  t.assert_lock(j, "GET", r);
  CHECK(t.run_until([&] { return t.has_lock(j, "ACCEPT", r); }, SimTime::from_sec(3)));
}

// Robot i holds r (ACCEPT shown) at `here`; it releases r, goes away, and j gets it.
void release_and_hand_over(Team& t, std::size_t i, std::size_t j, const char* r,
                           core::Pose2D here) {
  CHECK(t.assert_lock(i, "RELEASE", r));  // a new fact, not swallowed by an old one
  t.tick();
  leave_and_hand_over(t, i, j, r, here);
}

}  // namespace

TEST_CASE("lock trap: a GET takes back a pending RELEASE, the next RELEASE still goes out") {
  Team t;
  const std::size_t master = t.elect();
  // The same facts for a slave (lock over the radio) and for the master (served locally).
  std::size_t i = 0;
  SUBCASE("slave") { i = (master + 1) % 3; }
  SUBCASE("master") { i = master; }
  const std::size_t j = (i + 1) % 3;  // the next one to want M1
  const std::string name = t.hosts[i]->config().robot_name;

  t.assert_lock(i, "GET", "M1");
  REQUIRE(t.run_until([&] { return t.has_lock(i, "ACCEPT", "M1"); }, SimTime::from_sec(10)));

  // Done at M1: RELEASE while still there; it waits until the robot is 0.5 m away.
  t.assert_lock(i, "RELEASE", "M1");
  t.run_until([] { return false; }, SimTime::from_sec(1));
  CHECK(t.lock_state(i, "M1") == "RELEASING");
  CHECK(t.has_lock(i, "RELEASE", "M1"));

  // It needs M1 once more before leaving: the GET takes the lock back, and the pending RELEASE
  // fact goes with it (nothing will answer it).
  t.assert_lock(i, "GET", "M1");
  t.tick();
  CHECK(t.lock_state(i, "M1") == "ACCEPTED");
  CHECK(t.has_lock(i, "ACCEPT", "M1"));
  CHECK_FALSE(t.has_lock(i, "GET", "M1"));
  CHECK_FALSE(t.has_lock(i, "RELEASE", "M1"));
  t.run_until([] { return false; }, SimTime::from_sec(5));  // held past several leases
  CHECK(t.lock_state(i, "M1") == "ACCEPTED");

  // Now the RELEASE is a new fact again: it goes out 0.5 m away and the other robot gets M1.
  release_and_hand_over(t, i, j, "M1", {});
  CHECK(t.lock_events[name] ==
        std::vector<std::string>{"M1 NONE>REQUESTED", "M1 REQUESTED>ACCEPTED",
                                 "M1 ACCEPTED>RELEASING", "M1 RELEASING>ACCEPTED",
                                 "M1 ACCEPTED>RELEASING", "M1 RELEASING>NONE"});
  for (std::size_t k = 0; k < 3; ++k) CHECK(t.hosts[k]->runtime_errors() == 0);
}

TEST_CASE("lock trap: a GET after the RELEASE went out, before its RELEASE_RVCD") {
  Team t;
  const std::size_t master = t.elect();
  const std::size_t a = (master + 1) % 3, b = (master + 2) % 3;
  const std::string name = t.hosts[a]->config().robot_name;
  t.assert_lock(a, "GET", "M1");
  REQUIRE(t.run_until([&] { return t.has_lock(a, "ACCEPT", "M1"); }, SimTime::from_sec(10)));
  t.assert_lock(a, "RELEASE", "M1");
  t.tick();

  // In one cycle the robot is 0.5 m away (the RELEASE goes out before the rules run) and asks
  // for M1 again: a new request, whose GET waits until the RELEASE has reached the master. The
  // master's RELEASE_RVCD answers a release the robot no longer makes: no RELEASE_RVCD fact.
  t.hosts[a]->set_pose({0.0, 0.6, 0.0});
  t.assert_lock(a, "GET", "M1");
  t.tick();
  CHECK(t.lock_state(a, "M1") == "REQUESTED");
  CHECK_FALSE(t.has_lock(a, "RELEASE", "M1"));
  REQUIRE(t.run_until([&] { return t.has_lock(a, "ACCEPT", "M1"); }, SimTime::from_sec(3)));
  CHECK_FALSE(t.has_lock(a, "GET", "M1"));
  CHECK_FALSE(t.has_lock(a, "RELEASE", "M1"));
  CHECK_FALSE(t.has(a, "(any-factp ((?f released)) TRUE)"));

  release_and_hand_over(t, a, b, "M1", {0.0, 0.6, 0.0});
  CHECK(t.lock_events[name] ==
        std::vector<std::string>{"M1 NONE>REQUESTED", "M1 REQUESTED>ACCEPTED",
                                 "M1 ACCEPTED>RELEASING", "M1 RELEASING>REQUESTED",
                                 "M1 REQUESTED>ACCEPTED", "M1 ACCEPTED>RELEASING",
                                 "M1 RELEASING>NONE"});
  for (std::size_t k = 0; k < 3; ++k) CHECK(t.hosts[k]->runtime_errors() == 0);
}

TEST_CASE("lock trap: GET and RELEASE of one resource in one cycle; the fact left is the state") {
  // A rule that changes its mind within one firing. The host hands the facts over in the order
  // the rules fire (newest first by CLIPS' default depth strategy); the first one handed over
  // consumes the other, so the fact that stays always says what the manager does.
  constexpr const char* kChangeMind =
      "(defrule get-then-release ?f <- (get-then-release ?r) => (retract ?f)\n"
      "  (assert (lock (type GET) (agent ?*ROBOT-NAME*) (resource ?r)))\n"
      "  (assert (lock (type RELEASE) (agent ?*ROBOT-NAME*) (resource ?r))))\n"
      "(defrule release-then-get ?f <- (release-then-get ?r) => (retract ?f)\n"
      "  (assert (lock (type RELEASE) (agent ?*ROBOT-NAME*) (resource ?r)))\n"
      "  (assert (lock (type GET) (agent ?*ROBOT-NAME*) (resource ?r))))\n";
  Team t;
  const std::size_t master = t.elect();
  const std::size_t a = (master + 1) % 3, b = (master + 2) % 3;
  t.hosts[a]->load_string(kChangeMind, "change-mind.clp");
  t.assert_lock(a, "GET", "M1");
  REQUIRE(t.run_until([&] { return t.has_lock(a, "ACCEPT", "M1"); }, SimTime::from_sec(10)));

  // RELEASE asserted last: it is handed over and the GET goes; the lock is being released.
  t.hosts[a]->assert_fact("(get-then-release M1)");
  t.tick();
  CHECK(t.lock_state(a, "M1") == "RELEASING");
  CHECK(t.has_lock(a, "RELEASE", "M1"));
  CHECK_FALSE(t.has_lock(a, "GET", "M1"));
  CHECK_FALSE(t.has_lock(a, "ACCEPT", "M1"));

  // GET asserted last: the lock is taken back and the RELEASE goes.
  t.hosts[a]->assert_fact("(release-then-get M1)");
  t.tick();
  CHECK(t.lock_state(a, "M1") == "ACCEPTED");
  CHECK(t.has_lock(a, "ACCEPT", "M1"));
  CHECK_FALSE(t.has_lock(a, "RELEASE", "M1"));
  CHECK_FALSE(t.has_lock(a, "GET", "M1"));

  release_and_hand_over(t, a, b, "M1", {});
  for (std::size_t k = 0; k < 3; ++k) CHECK(t.hosts[k]->runtime_errors() == 0);
}

TEST_CASE("lock facts: repeated GETs and RELEASEs are harmless") {
  Team t;
  const std::size_t master = t.elect();
  const std::size_t a = (master + 1) % 3, b = (master + 2) % 3;
  const std::string name = t.hosts[a]->config().robot_name;

  // A GET while the same GET is pending is the same fact: one request, one ACCEPT.
  t.assert_lock(a, "GET", "M1");
  t.tick();
  CHECK(t.has_lock(a, "GET", "M1"));  // the new master is still quiet
  CHECK_FALSE(t.assert_lock(a, "GET", "M1"));
  REQUIRE(t.run_until([&] { return t.has_lock(a, "ACCEPT", "M1"); }, SimTime::from_sec(10)));
  // A GET for a held lock is answered at once, even when the agent retracted its ACCEPT.
  t.assert_lock(a, "GET", "M1");
  t.tick();
  CHECK_FALSE(t.has_lock(a, "GET", "M1"));
  t.hosts[a]->eval("(do-for-all-facts ((?l lock)) (eq ?l:type ACCEPT) (retract ?l))");
  t.assert_lock(a, "GET", "M1");
  t.tick();
  CHECK(t.has_lock(a, "ACCEPT", "M1"));
  CHECK_FALSE(t.has_lock(a, "GET", "M1"));

  // A RELEASE while the same RELEASE is pending: one release.
  t.assert_lock(a, "RELEASE", "M1");
  t.tick();
  CHECK_FALSE(t.assert_lock(a, "RELEASE", "M1"));
  t.tick();
  leave_and_hand_over(t, a, b, "M1", {});

  // A RELEASE of nothing held is answered at once and leaves no fact behind; the next GET and
  // RELEASE work as usual.
  t.hosts[a]->eval("(do-for-all-facts ((?f released)) TRUE (retract ?f))");
  t.assert_lock(a, "RELEASE", "M2");
  t.tick();
  CHECK(t.has(a, "(any-factp ((?f released)) TRUE)"));
  CHECK(t.hosts[a]->find_facts("lock", {{"resource", Value::symbol("M2")}}).empty());
  t.hosts[a]->eval("(do-for-all-facts ((?f released)) TRUE (retract ?f))");
  t.assert_lock(a, "GET", "M2");
  REQUIRE(t.run_until([&] { return t.has_lock(a, "ACCEPT", "M2"); }, SimTime::from_sec(3)));
  release_and_hand_over(t, a, b, "M2", {0.0, 0.6, 0.0});

  CHECK(t.lock_events[name] ==
        std::vector<std::string>{"M1 NONE>REQUESTED", "M1 REQUESTED>ACCEPTED",
                                 "M1 ACCEPTED>RELEASING", "M1 RELEASING>NONE", "M2 NONE>REQUESTED",
                                 "M2 REQUESTED>ACCEPTED", "M2 ACCEPTED>RELEASING",
                                 "M2 RELEASING>NONE"});
  for (std::size_t k = 0; k < 3; ++k) CHECK(t.hosts[k]->runtime_errors() == 0);
}
