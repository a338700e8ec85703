// SPDX-License-Identifier: MIT
// Time feature: the (time sec usec) fact of each cycle and the Fawkes time helpers, in C++ so
// that LHS tests such as (timer (time $?t&:(timeout ?now ?t 1.0))) stay cheap.
#include <cmath>

#include "feature.h"

namespace llsf::clips::detail {
namespace {

constexpr std::int64_t kNsPerSec = 1'000'000'000;

class TimeFeature final : public Feature {
 public:
  explicit TimeFeature(HostState& s) : s_(s) {}

  void define(Environment& env) override {
    // (now): seconds of simulated time as FLOAT; in Fawkes-style agents (sec usec), as Fawkes'
    // clips plugin returns it. (now-sec-usec) is (sec usec) in both (the timer's default).
    auto sec_usec = [this](Args&) {
      const std::int64_t ns = s_.now.ns();
      return Value::multifield(
          {Value::integer_value(ns / kNsPerSec), Value::integer_value((ns % kNsPerSec) / 1000)});
    };
    if (s_.config.fawkes) {
      env.define_function("now", "00", sec_usec);
    } else {
      env.define_function("now", "00",
                          [this](Args&) { return Value::float_value(s_.now.seconds()); });
    }
    env.define_function("now-sec-usec", "00", sec_usec);
    // (time-diff-sec ?t1 ?t2): t1 - t2 in seconds; times are (sec usec) or seconds.
    env.define_function("time-diff-sec", "22", [](Args& a) {
      double t1 = 0, t2 = 0;
      if (!read_times(a, t1, t2)) return Value::boolean(false);
      return Value::float_value(t1 - t2);
    });
    // (time-diff ?t1 ?t2): t1 - t2 as (sec usec).
    env.define_function("time-diff", "22", [](Args& a) {
      double t1 = 0, t2 = 0;
      if (!read_times(a, t1, t2)) return Value::boolean(false);
      const auto usec = static_cast<std::int64_t>(std::llround((t1 - t2) * 1e6));
      std::int64_t sec = usec / 1'000'000, rest = usec % 1'000'000;
      if (rest < 0) {
        sec -= 1;
        rest += 1'000'000;
      }
      return Value::multifield({Value::integer_value(sec), Value::integer_value(rest)});
    });
    // (timeout ?now ?since ?secs): more than ?secs passed between ?since and ?now.
    env.define_function("timeout", "33", [](Args& a) {
      double now = 0, since = 0, secs = 0;
      if (!read_times(a, now, since)) return Value::boolean(false);
      if (!a.number(2, secs)) {
        a.env().error(a.function(), "the third argument must be a number of seconds");
        return Value::boolean(false);
      }
      a.return_boolean(now - since > secs);  // (no Value made: a test in many rules' LHS)
      return Value{};
    });
    // (time> ?t1 ?t2): t1 later than t2.
    env.define_function("time>", "22", [](Args& a) {
      double t1 = 0, t2 = 0;
      if (!read_times(a, t1, t2)) return Value::boolean(false);
      a.return_boolean(t1 > t2);
      return Value{};
    });
  }

  // (time sec usec) is an ordered fact: its template is the implied one.
  void bind(Environment& env) override { time_ = env.implied_template("time"); }

  void after_reset(Environment& env) override { env.release(fact_); }

  void before_run(Environment& env) override {
    env.retract(fact_);  // (after_run removed it already unless the cycle was cut short)
    const std::int64_t ns = s_.now.ns();
    values_[0].integer = ns / kNsPerSec;
    values_[1].integer = (ns % kNsPerSec) / 1000;
    fact_ = env.assert_fact(time_, values_);
  }

  // The cycle's time fact goes when its rules have run (as Fawkes' time-retract rule at salience
  // -10000 did, without a rule firing and its activation in every cycle).
  void after_run(Environment& env) override { env.retract(fact_); }

 private:
  static bool read_times(Args& a, double& t1, double& t2) {
    if (!a.time(0, t1) || !a.time(1, t2)) {
      a.env().error(a.function(), "times must be (sec usec) multifields or seconds");
      return false;
    }
    return true;
  }

  HostState& s_;
  Template time_;
  FactHandle fact_;
  Value values_[2] = {Value::integer_value(0), Value::integer_value(0)};
};

}  // namespace

std::unique_ptr<Feature> make_time_feature(HostState& s) {
  return std::make_unique<TimeFeature>(s);
}

}  // namespace llsf::clips::detail
