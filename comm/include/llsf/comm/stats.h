// SPDX-License-Identifier: MIT
// Traffic counters of the hub: per directed link, per message type and per peer.
#pragma once

#include <array>
#include <cstdint>

#include "llsf/comm/frame.h"
#include "llsf/core/sim_time.h"

namespace llsf::comm {

/// Why a message copy did not reach its receiver.
enum class DropCause {
  kLoss,       ///< the loss model (global, per_link or burst)
  kOutage,     ///< an outage window covered the link when the copy was sent
  kTransport,  ///< socket mode: no known address for the receiver, or the send failed
};
inline constexpr int kDropCauseCount = 3;
/// "loss", "outage", "transport".
const char* drop_cause_name(DropCause c);

/// Distribution of delivery delays (delivery time - send time) in fixed buckets, plus exact
/// count, sum, min and max.
struct DelayHistogram {
  /// Upper bounds (exclusive) of the buckets in ms; a last bucket takes everything above.
  static constexpr std::array<std::int64_t, 12> kBucketUpperMs = {1,   2,   5,   10,   20,   50,
                                                                  100, 200, 500, 1000, 2000, 5000};
  static constexpr int kBuckets = static_cast<int>(kBucketUpperMs.size()) + 1;

  std::array<std::int64_t, kBuckets> counts{};
  std::int64_t count = 0;
  std::int64_t sum_ns = 0;
  std::int64_t min_ns = 0;  ///< valid if count > 0
  std::int64_t max_ns = 0;  ///< valid if count > 0

  void add(core::SimTime delay);
  void merge(const DelayHistogram& o);
  /// Mean delay in ms (0 if empty).
  double mean_ms() const;
};

/// Counters of message copies (one copy per receiver of a broadcast).
/// Invariant: sent == delivered + dropped_total() + copies still in flight.
struct TrafficCounters {
  std::int64_t sent = 0;
  std::int64_t delivered = 0;
  std::array<std::int64_t, kDropCauseCount> dropped{};
  std::int64_t bytes_sent = 0;       ///< frame bytes (header + payload) of the copies sent
  std::int64_t bytes_delivered = 0;  ///< frame bytes of the copies delivered
  DelayHistogram delay;              ///< of the delivered copies

  std::int64_t dropped_by(DropCause c) const { return dropped[static_cast<std::size_t>(c)]; }
  std::int64_t dropped_total() const;
  void merge(const TrafficCounters& o);
};

/// Counters of what one peer put on the air.
struct PeerCounters {
  std::int64_t broadcasts = 0;  ///< messages accepted from this peer
  std::int64_t bytes = 0;       ///< frame bytes of those messages
  /// Frames from this peer that were refused, by FrameError (index 0, kNone, stays 0).
  std::array<std::int64_t, kFrameErrorCount> malformed{};

  std::int64_t malformed_by(FrameError e) const { return malformed[static_cast<std::size_t>(e)]; }
  std::int64_t malformed_total() const;
};

}  // namespace llsf::comm
