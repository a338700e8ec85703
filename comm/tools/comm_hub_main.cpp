// SPDX-License-Identifier: MIT
// llsf-comm-hub: the radio as a stand-alone UDP hub on loopback, so that agents and LLSF tools in
// other processes can talk through the loss, delay and outage models (docs/comm.md). Prints each
// peer's ports at start and the counters (JSON) at the end.
#include <CLI/CLI.hpp>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <exception>

#include "llsf/comm/hub_config.h"
#include "llsf/comm/socket_config.h"
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
    llsf::comm::add_agent_messages(registry);
    llsf::comm::UdpHub hub(hub_cfg, registry, llsf::core::Rng(seed),
                           llsf::comm::UdpHubOptions{sock_cfg.address});
    for (const auto& p : sock_cfg.udp_peers) {
      const auto id = hub.add_peer(p);
      std::printf("peer %-12s channel %-8s hub listens on %s:%d, sends to port %s\n",
                  p.name.c_str(), p.channel.c_str(), sock_cfg.address.c_str(), hub.listen_port(id),
                  p.recv_port ? std::to_string(p.recv_port).c_str() : "(learnt)");
    }
    std::fflush(stdout);

    std::signal(SIGINT, on_signal);
    std::signal(SIGTERM, on_signal);
    const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
    while (!g_stop && (seconds <= 0.0 || std::chrono::steady_clock::now() < end)) {
      hub.run_for(std::chrono::milliseconds(100));
    }
    std::printf("%s\n", hub.hub().counters_json().c_str());
    return 0;
  } catch (const llsf::core::ConfigError& e) {
    std::fprintf(stderr, "llsf-comm-hub: %s\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "llsf-comm-hub: %s\n", e.what());
    return 1;
  }
}
