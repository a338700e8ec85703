// SPDX-License-Identifier: MIT
// Simulated time as integer nanoseconds: exact, no floating-point drift over long games.
#pragma once

#include <cmath>
#include <compare>
#include <cstdint>

namespace llsf::core {

/// A point in simulated time, or a duration, in integer nanoseconds.
/// Trivially copyable; arithmetic is exact (an 18-minute game is ~1.1e12 ns, far from overflow).
class SimTime {
 public:
  constexpr SimTime() = default;

  static constexpr SimTime from_ns(std::int64_t ns) { return SimTime(ns); }
  static constexpr SimTime from_us(std::int64_t us) { return SimTime(us * 1000); }
  static constexpr SimTime from_ms(std::int64_t ms) { return SimTime(ms * 1000000); }
  static constexpr SimTime from_sec(std::int64_t s) { return SimTime(s * 1000000000); }
  /// Rounds to the nearest nanosecond (for user-facing values given in seconds).
  static SimTime from_seconds(double s) { return SimTime(std::llround(s * 1e9)); }
  /// The period of a rate, rounded to the nearest nanosecond; hz must be > 0.
  static SimTime period_of_hz(double hz) { return SimTime(std::llround(1e9 / hz)); }

  constexpr std::int64_t ns() const { return ns_; }
  constexpr double seconds() const { return static_cast<double>(ns_) * 1e-9; }

  constexpr SimTime& operator+=(SimTime o) {
    ns_ += o.ns_;
    return *this;
  }
  constexpr SimTime& operator-=(SimTime o) {
    ns_ -= o.ns_;
    return *this;
  }
  friend constexpr SimTime operator+(SimTime a, SimTime b) { return SimTime(a.ns_ + b.ns_); }
  friend constexpr SimTime operator-(SimTime a, SimTime b) { return SimTime(a.ns_ - b.ns_); }
  friend constexpr SimTime operator*(SimTime a, std::int64_t k) { return SimTime(a.ns_ * k); }
  friend constexpr SimTime operator*(std::int64_t k, SimTime a) { return SimTime(a.ns_ * k); }
  friend constexpr std::int64_t operator/(SimTime a, SimTime b) { return a.ns_ / b.ns_; }
  friend constexpr auto operator<=>(SimTime a, SimTime b) = default;

 private:
  constexpr explicit SimTime(std::int64_t ns) : ns_(ns) {}
  std::int64_t ns_ = 0;
};

}  // namespace llsf::core
