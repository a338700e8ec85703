// SPDX-License-Identifier: MIT
// The protobuf feature with the refbox's 2013 messages (llsf_msgs), if they are built: a
// GameState from the refbox read by rules (enums as symbols, the nested Time as a pointer), and
// a BeaconSignal built and broadcast by an agent.
#include <doctest/doctest.h>

#ifdef LLSF_HAVE_MSGS
#include <llsf_msgs/BeaconSignal.pb.h>
#include <llsf_msgs/GameState.pb.h>

#include "llsf/clips/testing.h"
#include "llsf/comm/registry.h"

using namespace llsf;
using namespace llsf::clips;

TEST_CASE("refbox messages: GameState in, BeaconSignal out") {
  comm::MessageRegistry reg;
  reg.add<llsf_msgs::GameState>();
  reg.add<llsf_msgs::BeaconSignal>();
  AgentFixture f({}, &reg);
  f.load(
      "(defrule game-state\n"
      "  ?pf <- (protobuf-msg (type \"llsf_msgs.GameState\") (ptr ?p) (comp-id 2000))\n"
      "  =>\n"
      "  (retract ?pf)\n"
      "  (bind ?t (pb-field-value ?p \"game_time\"))\n"
      "  (assert (game (pb-field-value ?p \"state\") (pb-field-value ?p \"phase\")\n"
      "                (pb-field-value ?t \"sec\")))\n"
      "  (bind ?b (pb-create \"llsf_msgs.BeaconSignal\"))\n"
      "  (bind ?bt (pb-create \"llsf_msgs.Time\"))\n"
      "  (pb-set-field ?bt \"sec\" 12) (pb-set-field ?bt \"nsec\" 0)\n"
      "  (pb-set-field ?b \"time\" ?bt)\n"
      "  (pb-set-field ?b \"seq\" 1)\n"
      "  (pb-set-field ?b \"team_name\" ?*TEAM-NAME*)\n"
      "  (pb-set-field ?b \"peer_name\" ?*ROBOT-NAME*)\n"
      "  (pb-set-field ?b \"number\" ?*ROBOT-NUMBER*)\n"
      "  (pb-broadcast ?b)\n"
      "  (pb-destroy ?b) (pb-destroy ?bt))\n");
  f.step();
  auto gs = std::make_unique<llsf_msgs::GameState>();
  gs->mutable_game_time()->set_sec(42);
  gs->mutable_game_time()->set_nsec(0);
  gs->set_state(llsf_msgs::GameState::RUNNING);
  gs->set_phase(llsf_msgs::GameState::EXPLORATION);
  f.agent().receive(std::move(gs), "refbox", 0, f.now());
  f.step();
  CHECK(f.has("(game RUNNING EXPLORATION 42)"));
  REQUIRE(f.sent().size() == 1);
  const auto* b = dynamic_cast<const llsf_msgs::BeaconSignal*>(f.sent()[0].get());
  REQUIRE(b != nullptr);
  CHECK(b->peer_name() == "robot1");
  CHECK(b->team_name() == "Carologistics");
  CHECK(b->time().sec() == 12);
  CHECK(f.agent().live_messages() == 0);
  CHECK(f.agent().runtime_errors() == 0);
}
#endif
