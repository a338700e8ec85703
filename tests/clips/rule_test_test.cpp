// SPDX-License-Identifier: MIT
// Rule tests from YAML (llsf/clips/rule_test.h): a passing file, a failure with its file:line and
// context, the window of skill expectations, bad input (unknown keys with "did you mean", unknown
// message fields, a slot the template lacks, agent code that does not load).
#include <doctest/doctest.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>

#include "llsf/clips/rule_test.h"
#include "llsf/comm/registry.h"
#include "llsf/core/error.h"

using namespace llsf;
using namespace llsf::clips;

namespace {

namespace fs = std::filesystem;

constexpr const char* kAgent = R"clp(
(deftemplate job (slot place (type SYMBOL)) (slot state (type SYMBOL) (default NEW)))
(deffacts start (mode idle))
(defrule start-job
  ?j <- (job (place ?p) (state NEW))
  =>
  (modify ?j (state RUNNING))
  (skill-call drive_to place ?p))
(defrule job-done
  ?j <- (job (place ?p) (state RUNNING))
  ?s <- (skill (name "drive_to") (status FINAL))
  =>
  (retract ?s)
  (modify ?j (state DONE))
  (log-info "arrived")
  (bind ?m (pb-create "llsf_agent_msgs.LockMessage"))
  (pb-set-field ?m "type" RELEASE)
  (pb-set-field ?m "agent" (str-cat ?*ROBOT-NAME*))
  (pb-set-field ?m "resource" (str-cat ?p))
  (pb-broadcast ?m)
  (pb-destroy ?m))
(defrule heard
  ?pf <- (protobuf-msg (type "llsf_agent_msgs.LockMasterAnnounce") (ptr ?p))
  =>
  (retract ?pf)
  (assert (master (sym-cat (pb-field-value ?p "agent")))))
)clp";

/// A directory with agent.clp and the given test file.
struct Dir {
  explicit Dir(const std::string& test) {
    path = fs::temp_directory_path() /
           ("llsf-rule-test-" + std::to_string(reinterpret_cast<std::uintptr_t>(this)));
    fs::create_directories(path);
    std::ofstream(path / "agent.clp") << kAgent;
    std::ofstream(path / "a_test.yaml") << test;
  }
  ~Dir() { fs::remove_all(path); }
  std::string file() const { return (path / "a_test.yaml").string(); }
  fs::path path;
};

const comm::MessageRegistry& registry() {
  static const comm::MessageRegistry r = [] {
    comm::MessageRegistry reg;
    comm::add_agent_messages(reg);
    return reg;
  }();
  return r;
}

std::string load_error(const Dir& d) {
  try {
    RuleTestFile::load(d.file(), registry());
  } catch (const core::UserError& e) {
    return e.what();
  }
  return "";
}

std::string joined(const RuleTestResult& r) {
  std::string s;
  for (const std::string& l : r.failure) s += l + "\n";
  return s;
}

}  // namespace

TEST_CASE("rule tests: a file of passing cases") {
  const Dir d(R"yaml(
agent: agent.clp
tests:
  - name: a job drives there and reports
    given:
      - (job (place M1))
    steps:
      - step: 1
      - expect: (job (place M1) (state RUNNING))
      - expect_skill: drive_to{place="M1"}
      - expect_skill: drive_to
      - skill: FINAL
      - step: 1
      - expect: (job (state DONE))
      - expect_not: (job (state RUNNING))
      - expect_log: arrived
      - expect_sent: llsf_agent_msgs.LockMessage
        fields: {type: RELEASE, resource: M1}
        count: 1
      - expect_no_skill: true
      - expect: (mode idle)
      - expect_true: (eq ?*ROBOT-NAME* robot1)
  - name: a message from a peer
    robot: {name: robot7, number: 7}
    steps:
      - receive: LockMasterAnnounce
        fields: {agent: robot2}
        from: robot2
        from_id: 2
      - until: (master robot2)
        max: 3
      - assert: (job (place M2))
      - modify: (job (place M3))
      - step: 1
      - expect_skill: drive_to{place="M3"}
      - retract: (job)
      - expect_not: (job)
)yaml");
  const RuleTestFile f = RuleTestFile::load(d.file(), registry());
  REQUIRE(f.size() == 2);
  for (int i = 0; i < f.size(); ++i) {
    const RuleTestResult r = f.run(i);
    INFO(joined(r));
    CHECK(r.passed);
    CHECK_FALSE(r.bad_input);
  }
}

