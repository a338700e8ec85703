// SPDX-License-Identifier: MIT
// `llsfsim serve`: the browser viewer's server over the statistics store and the recordings,
// until SIGINT or SIGTERM.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <memory>
#include <ostream>
#include <stdexcept>
#include <string>

#include "commands.h"
#include "llsf/app/cli.h"
#include "llsf/core/error.h"
#include "llsf/study/stats_store.h"
#include "server.h"

namespace llsf::app {

Action add_serve_command(CLI::App& app) {
  auto o = std::make_shared<ServerOptions>();
  o->db = std::string(study::StatsStore::kDefaultPath);
  app.add_option("--bind", o->bind, "Address to listen on")->capture_default_str();
  app.add_option("--port", o->port, "Port to listen on (0: any free port)")
      ->capture_default_str()
      ->check(CLI::Range(0, 65535));
  app.add_option("--db", o->db,
                 "Statistics store whose batches are served: a SQLite file or a "
                 "postgresql://USER@HOST:PORT/DB URL (docs/statistics.md)")
      ->capture_default_str();
  app.add_option("--recordings", o->recordings,
                 "Recordings served below /api/recordings/ (default: <db>-recordings beside "
                 "the --db file; <database>-recordings in the working directory for a URL)");
  app.add_option("--viewer", o->viewer,
                 "The built viewer (default: $LLSF_VIEWER_DIR, else viewer/dist of the data "
                 "directory; `make viewer`)");
  app.add_option("--max-connections", o->max_connections,
                 "HTTP connections open at once; more are closed at once (logged)")
      ->capture_default_str()
      ->check(CLI::Range(1, 1000000));
  app.add_option("--max-websockets", o->max_websocket_clients,
                 "live WebSocket clients at once; more get 503 (logged)")
      ->capture_default_str()
      ->check(CLI::Range(0, 1000000));
  auto request_timeout_s =
      std::make_shared<double>(std::chrono::duration<double>(o->request_timeout).count());
  app.add_option("--request-timeout", *request_timeout_s,
                 "seconds a request may take to arrive in full (and a keep-alive connection to "
                 "wait for the next one)")
      ->capture_default_str()
      ->check(CLI::Range(0.001, 3600.0));
  app.footer(
      "Serves the browser viewer, the stored batches, runs and reports as JSON and the "
      "recordings as JSON lines (docs/llsfsim.md). Prints 'llsfsim serve: URL' and runs until "
      "Ctrl-C or SIGTERM.\n"
      "Exit code: 0 stopped, 2 cannot listen (bad address or port, port in use) or cannot open "
      "a --db URL's database, 3 internal error (a bug: please report it).");
  return [o, request_timeout_s](std::ostream& out, std::ostream& err) {
    o->request_timeout = std::chrono::milliseconds(
        std::max<std::int64_t>(1, std::llround(*request_timeout_s * 1000.0)));
    std::unique_ptr<Server> server;
    try {
      server = std::make_unique<Server>(*o);
    } catch (const core::UserError& e) {  // cannot listen, cannot open the database
      err << "llsfsim serve: " << e.what() << "\n";
      return kExitBadInput;
    }
    server->start();
    out << "llsfsim serve: " << server->url() << std::endl;
    wait_for_stop_signal();
    server->stop();
    return kExitOk;
  };
}

}  // namespace llsf::app
