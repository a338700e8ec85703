// SPDX-License-Identifier: MIT
// HubConfig::validate() and the YAML loader (docs/comm.md).
#include "llsf/comm/hub_config.h"

#include <cmath>
#include <cstdio>
#include <set>

#include "llsf/comm/frame.h"
#include "llsf/core/error.h"

namespace llsf::comm {

using core::ConfigError;
using core::ConfigNode;

const char* loss_model_name(LossModel m) {
  switch (m) {
    case LossModel::kNone:
      return "none";
    case LossModel::kGlobal:
      return "global";
    case LossModel::kPerLink:
      return "per_link";
    case LossModel::kBurst:
      return "burst";
  }
  return "?";
}

namespace {

std::string num(double v) { return core::number_text(v); }

// Upper bounds (docs/comm.md, "Bounds"), checked at each key before any conversion to the
// clock and again by validate() for configs built in code.
/// A burst of 1,000 lost copies in a row is a dead link for many seconds; longer ones are
/// outages (`outages:`), and L / (L + 1) stays distinguishable from 1.
constexpr double kMaxMeanBurstLength = 1000.0;
/// A radio delay over a minute is an outage, not a delay; ms that fit the game clock.
constexpr double kMaxDelayMs = 60000.0;
/// Outage times: a day, far beyond a game (at most 3600 s) and inside the game clock.
constexpr double kMaxOutageS = 86400.0;

constexpr core::Bound kBurstLength = core::in_range(1.0, kMaxMeanBurstLength);
constexpr core::Bound kDelayMs = core::in_range(0.0, kMaxDelayMs);
constexpr core::Bound kOutageS = core::in_range(0.0, kMaxOutageS);
constexpr core::Bound kFrameBytes = core::in_range(kHeaderSize, 65507);

[[noreturn]] void fail(const std::string& path, const std::string& reason) {
  throw ConfigError(path + ": " + reason);
}

/// A delay given in ms (the key says so): 0 .. kMaxDelayMs.
void require_delay(const std::string& path, SimTime t) {
  core::require(path, static_cast<double>(t.ns()) / 1e6, kDelayMs);  // exact for whole ms
}

/// In the burst model a link with long-run loss p and mean burst length L enters the bad state
/// with probability p / (1 - p) / L per copy, which must not exceed 1.
void require_burst_feasible(const std::string& path, double p, double mean_burst) {
  if (p > mean_burst / (mean_burst + 1.0)) {
    fail(path, "a long-run loss of " + num(p) + " is impossible with mean_burst_length " +
                   num(mean_burst) +
                   " (at most L / (L + 1) = " + num(mean_burst / (mean_burst + 1.0)) + ")");
  }
}

std::string indexed(const char* list, std::size_t i) {
  return std::string(list) + "[" + std::to_string(i) + "]";
}

}  // namespace

void HubConfig::validate() const {
  core::require("loss.probability", loss_probability, core::probability());
  core::require("loss.mean_burst_length", mean_burst_length, kBurstLength);
  if (loss_model == LossModel::kBurst) {
    require_burst_feasible("loss.probability", loss_probability, mean_burst_length);
  }
  require_delay("delay.fixed_ms", delay.fixed);
  require_delay("delay.jitter_ms", delay.jitter);
  core::require("max_frame_bytes", max_frame_bytes, kFrameBytes);
  for (std::size_t i = 0; i < links.size(); ++i) {
    const LinkConfig& l = links[i];
    const std::string p = indexed("links", i);
    if (l.from.empty()) fail(p + ".from", "must name a peer");
    if (l.to.empty()) fail(p + ".to", "must name a peer");
    if (l.from == l.to) fail(p + ".to", "must differ from 'from' (" + l.from + ")");
    if (l.loss_probability) {
      if (loss_model != LossModel::kPerLink && loss_model != LossModel::kBurst) {
        fail(p + ".loss_probability", std::string("is only used with loss.model per_link or "
                                                  "burst (model is ") +
                                          loss_model_name(loss_model) + ")");
      }
      core::require(p + ".loss_probability", *l.loss_probability, core::probability());
      if (loss_model == LossModel::kBurst) {
        require_burst_feasible(p + ".loss_probability", *l.loss_probability, mean_burst_length);
      }
    }
    if (l.delay_fixed) require_delay(p + ".fixed_ms", *l.delay_fixed);
    if (l.delay_jitter) require_delay(p + ".jitter_ms", *l.delay_jitter);
  }
  for (std::size_t i = 0; i < outages.size(); ++i) {
    const OutageConfig& o = outages[i];
    const std::string p = indexed("outages", i);
    if (o.peer.empty()) fail(p + ".peer", "must name a peer");
    if (o.other == o.peer) fail(p + ".other", "must differ from 'peer' (" + o.peer + ")");
    core::require(p + ".from_s", static_cast<double>(o.from.ns()) / 1e9, kOutageS);
    core::require(p + ".until_s", static_cast<double>(o.until.ns()) / 1e9, kOutageS);
    if (!(o.until > o.from)) fail(p + ".until_s", "must be after from_s");
  }
}

void HubConfig::validate_peer_names(const std::vector<std::string>& peer_names) const {
  const std::set<std::string> known(peer_names.begin(), peer_names.end());
  const auto check = [&](const std::string& path, const std::string& name) {
    if (!name.empty() && !known.count(name)) fail(path, "no peer is called '" + name + "'");
  };
  for (std::size_t i = 0; i < links.size(); ++i) {
    check(indexed("links", i) + ".from", links[i].from);
    check(indexed("links", i) + ".to", links[i].to);
  }
  for (std::size_t i = 0; i < outages.size(); ++i) {
    check(indexed("outages", i) + ".peer", outages[i].peer);
    check(indexed("outages", i) + ".other", outages[i].other);
  }
}

// ---------------------------------------------------------------------------------------------
// YAML
// ---------------------------------------------------------------------------------------------

namespace {

/// Checked at the key against kDelayMs before the conversion to the clock.
void read_ms(const ConfigNode& n, std::string_view key, SimTime& out) {
  if (!n[key].defined()) return;
  out = SimTime::from_seconds(n[key].as_double(kDelayMs) * 1e-3);
}

/// Checked at the key against kOutageS before the conversion to the clock.
void read_s(const ConfigNode& n, std::string_view key, SimTime& out) {
  if (!n[key].defined()) return;
  out = SimTime::from_seconds(n[key].as_double(kOutageS));
}

LossModel parse_loss_model(const ConfigNode& n) {
  const std::string s = n.as_string();
  if (s == "none") return LossModel::kNone;
  if (s == "global") return LossModel::kGlobal;
  if (s == "per_link") return LossModel::kPerLink;
  if (s == "burst") return LossModel::kBurst;
  n.fail("unknown loss model '" + s + "' (expected none, global, per_link or burst)");
}

LockNumbering parse_lock_numbering(const ConfigNode& n) {
  const std::string s = n.as_string();
  if (s == lock_numbering_name(LockNumbering::kLlsfsim)) return LockNumbering::kLlsfsim;
  if (s == lock_numbering_name(LockNumbering::k2013)) return LockNumbering::k2013;
  n.fail("unknown lock message numbering '" + s +
         "' (expected llsfsim: component 2100, or 2013: component 2000, types 1337 and 1338)");
}

}  // namespace

HubConfig load_hub_config(const ConfigNode& node, HubConfig base) {
  HubConfig c = std::move(base);
  node.require_map();
  if (node.is_null()) return c;

  if (const ConfigNode loss = node["loss"]; loss.defined()) {
    loss.require_map();
    if (loss["model"].defined()) c.loss_model = parse_loss_model(loss["model"]);
    loss.read("probability", c.loss_probability, core::probability());
    loss.read("mean_burst_length", c.mean_burst_length, kBurstLength);
    loss.no_other_keys();
  }
  if (const ConfigNode delay = node["delay"]; delay.defined()) {
    delay.require_map();
    read_ms(delay, "fixed_ms", c.delay.fixed);
    read_ms(delay, "jitter_ms", c.delay.jitter);
    delay.no_other_keys();
  }
  node.read("max_frame_bytes", c.max_frame_bytes, kFrameBytes);
  node.read("forward_unregistered", c.forward_unregistered);
  if (node["lock_messages"].defined()) {
    c.lock_messages = parse_lock_numbering(node["lock_messages"]);
  }

  if (const ConfigNode links = node["links"]; links.defined()) {
    c.links.clear();
    for (const ConfigNode& l : links.elements()) {
      l.require_map();
      LinkConfig lc;
      lc.from = l.at("from").as_string();
      lc.to = l.at("to").as_string();
      l.read("symmetric", lc.symmetric);
      if (l["loss_probability"].defined()) {
        lc.loss_probability = l["loss_probability"].as_double(core::probability());
      }
      if (l["fixed_ms"].defined()) read_ms(l, "fixed_ms", lc.delay_fixed.emplace());
      if (l["jitter_ms"].defined()) read_ms(l, "jitter_ms", lc.delay_jitter.emplace());
      l.no_other_keys();
      // Ranges are checked by validate(), whose errors are located below.
      c.links.push_back(lc);
    }
  }
  if (const ConfigNode outages = node["outages"]; outages.defined()) {
    c.outages.clear();
    for (const ConfigNode& o : outages.elements()) {
      o.require_map();
      OutageConfig oc;
      oc.peer = o.at("peer").as_string();
      o.read("other", oc.other);
      o.at("from_s");  // both are required
      o.at("until_s");
      read_s(o, "from_s", oc.from);
      read_s(o, "until_s", oc.until);
      o.no_other_keys();
      c.outages.push_back(oc);
    }
  }
  node.no_other_keys();
  // validate() names fields by their YAML paths; point at the deepest node that exists.
  node.locate_errors([&] { c.validate(); });
  return c;
}

HubConfig load_hub_config_file(const std::string& path) {
  return load_hub_config(ConfigNode::load_file(path));
}

}  // namespace llsf::comm
