// SPDX-License-Identifier: MIT
// The size budgets of an agent (docs/clips.md, "Budgets"): strings, multifields, CLIPS' memory,
// log lines, and CLIPS running out of memory for real (a clear word and exit code 1).
#include <doctest/doctest.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <string>

#include "llsf/clips/agent.h"
#include "llsf/clips/testing.h"

using namespace llsf;
using namespace llsf::clips;

namespace {

// One rule per attack; each fires once on (go NAME).
constexpr const char* kBombs =
    "(defrule str-double (go str-double) =>\n"
    "  (bind ?s \"xxxxxxxxxxxxxxxx\") (loop-for-count 40 (bind ?s (str-cat ?s ?s))))\n"
    "(defrule sym-double (go sym-double) =>\n"
    "  (bind ?s x) (loop-for-count 40 (bind ?s (sym-cat ?s ?s))))\n"
    "(defrule implode (go implode) =>\n"
    "  (bind ?m (create$ \"a\\\"b\")) (loop-for-count 13 (bind ?m (create$ ?m ?m)))\n"
    "  (implode$ ?m))\n"
    "(defrule format-width (go format-width) => (format nil \"%2000000000d\" 1))\n"
    "(defrule format-args (go format-args) =>\n"
    "  (bind ?s \"xxxxxxxxxxxxxxxx\") (loop-for-count 11 (bind ?s (str-cat ?s ?s)))\n"
    "  (format nil \"%s%s\" ?s ?s))\n"
    "(defrule print-big (go print-big) =>\n"
    "  (bind ?s \"xxxxxxxxxxxxxxxx\") (loop-for-count 11 (bind ?s (str-cat ?s ?s)))\n"
    "  (printout t ?s ?s crlf))\n"
    "(defrule log-big (go log-big) =>\n"
    "  (bind ?s \"xxxxxxxxxxxxxxxx\") (loop-for-count 11 (bind ?s (str-cat ?s ?s)))\n"
    "  (log-info ?s ?s))\n"
    "(defrule mf-double (go mf-double) =>\n"
    "  (bind ?m (create$ a)) (loop-for-count 40 (bind ?m (create$ ?m ?m))))\n"
    "(defrule mf-insert (go mf-insert) =>\n"
    "  (bind ?m (create$ a)) (loop-for-count 40 (bind ?m (insert$ ?m 1 ?m))))\n"
    "(defrule mf-replace (go mf-replace) =>\n"
    "  (bind ?m (create$ a b)) (loop-for-count 40 (bind ?m (replace$ ?m 1 1 ?m))))\n"
    "(defrule mf-member (go mf-member) =>\n"
    "  (bind ?m (create$ a a a a a a a a a a a a a a a a a a a a a a a a a a a a a a a a))\n"
    "  (loop-for-count 4 (bind ?m (replace-member$ ?m ?m a))))\n"
    "(defrule explode (go explode) =>\n"
    "  (bind ?s \"a \") (loop-for-count 14 (bind ?s (str-cat ?s ?s))) (explode$ ?s))\n"
    "(defrule alive (time $?) => (assert (alive)))\n";

AgentConfig small_budgets() {
  AgentConfig cfg;
  cfg.max_string_length = 40'000;
  cfg.max_multifield_length = 10'000;
  return cfg;
}

// Fires the rule NAME in a fresh cycle; returns the cycle's result.
CycleResult fire(AgentFixture& f, const std::string& name) {
  f.assert_fact("(go " + name + ")");
  return f.step();
}

}  // namespace

TEST_CASE("the string budget stops str-cat, sym-cat, implode$, format, printout and log-*") {
  AgentFixture f(small_budgets());
  f.load(kBombs, "bombs.clp");
  f.step();
  struct Case {
    const char* rule;
    int line;
    const char* message;
  };
  const Case cases[] = {
      {"str-double", 1,
       "[LLSF1] str-cat: the result would have up to 65536 characters, more than the string "
       "budget of 40000 (max_string_length); the game goes on"},
      {"sym-double", 3, "[LLSF1] sym-cat: the result would have up to 65536 characters"},
      {"implode", 5, "[LLSF1] implode$: the result would have up to 73730 characters"},
      {"format-width", 8, "[LLSF1] format: the result would have up to 2000000"},
      {"format-args", 9, "[LLSF1] format: the result would have up to 65540 characters"},
      {"print-big", 12,
       "[LLSF1] printout: would print up to 65536 characters, more than the string budget of "
       "40000 (max_string_length); the game goes on"},
      {"log-big", 15, "[LLSF1] log-info: the result would have up to 65536 characters"},
  };
  for (const Case& c : cases) {
    CAPTURE(c.rule);
    const CycleResult r = fire(f, c.rule);
    CHECK(r.runtime_errors == 1);
    CHECK(f.logged("runtime error in rule " + std::string(c.rule) +
                   " (bombs.clp:" + std::to_string(c.line) + "): " + c.message));
  }
  // printout printed its first piece (within budget) before the second was refused: CLIPS'
  // own printout, piece by piece.
  CHECK(f.logged(std::string(32768, 'x')));
  CHECK_FALSE(f.logged(std::string(32769, 'x')));
  // The game goes on: the next cycle runs.
  CHECK(f.step().runtime_errors == 0);
  CHECK(f.has("(alive)"));
}

