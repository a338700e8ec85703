// SPDX-License-Identifier: MIT
// Playing batches from a command (`llsfsim batch`, `llsfsim experiment`): Ctrl-C handling and
// the progress output -- a bar on a terminal, otherwise one line per stored run.
#pragma once

#include <atomic>
#include <csignal>
#include <cstdint>
#include <iosfwd>
#include <string>

#include "llsf/study/batch.h"

namespace llsf::app {

/// Exit code of a command stopped by Ctrl-C (128 + SIGINT, the shell's convention).
inline constexpr int kExitInterrupted = 130;

/// Catches SIGINT for its lifetime: the first Ctrl-C sets interrupted() (no new game starts, the
/// running ones finish and are stored); SA_RESETHAND gives a second Ctrl-C the default action,
/// which ends the process at once (SQLite rolls back the run being written). One at a time.
class SigintGuard {
 public:
  SigintGuard();
  ~SigintGuard();
  SigintGuard(const SigintGuard&) = delete;
  SigintGuard& operator=(const SigintGuard&) = delete;

  /// Set by the first Ctrl-C since the guard was made.
  static const std::atomic<bool>& interrupted();

 private:
  struct sigaction old_ {};
  bool installed_ = false;
};

/// "1m05s", "2h03m": a wall-clock duration for progress lines.
std::string duration_text(double s);

/// "[#########.....................]": `done` of `total` as a bar of 30 characters.
std::string progress_bar(std::int64_t done, std::int64_t total);

/// Prints the progress of run_batch on `err` for the command `command` ("llsfsim batch"): a bar
/// when `err` is std::cerr on a terminal, else one line per stored run; says once that Ctrl-C
/// was pressed. Nothing with `quiet`.
class BatchProgressPrinter {
 public:
  BatchProgressPrinter(std::string command, std::ostream& err, bool quiet);

  /// Hooks for run_batch: the progress output and SigintGuard::interrupted() as the stop flag.
  /// The printer must outlive the batch.
  study::BatchHooks hooks();
  /// True if a bar is drawn (a line ended by "\r": end it before other output).
  bool bar() const { return bar_; }

 private:
  void stored(const study::RunResult& r, const study::BatchProgress& p);

  std::string command_;
  std::ostream& err_;
  bool quiet_;
  bool bar_;
  bool told_ = false;
};

}  // namespace llsf::app
