// SPDX-License-Identifier: MIT
// Locks feature: the resource-lock protocol (LockManager, docs/locks.md) behind Fawkes-style
// (lock (type GET|RELEASE|ACCEPT|REFUSE|RELEASE_RVCD) (agent) (resource)) facts and a
// (lock-role MASTER|SLAVE) fact. Off unless AgentConfig::locks: then locks.clp is not loaded
// (the agent may define its own `lock` template), the functions report an error and lock
// messages stay ordinary protobuf-msg facts.
//
// Each cycle, before the run (this feature runs before the protobuf feature): received
// LockMessage/LockMasterAnnounce/LockStatus are taken out of the inbox and given to the manager
// (every other message counts as a sign of life of its sender), the pose is passed on, the
// manager steps and its messages are broadcast, and the facts follow the manager's states. After
// the run the manager steps again (same time) to send what the rules asked for at once.
#include <map>
#include <optional>

#include "feature.h"
#include "llsf/clips/lock_manager.h"
#include "llsf/core/rng.h"

namespace llsf::clips::detail {
namespace {

class LocksFeature final : public Feature {
 public:
  explicit LocksFeature(HostState& s) : s_(s) {}

  void define(Environment& env) override {
    // (lock-request R), (lock-release R): called by the rules of locks.clp.
    env.define_function("lock-request", "11k", [this, &env](Args& a) {
      std::string_view r;
      if (!check(env, a, r)) return Value{};
      mgr_->request(r);
      Shown& sh = shown_[std::string(r)];
      env.retract(sh.refuse);
      const LockState st = mgr_->state(r);
      if (st == LockState::kAccepted && !env.exists(sh.accept)) {
        env.release(sh.accept);
        sh.accept = assert_lock(env, "ACCEPT", r, true);
      }
      set_state(sh, r, st);
      return Value{};
    });
    env.define_function("lock-release", "11k", [this, &env](Args& a) {
      std::string_view r;
      if (!check(env, a, r)) return Value{};
      mgr_->release(r);
      Shown& sh = shown_[std::string(r)];
      env.retract(sh.accept);
      env.retract(sh.refuse);
      set_state(sh, r, mgr_->state(r));
      if (sh.state == LockState::kNone) assert_lock(env, "RELEASE_RVCD", r, false);
      return Value{};
    });
    // (lock-assert GET|RELEASE R): asserts this robot's (lock (type ...) (agent ...) (resource R))
    // for agent code that must also load without the lock template (locks off), without
    // parsing the fact from a string in every call as assert-string does.
    env.define_function("lock-assert", "22k", [this, &env](Args& a) {
      std::string_view type;
      std::string_view r;
      if (!a.text(0, type) || (type != "GET" && type != "RELEASE")) {
        env.error(a.function(), "the type must be GET or RELEASE");
        return Value::boolean(false);
      }
      if (!a.text(1, r) || r.empty()) {
        env.error(a.function(), "the resource must be a symbol or string");
        return Value::boolean(false);
      }
      if (!mgr_) {
        env.error(a.function(), "locks are off (AgentConfig::locks)");
        return Value::boolean(false);
      }
      assert_lock(env, type == "GET" ? "GET" : "RELEASE", r, false);
      return Value::boolean(true);
    });
    // (lock-state R): NONE, REQUESTED, ACCEPTED, REFUSED or RELEASING.
    env.define_function("lock-state", "11k", [this, &env](Args& a) {
      std::string_view r;
      if (!check(env, a, r)) return Value::symbol("NONE");
      return Value::symbol(to_string(mgr_->state(r)));
    });
    // (lock-master): the master this robot follows (itself if master), or nil.
    env.define_function("lock-master", "00", [this, &env](Args& a) {
      if (!mgr_) {
        env.error(a.function(), "locks are off (AgentConfig::locks)");
        return Value::symbol("nil");
      }
      return Value::symbol(mgr_->master().empty() ? "nil" : mgr_->master());
    });
  }

  void bind(Environment& env) override {
    if (!s_.config.locks) return;  // locks.clp is not loaded
    lock_ = env.find_template("lock");
    role_ = env.find_template("lock-role");
  }

  // A restarted agent starts a fresh manager: the master releases its old locks (stray).
  void after_reset(Environment& env) override {
    for (auto& [r, sh] : shown_) {
      env.release(sh.accept);
      env.release(sh.refuse);
    }
    shown_.clear();
    synced_version_.reset();
    env.release(role_fact_);
    if (!s_.config.locks) return;
    mgr_.emplace(s_.config.robot_name, s_.config.lock_config,
                 core::Rng(s_.config.seed).stream("clips/locks").next_u64());
    set_role(env);
  }

