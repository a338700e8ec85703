// SPDX-License-Identifier: MIT
// llsf-comm-hub: the radio as a stand-alone UDP hub on loopback, so that agents and LLSF tools in
// other processes can talk through the loss, delay and outage models (docs/comm.md). Prints each
// peer's ports at start and the counters (JSON) at the end. With --stream-port it also runs the
// refbox's TCP stream server (the messages it receives are counted, not routed).
#include <CLI/CLI.hpp>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <exception>
#include <memory>

#include "llsf/comm/hub_config.h"
#include "llsf/comm/socket_config.h"
#include "llsf/comm/stream.h"
#include "llsf/comm/udp_hub.h"
#include "llsf/core/config.h"
#include "llsf/core/error.h"

namespace {
volatile std::sig_atomic_t g_stop = 0;
void on_signal(int) { g_stop = 1; }
}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"llsf-comm-hub: a UDP comm hub on loopback with loss, delay and outages"};
  std::string hub_file, sockets_file;
  std::uint64_t seed = 1;
  double seconds = 0.0;
  app.add_option("--config", hub_file, "hub config YAML (loss, delay, links, outages)");
  app.add_option("--sockets", sockets_file, "socket config YAML (address, udp_peers)")->required();
  app.add_option("--seed", seed, "seed of the loss/delay streams")->capture_default_str();
  app.add_option("--seconds", seconds, "run time in seconds (0: until Ctrl-C)")
      ->capture_default_str();
  int stream_port = -1;
  llsf::comm::StreamServerOptions stream_opts;
  int partial_timeout_ms = static_cast<int>(stream_opts.partial_frame_timeout.count());
  app.add_option("--stream-port", stream_port,
                 "also run the TCP stream server on this port (0: any free port; -1: none)")
      ->capture_default_str()
      ->check(CLI::Range(-1, 65535));
  app.add_option("--stream-max-connections", stream_opts.max_connections,
                 "stream server: connections open at once")
      ->capture_default_str()
      ->check(CLI::Range(1, 100000));
  app.add_option("--stream-max-payload", stream_opts.max_payload,
                 "stream server: largest payload size a frame may announce, bytes")
      ->capture_default_str()
      ->check(CLI::Range(std::int64_t{0}, std::int64_t{0xffffffff}));
  app.add_option("--stream-partial-timeout-ms", partial_timeout_ms,
                 "stream server: a frame incomplete this long closes its connection")
      ->capture_default_str()
      ->check(CLI::Range(1, 3600000));
  CLI11_PARSE(app, argc, argv);

  try {
    // Relay what this build cannot parse (e.g. the refbox's llsf_msgs) unless the config says
    // forward_unregistered: false.
    llsf::comm::HubConfig hub_cfg;
    hub_cfg.forward_unregistered = true;
    if (!hub_file.empty()) {
      hub_cfg = llsf::comm::load_hub_config(llsf::core::ConfigNode::load_file(hub_file), hub_cfg);
    }
    const llsf::comm::SocketConfig sock_cfg =
        llsf::comm::load_socket_config(llsf::core::ConfigNode::load_file(sockets_file));
    std::vector<std::string> names;
    for (const auto& p : sock_cfg.udp_peers) names.push_back(p.name);
    try {
      hub_cfg.validate_peer_names(names);
    } catch (const llsf::core::ConfigError& e) {
      throw llsf::core::ConfigError(hub_file + ": " + e.what() + " (peers come from " +
                                    sockets_file + ")");
    }

    llsf::comm::MessageRegistry registry;
    llsf::comm::add_agent_messages(registry, hub_cfg.lock_messages);
    llsf::comm::UdpHub hub(hub_cfg, registry, llsf::core::Rng(seed),
                           llsf::comm::UdpHubOptions{sock_cfg.address});
    for (const auto& p : sock_cfg.udp_peers) {
      const auto id = hub.add_peer(p);
      std::printf("peer %-12s channel %-8s hub listens on %s:%d, sends to port %s\n",
                  p.name.c_str(), p.channel.c_str(), sock_cfg.address.c_str(), hub.listen_port(id),
                  p.recv_port ? std::to_string(p.recv_port).c_str() : "(learnt)");
    }
    std::unique_ptr<llsf::comm::StreamServer> stream;
    std::int64_t stream_messages = 0;
    if (stream_port >= 0) {
      stream_opts.address = sock_cfg.address;
      stream_opts.port = stream_port;
      stream_opts.partial_frame_timeout = std::chrono::milliseconds(partial_timeout_ms);
      stream = std::make_unique<llsf::comm::StreamServer>(registry, stream_opts);
      std::printf("stream server listens on %s:%d\n", sock_cfg.address.c_str(), stream->port());
    }
    std::fflush(stdout);

    std::signal(SIGINT, on_signal);
    std::signal(SIGTERM, on_signal);
    const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
    while (!g_stop && (seconds <= 0.0 || std::chrono::steady_clock::now() < end)) {
      if (!stream) {
        hub.run_for(std::chrono::milliseconds(100));
        continue;
      }
      hub.run_for(std::chrono::milliseconds(5));
      stream->run_for(std::chrono::milliseconds(5));
      for (const auto& e : stream->take_events()) {
        if (e.kind == llsf::comm::StreamEvent::Kind::kMessage) ++stream_messages;
      }
    }
    std::printf("%s\n", hub.hub().counters_json().c_str());
    if (stream) {
      std::printf("stream server: %lld messages received, %lld connections refused\n",
                  static_cast<long long>(stream_messages),
                  static_cast<long long>(stream->refused_count()));
    }
    return 0;
  } catch (const llsf::core::ConfigError& e) {
    std::fprintf(stderr, "llsf-comm-hub: %s\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "llsf-comm-hub: %s\n", e.what());
    return 1;
  }
}
