// SPDX-License-Identifier: MIT
// `llsfsim new agent DIR`: a minimal working two-robot CLIPS agent -- the agent, a scenario that
// plays it and a rule test -- that `llsfsim run` and `llsfsim test-agent` accept as written.
// The files name nothing outside DIR (the skill library comes from the data directory), so an
// installed llsfsim works with them.
#include <filesystem>
#include <fstream>
#include <memory>
#include <ostream>
#include <string>
#include <string_view>
#include <vector>

#include "commands.h"
#include "llsf/app/cli.h"
#include "llsf/core/error.h"

namespace llsf::app {

namespace {

namespace fs = std::filesystem;

constexpr std::string_view kAgentClp =
    R"clp(; A two-robot LLSF 2013 agent, written by `llsfsim new agent`. In the exploration phase each
; robot drives to its machines in turn (confval /clips-agent/machines, set per robot in
; ../scenario.yaml), reads their signal lights and reports the machine types to the refbox, which
; gives points for each correct report; when production begins, it parks.
;
; What the agent sees (docs/clips.md):
;   (time sec usec)        every cycle (10 Hz of simulated time); (now) is the time in seconds
;   (skill-call NAME k v)  runs a skill of the library (docs/skills.md, `llsfsim skill --list`);
;                          the fact (skill (name) (status RUNNING|FINAL|FAILED) (result) (error))
;                          follows it and is retracted at the end of the cycle it finished in
;   (confval (path) (value) (list-value))   from the scenario's robots.config
;   (protobuf-msg (type) (ptr))             each message the radio delivered this cycle; read it
;                          with pb-field-value / pb-field-list; send with pb-create,
;                          pb-set-field, pb-add-list, pb-broadcast, pb-destroy
;   ?*ROBOT-NAME* ?*ROBOT-NUMBER*, (pose (x) (y) (ori)), (log-info ...), (log-warn ...)
;
; Test it: llsfsim test-agent .        Play it: llsfsim run scenario.yaml

(deftemplate game                                  ; the refbox's GameState as last heard
  (slot phase (type SYMBOL) (default PRE_GAME))
  (slot state (type SYMBOL) (default INIT)))
(deftemplate signal                                ; the light code of a machine type
  (slot type (type SYMBOL))
  (slot code (type STRING)))                       ; "red=ON yellow=OFF green=BLINK"
(deftemplate todo                                  ; a machine this robot explores
  (slot machine (type SYMBOL))
  (slot order (type INTEGER))
  (slot state (type SYMBOL) (default OPEN)))       ; OPEN EXPLORING DONE
(deftemplate found                                 ; what it read there
  (slot machine (type SYMBOL))
  (slot type (type SYMBOL)))

(deffacts start
  (game)
  (timer (name report) (time 0 0) (seq 0)))

;---- what the refbox says -----------------------------------------------------------------------

(defrule refbox-game-state
  ?pf <- (protobuf-msg (type "llsf_msgs.GameState") (ptr ?p))
  ?g <- (game (phase ?phase) (state ?state))
  =>
  (retract ?pf)
  (bind ?new-phase (pb-field-value ?p "phase"))
  (bind ?new-state (pb-field-value ?p "state"))
  (if (or (neq ?new-phase ?phase) (neq ?new-state ?state)) then
    (modify ?g (phase ?new-phase) (state ?new-state))))

(defrule refbox-exploration-info
  ?pf <- (protobuf-msg (type "llsf_msgs.ExplorationInfo") (ptr ?p))
  =>
  (retract ?pf)
  (if (not (any-factp ((?s signal)) TRUE)) then
    (foreach ?s (pb-field-list ?p "signals")
      (bind ?red OFF) (bind ?yellow OFF) (bind ?green OFF)
      (foreach ?l (pb-field-list ?s "lights")
        (switch (pb-field-value ?l "color")
          (case RED then (bind ?red (pb-field-value ?l "state")))
          (case YELLOW then (bind ?yellow (pb-field-value ?l "state")))
          (case GREEN then (bind ?green (pb-field-value ?l "state")))))
      (assert (signal (type (sym-cat (pb-field-value ?s "type")))
                      (code (str-cat "red=" ?red " yellow=" ?yellow " green=" ?green)))))))

;---- exploration: this robot's machines, one after the other -------------------------------------

(defrule explore-plan
  (game (phase EXPLORATION))
  (not (todo))
  =>
  (bind ?machines (create$ M1 M2 M3 M4 M5 M6 M7 M8 M9 M10))
  (do-for-fact ((?c confval)) (eq ?c:path "/clips-agent/machines")
    (bind ?machines ?c:list-value))
  (loop-for-count (?i 1 (length$ ?machines))
    (assert (todo (machine (sym-cat (nth$ ?i ?machines))) (order ?i)))))

(defrule explore-next
  (game (phase EXPLORATION) (state RUNNING))
  (signal)
  (not (todo (state EXPLORING)))
  ?t <- (todo (machine ?m) (state OPEN) (order ?o))
  (not (todo (state OPEN) (order ?o2&:(< ?o2 ?o))))
  =>
  (modify ?t (state EXPLORING))
  (skill-call explore_machine place ?m))

(defrule explore-read
  ?t <- (todo (machine ?m) (state EXPLORING))
  ?s <- (skill (name "explore_machine") (status FINAL) (result ?code))
  =>
  (retract ?s)
  (modify ?t (state DONE))
  (bind ?type NONE)
  (do-for-all-facts ((?sig signal)) (str-index ?sig:code ?code) (bind ?type ?sig:type))
  (if (eq ?type NONE)
   then (log-warn "explore: " ?m " shows a code of no type (" ?code ")")
   else (log-info "explore: " ?m " is a " ?type)
        (assert (found (machine ?m) (type ?type)))))

(defrule explore-failed
  ?t <- (todo (machine ?m) (state EXPLORING))
  ?s <- (skill (name "explore_machine") (status FAILED) (error ?e))
  =>
  (retract ?s)
  (modify ?t (state DONE))
  (log-warn "explore: " ?m " failed: " ?e))

;---- reports: everything found, every second of the exploration phase ----------------------------

(deffunction send-report ()
  (bind ?msg (pb-create "llsf_msgs.MachineReport"))
  (do-for-all-facts ((?f found)) TRUE
    (bind ?entry (pb-create "llsf_msgs.MachineReportEntry"))
    (pb-set-field ?entry "name" (str-cat ?f:machine))
    (pb-set-field ?entry "type" (str-cat ?f:type))
    (pb-add-list ?msg "machines" ?entry)
    (pb-destroy ?entry))
  (pb-broadcast ?msg)
  (pb-destroy ?msg))

(defrule report-found
  (time $?now)
  (game (phase EXPLORATION))
  (found)
  ?t <- (timer (name report) (time $?last&:(timeout ?now ?last 1.0)) (seq ?seq))
  =>
  (modify ?t (time ?now) (seq (+ ?seq 1)))
  (send-report))

;---- production: out of the way -----------------------------------------------------------------

(defrule production-park
  (game (phase PRODUCTION))
  (not (parked))
  =>
  (assert (parked))
  (skill-call park))
)clp";

constexpr std::string_view kScenario =
    R"yaml(# Two robots with the agent in agent/ (written by `llsfsim new agent`): the exploration phase and
# the start of production. Play it: llsfsim run scenario.yaml   Keys: docs/scenarios.md.
name: my-agent
seed: 1
start: exploration          # the refbox starts in the exploration phase (180 s)
duration_s: 200             # ... and the first 20 s of production
robots:
  count: 2
  agent: [agent]            # files or directories (their *.clp in name order), relative to here
  each:                     # per robot: the machines it explores (/clips-agent/machines)
    - {config: {machines: [M8, M4, M3, M1, M5]}}
    - {config: {machines: [M9, M10, M7, M6, M2]}}
tests:
  - {name: most machines explored and reported, exploration_points_at_least: 30}
  - no_agent_errors: true
)yaml";