  void before_run(Environment& env) override {
    if (!mgr_) return;
    // Lock messages are the feature's; the rest stay in the inbox for protobuf-msg facts.
    auto& inbox = s_.inbox;
    std::size_t keep = 0;
    for (std::size_t i = 0; i < inbox.size(); ++i) {
      auto& r = inbox[i];
      if (mgr_->receive(*r.message, r.from, r.at)) continue;
      if (keep != i) inbox[keep] = std::move(r);
      ++keep;
    }
    inbox.resize(keep);
    if (s_.pose) mgr_->set_pose(*s_.pose);
    step(env);
  }

  // Again after the run, so that the rules' requests and releases go out in this cycle (and the
  // master's own answers appear as facts for the next one).
  void after_run(Environment& env) override {
    if (mgr_) step(env);
  }

 private:
  struct Shown {
    LockState state = LockState::kNone;
    FactHandle accept, refuse;
  };

  void step(Environment& env) {
    for (const auto& m : mgr_->step(s_.now))
      if (s_.io.broadcast) s_.io.broadcast(*m);
    sync(env);
  }

  // Every change of a shown state goes to AgentIo::lock_events.
  void set_state(Shown& sh, std::string_view r, LockState st) {
    if (st == sh.state) return;
    const LockState from = sh.state;
    sh.state = st;
    if (s_.io.lock_events) s_.io.lock_events(LockEvent{s_.now, r, from, st});
  }

  bool check(Environment& env, Args& a, std::string_view& r) {
    if (!mgr_) {
      env.error(a.function(), "locks are off (AgentConfig::locks)");
      return false;
    }
    if (!a.text(0, r) || r.empty()) {
      env.error(a.function(), "the resource must be a symbol or string");
      return false;
    }
    return true;
  }

  FactHandle assert_lock(Environment& env, const char* type, std::string_view r, bool keep) {
    const Value v[] = {Value::symbol(type), Value::symbol(s_.config.robot_name),
                       Value::symbol(std::string(r))};
    FactHandle h = env.assert_fact(lock_, v);
    if (!keep) env.release(h);
    return h;
  }

  void set_role(Environment& env) {
    const bool master = mgr_->is_master();
    if (!role_fact_.empty() && env.exists(role_fact_) && master == role_master_) return;
    env.retract(role_fact_);
    const Value v[] = {Value::symbol(master ? "MASTER" : "SLAVE")};
    role_fact_ = env.assert_fact(role_, v);
    role_master_ = master;
  }

  // The facts follow the manager: ACCEPT while ACCEPTED, REFUSE from a refusal or a lost lease
  // until the next request, RELEASE_RVCD when a release is done.
  void sync(Environment& env) {
    set_role(env);
    // Nothing new since the last walk (most cycles): the facts already show every state.
    if (synced_version_ && *synced_version_ == mgr_->states_version()) return;
    synced_version_ = mgr_->states_version();
    // One sorted walk over the manager's resources and shown_ (both ordered by name): shown_
    // gains every resource with a state, and each entry is updated in name order, as a look-up
    // per entry would.
    auto it = shown_.begin();
    mgr_->for_each_state([&](const std::string& r, LockState st) {
      for (; it != shown_.end() && it->first < r; ++it)
        update(env, it->first, it->second, LockState::kNone);
      if (it == shown_.end() || it->first != r) {
        if (st == LockState::kNone) return;
        it = shown_.emplace_hint(it, r, Shown{});
      }
      update(env, it->first, it->second, st);
      ++it;
    });
    for (; it != shown_.end(); ++it) update(env, it->first, it->second, LockState::kNone);
  }

  // One shown entry follows the manager's state `st` (facts and lock events on a change).
  void update(Environment& env, const std::string& r, Shown& sh, LockState st) {
    if (st == sh.state) return;
    switch (st) {
      case LockState::kAccepted:
        env.retract(sh.refuse);
        env.retract(sh.accept);
        sh.accept = assert_lock(env, "ACCEPT", r, true);
        break;
      case LockState::kRefused:
        env.retract(sh.accept);
        env.retract(sh.refuse);
        sh.refuse = assert_lock(env, "REFUSE", r, true);
        break;
      case LockState::kNone:
        env.retract(sh.accept);
        env.retract(sh.refuse);
        if (sh.state == LockState::kReleasing) assert_lock(env, "RELEASE_RVCD", r, false);
        break;
      case LockState::kRequested:
      case LockState::kReleasing:
        env.retract(sh.accept);
        break;
    }
    set_state(sh, r, st);
  }

  HostState& s_;
  std::optional<LockManager> mgr_;
  Template lock_, role_;
  FactHandle role_fact_;
  bool role_master_ = false;
  std::optional<std::uint64_t> synced_version_;  // the manager's states_version() shown
  std::map<std::string, Shown, std::less<>> shown_;
};

}  // namespace

std::unique_ptr<Feature> make_locks_feature(HostState& s) {
  return std::make_unique<LocksFeature>(s);
}

}  // namespace llsf::clips::detail
