// SPDX-License-Identifier: MIT
// What CLIPS says too vaguely or not at all, made clear at load: a constraint error in a rule's
// conditions points at the pattern (not the rule's last line) and names what the slot allows; a
// rule condition that reads the time where CLIPS never evaluates it again is a warning with its
// line (TimeReadCheck, also in `llsfsim check`).
#include <doctest/doctest.h>

#include <string>

#include "llsf/clips/agent.h"
#include "llsf/clips/source_check.h"
#include "llsf/clips/testing.h"

using namespace llsf;
using namespace llsf::clips;

namespace {

std::string load_error(std::string_view code) {
  AgentFixture f;
  try {
    f.load(code, "c.clp");
  } catch (const AgentLoadError& e) {
    return e.what();
  }
  return "";
}

constexpr std::string_view kTemplates =
    "(deftemplate todo (slot machine (type SYMBOL)) (slot order (type INTEGER)))\n"  // 1
    "(deftemplate colour (slot c (type SYMBOL) (allowed-values RED GREEN)))\n"       // 2
    "(deftemplate rr (slot n (type INTEGER) (range 0 10)))\n";                       // 3

}  // namespace

TEST_CASE("a constraint error in a rule's conditions points at the pattern and names the slot") {
  struct Case {
    std::string rule;
    std::string want;
  };
  const Case cases[] = {
      // A type: CE #2 on line 6, not the rule's last line (8).
      {"(defrule r\n"                // 4
       "  (colour)\n"                // 5
       "  (todo (order foo))\n"      // 6
       "  =>\n"                      // 7
       "  (printout t hi crlf))\n",  // 8
       "c.clp:6: [CSTRNCHK1] A literal restriction value found in CE #2 does not match the "
       "allowed types for slot order; deftemplate todo has (slot order (type INTEGER)) (in "
       "defrule MAIN::r)"},
      // Allowed values, inside a not and an and, after a test: CE #4 is the colour pattern.
      {"(defrule r\n"                       // 4
       "  ?t <- (todo (order ?o))\n"        // 5
       "  (test (> ?o 1))\n"                // 6
       "  (not (and (todo)\n"               // 7
       "            (colour (c BLUE))))\n"  // 8
       "  =>\n"                             // 9
       "  (retract ?t))\n",                 // 10
       "c.clp:8: [CSTRNCHK1] A literal restriction value found in CE #4 does not match the "
       "allowed values for slot c; deftemplate colour has (slot c (type SYMBOL) (allowed-values "
       "RED GREEN)) (in defrule MAIN::r)"},
      {"(defrule r\n"                // 4
       "  (todo)\n"                  // 5
       "  (rr (n 20))\n"             // 6
       "  =>\n"                      // 7
       "  (printout t hi crlf))\n",  // 8
       "c.clp:6: [CSTRNCHK1] A literal restriction value found in CE #2 does not fall in the "
       "allowed range 0 to 10 for slot n; deftemplate rr has (slot n (type INTEGER) (range 0 "
       "10)) (in defrule MAIN::r)"},
      // A variable whose two uses conflict: the second pattern's line.
      {"(defrule r\n"                // 4
       "  (todo (order ?x))\n"       // 5
       "  (todo (machine ?x))\n"     // 6
       "  =>\n"                      // 7
       "  (printout t hi crlf))\n",  // 8
       "c.clp:6: [RULECSTR1] Variable ?x in CE #2 slot machine has constraint conflicts which "
       "make the pattern unmatchable; deftemplate todo has (slot machine (type SYMBOL)) (in "
       "defrule MAIN::r)"},
      // In the actions CLIPS' line is right already; the slot is named from the assert.
      {"(defrule r\n"                      // 4
       "  (todo)\n"                        // 5
       "  =>\n"                            // 6
       "  (assert (colour (c BLUE))))\n",  // 7
       "c.clp:7: [CSTRNCHK1] A literal slot value found in the assert command does not match the "
       "allowed values for slot c; deftemplate colour has (slot c (type SYMBOL) (allowed-values "
       "RED GREEN)) (in defrule MAIN::r)"},
      // ... and from the pattern that bound the modified fact.
      {"(defrule r\n"                 // 4
       "  ?t <- (todo)\n"             // 5
       "  =>\n"                       // 6
       "  (modify ?t (order x)))\n",  // 7
       "c.clp:7: [CSTRNCHK1] A literal slot value found in the modify command does not match the "
       "allowed types for slot order; deftemplate todo has (slot order (type INTEGER))"},
  };
  for (const Case& c : cases) {
    CAPTURE(c.rule);
    const std::string err = load_error(std::string(kTemplates) + c.rule);
    CHECK(err.find(c.want) == 0);
  }
}

