// SPDX-License-Identifier: MIT
// What `llsfsim run` and `llsfsim exercise` share for watching a game as it is played: pacing
// (--speed, --realtime) and the viewer's server with a live feed (--serve, --port,
// --serve-exit).
#pragma once

#include <CLI/CLI.hpp>

#include <chrono>
#include <memory>
#include <ostream>
#include <string>

#include "server.h"

namespace llsf::app {

struct LiveOptions {
  double speed = 0.0;  ///< 0: as fast as possible; else game seconds per wall second
  bool realtime = false;
  bool serve = false;  ///< serve the viewer with the game live (server.h)
  int port = 8080;
  bool serve_exit = false;  ///< with serve: exit when the game ends instead of serving on
  /// Game seconds per wall second (0: unpaced).
  double pace() const { return realtime ? 1.0 : speed; }
};

/// Registers --speed, --realtime, --serve (described by `serve_help`), --port and --serve-exit.
void add_live_options(CLI::App& app, LiveOptions& o, const std::string& serve_help);

/// Paced play: wait(t) sleeps until t game seconds at `speed` have passed on the wall clock
/// since construction (the wall clock only paces; it never enters the game). speed <= 0: no-op.
class Pacer {
 public:
  explicit Pacer(double speed) : speed_(speed), start_(std::chrono::steady_clock::now()) {}
  void wait(double game_time_s) const;

 private:
  double speed_;
  std::chrono::steady_clock::time_point start_;
};

/// With o.serve: starts the viewer's server on `base` (port from `o`) fed by `feed`, prints
/// "llsfsim serve: URL" (and `watch_hint`'s suffix, e.g. "#/live") to `note` and returns it;
/// without: nullptr. Throws std::runtime_error if it cannot listen.
std::unique_ptr<Server> start_live_server(const LiveOptions& o, ServerOptions base, LiveFeed& feed,
                                          std::ostream& note);

/// After the game: with a server and without --serve-exit, says so on `note` and serves until
/// Ctrl-C or SIGTERM.
void serve_until_stopped(const LiveOptions& o, const std::unique_ptr<Server>& server,
                         std::ostream& note);

}  // namespace llsf::app
