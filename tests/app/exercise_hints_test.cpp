// SPDX-License-Identifier: MIT
// `llsfsim exercise` on the deliberate mistakes of tests/app/exercises/mistakes/ (one file per
// mistake, the line marked "-- MISTAKE"): each is reported with the participant's file and
// line, its own message and its own hint, or with a warning (docs/exercises.md, "Mistakes and
// their messages"). The runs are short: load errors stop before the game, the others fail or end
// in the first seconds of game time.
#include <doctest/doctest.h>

#include <fstream>
#include <string>

#include "app/cli_fixture.h"
#include "llsf/app/cli.h"

namespace {

using llsf::test::has;
using llsf::test::llsfsim;
using llsf::test::Run;

const std::string kMistakes = LLSF_SOURCE_DIR "/tests/app/exercises/mistakes/";
const std::string kSolutions = LLSF_SOURCE_DIR "/tests/app/exercises/";

/// The line number of the "-- MISTAKE" marker in `path`.
int marked(const std::string& path) {
  std::ifstream in(path);
  std::string line;
  for (int n = 1; std::getline(in, line); ++n) {
    if (line.find("-- MISTAKE") != std::string::npos) return n;
  }
  FAIL("no -- MISTAKE marker in ", path);
  return 0;
}

struct Mistake {
  const char* file;
  const char* exercise;
  int code;             ///< exit code
  const char* message;  ///< follows "error    PATH:LINE: "
  const char* hint;     ///< follows "hint     "
};

}  // namespace

TEST_CASE("exercise: each mistake gets its own message at the participant's file:line and hint") {
  using llsf::app::kExitBadInput;
  using llsf::app::kExitFailed;
  const Mistake mistakes[] = {
      {"undefined_state.lua", "01", kExitBadInput,
       "add_transitions: {\"DRIVE\", \"CHEK\"} goes to an unknown state 'CHEK' (did you mean "
       "'CHECK'? states: DRIVE, CHECK, FINAL, FAILED)",
       "a state named in a transition"},
      {"no_define_states.lua", "01", kExitBadInput,
       "the state machine has no states: fsm:define_states{...} is missing (start state 'DRIVE' "
       "is not defined)",
       "define the states right after SkillHSM:new"},
      {"no_fsm.lua", "01", kExitBadInput,
       "undeclared global 'fsm': create the state machine first: fsm = SkillHSM:new{name=name, "
       "start=\"STATE\"}",
       "create the state machine below name = ..."},
      {"no_documentation.lua", "01", kExitBadInput,
       "the skill declares no 'documentation' string: add documentation = [==[what the skill "
       "does]==] next to name = ...",
       "every skill says what it does"},
      {"no_start.lua", "01", kExitBadInput,
       "SkillHSM:new{...} needs start=\"STATE\", the state the skill begins in",
       "name the state the skill begins in"},
      {"typo_state.lua", "01", kExitBadInput, "undeclared global 'DRVE' (did you mean 'DRIVE'?)",
       "a typo? Use the name the message suggests"},
      {"typo_runtime.lua", "01", kExitFailed, "undeclared global 'poes' (did you mean 'pose'?)",
       "a typo? Use the name the message suggests"},
      {"uses_os.lua", "01", kExitFailed,
       "'os' is not available in skills: no files, processes or wall clock: for time "
       "use clock.now() (game seconds) or a transition's timeout=SECS",
       "skills run in a sandbox"},
      {"uses_require.lua", "01", kExitBadInput,
       "module 'helpers' is not available in skills: require loads only the Lua files of the "
       "skill and module directories",
       "skills run in a sandbox"},
      {"printf_float.lua", "01", kExitFailed,
       "bad argument #2 to 'printf' (number has no integer representation)",
       "the format does not fit the value: %d needs a whole number"},
      {"out_of_memory.lua", "01", kExitFailed, "not enough memory (heap limit of 67108864 bytes)",
       "the skill holds more memory than allowed"},
      {"result_table.lua", "02", kExitFailed,
       "fsm.result must be a string (e.g. \"1.20 3.40\") or a number, not a table",
       "report text, not a table"},
      // At the skill's execute, not the prelude's line; not the syntax-error hint.
      {"execute_nil.lua", "01", kExitFailed,
       "drive_to_point: execute() returned nil, expected S_RUNNING, S_FINAL or S_FAILED (a path "
       "through execute() without a `return`?)",
       "execute() must return S_RUNNING, S_FINAL or S_FAILED on every path"},
      // The method meant; not the syntax-error hint ("nearst" has "near" in it).
      {"typo_method.lua", "02", kExitFailed,
       "attempt to call a nil value (method 'nearst') (did you mean 'nearest'?)",
       "the interface has no such method"},
      {"assign_in_cond.lua", "01", kExitBadInput,
       "bad cond \"vars.x = 1\": `=` assigns; a condition compares with `==` (or `~=`)",
       "in a cond string write `==` to compare"},
      // Not taken for a state only: a constant used too early is named as such too.
      {"early_constant.lua", "01", kExitBadInput,
       "undeclared global 'MAX_SPEED': if it is a state, no state is defined yet: call "
       "fsm:define_states{...} before using it (function MAX_SPEED:init() ...); otherwise define "
       "it before this line (local MAX_SPEED = ...)",
       "a name the file uses before defining it"},
  };
  for (const Mistake& m : mistakes) {
    const std::string path = kMistakes + m.file;
    const Run r = llsfsim({"exercise", m.exercise, "--skill", path, "-q"});
    INFO(m.file, "\n", r.out, r.err);
    CHECK(r.code == m.code);
    CHECK(has(r.out, "error    " + path + ":" + std::to_string(marked(path)) + ": " + m.message));
    CHECK(has(r.out, std::string("hint     ") + m.hint));
    CHECK(has(r.out, m.code == kExitBadInput ? "result   NOT RUN" : "result   FAIL"));
    CHECK_FALSE(has(r.out, "prelude.lua"));
    CHECK_FALSE(has(r.out, "llsfex-"));  // never the temporary copy's path
    CHECK_FALSE(has(r.out, "your skill failed with this error"));  // not the catch-all
  }
}

