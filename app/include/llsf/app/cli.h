// SPDX-License-Identifier: MIT
// The `llsfsim` command line: subcommands, their options and exit codes (docs/llsfsim.md).
#pragma once

#include <iosfwd>
#include <span>
#include <string>

namespace llsf::app {

/// Exit codes of every llsfsim command (and 130: a batch, experiment or exercise sweep
/// interrupted by Ctrl-C).
inline constexpr int kExitOk = 0;             ///< everything held
inline constexpr int kExitFailed = 1;         ///< a skill failed / a test case failed
inline constexpr int kExitBadInput = 2;       ///< the user's error (core::UserError, CLI11)
inline constexpr int kExitInternalError = 3;  ///< a bug in llsfsim: any other exception

/// Runs `llsfsim` with `args` (args[0] = program name), writing to `out` and `err`; returns the
/// exit code. Never throws.
int run(std::span<const std::string> args, std::ostream& out, std::ostream& err);

}  // namespace llsf::app
