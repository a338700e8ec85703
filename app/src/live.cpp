// SPDX-License-Identifier: MIT
#include "live.h"

#include <thread>

#include "cli_checks.h"

namespace llsf::app {

void add_live_options(CLI::App& app, LiveOptions& o, const std::string& serve_help) {
  auto* speed = app.add_option("--speed", o.speed,
                               "Paced: play X game seconds per wall-clock second (e.g. 4)")
                    ->check(kPositive);
  app.add_flag("--realtime", o.realtime, "Paced at real time (= --speed 1)")->excludes(speed);
  auto* serve = app.add_flag("--serve", o.serve, serve_help);
  app.add_option("--port", o.port, "With --serve: the port (0: any free port)")
      ->capture_default_str()
      ->check(CLI::Range(0, 65535))
      ->needs(serve);
  app.add_flag("--serve-exit", o.serve_exit,
               "With --serve: exit when the game ends (default: serve on until Ctrl-C)")
      ->needs(serve);
}

void Pacer::wait(double game_time_s) const {
  if (speed_ <= 0.0) return;
  std::this_thread::sleep_until(start_ +
                                std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                    std::chrono::duration<double>(game_time_s / speed_)));
}

std::unique_ptr<Server> start_live_server(const LiveOptions& o, ServerOptions base, LiveFeed& feed,
                                          std::ostream& note) {
  if (!o.serve) return nullptr;
  base.port = o.port;
  auto server = std::make_unique<Server>(base, &feed);
  server->start();
  note << "llsfsim serve: " << server->url() << "  (watch: " << server->url() << "#/live)"
       << std::endl;
  return server;
}

void serve_until_stopped(const LiveOptions& o, const std::unique_ptr<Server>& server,
                         std::ostream& note) {
  if (!server || o.serve_exit) return;
  note << "game over; serving until Ctrl-C" << std::endl;
  wait_for_stop_signal();
}

}  // namespace llsf::app