TEST_CASE("exercise: drive_to with string coordinates says what was wrong, not to retry") {
  const std::string path = kMistakes + "string_coordinates.lua";
  const Run r = llsfsim({"exercise", "01", "--skill", path, "-q"});
  INFO(r.out, r.err);
  CHECK(r.code == llsf::app::kExitFailed);
  CHECK(has(r.out,
            "drive_to needs place=<name> or x=, y=: x= and y= must be numbers (got "
            "x=\"1.5\" (a string), y=\"2\" (a string))"));
  CHECK(has(r.out, "hint     the arguments your skill gave drive_to are wrong"));
  CHECK_FALSE(has(r.out, "try again"));
}

TEST_CASE("exercise 02: the verdict's why names what the wrong position is") {
  struct Wrong {
    const char* file;
    const char* why;  ///< follows "why      "
  };
  const Wrong wrongs[] = {
      {"find_robot_frame.lua",
       "the position is the red puck's in the robot's frame (ahead, left): turn the sighting "
       "into field coordinates"},
      {"find_wrong_colour.lua", "the position is a green puck's (puck "},
      {"find_robot_position.lua", "the position is the robot's own (pose:get()), not the puck's"},
  };
  for (const Wrong& w : wrongs) {
    const Run r = llsfsim({"exercise", "02", "--skill", kMistakes + w.file, "-q"});
    INFO(w.file, "\n", r.out, r.err);
    CHECK(r.code == llsf::app::kExitFailed);
    CHECK(has(r.out, std::string("why      ") + w.why));
  }
}