TEST_CASE("the multifield budget stops create$, insert$, replace$, replace-member$, explode$") {
  AgentFixture f(small_budgets());
  f.load(kBombs, "bombs.clp");
  f.step();
  const std::pair<const char*, const char*> cases[] = {
      {"mf-double",
       "runtime error in rule mf-double (bombs.clp:18): [LLSF1] create$: the result would have up "
       "to 16384 fields, more than the multifield budget of 10000 (max_multifield_length); the "
       "game goes on"},
      {"mf-insert", "[LLSF1] insert$: the result would have up to 16385 fields"},
      {"mf-replace", "[LLSF1] replace$: the result would have up to 16388 fields"},
      {"mf-member", "[LLSF1] replace-member$: the result would have up to 1048576 fields"},
      {"explode", "[LLSF1] explode$: the result would have up to 16385 fields"},
  };
  for (const auto& c : cases) {
    const std::string rule = c.first;
    CAPTURE(rule);
    CHECK(fire(f, rule).runtime_errors == 1);
    CHECK(f.logged(c.second));
  }
}

TEST_CASE("within the budgets the guarded functions give CLIPS' own results, in CLIPS' order") {
  AgentConfig cfg = small_budgets();
  cfg.max_string_length = 80;  // these all stay within it
  AgentFixture f(cfg);
  f.load(
      "(deffunction noisy (?x) (printout t \"<\" ?x \">\") ?x)\n"
      "(defrule show (time $?) (not (shown)) =>\n"
      "  (assert (shown))\n"
      "  (printout t \"a\" (noisy b) \"c\" 1.5 (create$ d e) crlf)\n"
      "  (assert (r (str-cat x 1 2.5) (sym-cat a \"b\") (implode$ (create$ a \"q\" 3))\n"
      "             (length$ (create$ (create$ 1 2) 3 (create$))) (explode$ \"a b\")\n"
      "             (insert$ (create$ a c) 2 b) (replace$ (create$ a b c) 2 2 x)\n"
      "             (format nil \"%d-%s\" 7 ab))))\n"
      "(defrule over (time $?) (shown) (not (over)) => (assert (over)) \n"
      "  (str-cat \"0123456789012345678901234567890123456789\"\n"
      "           \"01234567890123456789012345678901234567890\"))\n");
  CHECK(f.step().runtime_errors == 1);  // the rule over, below
  // The deffunction's output comes between "a" and "c" (printout prints each argument in turn).
  CHECK(f.logged("a<b>bc1.5(d e)"));
  CHECK(f.has("(r \"x12.5\" ab \"a \\\"q\\\" 3\" 3 a b a b c a x c \"7-ab\")"));
  // And one past the budget is refused.
  CHECK(f.logged(
      "str-cat: the result would have up to 81 characters, more than the string budget of 80"));
}

