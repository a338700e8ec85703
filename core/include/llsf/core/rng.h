// SPDX-License-Identifier: MIT
// Seeded randomness with named, independent streams and portable distributions.
//
// Every random draw in llsfsim comes from a RandomStream obtained by name from the scenario's Rng:
// rng.stream("comm"), rng.stream("kinematic/robot1/laser"), ... A stream's numbers depend only on
// (seed, name), so adding draws in one module never changes another module's numbers. The
// distributions are implemented here (not std::*_distribution, whose output differs between
// standard libraries), so a seed gives the same numbers on every machine of this kind.
#pragma once

#include <cstdint>
#include <span>
#include <string_view>

namespace llsf::core {

/// 64-bit FNV-1a hash of bytes; also used for state hashes.
constexpr std::uint64_t kFnvOffset = 0xcbf29ce484222325ULL;
constexpr std::uint64_t kFnvPrime = 0x100000001b3ULL;
inline std::uint64_t fnv1a(const void* data, std::size_t n, std::uint64_t h = kFnvOffset) {
  const auto* p = static_cast<const unsigned char*>(data);
  for (std::size_t i = 0; i < n; ++i) {
    h ^= p[i];
    h *= kFnvPrime;
  }
  return h;
}
inline std::uint64_t fnv1a(std::string_view s, std::uint64_t h = kFnvOffset) {
  return fnv1a(s.data(), s.size(), h);
}

/// One independent pseudo-random sequence (xoshiro256**). Copyable: a copy continues identically.
class RandomStream {
 public:
  /// A stream seeded from a 64-bit value (expanded with splitmix64).
  explicit RandomStream(std::uint64_t seed = 0);

  /// The next raw 64 random bits.
  std::uint64_t next_u64();
  /// Uniform in [0, 1) with 53 random bits.
  double uniform01();
  /// Uniform in [lo, hi).
  double uniform(double lo, double hi) { return lo + (hi - lo) * uniform01(); }
  /// Uniform integer in [lo, hi] (inclusive, unbiased); requires lo <= hi.
  std::int64_t uniform_int(std::int64_t lo, std::int64_t hi);
  /// Gaussian with the given mean and standard deviation (Marsaglia polar method).
  double normal(double mean, double stddev);
  /// out.size() draws of normal(mean, stddev), in order (the same values as that many calls,
  /// for less per draw).
  void normals(double mean, double stddev, std::span<double> out);
  /// True with probability p (clamped to [0, 1]).
  bool bernoulli(double p);
  /// Exponential with the given mean (> 0).
  double exponential(double mean);

 private:
  std::uint64_t s_[4];
  double spare_normal_ = 0.0;
  bool has_spare_ = false;
};

/// The scenario's random source: a seed from which named streams are derived.
class Rng {
 public:
  explicit Rng(std::uint64_t seed) : seed_(seed) {}
  std::uint64_t seed() const { return seed_; }
  /// The stream named `name`; the same (seed, name) always gives the same stream.
  RandomStream stream(std::string_view name) const;

 private:
  std::uint64_t seed_;
};

}  // namespace llsf::core