constexpr std::string_view kTest =
    R"yaml(# Rule tests of the agent, without the world (docs/agent-tests.md): each case loads the agent
# into a fresh CLIPS environment, plays steps of 100 ms and checks what the agent did.
# Run them: llsfsim test-agent .      (every *_test.yaml below the directory)
agent: ../agent             # relative to this file
robot: {name: robot1, number: 1}
config:                     # confval facts under /clips-agent, as the scenario's robots.config
  machines: [M8, M4]

tests:
  - name: explores its machines in turn and reports their types
    steps:
      - receive: llsf_msgs.GameState
        fields: {phase: EXPLORATION, state: RUNNING, game_time: {sec: 0, nsec: 0}}
      - receive: llsf_msgs.ExplorationInfo
        fields:
          signals:
            - type: T1
              lights: [{color: RED, state: ON}, {color: YELLOW, state: OFF}, {color: GREEN, state: OFF}]
            - type: T2
              lights: [{color: RED, state: OFF}, {color: YELLOW, state: ON}, {color: GREEN, state: OFF}]
      - step: 1
      - expect: (signal (type T1) (code "red=ON yellow=OFF green=OFF"))
      - expect_skill: explore_machine{place="M8"}
      - skill: FINAL
        result: M8 red=ON yellow=OFF green=OFF
      - step: 1
      - expect: (found (machine M8) (type T1))
      - expect_skill: explore_machine{place="M4"}
      - step: 1s
      - expect_sent: llsf_msgs.MachineReport
        fields: {machines: [{name: M8, type: T1}]}

  - name: parks when production begins
    given:
      - modify: (game (phase PRODUCTION) (state RUNNING))
    steps:
      - step: 1
      - expect: (parked)
      - expect_skill: park
)yaml";