TEST_CASE("the memory budget stops an agent whose facts pile up; the game goes on") {
  AgentConfig cfg;
  cfg.max_memory_bytes = 16LL << 20;
  AgentFixture f(cfg);
  f.load(
      "(defrule flood (flood) => (loop-for-count (?i 1 500000) (assert (x ?i))))\n"
      "(defrule alive (time $?) => (assert (alive)))\n",
      "flood.clp");
  f.step();
  CHECK(f.agent().runtime_errors() == 0);
  f.assert_fact("(flood)");
  const CycleResult r = f.step();
  CHECK(r.budget_exceeded);
  CHECK(f.logged("runtime error in rule flood (flood.clp:1): stopped at "));
  CHECK(
      f.logged("bytes of CLIPS memory, more than the memory budget of 16777216 bytes "
               "(max_memory_bytes; facts piling up?); the game goes on"));
  CHECK(f.facts("x").size() < 500'000);
}

TEST_CASE("output without a newline is logged in lines of at most max_string_length") {
  AgentConfig cfg;
  cfg.max_string_length = 1'000;
  AgentFixture f(cfg);
  f.load("(defrule chatter (time $?) => (loop-for-count 300 (printout t \"0123456789\")))\n");
  f.step();
  std::size_t lines = 0;
  for (const auto& l : f.log()) {
    CHECK(l.text.size() <= 1'000);
    if (l.text.find("0123456789") != std::string::npos) ++lines;
  }
  CHECK(lines == 3);
}

TEST_CASE("CLIPS out of memory for real: a clear message and exit code 1") {
  // In a child process with a small address space and the budgets lifted; stderr into a pipe.
  int pipe_fds[2];
  REQUIRE(::pipe(pipe_fds) == 0);
  const pid_t pid = ::fork();
  REQUIRE(pid >= 0);
  if (pid == 0) {
    ::dup2(pipe_fds[1], 2);
    ::close(pipe_fds[0]);
    AgentConfig cfg;
    cfg.max_memory_bytes = 1LL << 40;
    cfg.max_string_length = 1LL << 40;
    AgentFixture f(cfg);
    f.load(
        "(defrule grow (time $?) =>\n"
        "  (bind ?s \"xxxxxxxxxxxxxxxx\") (loop-for-count 26 (bind ?s (str-cat ?s ?s))))\n");
    rlimit limit{};
    ::getrlimit(RLIMIT_AS, &limit);
    limit.rlim_cur = 256ULL << 20;  // the 1 GB string does not fit; the rest does
    // Leave room for what is mapped already.
    if (FILE* status = std::fopen("/proc/self/statm", "r")) {
      unsigned long pages = 0;
      if (std::fscanf(status, "%lu", &pages) == 1)
        limit.rlim_cur += pages * static_cast<unsigned long>(::sysconf(_SC_PAGESIZE));
      std::fclose(status);
    }
    ::setrlimit(RLIMIT_AS, &limit);
    f.step();
    std::_Exit(0);
  }
  ::close(pipe_fds[1]);
  std::string err;
  char buf[512];
  ssize_t n = 0;
  while ((n = ::read(pipe_fds[0], buf, sizeof buf)) > 0) err.append(buf, static_cast<size_t>(n));
  ::close(pipe_fds[0]);
  int status = 0;
  REQUIRE(::waitpid(pid, &status, 0) == pid);
  REQUIRE(WIFEXITED(status));
  CHECK(WEXITSTATUS(status) == 1);
  CHECK(err.find("llsfsim: fatal: out of memory: CLIPS could not allocate ") == 0);
  CHECK(err.find("exiting with code 1: the run fails") != std::string::npos);
}

TEST_CASE("printout to a logical name no router takes reports it once, as CLIPS does") {
  AgentFixture f;
  f.load("(defrule badname (time $?) => (printout nosuch \"a\" \"b\" \"c\"))\n", "name.clp");
  CHECK(f.step().runtime_errors == 1);
  int reports = 0;
  for (const auto& l : f.log()) {
    for (std::size_t at = l.text.find("[ROUTER1]"); at != std::string::npos;
         at = l.text.find("[ROUTER1]", at + 1))
      ++reports;
  }
  CHECK(reports == 1);
  CHECK(f.logged("runtime error in rule badname (name.clp:1): [ROUTER1] Logical name nosuch"));
}

TEST_CASE("subsetp, member$ and delete-member$ are bounded in their comparisons") {
  // 2,000 x 2,000 fields = 4,000,000 comparisons, more than 100 x the multifield budget of 10,000;
  // with 1,000,000-field multifields (10^12 comparisons) one call ran for many minutes.
  AgentFixture f(small_budgets());
  f.load(
      "(deffunction seq (?n) (bind ?r (create$))\n"
      "  (loop-for-count (?i 1 ?n) (bind ?r (create$ ?r ?i))) ?r)\n"
      "(defrule subset-big (go subset-big) => (subsetp (seq 2000) (seq 2000)))\n"
      "(defrule member-big (go member-big) => (member$ (seq 2000) (seq 2000)))\n"
      "(defrule delete-big (go delete-big) => (delete-member$ (seq 2000) (seq 1000) (seq 1000)))\n"
      "(defrule small (go small) =>\n"
      "  (printout t (subsetp (seq 500) (seq 600)) \" \" (member$ 7 (seq 900)) \" \"\n"
      "    (length$ (delete-member$ (seq 900) (seq 100))) crlf))\n",
      "compare.clp");
  f.step();
  CHECK(fire(f, "subset-big").runtime_errors == 1);
  CHECK(
      f.logged("runtime error in rule subset-big (compare.clp:3): [LLSF1] subsetp: up to "
               "4000000 field comparisons, more than 1000000 (100 x max_multifield_length); the "
               "game goes on"));
  CHECK(fire(f, "member-big").runtime_errors == 1);
  CHECK(f.logged("[LLSF1] member$: up to 4000000 field comparisons"));
  CHECK(fire(f, "delete-big").runtime_errors == 1);
  CHECK(f.logged("[LLSF1] delete-member$: up to 4000000 field comparisons"));
  // Within the bound: CLIPS' own results.
  CHECK(fire(f, "small").runtime_errors == 0);
  CHECK(f.logged("TRUE 7 800"));
}
