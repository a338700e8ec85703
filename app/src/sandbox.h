// SPDX-License-Identifier: MIT
// A child process under limits, for the leaderboard's workers (`llsfsim hackathon serve`,
// docs/hackathon-server.md "The sandbox"): its own process group, setrlimit (address space, CPU
// seconds, file size, no core file), a wall-clock limit after which the whole group is killed,
// standard output and error captured up to a cap, no inherited descriptors, no stdin.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace llsf::app {

/// The limits of one sandboxed run.
struct SandboxLimits {
  double wall_s = 120.0;                                     ///< then SIGKILL to the group
  int cpu_s = 120;                                           ///< RLIMIT_CPU (SIGXCPU, then SIGKILL)
  std::int64_t address_space_bytes = std::int64_t{1} << 30;  ///< RLIMIT_AS
  std::int64_t file_size_bytes = std::int64_t{16} << 20;     ///< RLIMIT_FSIZE
  std::int64_t max_output_bytes = std::int64_t{1} << 20;     ///< kept of stdout and of stderr each
};

/// How a sandboxed run ended.
struct SandboxResult {
  bool started = false;    ///< false: fork or exec failed (`error` says why)
  int exit_code = -1;      ///< the exit status, -1 when killed by a signal
  int signal = 0;          ///< the signal that ended it (0: exited)
  bool timed_out = false;  ///< the wall-clock limit was reached (the group was killed)
  bool cancelled = false;  ///< cancel() returned true (the group was killed)
  std::string out;         ///< standard output (at most max_output_bytes)
  std::string err;         ///< standard error (at most max_output_bytes)
  bool out_truncated = false;
  bool err_truncated = false;
  double wall_s = 0.0;
  std::string error;
};

/// Runs `argv` (argv[0] the program's path, not searched in PATH) in directory `cwd` under
/// `limits` and waits for it. `cancel`, if given, is polled about every 50 ms: true kills the
/// group. Thread-safe (fork from any thread; the child execs at once).
SandboxResult run_sandboxed(const std::vector<std::string>& argv, const std::string& cwd,
                            const SandboxLimits& limits,
                            const std::function<bool()>& cancel = nullptr);

}  // namespace llsf::app
