// SPDX-License-Identifier: MIT
// The auction agent (clips/agents/auction): the market's rules without the world (AgentFixture)
// and whole games against the role-based llsf2013 agent, with and without radio loss.
#include <doctest/doctest.h>
#include <llsf_agent_msgs/Auction.pb.h>

#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>
#include <vector>

#include "fixture.h"
#include "llsf/clips/testing.h"
#include "llsf/comm/registry.h"
#include "llsf/sim/agent_brain.h"
#include "llsf/sim/game.h"

using namespace llsf;
using clips::SkillStatus;
using clips::Value;
using llsf_agent_msgs::AuctionAck;
using llsf_agent_msgs::AuctionAward;
using llsf_agent_msgs::AuctionBid;
using llsf_agent_msgs::AuctionCall;
using llsf_agent_msgs::AuctionStatus;

namespace {

const std::vector<std::string> kAuctionAgent = {LLSF_SOURCE_DIR "/clips/agents/common",
                                                LLSF_SOURCE_DIR "/clips/agents/auction"};
const std::vector<std::string> kRoleAgent = {LLSF_SOURCE_DIR "/clips/agents/common",
                                             LLSF_SOURCE_DIR "/clips/agents/llsf2013"};

const comm::MessageRegistry& registry_for_tests() {
  static const comm::MessageRegistry r = [] {
    comm::MessageRegistry reg;
    sim::add_refbox_messages(reg);
    comm::add_agent_messages(reg);
    return reg;
  }();
  return r;
}

/// One robot's auction agent without the world. The 2013 plan of these tests: T1 at M1 and M8,
/// T2 at M4, T3 at M3, T4 at M9, T5 at M6; the P1P2 target is M3 (farther from the T5).
struct Market {
  explicit Market(int number = 1) : f(config(number), &registry_for_tests()) {
    for (const std::string& file : sim::agent_files(kAuctionAgent)) f.load_file(file);
    f.load(
        "(deffunction t-type (?n ?t) (do-for-fact ((?m machine)) (eq ?m:name ?n) "
        "(modify ?m (mtype ?t))))\n"
        "(deffunction t-game (?p ?s) (do-for-fact ((?g game)) TRUE (modify ?g (phase ?p) "
        "(state ?s))))\n",
        "test-helpers.clp");
    f.step();  // (reset) and the deffacts
    for (const char* e : {"(t-type M1 T1)", "(t-type M8 T1)", "(t-type M4 T2)", "(t-type M3 T3)",
                          "(t-type M9 T4)", "(t-type M6 T5)", "(t-game PRODUCTION RUNNING)"}) {
      f.agent().eval(e);
    }
    REQUIRE(f.agent().runtime_errors() == 0);
  }
  static clips::AgentConfig config(int number) {
    clips::AgentConfig c;
    c.robot_name = "robot" + std::to_string(number);
    c.robot_number = number;
    return c;
  }
  template <typename M>
  void receive(const M& m, const std::string& from, int id) {
    f.agent().receive(std::make_unique<M>(m), from, id, f.now());
  }
  template <typename M>
  std::vector<const M*> sent() {
    std::vector<const M*> r;
    for (const auto& m : f.sent()) {
      if (const auto* x = dynamic_cast<const M*>(m.get())) r.push_back(x);
    }
    return r;
  }
  /// The calls sent for `task` (in order).
  std::vector<const AuctionCall*> calls(const std::string& task) {
    std::vector<const AuctionCall*> r;
    for (const AuctionCall* c : sent<AuctionCall>()) {
      if (c->task() == task) r.push_back(c);
    }
    return r;
  }
  std::vector<const AuctionAward*> awards(std::uint32_t id) {
    std::vector<const AuctionAward*> r;
    for (const AuctionAward* a : sent<AuctionAward>()) {
      if (a->auction_id() == id) r.push_back(a);
    }
    return r;
  }
  void bid(std::uint32_t id, int robot, double cost) {
    AuctionBid b;
    b.set_auction_id(id);
    b.set_bidder("robot" + std::to_string(robot));
    b.set_cost(cost);
    receive(b, b.bidder(), robot);
  }
  void heartbeat(int robot, std::uint32_t job = 0, const std::string& task = "",
                 std::vector<std::pair<std::uint32_t, bool>> done = {}) {
    AuctionStatus s;
    s.set_robot("robot" + std::to_string(robot));
    s.set_number(static_cast<std::uint32_t>(robot));
    s.set_holding("NONE");
    if (job != 0) {
      s.set_auction_id(job);
      s.set_task(task);
    }
    for (const auto& [id, ok] : done) {
      s.add_done_ids(id);
      s.add_done_ok(ok);
    }
    receive(s, s.robot(), robot);
  }
  /// `n` cycles; the robots in `idle` send an idle heartbeat every second.
  void run(int n) {
    for (int i = 0; i < n; ++i) {
      if (++cycle % 10 == 0) {
        for (int r : idle) heartbeat(r);
      }
      f.step();
    }
  }
  /// Runs until `n` calls for `task` were sent (at most `max` cycles).
  void run_until_call(const std::string& task, std::size_t n, int max) {
    for (int i = 0; i < max && calls(task).size() < n; ++i) run(1);
  }
  std::string last_call() { return f.skills().calls().empty() ? "" : f.skills().calls().back(); }
  clips::AgentFixture f;
  std::vector<int> idle;
  int cycle = 0;
};

}  // namespace