TEST_CASE("rule tests: a failure names the line, what was expected and the facts there are") {
  const Dir d(R"yaml(agent: agent.clp
tests:
  - name: wrong place
    given: ["(job (place M1))"]
    steps:
      - step: 1
      - expect: (job (place M2))
)yaml");
  const RuleTestResult r = RuleTestFile::load(d.file(), registry()).run(0);
  CHECK_FALSE(r.passed);
  CHECK_FALSE(r.bad_input);
  REQUIRE(r.failure.size() >= 2);
  CHECK(r.failure[0] == d.file() +
                            ":7: test wrong place: expected a fact (job (place M2)) but there is "
                            "none");
  CHECK(joined(r).find("(job (place M1) (state RUNNING))") != std::string::npos);
}

TEST_CASE("rule tests: a broadcast must have the given fields") {
  const Dir d(R"yaml(agent: agent.clp
tests:
  - name: wrong resource
    given: ["(job (place M1))"]
    steps:
      - step: 1
      - skill: FINAL
      - step: 1
      - expect_sent: llsf_agent_msgs.LockMessage
        fields: {resource: M2}
)yaml");
  const RuleTestResult r = RuleTestFile::load(d.file(), registry()).run(0);
  CHECK_FALSE(r.passed);
  REQUIRE_FALSE(r.failure.empty());
  CHECK(r.failure[0].find(":9: test wrong resource: expected a broadcast "
                          "llsf_agent_msgs.LockMessage {resource: \"M2\"} since the start of the "
                          "case but none of the 1 of that type matches") != std::string::npos);
  CHECK(joined(r).find("resource: \"M1\"") != std::string::npos);
}

TEST_CASE("rule tests: skill expectations look at the calls since the last step after one") {
  const Dir d(R"yaml(agent: agent.clp
tests:
  - name: window
    given: ["(job (place M1))"]
    steps:
      - step: 1
      - expect_skill: drive_to
      - step: 1
      - expect_skill: drive_to
)yaml");
  const RuleTestResult r = RuleTestFile::load(d.file(), registry()).run(0);
  CHECK_FALSE(r.passed);
  REQUIRE_FALSE(r.failure.empty());
  CHECK(r.failure[0].find(":9: test window: expected a skill call drive_to since line 8 but the "
                          "agent called no skill") != std::string::npos);
}

TEST_CASE("rule tests: a runtime error fails the case unless allowed") {
  const Dir d(R"yaml(agent: agent.clp
tests:
  - name: error
    steps:
      - eval: (no-such-function 1)
      - step: 1
  - name: allowed
    allow_runtime_errors: true
    steps:
      - eval: (no-such-function 1)
)yaml");
  const RuleTestFile f = RuleTestFile::load(d.file(), registry());
  const RuleTestResult r = f.run(0);
  CHECK_FALSE(r.passed);
  CHECK(joined(r).find("expected no runtime errors") != std::string::npos);
  CHECK(f.run(1).passed);
}

