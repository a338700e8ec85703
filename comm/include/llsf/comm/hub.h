// SPDX-License-Identifier: MIT
// Hub: the in-process radio. Peers (robot agents, the refbox, observers) broadcast messages; the
// hub forwards each to every other peer of the same channel through the loss, delay and outage
// models of its HubConfig, in simulated time, and counts what happened.
//
// Messages travel as encoded 2013 frames, so byte counts equal those on the wire and a frame from
// a socket takes the same path as one from an in-process agent. Each frame is stored once in a
// pool and shared by all its receivers; the steady state does not allocate.
//
// Determinism: loss draws come from the stream "<stream>/loss" and delay draws from
// "<stream>/delay" of the Rng, in a fixed order: per message, [global: one loss draw], then for
// each receiver in ascending peer id [per_link/burst: one loss draw] [jitter > 0: one delay draw].
// Draws are made for every copy, including copies an outage drops, and do not depend on the
// probabilities' values: an outage never shifts a draw, changing a (per-link) loss probability
// only changes the outcomes of the links it sets, and delay settings never change which copies
// are lost (and loss settings never change the delays). Same seed + same sends = same drops,
// delays and deliveries.
#pragma once

#include <google/protobuf/message.h>

#include <cstdint>
#include <deque>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "llsf/comm/frame.h"
#include "llsf/comm/hub_config.h"
#include "llsf/comm/registry.h"
#include "llsf/comm/stats.h"
#include "llsf/core/ids.h"
#include "llsf/core/rng.h"
#include "llsf/core/sim_time.h"

namespace llsf::comm {

struct PeerTag {};
/// A peer of a hub (index in order of add_peer()).
using PeerId = core::Id<PeerTag>;

/// The channel name that joins every channel (for the refbox and observers).
inline constexpr std::string_view kAllChannels = "*";

/// Delivery::type_index of a frame whose type is not in the registry (forwarded unparsed).
inline constexpr int kUnregistered = -1;

/// One message copy handed to its receiver by Hub::step().
struct Delivery {
  PeerId from;
  PeerId to;
  /// The message type's dense index in the hub's registry; kUnregistered for a forwarded frame
  /// of an unregistered type (HubConfig::forward_unregistered).
  int type_index = -1;
  SimTime sent_at;
  SimTime due;                          ///< sent_at + the drawn delay
  std::span<const std::uint8_t> frame;  ///< header + payload; valid until the next step()

  /// The frame split into header and payload.
  FrameView view() const;
};

/// What the hub decided for one message copy (recorded when tracing is on).
struct TraceEntry {
  enum class Outcome { kQueued, kLost, kOutage };
  SimTime sent_at;
  PeerId from;
  PeerId to;
  int type_index = -1;
  Outcome outcome = Outcome::kQueued;
  SimTime delay;  ///< the drawn delay (also for dropped copies)
  friend bool operator==(const TraceEntry&, const TraceEntry&) = default;
};

/// The in-process hub. Not copyable (peers hold ids into it), movable; not thread-safe.
class Hub {
 public:
  /// A hub with `config` (validated here; throws core::ConfigError) that routes the types of
  /// `registry` (borrowed: must outlive the hub) and draws from `rng`'s streams "<stream>/loss"
  /// and "<stream>/delay".
  Hub(HubConfig config, const MessageRegistry& registry, const core::Rng& rng,
      std::string_view stream = "comm");
  Hub(const Hub&) = delete;
  Hub& operator=(const Hub&) = delete;
  Hub(Hub&&) = default;
  Hub& operator=(Hub&&) = default;
  ~Hub() = default;

  /// Adds a peer that hears and is heard by the peers of `channel` (kAllChannels: of every
  /// channel). Names must be unique; the config's links and outages refer to them.
  PeerId add_peer(std::string name, std::string channel = "team");
  int peer_count() const { return static_cast<int>(peers_.size()); }
  const std::string& peer_name(PeerId p) const;
  /// The peer called `name`, if any.
  std::optional<PeerId> find_peer(std::string_view name) const;

  /// Adds an outage while running (e.g. a scenario event "cut robot2 for 30 s from now"), as if
  /// it had been in the config; throws core::ConfigError if it is invalid. Copies sent before
  /// this call are not affected.
  void add_outage(const OutageConfig& outage);

  /// Broadcasts `message` from `from` at time `now` (>= the last step's time). Returns kNone if
  /// it was accepted (even if every copy is then lost), kUnknownType if its type is not
  /// registered, kBadPayload if required fields are missing, kOversized if the frame exceeds
  /// max_frame_bytes; refused messages are counted as the sender's malformed frames.
  FrameError broadcast(PeerId from, const google::protobuf::Message& message, SimTime now);
  /// Broadcasts a raw datagram from `from` (e.g. one received on a socket): it must be exactly
  /// one frame of a registered type whose payload parses. Same results as broadcast().
  FrameError broadcast_frame(PeerId from, std::span<const std::uint8_t> datagram, SimTime now);

