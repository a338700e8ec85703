// SPDX-License-Identifier: MIT
// `llsfsim test-agent`: rule tests of CLIPS agents from YAML files (clips::RuleTestFile,
// docs/agent-tests.md), every case on a fresh agent without the world.
#include <fmt/format.h>

#include <memory>
#include <ostream>
#include <string>
#include <vector>

#include "commands.h"
#include "llsf/app/cli.h"
#include "llsf/clips/rule_test.h"
#include "llsf/comm/registry.h"
#include "llsf/core/error.h"
#include "llsf/sim/game.h"

namespace llsf::app {

namespace {

struct TestAgentOptions {
  std::vector<std::string> paths;
  std::string filter;
  bool verbose = false;
};

int test_agent(const TestAgentOptions& o, std::ostream& out, std::ostream& err) {
  const std::vector<std::string> files = clips::find_rule_test_files(o.paths);
  // The messages a game knows: the refbox's (llsf_msgs) and the agents' (llsf_agent_msgs).
  comm::MessageRegistry registry;
  sim::add_refbox_messages(registry);
  comm::add_agent_messages(registry);

  int passed = 0, failed = 0, bad = 0, skipped = 0, bad_files = 0;
  for (const std::string& path : files) {
    std::unique_ptr<clips::RuleTestFile> file;
    try {
      file = std::make_unique<clips::RuleTestFile>(clips::RuleTestFile::load(path, registry));
    } catch (const core::UserError& e) {
      err << "llsfsim test-agent: " << e.what() << "\n";
      ++bad_files;
      continue;
    }
    for (int i = 0; i < file->size(); ++i) {
      if (!o.filter.empty() && file->case_name(i).find(o.filter) == std::string::npos) {
        ++skipped;
        continue;
      }
      const clips::RuleTestResult r = file->run(i);
      out << (r.passed ? "PASS " : "FAIL ") << path << ": " << r.name << "\n";
      if (r.passed) {
        ++passed;
        continue;
      }
      r.bad_input ? ++bad : ++failed;
      for (const std::string& line : r.failure) out << "  " << line << "\n";
      if (o.verbose) {
        out << "  the agent's log (" << r.cycles << " cycles):\n";
        for (const clips::LoggedLine& l : r.log) {
          out << fmt::format("    [{:7.2f} s] {}: {}\n", l.time.seconds(),
                             clips::to_string(l.level), l.text);
        }
      }
    }
  }
  const int run = passed + failed + bad;
  out << fmt::format("{} test case{} in {} file{}: {} passed, {} failed", run, run == 1 ? "" : "s",
                     files.size(), files.size() == 1 ? "" : "s", passed, failed + bad);
  if (bad_files > 0)
    out << fmt::format(", {} file{} not loaded", bad_files, bad_files == 1 ? "" : "s");
  if (skipped > 0) out << fmt::format(" ({} left out by --filter)", skipped);
  out << "\n";
  if (bad_files > 0 || bad > 0) return kExitBadInput;
  if (run == 0 && !o.filter.empty()) {
    err << "llsfsim test-agent: no test case matches --filter '" << o.filter << "'\n";
    return kExitBadInput;
  }
  return failed > 0 ? kExitFailed : kExitOk;
}

}  // namespace

Action add_test_agent_command(CLI::App& app) {
  auto o = std::make_shared<TestAgentOptions>();
  app.add_option("paths", o->paths,
                 "Test files, or directories searched (recursively) for *_test.yaml files")
      ->required();
  app.add_option("--filter", o->filter, "Run only the test cases whose name contains TEXT");
  app.add_flag("-v,--verbose", o->verbose, "Print the agent's log of every failing case");
  app.footer(
      "Runs rule tests of CLIPS agents without the world: each test case loads the agent into a "
      "fresh CLIPS environment, asserts the given facts and plays its steps (agent cycles of "
      "100 ms, skill outcomes, messages) with its expectations (facts, skill calls, broadcasts, "
      "log lines). A failure names the file and line of the failing expectation. Format: "
      "docs/agent-tests.md.\n"
      "Exit code: 0 all test cases passed, 1 one failed, 2 bad input (a test file, the agent "
      "code, a fact CLIPS cannot parse; file:line), 3 internal error (a bug: please report it).");
  return [o](std::ostream& out, std::ostream& err) { return test_agent(*o, out, err); };
}

}  // namespace llsf::app