TEST_CASE("a time read that CLIPS never evaluates again is a warning with its line") {
  TimeReadCheck check;
  const auto w = check.scan(
      "(deffunction late (?t) (> (now) ?t))\n"      // 1
      "(defrule no-time\n"                          // 2
      "  (task (since ?s))\n"                       // 3
      "  (test (> (- (now) ?s) 1.0))\n"             // 4: no (time) before
      "  =>)\n"                                     // 5
      "(defrule time-after\n"                       // 6
      "  (task (since ?s))\n"                       // 7
      "  (test (late ?s))\n"                        // 8: (late) calls (now)
      "  (time ? ?)\n"                              // 9
      "  =>)\n"                                     // 10
      "(defrule in-pattern\n"                       // 11
      "  (time ? ?)\n"                              // 12
      "  (idle (until ?u&:(< ?u (now))))\n"         // 13: its own slot only
      "  =>)\n"                                     // 14
      "(defrule fine\n"                             // 15
      "  (task (since ?s))\n"                       // 16
      "  (time $?now)\n"                            // 17
      "  (test (> (now) ?s))\n"                     // 18
      "  (idle (until ?u&:(< ?u (+ ?s (now)))))\n"  // 19: joins ?s
      "  (not (idle (until ?v&:(> ?v (now)))))\n"   // 20: after (time): ok? no
      "  =>)\n"                                     // 21
      "(defrule time-in-not\n"                      // 22
      "  (not (time ? ?))\n"                        // 23
      "  (test (> (now) 3))\n"                      // 24
      "  =>)\n");                                   // 25
  REQUIRE(w.size() == 5);
  CHECK(w[0].line == 4);
  CHECK(w[0].message.find("rule no-time: (test ...) reads the time ((now)) but no (time ...) "
                          "pattern comes before it") == 0);
  CHECK(w[1].line == 8);
  CHECK(w[1].message.find("rule time-after: (test ...) reads the time ((late ...), which calls "
                          "(now))") == 0);
  CHECK(w[2].line == 13);
  CHECK(w[2].message.find("rule in-pattern: the pattern (idle ...) reads the time ((now)) in a "
                          "slot constraint") == 0);
  CHECK(w[3].line == 20);  // a not's own constraint: tested when an idle fact changes
  CHECK(w[4].line == 24);  // a (time) inside a not holds no time fact
  // The (sec usec) clock of Fawkes-style agents counts too.
  TimeReadCheck fawkes;
  const auto f =
      fawkes.scan("(defrule t (task (since $?s)) (test (timeout (now-sec-usec) ?s 1.0)) =>)\n");
  REQUIRE(f.size() == 1);
  CHECK(f[0].message.find("reads the time ((now-sec-usec))") != std::string::npos);
  // The shipped agents' way (docs/clips.md) is quiet.
  TimeReadCheck quiet;
  CHECK(quiet
            .scan("(defrule send-beacon\n"
                  "  ?t <- (timer (name beacon) (time $?last) (seq ?seq))\n"
                  "  (time $?now&:(timeout ?now ?last 1.0))\n"
                  "  =>\n"
                  "  (modify ?t (time ?now) (seq (+ ?seq 1))))\n")
            .empty());
}

TEST_CASE("the agent host logs a time-read warning when the file loads") {
  AgentFixture f;
  f.load(
      "(deftemplate task (slot since (type FLOAT)))\n"
      "(defrule stale\n"
      "  (task (since ?s))\n"
      "  (test (> (now) (+ ?s 1.0)))\n"
      "  =>)\n",
      "agent/tasks.clp");
  CHECK(
      f.logged("agent/tasks.clp:4: rule stale: (test ...) reads the time ((now)) but no (time "
               "...) pattern comes before it"));
}