TEST_CASE("auction: a task is announced, the lowest bid wins, the award is resent until acked") {
  Market m;
  m.idle = {2, 3};
  m.run(25);                                 // past the start grace (2 s)
  const auto calls = m.calls("FEED M3 S0");  // the complex target's first input
  REQUIRE(calls.size() == 1);
  const std::uint32_t id = calls[0]->auction_id();
  CHECK(calls[0]->auctioneer() == "robot1");
  CHECK(calls[0]->priority() == 3);
  m.bid(id, 2, 5.0);
  m.bid(id, 3, 3.0);  // robot1's own bid (it drives from the insertion area) is ~35 s
  m.run(10);          // the 1 s bid window ends
  REQUIRE(m.awards(id).size() == 1);
  CHECK(m.awards(id)[0]->winner() == "robot3");
  CHECK(m.awards(id)[0]->auctioneer() == "robot1");
  m.run(6);  // no ack: resent after 0.5 s
  CHECK(m.awards(id).size() == 2);
  AuctionAck ack;
  ack.set_auction_id(id);
  ack.set_bidder("robot3");
  ack.set_accepted(true);
  m.receive(ack, "robot3", 3);
  m.f.step();
  const std::size_t n = m.awards(id).size();
  m.run(20);
  CHECK(m.awards(id).size() == n);  // acknowledged: no more resends
  CHECK(m.f.find("au-auction",
                 {{"id", Value::integer_value(id)}, {"state", Value::symbol("RUNNING")}})
            .size() == 1);
  m.heartbeat(3, id, "FEED M3 S0");
  m.run(50);  // heartbeats keep it running: nobody auctions it again
  CHECK(m.calls("FEED M3 S0").size() == 1);
  CHECK(m.f.agent().runtime_errors() == 0);
}

TEST_CASE("auction: a lost award is re-auctioned after the award timeout") {
  Market m;
  m.idle = {2, 3};
  m.run(25);
  const auto calls = m.calls("FEED M3 S0");
  REQUIRE(calls.size() == 1);
  const std::uint32_t id = calls[0]->auction_id();
  m.bid(id, 2, 1.0);
  m.run(10);
  REQUIRE(m.awards(id).size() == 1);
  CHECK(m.awards(id)[0]->winner() == "robot2");
  m.run(35);  // every award lost: resent, then given up after 3 s
  CHECK(m.awards(id).size() >= 5);
  CHECK(m.f.find("au-auction", {{"id", Value::integer_value(id)}}).empty());
  m.run_until_call("FEED M3 S0", 2, 80);
  const auto again = m.calls("FEED M3 S0");
  REQUIRE(again.size() == 2);
  CHECK(again[1]->auction_id() != id);
  CHECK(m.f.agent().runtime_errors() == 0);
}

