// SPDX-License-Identifier: MIT
#include "batch_progress.h"

#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <iostream>
#include <ostream>
#include <utility>

namespace llsf::app {

namespace {

// Set by the SIGINT handler; a lock-free atomic may be written from a signal handler.
std::atomic<bool> g_interrupted{false};
static_assert(std::atomic<bool>::is_always_lock_free);

extern "C" void on_sigint(int) { g_interrupted.store(true); }

}  // namespace

SigintGuard::SigintGuard() {
  g_interrupted = false;
  struct sigaction sa {};
  sa.sa_handler = &on_sigint;
  sigemptyset(&sa.sa_mask);
  sa.sa_flags = SA_RESETHAND;
  installed_ = sigaction(SIGINT, &sa, &old_) == 0;
}

SigintGuard::~SigintGuard() {
  if (installed_) sigaction(SIGINT, &old_, nullptr);
}

const std::atomic<bool>& SigintGuard::interrupted() { return g_interrupted; }

std::string duration_text(double s) {
  const long t = static_cast<long>(s + 0.5);
  if (t >= 3600) return fmt::format("{}h{:02}m", t / 3600, t / 60 % 60);
  return fmt::format("{}m{:02}s", t / 60, t % 60);
}

std::string progress_bar(std::int64_t done, std::int64_t total) {
  constexpr std::int64_t kWidth = 30;
  const std::int64_t filled =
      total > 0 ? std::clamp<std::int64_t>(kWidth * done / total, 0, kWidth) : kWidth;
  return "[" + std::string(static_cast<std::size_t>(filled), '#') +
         std::string(static_cast<std::size_t>(kWidth - filled), '.') + "]";
}

BatchProgressPrinter::BatchProgressPrinter(std::string command, std::ostream& err, bool quiet)
    : command_(std::move(command)),
      err_(err),
      quiet_(quiet),
      bar_(&err == &std::cerr && isatty(STDERR_FILENO) != 0 && !quiet) {}

study::BatchHooks BatchProgressPrinter::hooks() {
  study::BatchHooks h;
  h.stop = &g_interrupted;
  h.stored = [this](const study::RunResult& r, const study::BatchProgress& p) { stored(r, p); };
  return h;
}

void BatchProgressPrinter::stored(const study::RunResult& r, const study::BatchProgress& p) {
  if (quiet_) return;
  const double eta = p.done > 0 ? p.elapsed_s / p.done * (p.to_play - p.done) : 0.0;
  if (bar_) {
    err_ << fmt::format("\r{} {}/{} runs, {} failed, {} elapsed, ETA {}   ",
                        progress_bar(p.done, p.to_play), p.done, p.to_play, p.failed,
                        duration_text(p.elapsed_s), duration_text(eta));
    if (p.done == p.to_play) err_ << "\n";
  } else {
    err_ << fmt::format("[{}/{}] {}{}seed {}: {} points, {}, result {:016x}, ETA {}\n", p.done,
                        p.to_play, r.variant, r.variant.empty() ? "" : " ", r.seed, r.points,
                        r.passed() ? "PASS" : "FAIL", r.result_hash, duration_text(eta));
  }
  if (g_interrupted && !told_) {
    err_ << (bar_ ? "\n" : "") << command_
         << ": interrupted; storing the running games (Ctrl-C again abandons them)\n";
    told_ = true;
  }
  err_.flush();
}

}  // namespace llsf::app
