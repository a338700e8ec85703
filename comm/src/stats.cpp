// SPDX-License-Identifier: MIT
// Traffic counters.
#include "llsf/comm/stats.h"

#include <algorithm>

namespace llsf::comm {

const char* drop_cause_name(DropCause c) {
  switch (c) {
    case DropCause::kLoss:
      return "loss";
    case DropCause::kOutage:
      return "outage";
    case DropCause::kTransport:
      return "transport";
  }
  return "?";
}

void DelayHistogram::add(core::SimTime delay) {
  const std::int64_t ns = delay.ns();
  int b = 0;
  while (b < kBuckets - 1 && ns >= kBucketUpperMs[static_cast<std::size_t>(b)] * 1000000) ++b;
  ++counts[static_cast<std::size_t>(b)];
  if (count == 0) {
    min_ns = max_ns = ns;
  } else {
    min_ns = std::min(min_ns, ns);
    max_ns = std::max(max_ns, ns);
  }
  ++count;
  sum_ns += ns;
}

void DelayHistogram::merge(const DelayHistogram& o) {
  if (o.count == 0) return;
  for (int b = 0; b < kBuckets; ++b) {
    counts[static_cast<std::size_t>(b)] += o.counts[static_cast<std::size_t>(b)];
  }
  min_ns = count == 0 ? o.min_ns : std::min(min_ns, o.min_ns);
  max_ns = count == 0 ? o.max_ns : std::max(max_ns, o.max_ns);
  count += o.count;
  sum_ns += o.sum_ns;
}

double DelayHistogram::mean_ms() const {
  return count == 0 ? 0.0 : static_cast<double>(sum_ns) / static_cast<double>(count) * 1e-6;
}

std::int64_t TrafficCounters::dropped_total() const {
  std::int64_t n = 0;
  for (const std::int64_t d : dropped) n += d;
  return n;
}

void TrafficCounters::merge(const TrafficCounters& o) {
  sent += o.sent;
  delivered += o.delivered;
  for (std::size_t i = 0; i < dropped.size(); ++i) dropped[i] += o.dropped[i];
  bytes_sent += o.bytes_sent;
  bytes_delivered += o.bytes_delivered;
  delay.merge(o.delay);
}

std::int64_t PeerCounters::malformed_total() const {
  std::int64_t n = 0;
  for (const std::int64_t m : malformed) n += m;
  return n;
}

}  // namespace llsf::comm
