// SPDX-License-Identifier: MIT
// Benchmark of the CLIPS agent host: CPU time of one agent cycle (10 Hz) of a small LLSF-like
// rule base, with the facts that change in a game: the (time) fact, the pose, one received
// LockMessage per cycle, a beacon timer broadcasting once per second, and a skill that finishes
// every 2 s (then the machine facts change and a new task is chosen).
#include <llsf_agent_msgs/LockMessage.pb.h>

#include <string>

#include "harness.h"
#include "llsf/clips/testing.h"
#include "llsf/comm/registry.h"

using namespace llsf;

namespace {

constexpr int kCycles = 20000;
constexpr int kRepeats = 5;

constexpr const char* kRules = R"clp(
(deftemplate machine (slot name) (slot mtype) (slot state (default IDLE)) (slot x) (slot y)
  (slot loaded (default 0)))
(deftemplate proposal (slot machine) (slot priority))
(deffacts world
  (state IDLE)
  (timer (name beacon))
  (machine (name M1) (mtype T1) (x 1.05) (y 1.00)) (machine (name M2) (mtype T2) (x 2.15) (y 1.00))
  (machine (name M3) (mtype T3) (x 3.45) (y 1.00)) (machine (name M4) (mtype T4) (x 4.55) (y 1.00))
  (machine (name M5) (mtype T1) (x 1.05) (y 2.25)) (machine (name M6) (mtype T2) (x 2.15) (y 2.25))
  (machine (name M7) (mtype T3) (x 3.45) (y 2.25)) (machine (name M8) (mtype T5) (x 4.55) (y 2.25))
  (machine (name M9) (mtype T1) (x 1.05) (y 3.35)) (machine (name M10) (mtype T2) (x 2.15) (y 3.35)))

(defrule propose
  (state IDLE)
  (pose (x ?rx) (y ?ry))
  (machine (name ?m) (state IDLE) (x ?x) (y ?y) (loaded ?l))
  (not (proposal (machine ?m)))
  =>
  (assert (proposal (machine ?m)
                    (priority (- 10 ?l (+ (abs (- ?x ?rx)) (abs (- ?y ?ry))))))))

(defrule select
  ?s <- (state IDLE)
  (proposal (machine ?m) (priority ?p))
  (not (proposal (priority ?p2&:(> ?p2 ?p))))
  ?mf <- (machine (name ?m))
  =>
  (retract ?s)
  (modify ?mf (state BUSY))
  (assert (state GOTO ?m))
  (skill-call drive_to place ?m))

(defrule drop-proposals
  (declare (salience -10))
  (state GOTO ?)
  ?p <- (proposal)
  =>
  (retract ?p))

(defrule arrived
  ?s <- (state GOTO ?m)
  ?sk <- (skill (name "drive_to") (status FINAL|FAILED))
  ?mf <- (machine (name ?m) (loaded ?l))
  =>
  (retract ?s ?sk)
  (modify ?mf (state IDLE) (loaded (+ ?l 1)))
  (assert (state IDLE)))

(defrule lock-seen
  ?pf <- (protobuf-msg (type "llsf_agent_msgs.LockMessage") (ptr ?p))
  =>
  (retract ?pf)
  (bind ?res (pb-field-value ?p "resource"))
  (do-for-fact ((?m machine)) (eq ?m:name (sym-cat ?res)) (assert (seen-lock ?res))))

(defrule forget-lock
  (declare (salience -20))
  ?f <- (seen-lock ?)
  =>
  (retract ?f))

(defrule beacon
  (time $?now)
  ?t <- (timer (name beacon) (time $?last&:(timeout ?now ?last 1.0)) (seq ?seq))
  =>
  (modify ?t (time ?now) (seq (+ ?seq 1)))
  (bind ?m (pb-create "llsf_agent_msgs.LockMasterAnnounce"))
  (pb-set-field ?m "agent" (str-cat ?*ROBOT-NAME*))
  (pb-broadcast ?m)
  (pb-destroy ?m))
)clp";

// CPU microseconds per agent cycle.
double us_per_cycle() {
  comm::MessageRegistry reg;
  comm::add_agent_messages(reg);
  clips::FakeSkillRunner skills;
  int broadcasts = 0;
  clips::AgentIo io;
  io.skills = &skills;
  io.messages = &reg;
  io.broadcast = [&](const google::protobuf::Message&) { ++broadcasts; };
  clips::AgentHost agent(clips::AgentConfig{}, io);
  agent.load_string(kRules, "bench.clp");
  const core::SimTime dt = core::SimTime::from_ms(100);
  core::SimTime now;
  const char* resources[] = {"M1", "M2", "INS", "M5"};
  auto run = [&](int cycles) {
    for (int i = 0; i < cycles; ++i) {
      now += dt;
      agent.set_pose({1.0 + 0.001 * (i % 1000), 2.0, 0.1});
      auto msg = std::make_unique<llsf_agent_msgs::LockMessage>();
      msg->set_type(llsf_agent_msgs::LockMessage::GET);
      msg->set_agent("robot2");
      msg->set_resource(resources[i % 4]);
      agent.receive(std::move(msg), "robot2", 2, now);
      if (i % 20 == 19) skills.set_status(clips::SkillStatus::kFinal);
      agent.cycle(now);
    }
  };
  run(1000);  // warm-up
  const double t0 = bench::cpu_seconds();
  run(kCycles);
  const double us = (bench::cpu_seconds() - t0) * 1e6 / kCycles;
  if (agent.runtime_errors() != 0 || agent.limit_hits() != 0 || broadcasts == 0 ||
      skills.calls().size() < 100)
    return -1.0;
  return us;
}

}  // namespace

LLSF_BENCH(clips_cycle,
           "AgentHost::cycle of one robot: 10 machines, pose + time + 1 message per cycle, "
           "beacon 1 Hz, a task every 2 s") {
  const double us = bench::median_of(kRepeats, [] { return us_per_cycle(); });
  bench::report("clips_cycle", "us_per_agent_cycle", us, "us");
  // 3 robots at 10 Hz over an 18-minute game.
  bench::report("clips_cycle", "cpu_s_per_game_3_robots", us * 1e-6 * 3 * 10 * 1080, "s");
}
