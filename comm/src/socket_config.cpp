// SPDX-License-Identifier: MIT
// SocketConfig::validate() and its YAML loader.
#include "llsf/comm/socket_config.h"

#include <boost/asio/ip/address.hpp>
#include <set>

#include "llsf/core/error.h"

namespace llsf::comm {

using core::ConfigError;
using core::ConfigNode;

namespace {

[[noreturn]] void fail(const std::string& path, const std::string& reason) {
  throw ConfigError(path + ": " + reason);
}

std::string peer_path(std::size_t i, const char* field) {
  std::string p = "udp_peers[";
  p += std::to_string(i);
  p += "].";
  p += field;
  return p;
}

}  // namespace

void SocketConfig::validate() const {
  boost::system::error_code ec;
  boost::asio::ip::make_address(address, ec);
  if (ec) fail("address", "'" + address + "' is not an IP address");
  core::require("stream.port", stream_port, core::port());
  std::set<std::string> names;
  std::set<int> ports;
  for (std::size_t i = 0; i < udp_peers.size(); ++i) {
    const UdpPeerConfig& p = udp_peers[i];
    if (p.name.empty()) fail(peer_path(i, "name"), "must not be empty");
    if (!names.insert(p.name).second) fail(peer_path(i, "name"), "'" + p.name + "' is taken");
    if (p.channel.empty()) fail(peer_path(i, "channel"), "must not be empty");
    core::require(peer_path(i, "send_port"), p.send_port, core::port());
    core::require(peer_path(i, "recv_port"), p.recv_port, core::port());
    if (p.send_port != 0 && !ports.insert(p.send_port).second) {
      fail(peer_path(i, "send_port"), std::to_string(p.send_port) + " is used by another peer");
    }
  }
  // The hub forwards to recv_port: if that is a port the hub itself listens on, a frame goes
  // round for ever (UdpHub::add_peer checks ports chosen at bind time as well).
  for (std::size_t i = 0; i < udp_peers.size(); ++i) {
    const int recv = udp_peers[i].recv_port;
    if (recv == 0) continue;
    for (std::size_t j = 0; j < udp_peers.size(); ++j) {
      if (udp_peers[j].send_port != recv) continue;
      fail(peer_path(i, "recv_port"),
           std::to_string(recv) + " is where the hub listens for " +
               (i == j ? std::string("this peer (its own send_port)")
                       : "'" + udp_peers[j].name + "' (" + peer_path(j, "send_port") + ")") +
               ": frames would be forwarded in a loop");
    }
  }
}

SocketConfig load_socket_config(const ConfigNode& node, SocketConfig base) {
  SocketConfig c = std::move(base);
  node.require_map();
  if (node.is_null()) return c;
  node.read("address", c.address);
  if (const ConfigNode s = node["stream"]; s.defined()) {
    s.require_map();
    s.read("enabled", c.stream_enabled);
    s.read("port", c.stream_port);
    s.no_other_keys();
  }
  if (const ConfigNode peers = node["udp_peers"]; peers.defined()) {
    c.udp_peers.clear();
    for (const ConfigNode& p : peers.elements()) {
      p.require_map();
      UdpPeerConfig u;
      u.name = p.at("name").as_string();
      p.read("channel", u.channel);
      p.read("send_port", u.send_port);
      p.read("recv_port", u.recv_port);
      p.no_other_keys();
      c.udp_peers.push_back(u);
    }
  }
  node.no_other_keys();
  node.locate_errors([&] { c.validate(); });
  return c;
}

}  // namespace llsf::comm