TEST_CASE("auction: a failed or silent winner's task is auctioned again") {
  Market m;
  m.idle = {3};  // robot2 speaks for itself below
  m.run(25);
  const auto calls = m.calls("FEED M3 S0");
  REQUIRE(calls.size() == 1);
  const std::uint32_t id = calls[0]->auction_id();
  m.bid(id, 2, 1.0);
  m.run(10);
  // The ack is lost; the winner's heartbeat claiming the task acknowledges it as well.
  m.heartbeat(2, id, "FEED M3 S0");
  m.f.step();
  CHECK(m.f.find("au-auction",
                 {{"id", Value::integer_value(id)}, {"state", Value::symbol("RUNNING")}})
            .size() == 1);
  // It fails: the heartbeat reports it; the task is announced again after the retry delay.
  m.heartbeat(2, 0, "", {{id, false}});
  m.f.step();
  CHECK(m.f.find("au-auction", {{"id", Value::integer_value(id)}}).empty());
  m.run_until_call("FEED M3 S0", 2, 80);
  auto again = m.calls("FEED M3 S0");
  REQUIRE(again.size() == 2);
  const std::uint32_t id2 = again[1]->auction_id();
  m.bid(id2, 2, 1.0);
  m.run(11);
  AuctionAck ack;
  ack.set_auction_id(id2);
  ack.set_bidder("robot2");
  ack.set_accepted(true);
  m.receive(ack, "robot2", 2);
  m.run(2);
  CHECK(m.f.find("au-auction",
                 {{"id", Value::integer_value(id2)}, {"state", Value::symbol("RUNNING")}})
            .size() == 1);
  // Now robot2 falls silent: after 8 s the task is auctioned a third time.
  m.run(90);
  CHECK(m.f.find("au-auction", {{"id", Value::integer_value(id2)}}).empty());
  CHECK(m.f.logged("robot2 is silent"));
  m.run_until_call("FEED M3 S0", 3, 80);
  CHECK(m.calls("FEED M3 S0").size() == 3);
  CHECK(m.f.agent().runtime_errors() == 0);
}

TEST_CASE("auction: a bidder answers calls with its cost and runs the task it wins") {
  Market m(2);     // robot2: robot1 is alive and the auctioneer
  m.heartbeat(1);  // before the start grace ends
  m.f.agent().set_pose({2.0, 2.0, 0.0});
  m.f.steps(10);
  AuctionCall call;
  call.set_auction_id(100001);
  call.set_auctioneer("robot1");
  call.set_task("P3 M6 1");
  call.set_priority(2);
  m.receive(call, "robot1", 1);
  m.f.step();
  const auto bids = m.sent<AuctionBid>();
  REQUIRE(bids.size() == 1);
  CHECK(bids[0]->auction_id() == 100001);
  CHECK(bids[0]->bidder() == "robot2");
  CHECK(bids[0]->cost() > 30.0);  // S0 from the storage, the T5, machine time, the gates
  CHECK(bids[0]->cost() < 120.0);
  CHECK(m.sent<AuctionCall>().empty());  // robot2 is no auctioneer while robot1 is alive
  AuctionAward award;
  award.set_auction_id(100001);
  award.set_winner("robot2");
  award.set_task("P3 M6 1");
  award.set_auctioneer("robot1");
  m.receive(award, "robot1", 1);
  m.f.steps(2);
  REQUIRE(m.sent<AuctionAck>().size() == 1);
  CHECK(m.sent<AuctionAck>()[0]->accepted());
  CHECK(m.last_call() == "get_s0{}");
  m.receive(award, "robot1", 1);  // a resent award (the ack was lost): acknowledged again
  m.f.step();
  CHECK(m.sent<AuctionAck>().size() == 2);
  m.f.skills().set_status(SkillStatus::kFinal);
  m.f.steps(2);
  CHECK(m.last_call() == "finish_puck_at{place=\"M6\"}");
  m.f.skills().set_result("DONE");
  m.f.skills().set_status(SkillStatus::kFinal);
  m.f.steps(2);
  CHECK(m.last_call() == "deliver{}");
  m.f.skills().set_status(SkillStatus::kFinal);
  m.f.steps(2);
  // Done: the heartbeat reports it.
  const auto status = m.sent<AuctionStatus>();
  REQUIRE(!status.empty());
  REQUIRE(status.back()->done_ids_size() == 1);
  CHECK(status.back()->done_ids(0) == 100001);
  CHECK(status.back()->done_ok(0));
  CHECK_FALSE(status.back()->has_auction_id());
  CHECK(m.f.agent().runtime_errors() == 0);
}