TEST_CASE("exercise: silent mistakes are warnings with the line; a load-time print is shown") {
  struct Warning {
    const char* file;
    const char* text;  ///< follows ":LINE: " in a "warn: " line
  };
  const Warning warnings[] = {
      {"bounce.lua",
       "drive_to_point: states PLAN -> CHECK -> PLAN keep switching without waiting ("},
      {"args_ignored.lua",
       "drive_to_point: state 'DRIVE' sets self.args[\"drive_to\"], but it runs no sub-skill (it "
       "is a JumpState), so the arguments are ignored"},
      {"no_way_out.lua",
       "drive_to_point: state 'WAIT' has no way out: no transition, timeout or sub-skill leaves "
       "it, so the skill would stay there"},
      {"never_fires.lua",
       "drive_to_point: the transition {\"CHECK\", \"FINAL\", cond=\"vars.done\"} can never "
       "fire: {\"CHECK\", \"DRIVE\", cond=true} before it has cond=true and is always taken first"},
      {"typo_vars.lua",
       "drive_to_point: state 'CHECK' has waited 5 s on {\"CHECK\", \"FINAL\", "
       "cond=\"vars.arived\"}, which reads vars.arived: nothing set it (did you mean "
       "vars.arrived?), so the condition never holds"},
  };
  for (const Warning& w : warnings) {
    const std::string path = kMistakes + w.file;
    const Run r = llsfsim({"exercise", "01", "--skill", path, "-q"});
    INFO(w.file, "\n", r.out, r.err);
    CHECK(r.code == llsf::app::kExitFailed);
    const std::size_t at = r.out.find(" warn: ");
    REQUIRE(at != std::string::npos);
    const std::string line = r.out.substr(at, r.out.find('\n', at) - at);
    CHECK(has(line, ":" + std::to_string(marked(path)) + ": " + w.text));
    // Once per call of the skill, not once per cycle.
    CHECK(r.out.find(" warn: ", at + 1) == std::string::npos);
  }

  const Run r = llsfsim({"exercise", "01", "--skill", kMistakes + "print_at_load.lua"});
  INFO(r.out, r.err);
  CHECK(has(r.out, "[    0.00 s] robot1 info: loading drive_to_point, version 3\n"));
}

TEST_CASE("exercise: every state a step passes is printed; --trace says what took it there") {
  const std::string path = kMistakes + "typo_vars.lua";
  const Run r = llsfsim({"exercise", "01", "--skill", path});
  INFO(r.out, r.err);
  // START -> DRIVE within the first skill cycle: both states are printed.
  CHECK(has(r.out, "[    0.01 s] robot1   drive_to_point: START\n"));
  CHECK(has(r.out, "[    0.01 s] robot1   drive_to_point: DRIVE\n"));
  // Still running at the end: the why names the state, since when and what it waits for.
  const std::string line = ":" + std::to_string(marked(path)) + ")";
  CHECK(has(r.out, "why      the skill was still running after 60 s: in state CHECK since "));
  CHECK(has(r.out, ", waiting for {\"CHECK\", \"FINAL\", cond=\"vars.arived\"} ("));
  CHECK(has(r.out, line + "; vars.arived is never set (did you mean vars.arrived?)\n"));

  const Run t = llsfsim({"exercise", "01", "--skill", path, "--trace"});
  INFO(t.out, t.err);
  CHECK(has(t.out, "[    0.01 s] robot1   drive_to_point: START\n"));
  CHECK(has(t.out,
            "[    0.01 s] robot1   drive_to_point: START -> DRIVE  ({\"START\", \"DRIVE\", "
            "cond=true} at "));
  CHECK(has(t.out, "typo_vars.lua:" + std::to_string(marked(path)) + ")\n"));
  CHECK(has(t.out, "drive_to_point: DRIVE -> CHECK  (its sub-skills ended FINAL (final_to))\n"));

  // A step that ends the skill: its states are printed too (DRIVE -> CHECK -> FINAL at once).
  const Run f =
      llsfsim({"exercise", "01", "--skill", kSolutions + "01-drive-to-point.lua", "--trace"});
  INFO(f.out, f.err);
  CHECK(has(f.out, "drive_to_point: DRIVE -> CHECK  (its sub-skills ended FINAL (final_to))\n"));
  CHECK(has(f.out, "drive_to_point: CHECK -> FINAL  ({\"CHECK\", \"FINAL\", cond=<function>} at "));
}

TEST_CASE("exercise: a condition on a key of vars nothing sets and no set key is near") {
  // vars.reached, while the skill sets vars.arrived: no did-you-mean, so the why names what is
  // set; no warning during the game (a key may be set later, by a loop that finds something).
  const std::string path = kMistakes + "unset_vars.lua";
  const Run r = llsfsim({"exercise", "01", "--skill", path});
  INFO(r.out, r.err);
  CHECK(r.code == llsf::app::kExitFailed);
  CHECK(has(r.out, ", waiting for {\"CHECK\", \"FINAL\", cond=\"vars.reached\"} ("));
  const std::size_t at = r.out.find("; vars.reached is never set (what is set: ");
  REQUIRE(at != std::string::npos);
  CHECK(r.out.substr(at, r.out.find('\n', at) - at).find("vars.arrived") != std::string::npos);
  CHECK_FALSE(has(r.out, " warn: "));
}
