// SPDX-License-Identifier: MIT
// HubConfig: validate() names the field; the YAML loader names file, line and field.
#include <doctest/doctest.h>

#include <string>

#include "llsf/comm/hub_config.h"
#include "llsf/core/error.h"

using namespace llsf::comm;
using llsf::core::ConfigError;
using llsf::core::ConfigNode;

namespace {

HubConfig parse(const std::string& yaml) {
  return load_hub_config(ConfigNode::parse(yaml, "hub.yaml"));
}

std::string error_of(const std::string& yaml) {
  try {
    parse(yaml);
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "(no error)";
}

bool contains(const std::string& s, const std::string& part) {
  return s.find(part) != std::string::npos;
}

}  // namespace

TEST_CASE("defaults are valid: no loss, 2 ms delay, 1024-byte frames") {
  const HubConfig c;
  CHECK_NOTHROW(c.validate());
  CHECK(c.loss_model == LossModel::kNone);
  CHECK(c.delay.fixed == SimTime::from_ms(2));
  CHECK(c.max_frame_bytes == 1024);
  const HubConfig empty = parse("");
  CHECK(empty.loss_model == LossModel::kNone);
}

TEST_CASE("a full config loads") {
  const HubConfig c = parse(R"(
loss:
  model: burst
  probability: 0.2
  mean_burst_length: 6
delay:
  fixed_ms: 3
  jitter_ms: 4.5
max_frame_bytes: 2048
forward_unregistered: true
links:
  - {from: robot1, to: refbox, loss_probability: 0.4, fixed_ms: 10}
  - {from: robot2, to: robot3, symmetric: false, jitter_ms: 0}
outages:
  - {peer: robot2, from_s: 60, until_s: 90.5}
  - {peer: robot1, other: refbox, from_s: 0, until_s: 1}
)");
  CHECK(c.loss_model == LossModel::kBurst);
  CHECK(c.loss_probability == 0.2);
  CHECK(c.mean_burst_length == 6.0);
  CHECK(c.delay.fixed == SimTime::from_ms(3));
  CHECK(c.delay.jitter == SimTime::from_us(4500));
  CHECK(c.max_frame_bytes == 2048);
  CHECK(c.forward_unregistered);
  REQUIRE(c.links.size() == 2);
  CHECK(c.links[0].from == "robot1");
  CHECK(c.links[0].to == "refbox");
  CHECK(c.links[0].symmetric);
  CHECK(c.links[0].loss_probability == 0.4);
  CHECK(c.links[0].delay_fixed == SimTime::from_ms(10));
  CHECK_FALSE(c.links[0].delay_jitter);
  CHECK_FALSE(c.links[1].symmetric);
  CHECK_FALSE(c.links[1].loss_probability);
  CHECK(c.links[1].delay_jitter == SimTime::from_ms(0));
  REQUIRE(c.outages.size() == 2);
  CHECK(c.outages[0].peer == "robot2");
  CHECK(c.outages[0].other.empty());
  CHECK(c.outages[0].from == SimTime::from_sec(60));
  CHECK(c.outages[0].until == SimTime::from_ms(90500));
  CHECK(c.outages[1].other == "refbox");
  CHECK_NOTHROW(c.validate_peer_names({"robot1", "robot2", "robot3", "refbox"}));
  CHECK_THROWS_WITH_AS(c.validate_peer_names({"robot1", "robot2", "robot3"}),
                       "links[0].to: no peer is called 'refbox'", ConfigError);
}

TEST_CASE("bad input names file, line and field") {
  CHECK(error_of("loss:\n  model: lossy\n") ==
        "hub.yaml:2:10: loss.model: unknown loss model 'lossy' (expected none, global, per_link "
        "or burst)");
  CHECK(contains(error_of("loss:\n  model: global\n  probability: 1.5\n"),
                 "hub.yaml:3:16: loss.probability: must be in [0, 1]"));
  CHECK(contains(error_of("loss:\n  probabilty: 0.1\n"), "hub.yaml:2:"));
  CHECK(contains(error_of("loss:\n  probabilty: 0.1\n"), "probabilty"));
  CHECK(contains(error_of("loss:\n  model: burst\n  probability: 0.9\n  mean_burst_length: 2\n"),
                 "hub.yaml:3:16: loss.probability: a long-run loss of 0.9 is impossible with "
                 "mean_burst_length 2"));
  CHECK(contains(error_of("loss:\n  mean_burst_length: 0.5\n"),
                 "hub.yaml:2:22: loss.mean_burst_length: must be in [1, 1000] (got 0.5)"));
  CHECK(contains(error_of("delay:\n  fixed_ms: -1\n"),
                 "hub.yaml:2:13: delay.fixed_ms: must be in [0, 60000] (got -1)"));
  CHECK(contains(error_of("links:\n  - {from: a, to: b, loss_probability: 0.5}\n"),
                 "links[0].loss_probability: is only used with loss.model per_link or burst"));
  CHECK(contains(error_of("links:\n  - {from: a, to: b, loss_probability: 0.5}\n"), "hub.yaml:2:"));
  CHECK(contains(error_of("links:\n  - {from: a}\n"), "hub.yaml:2:"));
  CHECK(contains(error_of("links:\n  - {from: a, to: a}\n"), "links[0].to: must differ"));
  CHECK(contains(error_of("outages:\n  - {peer: r1, from_s: 5, until_s: 5}\n"),
                 "outages[0].until_s: must be after from_s"));
  CHECK(contains(error_of("outages:\n  - {peer: r1, from_s: 5}\n"), "until_s"));
  CHECK(error_of("outages:\n  - {peer: r1, from_s: 5, until_s: 4}\n") ==
        "hub.yaml:2:36: outages[0].until_s: must be after from_s");
  CHECK(error_of("loss: {model: per_link}\nlinks:\n  - {from: a, to: b, jitter_ms: -2}\n") ==
        "hub.yaml:3:33: links[0].jitter_ms: must be in [0, 60000] (got -2)");
  CHECK(contains(error_of("max_frame_bytes: 4\n"), "hub.yaml:1:18: max_frame_bytes: must be in"));
  CHECK(contains(error_of("bogus: 1\n"), "bogus"));
}

TEST_CASE("every number has an upper bound, checked at its key before the clock conversion") {
  // Each of these used to load (1e300 ms overflowed the clock; a burst of 1e300 copies).
  CHECK(error_of("loss:\n  model: burst\n  mean_burst_length: 1e300\n") ==
        "hub.yaml:3:22: loss.mean_burst_length: must be in [1, 1000] (got 1e+300)");
  CHECK(error_of("delay:\n  fixed_ms: 1e300\n") ==
        "hub.yaml:2:13: delay.fixed_ms: must be in [0, 60000] (got 1e+300)");
  CHECK(error_of("delay:\n  jitter_ms: 60001\n") ==
        "hub.yaml:2:14: delay.jitter_ms: must be in [0, 60000] (got 60001)");
  CHECK(error_of("loss: {model: per_link}\nlinks:\n  - {from: a, to: b, fixed_ms: 1e300}\n") ==
        "hub.yaml:3:32: links[0].fixed_ms: must be in [0, 60000] (got 1e+300)");
  CHECK(error_of("loss: {model: per_link}\nlinks:\n  - {from: a, to: b, loss_probability: 7}\n") ==
        "hub.yaml:3:40: links[0].loss_probability: must be in [0, 1] (got 7)");
  CHECK(error_of("outages:\n  - {peer: r1, from_s: 0, until_s: 1e300}\n") ==
        "hub.yaml:2:36: outages[0].until_s: must be in [0, 86400] (got 1e+300)");
  CHECK(error_of("outages:\n  - {peer: r1, from_s: -1, until_s: 4}\n") ==
        "hub.yaml:2:24: outages[0].from_s: must be in [0, 86400] (got -1)");
  // The bounds themselves load.
  const HubConfig c = parse(
      "loss: {model: burst, probability: 0.5, mean_burst_length: 1000}\n"
      "delay: {fixed_ms: 60000, jitter_ms: 0}\n"
      "outages:\n  - {peer: r1, from_s: 0, until_s: 86400}\n");
  CHECK(c.mean_burst_length == 1000.0);
  CHECK(c.delay.fixed == SimTime::from_sec(60));
  CHECK(c.outages.at(0).until == SimTime::from_sec(86400));
  // validate() applies the same bounds to a config built in code.
  HubConfig d;
  d.mean_burst_length = 1e300;
  CHECK_THROWS_WITH_AS(d.validate(), "loss.mean_burst_length: must be in [1, 1000] (got 1e+300)",
                       ConfigError);
}

TEST_CASE("validate() without YAML names the field") {
  HubConfig c;
  c.loss_probability = -0.1;
  CHECK_THROWS_WITH_AS(c.validate(), "loss.probability: must be in [0, 1] (got -0.1)", ConfigError);
  c = HubConfig{};
  c.outages.push_back(OutageConfig{"", "", SimTime(), SimTime::from_sec(1)});
  CHECK_THROWS_WITH_AS(c.validate(), "outages[0].peer: must name a peer", ConfigError);
  c = HubConfig{};
  c.loss_model = LossModel::kPerLink;
  c.links.push_back(LinkConfig{"a", "b", true, 2.0});
  CHECK_THROWS_WITH_AS(c.validate(), "links[0].loss_probability: must be in [0, 1] (got 2)",
                       ConfigError);
}

// ---------------------------------------------------------------------------------------------
// SocketConfig
// ---------------------------------------------------------------------------------------------

#include "llsf/comm/socket_config.h"

TEST_CASE("socket config: loopback and port 4444 by default; YAML; errors") {
  const SocketConfig d;
  CHECK(d.address == "127.0.0.1");
  CHECK(d.stream_port == 4444);
  CHECK(d.stream_enabled);
  CHECK_NOTHROW(d.validate());
  const SocketConfig c = load_socket_config(ConfigNode::parse(R"(
address: 127.0.0.1
stream: {enabled: false, port: 0}
udp_peers:
  - {name: robot1, send_port: 4445, recv_port: 4446}
  - {name: refbox, channel: "*"}
)",
                                                              "sock.yaml"));
  CHECK_FALSE(c.stream_enabled);
  CHECK(c.stream_port == 0);
  REQUIRE(c.udp_peers.size() == 2);
  CHECK(c.udp_peers[0].channel == "team");
  CHECK(c.udp_peers[0].send_port == 4445);
  CHECK(c.udp_peers[0].recv_port == 4446);
  CHECK(c.udp_peers[1].channel == "*");
  CHECK(c.udp_peers[1].send_port == 0);

  const auto error_of_sock = [](const std::string& yaml) -> std::string {
    try {
      load_socket_config(ConfigNode::parse(yaml, "sock.yaml"));
    } catch (const ConfigError& e) {
      return e.what();
    }
    return "(no error)";
  };
  CHECK(error_of_sock("address: localhost\n") ==
        "sock.yaml:1:10: address: 'localhost' is not an IP address");
  CHECK(error_of_sock("stream: {port: 70000}\n") ==
        "sock.yaml:1:16: stream.port: must be a port in [0, 65535] (got 70000)");
  CHECK(error_of_sock(
            "udp_peers:\n  - {name: a, send_port: 5000}\n  - {name: b, send_port: 5000}\n") ==
        "sock.yaml:3:26: udp_peers[1].send_port: 5000 is used by another peer");
  CHECK(error_of_sock("udp_peers:\n  - {name: a}\n  - {name: a}\n") ==
        "sock.yaml:3:12: udp_peers[1].name: 'a' is taken");
  CHECK(contains(error_of_sock("udp_peers:\n  - {nme: a}\n"), "sock.yaml:2:"));
}
