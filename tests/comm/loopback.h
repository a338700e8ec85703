// SPDX-License-Identifier: MIT
// Test helpers for the socket tests on 127.0.0.1 (socket_test.cpp, limits_test.cpp): the agent
// messages' registry, a lock message, and an external program's UDP socket.
#pragma once

#include <llsf_agent_msgs/LockMessage.pb.h>

#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/udp.hpp>
#include <cstdint>
#include <string>
#include <vector>

#include "llsf/comm/registry.h"

namespace llsf::comm::test {

inline const boost::asio::ip::address kLoopback = boost::asio::ip::make_address("127.0.0.1");

inline MessageRegistry registry() {
  MessageRegistry r;
  add_agent_messages(r);
  return r;
}

/// A lock request of robot R1 for machine M<n>.
inline llsf_agent_msgs::LockMessage lock(int n) {
  llsf_agent_msgs::LockMessage m;
  m.set_type(llsf_agent_msgs::LockMessage::GET);
  m.set_agent("R1");
  m.set_resource("M" + std::to_string(n));
  return m;
}

/// An external program's UDP socket on 127.0.0.1 (non-blocking receive).
struct Endpoint {
  explicit Endpoint(boost::asio::io_context& io)
      : socket(io, boost::asio::ip::udp::endpoint(kLoopback, 0)) {
    socket.non_blocking(true);
  }
  int port() const { return socket.local_endpoint().port(); }
  void send(const std::vector<std::uint8_t>& frame, int to_port) {
    socket.send_to(boost::asio::buffer(frame),
                   boost::asio::ip::udp::endpoint(kLoopback, static_cast<unsigned short>(to_port)));
  }
  /// All datagrams waiting now.
  std::vector<std::vector<std::uint8_t>> drain() {
    std::vector<std::vector<std::uint8_t>> out;
    for (;;) {
      std::vector<std::uint8_t> buf(2048);
      boost::asio::ip::udp::endpoint from;
      boost::system::error_code ec;
      const std::size_t n = socket.receive_from(boost::asio::buffer(buf), from, 0, ec);
      if (ec) break;
      buf.resize(n);
      out.push_back(std::move(buf));
    }
    return out;
  }
  boost::asio::ip::udp::socket socket;
};

}  // namespace llsf::comm::test