TEST_CASE("auction: the next robot becomes the auctioneer when robot1 falls silent") {
  Market m(2);
  m.idle = {1, 3};  // robot1 is alive: robot2 only bids
  m.run(60);
  CHECK(m.sent<AuctionCall>().empty());
  m.idle = {3};  // robot1 falls silent: after 5 s robot2 runs the auctions
  m.run(40);
  CHECK(m.sent<AuctionCall>().empty());
  m.run(40);
  REQUIRE_FALSE(m.sent<AuctionCall>().empty());
  CHECK(m.sent<AuctionCall>()[0]->auctioneer() == "robot2");
  CHECK(m.sent<AuctionCall>()[0]->auction_id() / 100000 == 2);
  CHECK(m.f.agent().runtime_errors() == 0);
}

namespace {

struct Points {
  int production = 0;
  int runtime_errors = 0;
  int reauctions = 0;
};

Points play(const std::vector<std::string>& agent, std::uint64_t seed, double loss) {
  sim::GameConfig cfg = test::small_game(3, seed);
  if (loss > 0.0) {
    cfg.hub.loss_model = comm::LossModel::kPerLink;
    cfg.hub.loss_probability = loss;
  }
  sim::Game game(cfg);
  const bool print = std::getenv("LLSF_AGENT_LOG") != nullptr;
  std::vector<std::unique_ptr<sim::AgentBrain>> brains;
  Points p;
  for (int i = 0; i < 3; ++i) {
    sim::AgentBrainConfig c;
    c.agent_files = agent;
    brains.push_back(
        std::make_unique<sim::AgentBrain>(game, i, c, [print, &p](const clips::LogRecord& r) {
          const std::string_view text = r.text;
          if (text.find("auctioning") != std::string_view::npos) ++p.reauctions;
          if (print || r.level == clips::LogLevel::kError) {
            std::printf("%8.2f %s %s: %.*s\n", r.time.seconds(), std::string(r.agent).c_str(),
                        clips::to_string(r.level), static_cast<int>(r.text.size()), r.text.data());
          }
        }));
    game.set_brain(i, brains.back().get());
  }
  test::start_phase(game, refbox::GamePhase::kProduction);
  game.run_until(core::SimTime::from_sec(900));
  p.production = game.summary().production_points;
  for (const auto& b : brains) p.runtime_errors += b->agent().runtime_errors();
  return p;
}

}  // namespace

TEST_CASE("auction: three robots score in production, with and without 20 % radio loss") {
  for (const std::uint64_t seed : {7u, 11u}) {
    for (const double loss : {0.0, 0.2}) {
      CAPTURE(seed);
      CAPTURE(loss);
      const Points a = play(kAuctionAgent, seed, loss);
      const Points r = play(kRoleAgent, seed, loss);
      MESSAGE("seed ", seed, ", loss ", loss, ": auction ", a.production, " points (", a.reauctions,
              " re-auctions), llsf2013 ", r.production, " points");
      CHECK(a.runtime_errors == 0);
      CHECK(a.production > 0);
    }
  }
}