TEST_CASE("rule tests: bad input") {
  SUBCASE("a misspelt action, with did you mean") {
    const Dir d("agent: agent.clp\ntests:\n  - name: x\n    steps:\n      - expct: (a)\n");
    const std::string e = load_error(d);
    CHECK(e.find("a_test.yaml:5:") != std::string::npos);
    CHECK(e.find("unknown key 'expct' (did you mean 'expect'?)") != std::string::npos);
  }
  SUBCASE("a misspelt case key") {
    const Dir d("agent: agent.clp\ntests:\n  - name: x\n    step:\n      - step: 1\n");
    CHECK(load_error(d).find("did you mean 'steps'?") != std::string::npos);
  }
  SUBCASE("two actions in one step") {
    const Dir d(
        "agent: agent.clp\ntests:\n  - name: x\n    steps:\n      - {step: 1, expect: (a)}\n");
    CHECK(load_error(d).find("one action per step") != std::string::npos);
  }
  SUBCASE("an unknown message field and type") {
    const Dir d(
        "agent: agent.clp\ntests:\n  - name: x\n    steps:\n      - receive: LockMessage\n"
        "        fields: {resorce: M1}\n");
    CHECK(load_error(d).find("a_test.yaml:6:") != std::string::npos);
    CHECK(load_error(d).find("has no field 'resorce' (did you mean 'resource'?)") !=
          std::string::npos);
    const Dir t("agent: agent.clp\ntests:\n  - name: x\n    steps:\n      - receive: LockMesage\n");
    CHECK(load_error(t).find("unknown message type 'LockMesage'") != std::string::npos);
  }
  SUBCASE("an enum value") {
    const Dir d(
        "agent: agent.clp\ntests:\n  - name: x\n    steps:\n      - receive: LockMessage\n"
        "        fields: {type: TAKE}\n");
    CHECK(load_error(d).find("unknown value 'TAKE'") != std::string::npos);
  }
  SUBCASE("not a pattern") {
    const Dir d("agent: agent.clp\ntests:\n  - name: x\n    steps:\n      - expect: job M1\n");
    CHECK(load_error(d).find("not a fact pattern") != std::string::npos);
  }
  SUBCASE("an agent that does not load names its file and line") {
    const Dir d("agent: missing.clp\ntests:\n  - name: x\n    steps:\n      - step: 1\n");
    CHECK(load_error(d).find("no such file or directory") != std::string::npos);
    std::ofstream(d.path / "bad.clp") << "(defrule x\n  (a)\n  => (foo)\n";
    std::ofstream(d.path / "b_test.yaml")
        << "agent: bad.clp\ntests:\n  - name: x\n    steps:\n      - step: 1\n";
    try {
      RuleTestFile::load((d.path / "b_test.yaml").string(), registry());
      FAIL("no error");
    } catch (const core::UserError& e) {
      CHECK(std::string(e.what()).find("the agent does not load") != std::string::npos);
      CHECK(std::string(e.what()).find("bad.clp:") != std::string::npos);
    }
  }
  SUBCASE("an error in the setup code names the test file's line") {
    const Dir d(
        "agent: agent.clp\nsetup: |\n  (deffunction ok () 1)\n  (defrule bad (a) => (foo))\n"
        "tests:\n  - name: x\n    steps:\n      - step: 1\n");
    const std::string e = load_error(d);
    CHECK(e.find("the agent does not load") != std::string::npos);
    CHECK(e.find(d.file() + ":4: ") != std::string::npos);
  }
  SUBCASE("a slot the template does not have is bad input at run time") {
    const Dir d(
        "agent: agent.clp\ntests:\n  - name: x\n    given: ['(job (place M1))']\n"
        "    steps:\n      - expect: (job (plac M1))\n");
    const RuleTestResult r = RuleTestFile::load(d.file(), registry()).run(0);
    CHECK(r.bad_input);
    CHECK(joined(r).find("has no slot 'plac' (did you mean 'place'?)") != std::string::npos);
  }
}

TEST_CASE("rule tests: test files are found by name in directories") {
  const Dir d("agent: agent.clp\ntests:\n  - name: x\n    steps:\n      - step: 1\n");
  fs::create_directories(d.path / "sub");
  std::ofstream(d.path / "sub" / "c_test.yaml") << "x";
  std::ofstream(d.path / "sub" / "notes.yaml") << "x";
  const auto files = find_rule_test_files({d.path.string()});
  REQUIRE(files.size() == 2);
  CHECK(files[0] == d.file());
  CHECK(files[1] == (d.path / "sub" / "c_test.yaml").string());
  CHECK_THROWS_AS(find_rule_test_files({(d.path / "nope").string()}), core::UserError);
}

TEST_CASE("rule tests: a failed expectation shows the runtime errors before it, without -v") {
  const Dir d(R"yaml(agent: agent.clp
tests:
  - name: error first
    given: ["(job (place M1))"]
    steps:
      - eval: (no-such-function 1)
      - step: 1
      - expect: (job (place M2))
)yaml");
  const RuleTestResult r = RuleTestFile::load(d.file(), registry()).run(0);
  CHECK_FALSE(r.passed);
  REQUIRE_FALSE(r.failure.empty());
  CHECK(r.failure[0].find(":8: test error first: expected a fact (job (place M2))") !=
        std::string::npos);
  const std::string all = joined(r);
  CHECK(all.find("the agent had 1 runtime error (a likely cause):") != std::string::npos);
  CHECK(all.find("no-such-function") != std::string::npos);
}
