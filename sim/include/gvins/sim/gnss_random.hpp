// Reproducible random numbers for the GNSS simulator: a 64-bit generator whose sequence is fixed
// by this file (not by the standard library, whose distributions differ between
// implementations), independent streams derived from (seed, purpose, receiver, satellite, signal)
// so that one satellite's draws never shift another's, and the few distributions needed.
#pragma once

#include <cmath>
#include <cstdint>
#include <initializer_list>

namespace gvins::sim {

/// SplitMix64 finaliser (Steele, Lea & Flood, "Fast splittable pseudorandom number generators",
/// OOPSLA 2014): a bijective 64-bit mix used to derive stream seeds.
constexpr std::uint64_t splitMix64(std::uint64_t x) {
  x += 0x9E3779B97F4A7C15ULL;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ULL;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBULL;
  return x ^ (x >> 31);
}

/// Seed of an independent stream: the run seed mixed with any number of identifiers.
inline std::uint64_t streamSeed(std::uint64_t seed, std::initializer_list<std::uint64_t> ids) {
  std::uint64_t h = splitMix64(seed ^ 0x5A17C0DEULL);
  for (std::uint64_t id : ids) h = splitMix64(h ^ splitMix64(id + 0x1234567ULL));
  return h;
}

/// xoshiro256** (Blackman & Vigna, "Scrambled linear pseudorandom number generators", ACM TOMS
/// 47(4), 2021) with uniform, normal (Marsaglia polar method), exponential and integer draws.
class GnssRandom {
 public:
  explicit GnssRandom(std::uint64_t seed = 1) { reseed(seed); }

  void reseed(std::uint64_t seed) {
    std::uint64_t x = seed;
    for (auto& w : s_) {
      x += 0x9E3779B97F4A7C15ULL;
      w = splitMix64(x);
    }
    haveSpare_ = false;
  }

  std::uint64_t next() {
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

  /// Uniform in [0, 1) with 53 random bits.
  double uniform() { return static_cast<double>(next() >> 11) * 0x1.0p-53; }
  /// Uniform in [a, b).
  double uniform(double a, double b) { return a + (b - a) * uniform(); }
  /// Standard normal (Marsaglia & Bray polar method, SIAM Review 6(3), 1964).
  double normal() {
    if (haveSpare_) {
      haveSpare_ = false;
      return spare_;
    }
    double u, v, s;
    do {
      u = 2.0 * uniform() - 1.0;
      v = 2.0 * uniform() - 1.0;
      s = u * u + v * v;
    } while (s >= 1.0 || s == 0.0);
    const double m = std::sqrt(-2.0 * std::log(s) / s);
    spare_ = v * m;
    haveSpare_ = true;
    return u * m;
  }
  double normal(double sigma) { return sigma * normal(); }
  /// Exponential with the given mean.
  double exponential(double mean) { return -mean * std::log1p(-uniform()); }
  /// Uniform integer in [lo, hi] (lo when hi <= lo).
  std::int64_t integer(std::int64_t lo, std::int64_t hi) {
    if (hi <= lo) return lo;
    const std::uint64_t span = static_cast<std::uint64_t>(hi - lo) + 1;
    return lo + static_cast<std::int64_t>(next() % span);
  }
  /// True with probability p.
  bool bernoulli(double p) { return uniform() < p; }

 private:
  static std::uint64_t rotl(std::uint64_t x, int k) { return (x << k) | (x >> (64 - k)); }
  std::uint64_t s_[4]{};
  double spare_ = 0.0;
  bool haveSpare_ = false;
};

}  // namespace gvins::sim