  /// Advances to `now` (non-decreasing): the frames of the previous step are released, and every
  /// copy whose due time is <= now is delivered, per receiver in (due time, send order) order.
  /// Returns the number of copies delivered.
  int step(SimTime now);
  /// The copies delivered to `peer` by the last step(); valid until the next step().
  std::span<const Delivery> received(PeerId peer) const;
  /// Decodes a delivered copy (its payload was validated on the way in); nullptr for an
  /// unregistered type.
  std::unique_ptr<google::protobuf::Message> decode(const Delivery& d) const;

  /// Due time of the earliest copy in flight, if any.
  std::optional<SimTime> next_due() const;
  /// Number of copies in flight.
  int in_flight() const { return static_cast<int>(pending_.size()); }
  /// Number of frame buffers the pool holds (in flight, handed out or free): bounded by the
  /// traffic in flight, not by the traffic so far.
  int frame_pool_size() const { return static_cast<int>(frames_.size()); }
  /// Time of the last step().
  SimTime now() const { return now_; }

  /// For transports: the delivered copy `d` could not be passed on (no address, send error);
  /// moves it from `delivered` to `dropped[kTransport]` in the counters.
  void mark_undeliverable(const Delivery& d);

  // --- Counters --------------------------------------------------------------------------------
  /// Counters of the directed link `from` -> `to`.
  const TrafficCounters& link_counters(PeerId from, PeerId to) const;
  /// Counters of all copies of one message type (dense registry index, or kUnregistered).
  TrafficCounters type_counters(int type_index) const;
  /// Counters of everything the hub carried.
  TrafficCounters total_counters() const;
  const PeerCounters& peer_counters(PeerId p) const;
  /// All counters as one JSON object {"links": [...], "types": [...], "peers": [...]}, with peer
  /// and type names, for run statistics. Links and types without traffic are left out.
  std::string counters_json() const;

  // --- Trace -----------------------------------------------------------------------------------
  /// Records a TraceEntry per message copy from now on (off by default; allocates).
  void set_trace(bool on) { trace_on_ = on; }
  const std::vector<TraceEntry>& trace() const { return trace_; }
  void clear_trace() { trace_.clear(); }

  const HubConfig& config() const { return config_; }
  const MessageRegistry& registry() const { return *registry_; }

 private:
  struct Peer {
    std::string name;
    std::string channel;
    std::vector<std::int32_t> receivers;  ///< peer indices, ascending
    PeerCounters counters;
    std::vector<Delivery> inbox;
  };
  /// The state and parameters of one directed link.
  struct Link {
    double loss_probability = 0.0;
    double p_good_to_bad = 0.0;  ///< burst
    double p_bad_to_good = 1.0;  ///< burst
    bool bad = false;            ///< burst state
    std::int64_t delay_fixed_ns = 0;
    std::int64_t delay_jitter_ns = 0;
    TrafficCounters counters;
  };
  struct Pending {
    std::int64_t due_ns;
    std::int64_t seq;
    std::int64_t sent_ns;
    std::int32_t from;
    std::int32_t to;
    std::int32_t frame;
    std::int32_t type;
  };
  struct Frame {
    std::vector<std::uint8_t> bytes;
    int refs = 0;
  };
  struct Outage {
    std::int32_t a;
    std::int32_t b;  ///< -1: all of a's links
    std::int64_t from_ns;
    std::int64_t until_ns;
  };

  Link& link(int from, int to) {
    return links_[static_cast<std::size_t>(from * peer_count() + to)];
  }
  void rebuild_routes();
  void configure_link(int from, int to, Link& l) const;
  bool cut_off(int from, int to, std::int64_t t_ns) const;
  int acquire_frame();
  void release_frame(int f);
  FrameError route(int from, int frame, int type, SimTime now);
  FrameError refuse(int from, FrameError e);

  HubConfig config_;
  const MessageRegistry* registry_;
  core::RandomStream loss_rng_;
  core::RandomStream delay_rng_;
  std::vector<Peer> peers_;
  std::vector<Link> links_;  ///< peer_count()^2, row = sender
  std::vector<Outage> outages_;
  TrafficCounters& type_slot(int type);
  std::vector<TrafficCounters> type_counters_;  ///< per registry index (grows with it)
  TrafficCounters unregistered_counters_;
  std::vector<Pending> pending_;  ///< min-heap on (due, seq)
  std::deque<Frame> frames_;      ///< stable addresses for Delivery::frame
  std::vector<int> free_frames_;
  std::vector<int> handed_out_;  ///< frames of the last step's deliveries (one entry per copy)
  std::vector<TraceEntry> trace_;
  SimTime now_;
  std::int64_t seq_ = 0;
  bool trace_on_ = false;
};

}  // namespace llsf::comm