struct NewAgentOptions {
  std::string dir;
  bool force = false;
};

struct Written {
  std::string_view path;  ///< relative to the directory
  std::string_view text;
  std::string_view what;
};

int new_agent(const NewAgentOptions& o, std::ostream& out, std::ostream& err) {
  const fs::path dir(o.dir);
  std::error_code ec;
  if (fs::exists(dir, ec)) {
    if (!fs::is_directory(dir, ec)) {
      err << "llsfsim new agent: " << o.dir << " exists and is not a directory\n";
      return kExitBadInput;
    }
    if (!fs::is_empty(dir, ec) && !o.force) {
      err << "llsfsim new agent: " << o.dir
          << " is not empty; choose a new directory, or --force to write the files into it "
             "(replacing agent/agent.clp, scenario.yaml, tests/agent_test.yaml)\n";
      return kExitBadInput;
    }
  }
  const Written files[] = {
      {"agent/agent.clp", kAgentClp, "the agent (CLIPS): explore, report, park"},
      {"scenario.yaml", kScenario, "two robots with the agent: exploration, start of production"},
      {"tests/agent_test.yaml", kTest, "its rule tests"},
  };
  for (const Written& w : files) {
    const fs::path p = dir / w.path;
    fs::create_directories(p.parent_path(), ec);
    std::ofstream f(p, std::ios::binary | std::ios::trunc);
    f << w.text;
    f.close();
    if (!f) throw core::UserError("cannot write " + p.string());
  }
  for (const Written& w : files) {
    out << "wrote " << (dir / w.path).string() << "  (" << w.what << ")\n";
  }
  out << "next:\n"
      << "  llsfsim test-agent " << o.dir << "            # the rule tests, without the world\n"
      << "  llsfsim run " << (dir / "scenario.yaml").string() << "  # a game of two robots\n"
      << "  llsfsim run " << (dir / "scenario.yaml").string()
      << " --serve --speed 4  # watch it in the browser\n"
      << "Docs: docs/clips.md (the agent host), docs/agent-tests.md (the tests), "
         "docs/scenarios.md.\n";
  return kExitOk;
}

}  // namespace

Action add_new_command(CLI::App& app) {
  auto o = std::make_shared<NewAgentOptions>();
  app.require_subcommand(1);
  app.footer(
      "`llsfsim new agent DIR`: a minimal working two-robot CLIPS agent with a scenario and a "
      "rule test (llsfsim new agent --help).\n"
      "Exit code: 0 written, 2 bad input, 3 internal error (a bug: please report it).");
  CLI::App* agent = app.add_subcommand(
      "agent", "Write a minimal working two-robot CLIPS agent with a scenario and a rule test");
  agent->add_option("dir", o->dir, "Directory to write to (created; must be empty)")->required();
  agent->add_flag("--force", o->force, "Write into a non-empty directory (replacing the files)");
  agent->footer(
      "Writes DIR/agent/agent.clp (each robot explores its machines, reports their types to the "
      "refbox and parks in production), DIR/scenario.yaml (two robots with the agent) and "
      "DIR/tests/agent_test.yaml (rule tests). Then: `llsfsim test-agent DIR`, `llsfsim run "
      "DIR/scenario.yaml`.\n"
      "Exit code: 0 written, 2 DIR is not empty (without --force) or cannot be written, 3 "
      "internal error (a bug: please report it).");
  return [o](std::ostream& out, std::ostream& err) { return new_agent(*o, out, err); };
}

}  // namespace llsf::app
