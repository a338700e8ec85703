// SPDX-License-Identifier: MIT
// HubConfig: the radio's loss, delay and outage models (docs/comm.md documents every field and
// the YAML format that load_hub_config() reads).
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "llsf/comm/registry.h"
#include "llsf/core/config.h"
#include "llsf/core/sim_time.h"

namespace llsf::comm {

using core::SimTime;

/// How the hub decides that a message copy is lost.
enum class LossModel {
  kNone,     ///< nothing is lost (outages still apply)
  kGlobal,   ///< one draw per message drops it for every receiver (the Fawkes hubs' behaviour)
  kPerLink,  ///< an independent draw per receiver, with optional per-link probabilities
  kBurst,    ///< per directed link, a two-state Gilbert chain: in the bad state every copy is lost
};
/// "none", "global", "per_link", "burst".
const char* loss_model_name(LossModel m);

/// Transmission delay: `fixed` plus a uniform jitter in [0, `jitter`] (so messages can overtake
/// each other when jitter exceeds their spacing).
struct DelayConfig {
  SimTime fixed = SimTime::from_ms(2);
  SimTime jitter = SimTime::from_ms(0);
};

/// Overrides for the directed link from peer `from` to peer `to` (and back if `symmetric`).
/// Later entries override earlier ones for the same link.
struct LinkConfig {
  std::string from;  ///< peer name
  std::string to;    ///< peer name
  bool symmetric = true;
  /// Unset: the hub's. Only with loss model per_link or burst.
  std::optional<double> loss_probability{};
  std::optional<SimTime> delay_fixed{};   ///< unset: the hub's
  std::optional<SimTime> delay_jitter{};  ///< unset: the hub's
};

/// A radio outage in the window [from, until) of simulated time: every message copy *sent* in the
/// window on an affected link is dropped. Without `other`, all links of `peer` are cut (a robot,
/// or the refbox, out of reach); with `other`, only the links between the two peers.
struct OutageConfig {
  std::string peer;
  std::string other;  ///< empty: all of `peer`'s links
  SimTime from;
  SimTime until;
};

/// The hub's configuration. Plain aggregate with the defaults below; call validate() (Hub's
/// constructor does) to check it.
struct HubConfig {
  LossModel loss_model = LossModel::kNone;
  /// global, per_link: probability that a message (global) or a copy (per_link) is lost;
  /// burst: the long-run fraction of copies lost on a link.
  double loss_probability = 0.0;
  /// burst: mean number of consecutive lost copies on a link (>= 1).
  double mean_burst_length = 4.0;
  DelayConfig delay;
  std::vector<LinkConfig> links;
  std::vector<OutageConfig> outages;
  /// Largest frame (header + payload) in bytes; larger frames are refused (2013: 1024).
  int max_frame_bytes = 1024;
  /// Raw frames (sockets, Hub::broadcast_frame) of types not in the registry: refused as
  /// `unknown_type` (false), or forwarded unparsed and counted as type "(unregistered)" (true;
  /// a hub that relays bytes, for tools whose messages this build does not know).
  bool forward_unregistered = false;
  /// The (component id, message type) of the agents' lock messages: llsfsim's (2100, 1|2) or the
  /// 2013 Carologistics agent's (2000, 1337|1338), for tools that decode those. Read by whoever
  /// builds the registry (add_agent_messages); the hub itself only sees the registry.
  LockNumbering lock_messages = LockNumbering::kLlsfsim;

  /// Throws core::ConfigError naming the first bad field ("links[2].loss_probability: ...").
  void validate() const;
  /// Throws core::ConfigError if a link or outage names a peer not in `peer_names`.
  void validate_peer_names(const std::vector<std::string>& peer_names) const;
};

/// Reads a hub config from YAML on top of `base` (only the keys present override); every error
/// names the file, line and field. Validates the result.
HubConfig load_hub_config(const core::ConfigNode& node, HubConfig base = {});
/// load_hub_config() of a YAML file.
HubConfig load_hub_config_file(const std::string& path);

}  // namespace llsf::comm
