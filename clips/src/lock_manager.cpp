// SPDX-License-Identifier: MIT
// LockManager: election with endorsements (majority), leases, the master's table and answers,
// this robot's requests and releases. The safety argument is in docs/locks.md; the comments
// below name the rule each piece of code upholds.
#include "llsf/clips/lock_manager.h"

#include <llsf_agent_msgs/LockMessage.pb.h>

#include <algorithm>
#include <set>
#include <stdexcept>
#include <tuple>

namespace llsf::clips {

using core::SimTime;
using llsf_agent_msgs::LockMasterAnnounce;
using llsf_agent_msgs::LockMessage;
using llsf_agent_msgs::LockStatus;
using Out = std::vector<std::unique_ptr<google::protobuf::Message>>;

const char* to_string(LockState s) {
  switch (s) {
    case LockState::kNone:
      return "NONE";
    case LockState::kRequested:
      return "REQUESTED";
    case LockState::kAccepted:
      return "ACCEPTED";
    case LockState::kRefused:
      return "REFUSED";
    case LockState::kReleasing:
      return "RELEASING";
  }
  return "NONE";
}

void LockConfig::validate() const {
  auto positive = [](SimTime t, const char* name) {
    if (t <= SimTime())
      throw std::invalid_argument(std::string("LockConfig.") + name + " must be > 0");
  };
  positive(announce_period, "announce_period");
  positive(master_timeout, "master_timeout");
  positive(resend_period, "resend_period");
  positive(lost_timeout, "lost_timeout");
  positive(lease, "lease");
  positive(max_delay, "max_delay");
  positive(endorse_hold, "endorse_hold");
  if (backoff_max < SimTime()) throw std::invalid_argument("LockConfig.backoff_max must be >= 0");
  if (master_timeout <= announce_period)
    throw std::invalid_argument("LockConfig.master_timeout must exceed announce_period");
  if (lease <= announce_period)
    throw std::invalid_argument("LockConfig.lease must exceed announce_period");
  if (endorse_hold <= max_delay + announce_period)
    throw std::invalid_argument("LockConfig.endorse_hold must exceed max_delay + announce_period");
  if (!(release_distance_m >= 0.0))
    throw std::invalid_argument("LockConfig.release_distance_m must be >= 0");
  if (team_size < 1) throw std::invalid_argument("LockConfig.team_size must be >= 1");
}

LockManager::LockManager(std::string agent, LockConfig config, std::uint64_t seed)
    : agent_(std::move(agent)), config_(config), rng_(seed) {
  config_.validate();
  if (agent_.empty()) throw std::invalid_argument("LockManager: the agent name is empty");
}

LockManager::Own& LockManager::own(std::string_view resource) {
  auto it = own_.find(resource);
  if (it == own_.end()) {
    it = own_.emplace(std::string(resource), Own{}).first;
    ++states_version_;
  }
  return it->second;
}

void LockManager::set_state(Own& o, LockState state) {
  if (o.state == state) return;
  o.state = state;
  ++states_version_;
}

SimTime LockManager::draw_backoff() {
  return SimTime::from_ns(rng_.uniform_int(0, config_.backoff_max.ns()));
}

// ---- the agent's side ----------------------------------------------------------------------

void LockManager::request(std::string_view resource) {
  Own& o = own(resource);
  switch (o.state) {
    case LockState::kRequested:
    case LockState::kAccepted:
      return;  // idempotent
    case LockState::kReleasing:
      if (!o.release_sent) {  // still here and still ours: take it back
        set_state(o, LockState::kAccepted);
        o.release_pose.reset();
        return;
      }
      break;
    case LockState::kNone:
    case LockState::kRefused:
      break;
  }
  // A new request. Its GET waits 2 max_delay after our last RELEASE of the resource: by then
  // every RELEASE of ours has reached the master, and every confirmation the master sent before
  // it processed our RELEASE has arrived here (and been ignored).
  set_state(o, LockState::kRequested);
  o.get_sent = false;
  o.was_held = false;
  o.last_get.reset();
  o.release_sent = false;
  o.release_pose.reset();
  o.stray = false;
  o.get_not_before = o.last_release ? *o.last_release + config_.max_delay * 2 : SimTime();
  ++stats_.requests;
}

void LockManager::release(std::string_view resource) {
  auto it = own_.find(resource);
  if (it == own_.end()) return;
  Own& o = it->second;
  switch (o.state) {
    case LockState::kAccepted:
      set_state(o, LockState::kReleasing);
      o.release_sent = false;
      o.release_pose = pose_;  // the RELEASE waits until we are release_distance_m away
      return;
    case LockState::kRefused:
    case LockState::kRequested:
      if (!o.get_sent) {  // nobody heard of it
        set_state(o, LockState::kNone);
        return;
      }
      set_state(o, LockState::kReleasing);
      o.release_sent = false;
      // Held once (a lost lease): the robot may still be at the resource.
      o.release_pose = o.was_held ? pose_ : std::nullopt;
      return;
    case LockState::kNone:
    case LockState::kReleasing:
      return;
  }
}

bool LockManager::far_enough(const Own& o) const {
  return !o.release_pose || !pose_ ||
         pose_->distance_to(*o.release_pose) >= config_.release_distance_m;
}

LockState LockManager::state(std::string_view resource) const {
  auto it = own_.find(resource);
  return it == own_.end() ? LockState::kNone : it->second.state;
}

bool LockManager::holds(std::string_view resource, SimTime now) const {
  auto it = own_.find(resource);
  if (it == own_.end()) return false;
  const Own& o = it->second;
  const bool claimed = o.state == LockState::kAccepted ||
                       (o.state == LockState::kReleasing && !o.release_sent && o.was_held);
  return claimed && now < o.confirmed_at + config_.lease;
}

std::vector<std::string> LockManager::resources() const {
  std::vector<std::string> out;
  for (const auto& [r, o] : own_)
    if (o.state != LockState::kNone) out.push_back(r);
  return out;
}

// ---- receiving -----------------------------------------------------------------------------

void LockManager::heard_from(std::string_view agent, SimTime at) {
  if (agent.empty() || agent == agent_) return;
  auto it = heard_.find(agent);
  if (it == heard_.end())
    heard_.emplace(std::string(agent), at);
  else
    it->second = std::max(it->second, at);
}

// A confirmation (ACCEPT, or our entry in a LockStatus) of `resource` received at `at`. It
// reflects the master's table when it was sent; see docs/locks.md for why each state may use it.
void LockManager::confirm_own(std::string_view resource, SimTime at) {
  Own& o = own(resource);
  switch (o.state) {
    case LockState::kRequested:
      if (!o.get_sent) return;  // may be older than our request: ignore
      set_state(o, LockState::kAccepted);
      o.was_held = true;
      o.confirmed_at = at;
      ++stats_.accepted;
      return;
    case LockState::kAccepted:
      o.confirmed_at = std::max(o.confirmed_at, at);
      return;
    case LockState::kReleasing:
      if (!o.release_sent && o.was_held) o.confirmed_at = std::max(o.confirmed_at, at);
      return;
    case LockState::kNone:
      o.stray = true;  // the master thinks we hold it: release it
      return;
    case LockState::kRefused:
      return;  // the agent decides (request again, or release)
  }
}

bool LockManager::receive(const google::protobuf::Message& message, std::string_view from,
                          SimTime at) {
  advance(at);
  at = now_;
  heard_from(from, at);
  if (from == agent_) return false;

  if (const auto* a = dynamic_cast<const LockMasterAnnounce*>(&message)) {
    const std::string& x = a->agent();
    if (x == from) {
      // A master announces itself; two masters meet: step down.
      masters_heard_[x] = at;
      master_seen_ = at;
      if (is_master()) step_down(at);
    } else if (x == agent_) {
      // `from` endorses us; it promised to endorse nobody else until it sent + endorse_hold.
      support_[std::string(from)] = at + config_.endorse_hold - config_.max_delay;
    } else {
      master_seen_ = at;  // someone follows another master
    }
    return true;
  }
  if (const auto* s = dynamic_cast<const LockStatus*>(&message)) {
    if (s->master() != from) return true;  // only a master sends its table
    masters_heard_[s->master()] = at;
    master_seen_ = at;
    if (is_master()) {
      step_down(at);
    }
    table_.clear();
    for (const auto& e : s->locks()) {
      table_[e.resource()] = e.agent();
      if (e.agent() == agent_) confirm_own(e.resource(), at);
    }
    return true;
  }
  if (const auto* m = dynamic_cast<const LockMessage*>(&message)) {
    switch (m->type()) {
      case LockMessage::GET:
      case LockMessage::RELEASE:
        if (m->agent() != agent_) {
          heard_from(m->agent(), at);
          inbox_.push_back({m->type(), m->agent(), m->resource()});
        }
        break;
      case LockMessage::ACCEPT:
        if (m->agent() == agent_) confirm_own(m->resource(), at);
        break;
      case LockMessage::REFUSE:
        if (m->agent() == agent_) {
          Own& o = own(m->resource());
          // While ACCEPTED a REFUSE is stale (the lease decides); while REQUESTED it answers.
          if (o.state == LockState::kRequested && o.get_sent) {
            set_state(o, LockState::kRefused);
            ++stats_.refused;
          }
        }
        break;
      case LockMessage::RELEASE_RVCD:
        if (m->agent() == agent_) {
          Own& o = own(m->resource());
          o.stray = false;
          if (o.state == LockState::kReleasing && o.release_sent) {
            set_state(o, LockState::kNone);
            ++stats_.released;
          }
        }
        break;
    }
    return true;
  }
  return false;
}

// ---- election and authority ----------------------------------------------------------------

// Moves the clock to `t`; authority ends exactly when the last needed endorsement runs out, even
// between steps (a master must notice every gap: each new authority starts a quiet period).
void LockManager::advance(SimTime t) {
  if (!started_) {
    started_ = true;
    now_ = t;
    master_seen_ = t;
    backoff_ = draw_backoff();
  }
  now_ = std::max(now_, t);
  if (!authority_) return;
  if (!is_master()) {
    authority_ = false;
    return;
  }
  const int need = config_.team_size / 2;  // majority minus ourselves
  if (need == 0) return;
  std::vector<SimTime> until;
  until.reserve(support_.size());
  for (const auto& [who, u] : support_) until.push_back(u);
  if (static_cast<int>(until.size()) < need) {
    authority_ = false;
    return;
  }
  std::nth_element(until.begin(), until.begin() + (need - 1), until.end(), std::greater<>());
  if (until[static_cast<std::size_t>(need - 1)] <= now_) authority_ = false;
}

void LockManager::step_down(SimTime t) {
  endorsee_.clear();
  authority_ = false;
  last_announce_.reset();
  backoff_ = draw_backoff();
  master_seen_ = t;
  ++stats_.stepped_down;
}

void LockManager::update_election(SimTime now) {
  // Give up a master that stopped announcing itself.
  if (!endorsee_.empty() && !is_master()) {
    auto it = masters_heard_.find(endorsee_);
    if (it == masters_heard_.end() || now - it->second >= config_.master_timeout) {
      endorsee_.clear();
      last_announce_.reset();
    }
  }
  if (!endorsee_.empty()) return;
  auto may_endorse = [&](const std::string& x) {
    return pledged_to_.empty() || pledged_to_ == x || now >= pledge_until_;
  };
  // Follow the live master heard most recently (ties: the smallest name).
  const std::string* best = nullptr;
  SimTime best_at;
  for (const auto& [x, at] : masters_heard_) {
    if (now - at >= config_.master_timeout) continue;
    if (best == nullptr || at > best_at) {
      best = &x;
      best_at = at;
    }
  }
  if (best != nullptr) {
    if (may_endorse(*best)) {
      endorsee_ = *best;
      last_announce_.reset();
    }
    return;
  }
  // No master: claim mastership after the timeout plus our random back-off.
  if (now >= master_seen_ + config_.master_timeout + backoff_ && may_endorse(agent_)) {
    endorsee_ = agent_;
    last_announce_.reset();
    backoff_ = draw_backoff();
    ++stats_.became_master;
  }
}

void LockManager::update_authority(SimTime now) {
  if (!is_master() || authority_) return;
  const int need = config_.team_size / 2;
  int valid = 0;
  for (const auto& [who, until] : support_)
    if (until > now) ++valid;
  if (valid < need) return;
  // A new authority: another master may have confirmed locks until just now. Grant and confirm
  // nothing until every lease it gave has run out (lease + max_delay).
  authority_ = true;
  quiet_until_ = now + config_.lease + config_.max_delay;
  last_confirm_.clear();
  last_status_.reset();
  for (const auto& [r, x] : table_) heard_from(x, now);
  ++stats_.authority_gained;
}

// ---- master: answers ---------------------------------------------------------------------------

// Safety rule of one master: a resource goes to a new holder only when no other robot got a
// confirmation of it within lease + max_delay (except after that robot's own RELEASE).
bool LockManager::may_grant(std::string_view resource, std::string_view agent, SimTime now) const {
  auto lc = last_confirm_.find(resource);
  return lc == last_confirm_.end() || lc->second.agent == agent ||
         now >= lc->second.at + config_.lease + config_.max_delay;
}

void LockManager::send_lock(int type, std::string_view agent, std::string_view resource, Out& out) {
  auto m = std::make_unique<LockMessage>();
  m->set_type(static_cast<LockMessage::LockType>(type));
  m->set_agent(std::string(agent));
  m->set_resource(std::string(resource));
  out.push_back(std::move(m));
  ++stats_.messages_sent;
}

void LockManager::serve(SimTime now, bool granting, Out& out) {
  // Locks of robots not heard from for lost_timeout go (their confirmations still count).
  if (granting) {
    for (auto it = table_.begin(); it != table_.end();) {
      const std::string& x = it->second;
      auto h = heard_.find(x);
      if (x != agent_ && (h == heard_.end() || now - h->second >= config_.lost_timeout))
        it = table_.erase(it);
      else
        ++it;
    }
  }
  std::set<std::tuple<int, std::string, std::string>> answered;
  for (const Pending& p : inbox_) {
    if (!answered.insert({p.type, p.agent, p.resource}).second) continue;  // duplicate
    auto holder = table_.find(p.resource);
    if (p.type == LockMessage::GET) {
      if (holder != table_.end() && holder->second != p.agent) {
        send_lock(LockMessage::REFUSE, p.agent, p.resource, out);
      } else if (!granting) {
        // Quiet or without a majority: no answer, the GET is resent.
      } else if (holder != table_.end() || may_grant(p.resource, p.agent, now)) {
        table_[p.resource] = p.agent;  // idempotent for the holder
        last_confirm_[p.resource] = Confirm{now, p.agent};
        send_lock(LockMessage::ACCEPT, p.agent, p.resource, out);
      } else {
        send_lock(LockMessage::REFUSE, p.agent, p.resource, out);
      }
    } else {  // RELEASE: the sender stopped believing it holds the resource when it sent this
      if (holder != table_.end() && holder->second == p.agent) {
        table_.erase(holder);
        auto lc = last_confirm_.find(p.resource);
        if (lc != last_confirm_.end() && lc->second.agent == p.agent) last_confirm_.erase(lc);
      }
      send_lock(LockMessage::RELEASE_RVCD, p.agent, p.resource, out);  // also a stray one
    }
  }
  inbox_.clear();
}

// ---- this robot's requests -------------------------------------------------------------------

void LockManager::run_own(SimTime now, Out& out) {
  const bool master = is_master();
  const bool granting = master && authority_ && now >= quiet_until_;
  auto resend_due = [&](const std::optional<SimTime>& last) {
    return !last || now - *last >= config_.resend_period;
  };
  for (auto& [r, o] : own_) {
    switch (o.state) {
      case LockState::kRequested:
        if (master) {
          // The master serves itself locally, under the same rules.
          if (!granting) break;
          auto holder = table_.find(r);
          if ((holder != table_.end() && holder->second == agent_) ||
              (holder == table_.end() && may_grant(r, agent_, now))) {
            table_[r] = agent_;
            set_state(o, LockState::kAccepted);
            o.was_held = true;
            o.confirmed_at = now;
            ++stats_.accepted;
          } else {
            set_state(o, LockState::kRefused);
            ++stats_.refused;
          }
        } else if (now >= o.get_not_before && resend_due(o.last_get)) {
          send_lock(LockMessage::GET, agent_, r, out);
          o.get_sent = true;
          o.last_get = now;
        }
        break;
      case LockState::kAccepted:
        if (master) {
          if (!granting) break;
          auto holder = table_.find(r);
          if (holder == table_.end() && may_grant(r, agent_, now)) {
            table_[r] = agent_;  // re-claim after a change of master
            holder = table_.find(r);
          }
          if (holder != table_.end() && holder->second == agent_) o.confirmed_at = now;
        } else if (now - o.confirmed_at >= config_.resend_period && resend_due(o.last_get)) {
          // Not confirmed lately (lost status, new master): claim it again.
          send_lock(LockMessage::GET, agent_, r, out);
          o.last_get = now;
        }
        break;
      case LockState::kReleasing:
        if (!o.release_sent && !far_enough(o)) {
          if (granting) {
            auto holder = table_.find(r);
            if (holder != table_.end() && holder->second == agent_) o.confirmed_at = now;
          }
          break;
        }
        if (master) {
          auto holder = table_.find(r);
          if (holder != table_.end() && holder->second == agent_) table_.erase(holder);
          auto lc = last_confirm_.find(r);
          if (lc != last_confirm_.end() && lc->second.agent == agent_) last_confirm_.erase(lc);
          set_state(o, LockState::kNone);
          o.release_sent = false;
          ++stats_.released;
        } else if (!o.release_sent || resend_due(o.last_release)) {
          o.release_sent = true;  // from now on we do not hold it
          send_lock(LockMessage::RELEASE, agent_, r, out);
          o.last_release = now;
        }
        break;
      case LockState::kNone:
      case LockState::kRefused:
        if (!o.stray || o.state != LockState::kNone) break;
        if (master) {
          auto holder = table_.find(r);
          if (holder != table_.end() && holder->second == agent_) table_.erase(holder);
          o.stray = false;
        } else if (resend_due(o.last_release)) {
          send_lock(LockMessage::RELEASE, agent_, r, out);
          o.last_release = now;
          o.stray = false;
        }
        break;
    }
  }
}

// ---- the step --------------------------------------------------------------------------------

Out LockManager::step(SimTime now) {
  advance(now);
  now = now_;
  Out out;

  // Leases: ACCEPTED only while confirmed within the lease.
  for (auto& [r, o] : own_) {
    if (o.state == LockState::kAccepted && now >= o.confirmed_at + config_.lease) {
      set_state(o, LockState::kRefused);
      ++stats_.lease_expired;
    }
  }

  update_election(now);
  update_authority(now);

  // Announce our master (ourselves if master): a promise to endorse nobody else for a while.
  if (!endorsee_.empty() && (!last_announce_ || now - *last_announce_ >= config_.announce_period)) {
    auto a = std::make_unique<LockMasterAnnounce>();
    a->set_agent(endorsee_);
    out.push_back(std::move(a));
    ++stats_.messages_sent;
    pledged_to_ = endorsee_;
    pledge_until_ = now + config_.endorse_hold;
    last_announce_ = now;
  }

  const bool granting = is_master() && authority_ && now >= quiet_until_;
  if (is_master())
    serve(now, granting, out);
  else
    inbox_.clear();
  run_own(now, out);

  // The master's table: the confirmations that keep the holders' leases alive.
  if (granting && (!last_status_ || now - *last_status_ >= config_.announce_period)) {
    auto s = std::make_unique<LockStatus>();
    s->set_master(agent_);
    for (const auto& [r, x] : table_) {
      auto* e = s->add_locks();
      e->set_resource(r);
      e->set_agent(x);
      if (x != agent_) last_confirm_[r] = Confirm{now, x};
    }
    out.push_back(std::move(s));
    ++stats_.messages_sent;
    last_status_ = now;
  }
  return out;
}

}  // namespace llsf::clips
