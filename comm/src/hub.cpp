// SPDX-License-Identifier: MIT
// The in-process hub: routing, loss/delay/outage models, delivery in simulated time, counters.
#include "llsf/comm/hub.h"

#include <algorithm>
#include <nlohmann/json.hpp>
#include <string>

#include "llsf/core/assert.h"

namespace llsf::comm {

namespace {

constexpr std::size_t kFrameReserveBytes = 2048;

/// Min-heap order on (due, seq): std::push_heap keeps the *largest* on top, so invert.
struct Later {
  template <class P>
  bool operator()(const P& a, const P& b) const {
    return a.due_ns != b.due_ns ? a.due_ns > b.due_ns : a.seq > b.seq;
  }
};

bool channels_meet(const std::string& a, const std::string& b) {
  return a == b || a == kAllChannels || b == kAllChannels;
}

}  // namespace

FrameView Delivery::view() const {
  FrameView v;
  v.header = *read_header(frame);
  v.payload = frame.subspan(kHeaderSize);
  return v;
}

Hub::Hub(HubConfig config, const MessageRegistry& registry, const core::Rng& rng,
         std::string_view stream)
    : config_(std::move(config)),
      registry_(&registry),
      loss_rng_(rng.stream(std::string(stream) + "/loss")),
      delay_rng_(rng.stream(std::string(stream) + "/delay")) {
  config_.validate();
  type_counters_.resize(static_cast<std::size_t>(registry.size()));
}

// ---------------------------------------------------------------------------------------------
// Peers and links
// ---------------------------------------------------------------------------------------------

PeerId Hub::add_peer(std::string name, std::string channel) {
  LLSF_DEMAND_MSG(!find_peer(name), "peer name '" + name + "' is already taken");
  const int old_n = peer_count();
  const int n = old_n + 1;
  // Re-lay the link matrix for n peers, keeping the state of the existing links.
  std::vector<Link> links(static_cast<std::size_t>(n * n));
  for (int f = 0; f < old_n; ++f) {
    for (int t = 0; t < old_n; ++t) {
      links[static_cast<std::size_t>(f * n + t)] = links_[static_cast<std::size_t>(f * old_n + t)];
    }
  }
  links_ = std::move(links);
  peers_.push_back(Peer{std::move(name), std::move(channel), {}, {}, {}});
  for (int other = 0; other < n; ++other) {
    configure_link(other, old_n, link(other, old_n));
    configure_link(old_n, other, link(old_n, other));
  }
  rebuild_routes();
  return PeerId(old_n);
}

const std::string& Hub::peer_name(PeerId p) const {
  return peers_.at(static_cast<std::size_t>(p.value())).name;
}

std::optional<PeerId> Hub::find_peer(std::string_view name) const {
  for (int i = 0; i < peer_count(); ++i) {
    if (peers_[static_cast<std::size_t>(i)].name == name) return PeerId(i);
  }
  return std::nullopt;
}

void Hub::configure_link(int from, int to, Link& l) const {
  l.loss_probability = config_.loss_probability;
  l.delay_fixed_ns = config_.delay.fixed.ns();
  l.delay_jitter_ns = config_.delay.jitter.ns();
  const std::string& fn = peers_[static_cast<std::size_t>(from)].name;
  const std::string& tn = peers_[static_cast<std::size_t>(to)].name;
  for (const LinkConfig& lc : config_.links) {
    const bool forward = lc.from == fn && lc.to == tn;
    const bool backward = lc.symmetric && lc.from == tn && lc.to == fn;
    if (!forward && !backward) continue;
    if (lc.loss_probability) l.loss_probability = *lc.loss_probability;
    if (lc.delay_fixed) l.delay_fixed_ns = lc.delay_fixed->ns();
    if (lc.delay_jitter) l.delay_jitter_ns = lc.delay_jitter->ns();
  }
  // Gilbert chain with long-run loss p and mean burst length L: leave the bad state with 1/L,
  // enter it with p / (1 - p) / L (validate() ensures this is <= 1).
  const double p = l.loss_probability;
  const double L = config_.mean_burst_length;
  l.p_bad_to_good = 1.0 / L;
  l.p_good_to_bad = p >= 1.0 ? 1.0 : p / (1.0 - p) / L;
}

void Hub::rebuild_routes() {
  const int n = peer_count();
  for (int s = 0; s < n; ++s) {
    Peer& ps = peers_[static_cast<std::size_t>(s)];
    ps.receivers.clear();
    for (int r = 0; r < n; ++r) {
      if (r != s && channels_meet(ps.channel, peers_[static_cast<std::size_t>(r)].channel)) {
        ps.receivers.push_back(r);
      }
    }
  }
  outages_.clear();
  for (const OutageConfig& o : config_.outages) {
    const auto a = find_peer(o.peer);
    if (!a) continue;
    std::int32_t b = -1;
    if (!o.other.empty()) {
      const auto other = find_peer(o.other);
      if (!other) continue;
      b = other->value();
    }
    outages_.push_back(Outage{a->value(), b, o.from.ns(), o.until.ns()});
  }
}

void Hub::add_outage(const OutageConfig& outage) {
  HubConfig probe;  // validate just this entry, with the config's own messages
  probe.outages.push_back(outage);
  probe.validate();
  config_.outages.push_back(outage);
  rebuild_routes();
}

bool Hub::cut_off(int from, int to, std::int64_t t_ns) const {
  for (const Outage& o : outages_) {
    if (t_ns < o.from_ns || t_ns >= o.until_ns) continue;
    if (o.b < 0) {
      if (o.a == from || o.a == to) return true;
    } else if ((o.a == from && o.b == to) || (o.a == to && o.b == from)) {
      return true;
    }
  }
  return false;
}

// ---------------------------------------------------------------------------------------------
// Frame pool
// ---------------------------------------------------------------------------------------------

int Hub::acquire_frame() {
  if (!free_frames_.empty()) {
    const int f = free_frames_.back();
    free_frames_.pop_back();
    return f;
  }
  // A new frame has room for every message of a 2013 game, so that a frame reused for a larger
  // message than before (an OrderInfo after a late order) does not allocate in the tick.
  frames_.emplace_back().bytes.reserve(kFrameReserveBytes);
  return static_cast<int>(frames_.size()) - 1;
}

void Hub::release_frame(int f) {
  Frame& fr = frames_[static_cast<std::size_t>(f)];
  LLSF_ASSERT(fr.refs > 0);
  if (--fr.refs == 0) free_frames_.push_back(f);
}

// ---------------------------------------------------------------------------------------------
// Sending
// ---------------------------------------------------------------------------------------------

FrameError Hub::refuse(int from, FrameError e) {
  ++peers_[static_cast<std::size_t>(from)].counters.malformed[static_cast<std::size_t>(e)];
  return e;
}

FrameError Hub::broadcast(PeerId from, const google::protobuf::Message& message, SimTime now) {
  LLSF_DEMAND(from.valid() && from.value() < peer_count());
  const auto type = registry_->index_of(message);
  if (!type) return refuse(from.value(), FrameError::kUnknownType);
  if (!message.IsInitialized()) return refuse(from.value(), FrameError::kBadPayload);
  // Encoded here rather than with MessageRegistry::encode(), which would look the type up and
  // compute the size a second time.
  const auto payload = static_cast<std::int64_t>(message.ByteSizeLong());
  if (kHeaderSize + payload > config_.max_frame_bytes) {
    return refuse(from.value(), FrameError::kOversized);
  }
  const int f = acquire_frame();
  std::vector<std::uint8_t>& bytes = frames_[static_cast<std::size_t>(f)].bytes;
  bytes.resize(static_cast<std::size_t>(kHeaderSize + payload));
  write_header(std::span<std::uint8_t, kHeaderSize>(bytes.data(), kHeaderSize),
               registry_->key_at(*type), payload);
  message.SerializeWithCachedSizesToArray(bytes.data() + kHeaderSize);
  return route(from.value(), f, *type, now);
}

FrameError Hub::broadcast_frame(PeerId from, std::span<const std::uint8_t> datagram, SimTime now) {
  LLSF_DEMAND(from.valid() && from.value() < peer_count());
  const DatagramCheck c = check_datagram(datagram, config_.max_frame_bytes);
  if (c.error != FrameError::kNone) return refuse(from.value(), c.error);
  int type = kUnregistered;
  if (const FrameError e = registry_->validate(c.frame, &type); e != FrameError::kNone) {
    if (!(e == FrameError::kUnknownType && config_.forward_unregistered)) {
      return refuse(from.value(), e);
    }
    type = kUnregistered;
  }
  const int f = acquire_frame();
  std::vector<std::uint8_t>& bytes = frames_[static_cast<std::size_t>(f)].bytes;
  bytes.assign(datagram.begin(), datagram.end());
  return route(from.value(), f, type, now);
}

FrameError Hub::route(int from, int frame, int type, SimTime now) {
  LLSF_DEMAND_MSG(now >= now_, "Hub: sending into the past");
  Peer& sender = peers_[static_cast<std::size_t>(from)];
  Frame& fr = frames_[static_cast<std::size_t>(frame)];
  const auto bytes = static_cast<std::int64_t>(fr.bytes.size());
  ++sender.counters.broadcasts;
  sender.counters.bytes += bytes;
  TrafficCounters& tc = type_slot(type);

  // The draws, in the documented order (hub.h).
  const LossModel model = config_.loss_model;
  const bool global_lost =
      model == LossModel::kGlobal && loss_rng_.uniform01() < config_.loss_probability;
  for (const std::int32_t to : sender.receivers) {
    Link& l = link(from, to);
    bool lost = false;
    switch (model) {
      case LossModel::kNone:
        break;
      case LossModel::kGlobal:
        lost = global_lost;
        break;
      case LossModel::kPerLink:
        lost = loss_rng_.uniform01() < l.loss_probability;
        break;
      case LossModel::kBurst: {
        const double u = loss_rng_.uniform01();
        l.bad = l.bad ? !(u < l.p_bad_to_good) : u < l.p_good_to_bad;
        lost = l.bad;
        break;
      }
    }
    std::int64_t delay = l.delay_fixed_ns;
    if (l.delay_jitter_ns > 0) delay += delay_rng_.uniform_int(0, l.delay_jitter_ns);
    const bool cut = !outages_.empty() && cut_off(from, to, now.ns());

    ++l.counters.sent;
    ++tc.sent;
    l.counters.bytes_sent += bytes;
    tc.bytes_sent += bytes;
    TraceEntry::Outcome outcome = TraceEntry::Outcome::kQueued;
    if (cut || lost) {
      // An outage is the cause when both apply: the copy could not have arrived anyway.
      const auto cause = static_cast<std::size_t>(cut ? DropCause::kOutage : DropCause::kLoss);
      ++l.counters.dropped[cause];
      ++tc.dropped[cause];
      outcome = cut ? TraceEntry::Outcome::kOutage : TraceEntry::Outcome::kLost;
    } else {
      ++fr.refs;
      pending_.push_back(Pending{now.ns() + delay, seq_++, now.ns(), from, to, frame, type});
      std::push_heap(pending_.begin(), pending_.end(), Later{});
    }
    if (trace_on_) {
      trace_.push_back(
          TraceEntry{now, PeerId(from), PeerId(to), type, outcome, SimTime::from_ns(delay)});
    }
  }
  if (fr.refs == 0) free_frames_.push_back(frame);
  return FrameError::kNone;
}

// ---------------------------------------------------------------------------------------------
// Delivering
// ---------------------------------------------------------------------------------------------

int Hub::step(SimTime now) {
  LLSF_DEMAND_MSG(now >= now_, "Hub::step: time went backwards");
  now_ = now;
  // Release the frames handed out by the previous step.
  for (const int f : handed_out_) release_frame(f);
  handed_out_.clear();
  for (Peer& p : peers_) p.inbox.clear();

  int delivered = 0;
  while (!pending_.empty() && pending_.front().due_ns <= now.ns()) {
    std::pop_heap(pending_.begin(), pending_.end(), Later{});
    const Pending q = pending_.back();
    pending_.pop_back();
    const Frame& fr = frames_[static_cast<std::size_t>(q.frame)];
    const auto bytes = static_cast<std::int64_t>(fr.bytes.size());
    peers_[static_cast<std::size_t>(q.to)].inbox.push_back(
        Delivery{PeerId(q.from), PeerId(q.to), q.type, SimTime::from_ns(q.sent_ns),
                 SimTime::from_ns(q.due_ns), std::span<const std::uint8_t>(fr.bytes)});
    handed_out_.push_back(q.frame);
    const SimTime latency = SimTime::from_ns(now.ns() - q.sent_ns);
    for (TrafficCounters* c : {&link(q.from, q.to).counters, &type_slot(q.type)}) {
      ++c->delivered;
      c->bytes_delivered += bytes;
      c->delay.add(latency);
    }
    ++delivered;
  }
  return delivered;
}

std::span<const Delivery> Hub::received(PeerId peer) const {
  return peers_.at(static_cast<std::size_t>(peer.value())).inbox;
}

std::unique_ptr<google::protobuf::Message> Hub::decode(const Delivery& d) const {
  return std::move(registry_->decode(d.view()).message);
}

std::optional<SimTime> Hub::next_due() const {
  if (pending_.empty()) return std::nullopt;
  return SimTime::from_ns(pending_.front().due_ns);
}

void Hub::mark_undeliverable(const Delivery& d) {
  const auto bytes = static_cast<std::int64_t>(d.frame.size());
  const auto cause = static_cast<std::size_t>(DropCause::kTransport);
  for (TrafficCounters* c :
       {&link(d.from.value(), d.to.value()).counters, &type_slot(d.type_index)}) {
    --c->delivered;
    c->bytes_delivered -= bytes;
    ++c->dropped[cause];
  }
}

// ---------------------------------------------------------------------------------------------
// Counters
// ---------------------------------------------------------------------------------------------

const TrafficCounters& Hub::link_counters(PeerId from, PeerId to) const {
  LLSF_DEMAND(from.valid() && to.valid() && from.value() < peer_count() &&
              to.value() < peer_count());
  return links_[static_cast<std::size_t>(from.value() * peer_count() + to.value())].counters;
}

TrafficCounters& Hub::type_slot(int type) {
  if (type == kUnregistered) return unregistered_counters_;
  if (type >= static_cast<int>(type_counters_.size())) {
    type_counters_.resize(static_cast<std::size_t>(registry_->size()));  // registered later
  }
  return type_counters_[static_cast<std::size_t>(type)];
}

TrafficCounters Hub::type_counters(int type_index) const {
  if (type_index == kUnregistered) return unregistered_counters_;
  if (type_index < 0 || type_index >= static_cast<int>(type_counters_.size())) return {};
  return type_counters_[static_cast<std::size_t>(type_index)];
}

TrafficCounters Hub::total_counters() const {
  TrafficCounters t;
  for (const TrafficCounters& c : type_counters_) t.merge(c);
  t.merge(unregistered_counters_);
  return t;
}

const PeerCounters& Hub::peer_counters(PeerId p) const {
  return peers_.at(static_cast<std::size_t>(p.value())).counters;
}

namespace {

using Json = nlohmann::ordered_json;  // keys in the order written: a stable, readable object

/// `head`'s keys, then the counters'.
Json with_counters(Json head, const TrafficCounters& c) {
  Json dropped = Json::object();
  for (int i = 0; i < kDropCauseCount; ++i) {
    dropped[drop_cause_name(static_cast<DropCause>(i))] = c.dropped[static_cast<std::size_t>(i)];
  }
  const DelayHistogram& h = c.delay;
  head["sent"] = c.sent;
  head["delivered"] = c.delivered;
  head["dropped"] = std::move(dropped);
  head["bytes_sent"] = c.bytes_sent;
  head["bytes_delivered"] = c.bytes_delivered;
  head["delay_ms"] = {{"count", h.count},
                      {"mean", h.mean_ms()},
                      {"min", static_cast<double>(h.min_ns) * 1e-6},
                      {"max", static_cast<double>(h.max_ns) * 1e-6},
                      {"buckets", h.counts}};
  return head;
}

}  // namespace

std::string Hub::counters_json() const {
  Json links = Json::array();
  for (int f = 0; f < peer_count(); ++f) {
    for (int t = 0; t < peer_count(); ++t) {
      const TrafficCounters& c = link_counters(PeerId(f), PeerId(t));
      if (c.sent == 0) continue;
      links.push_back(
          with_counters({{"from", peer_name(PeerId(f))}, {"to", peer_name(PeerId(t))}}, c));
    }
  }
  Json types = Json::array();
  for (int i = 0; i < static_cast<int>(type_counters_.size()); ++i) {
    const TrafficCounters& c = type_counters_[static_cast<std::size_t>(i)];
    if (c.sent == 0) continue;
    const MessageKey k = registry_->key_at(i);
    types.push_back(with_counters({{"type", registry_->name_at(i)},
                                   {"component_id", k.component_id},
                                   {"msg_type", k.msg_type}},
                                  c));
  }
  if (unregistered_counters_.sent > 0) {
    types.push_back(with_counters({{"type", "(unregistered)"}}, unregistered_counters_));
  }
  Json peers = Json::array();
  for (int p = 0; p < peer_count(); ++p) {
    const PeerCounters& c = peer_counters(PeerId(p));
    Json malformed = Json::object();
    for (int e = 1; e < kFrameErrorCount; ++e) {
      malformed[std::string(frame_error_name(static_cast<FrameError>(e)))] =
          c.malformed[static_cast<std::size_t>(e)];
    }
    peers.push_back({{"name", peer_name(PeerId(p))},
                     {"channel", peers_[static_cast<std::size_t>(p)].channel},
                     {"broadcasts", c.broadcasts},
                     {"bytes", c.bytes},
                     {"malformed", std::move(malformed)}});
  }
  const Json j = {{"delay_bucket_upper_ms", DelayHistogram::kBucketUpperMs},
                  {"links", std::move(links)},
                  {"types", std::move(types)},
                  {"peers", std::move(peers)}};
  return j.dump(-1, ' ', false, Json::error_handler_t::replace);
}

}  // namespace llsf::comm
