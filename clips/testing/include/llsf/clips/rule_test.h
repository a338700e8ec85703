// SPDX-License-Identifier: MIT
// Rule tests without C++: a YAML file of test cases for a CLIPS agent -- given facts, steps of
// simulated time, skill outcomes and messages fed in, expected facts, skill calls, broadcasts and
// log lines -- run on AgentFixture (llsf/clips/testing.h). `llsfsim test-agent` runs them; the
// format is docs/agent-tests.md.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "llsf/clips/testing.h"

namespace llsf::comm {
class MessageRegistry;
}

namespace llsf::clips {

/// The outcome of one test case.
struct RuleTestResult {
  std::string file;  ///< the test file, as given to RuleTestFile::load()
  std::string name;  ///< the case's name
  bool passed = false;
  /// A fact, pattern or expression of the case that CLIPS could not take (bad input, exit 2).
  bool bad_input = false;
  /// The first failure, "file:line: test NAME: expected ... but ...", then context lines (the
  /// agent's facts of the expected template, the skill calls, the broadcasts, ...).
  std::vector<std::string> failure;
  std::vector<LoggedLine> log;  ///< everything the agent logged
  int cycles = 0;               ///< agent cycles the case ran
};

/// One test file, read and checked. Not copyable; movable.
class RuleTestFile {
 public:
  /// Reads `path`: YAML errors, unknown keys, unknown message types or fields throw
  /// core::ConfigError ("file:line:column: key: what"); agent code that does not load throws
  /// AgentLoadError (its file:line) prefixed with the test file's line naming the agent.
  /// `registry` (borrowed, must outlive this) knows the message types of `receive` and
  /// `expect_sent` and is the agent's registry for pb-create.
  static RuleTestFile load(const std::string& path, const comm::MessageRegistry& registry);
  ~RuleTestFile();
  RuleTestFile(RuleTestFile&&) noexcept;
  RuleTestFile& operator=(RuleTestFile&&) noexcept;
  RuleTestFile(const RuleTestFile&) = delete;
  RuleTestFile& operator=(const RuleTestFile&) = delete;

  const std::string& path() const;
  /// Number of test cases.
  int size() const;
  const std::string& case_name(int index) const;
  /// Runs case `index` on a fresh agent (the agent files loaded again).
  RuleTestResult run(int index) const;

 private:
  struct Impl;
  explicit RuleTestFile(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

/// The test files named by `paths`: a file as given, a directory's files named `*_test.yaml`
/// (searched recursively), each directory's in name order. Throws core::UserError for a path
/// that does not exist and for a directory without test files.
std::vector<std::string> find_rule_test_files(const std::vector<std::string>& paths);

}  // namespace llsf::clips
