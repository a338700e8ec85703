// SPDX-License-Identifier: MIT
// The `llsfsim` command line: subcommands, their options and exit codes (docs/llsfsim.md).
#pragma once

#include <iosfwd>
#include <span>
#include <string>

namespace llsf::app {

/// Exit codes of every llsfsim command.
inline constexpr int kExitOk = 0;        ///< everything held
inline constexpr int kExitFailed = 1;    ///< a skill failed / a test case failed
inline constexpr int kExitBadInput = 2;  ///< bad command line, config or skill file

/// Runs `llsfsim` with `args` (args[0] = program name), writing to `out` and `err`; returns the
/// exit code. Never throws.
int run(std::span<const std::string> args, std::ostream& out, std::ostream& err);

}  // namespace llsf::app
