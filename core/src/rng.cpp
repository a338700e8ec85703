// SPDX-License-Identifier: MIT
#include "llsf/core/rng.h"

#include <cmath>

#include "llsf/core/assert.h"

namespace llsf::core {

namespace {
std::uint64_t splitmix64(std::uint64_t& x) {
  std::uint64_t z = (x += 0x9e3779b97f4a7c15ULL);
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}
inline std::uint64_t rotl(std::uint64_t x, int k) { return (x << k) | (x >> (64 - k)); }
}  // namespace

RandomStream::RandomStream(std::uint64_t seed) {
  std::uint64_t x = seed;
  for (auto& s : s_) s = splitmix64(x);
}

std::uint64_t RandomStream::next_u64() {
  const std::uint64_t result = rotl(s_[1] * 5, 7) * 9;
  const std::uint64_t t = s_[1] << 17;
  s_[2] ^= s_[0];
  s_[3] ^= s_[1];
  s_[1] ^= s_[2];
  s_[0] ^= s_[3];
  s_[2] ^= t;
  s_[3] = rotl(s_[3], 45);
  return result;
}

double RandomStream::uniform01() { return static_cast<double>(next_u64() >> 11) * 0x1.0p-53; }

std::int64_t RandomStream::uniform_int(std::int64_t lo, std::int64_t hi) {
  LLSF_DEMAND(lo <= hi);
  const std::uint64_t range = static_cast<std::uint64_t>(hi) - static_cast<std::uint64_t>(lo);
  if (range == ~std::uint64_t{0}) return static_cast<std::int64_t>(next_u64());
  const std::uint64_t n = range + 1;
  // Rejection sampling on the top of the 64-bit range: unbiased and portable.
  const std::uint64_t limit = ~std::uint64_t{0} - (~std::uint64_t{0} % n);
  std::uint64_t r;
  do {
    r = next_u64();
  } while (r >= limit);
  return static_cast<std::int64_t>(static_cast<std::uint64_t>(lo) + r % n);
}

double RandomStream::normal(double mean, double stddev) {
  if (has_spare_) {
    has_spare_ = false;
    return mean + stddev * spare_normal_;
  }
  double u, v, s;
  do {
    u = 2.0 * uniform01() - 1.0;
    v = 2.0 * uniform01() - 1.0;
    s = u * u + v * v;
  } while (s >= 1.0 || s == 0.0);
  const double f = std::sqrt(-2.0 * std::log(s) / s);
  spare_normal_ = v * f;
  has_spare_ = true;
  return mean + stddev * u * f;
}

void RandomStream::normals(double mean, double stddev, std::span<double> out) {
  for (double& v : out) v = normal(mean, stddev);
}

bool RandomStream::bernoulli(double p) {
  if (p <= 0.0) return false;
  if (p >= 1.0) return true;
  return uniform01() < p;
}

double RandomStream::exponential(double mean) {
  LLSF_DEMAND(mean > 0.0);
  return -mean * std::log1p(-uniform01());
}

RandomStream Rng::stream(std::string_view name) const {
  std::uint64_t x = seed_;
  const std::uint64_t mixed = splitmix64(x) ^ fnv1a(name);
  return RandomStream(mixed);
}

}  // namespace llsf::core
