// Portable, reproducible random numbers for the simulator: xoshiro256** (Blackman & Vigna,
// "Scrambled linear pseudorandom number generators", ACM TOMS 2021) seeded through splitmix64,
// with uniform and normal variates computed here (not by <random>'s distributions, whose
// output differs between standard libraries). The same (seed, stream) gives the same numbers
// with any compiler, so that the same seed produces byte-identical datasets.
#pragma once

#include <cmath>
#include <cstdint>
#include <string_view>

namespace gvins::sim {

/// splitmix64 step (Steele, Lea & Flood, "Fast splittable pseudorandom number generators",
/// OOPSLA 2014): a good 64-bit mixer of consecutive states.
inline std::uint64_t splitmix64(std::uint64_t& state) {
  std::uint64_t z = (state += 0x9E3779B97F4A7C15ULL);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
  return z ^ (z >> 31);
}

/// Stateless 64-bit hash of a few integers (splitmix64 finaliser chain); used for
/// position-keyed randomness (texture cells, landmarks) that must not depend on the order in
/// which it is queried.
inline std::uint64_t hashCombine(std::uint64_t a, std::uint64_t b) {
  std::uint64_t s = a ^ (b + 0x9E3779B97F4A7C15ULL + (a << 6) + (a >> 2));
  return splitmix64(s);
}
inline std::uint64_t hash4(std::uint64_t seed, std::int64_t a, std::int64_t b, std::int64_t c) {
  return hashCombine(hashCombine(hashCombine(seed, static_cast<std::uint64_t>(a)), static_cast<std::uint64_t>(b)),
                     static_cast<std::uint64_t>(c));
}
/// FNV-1a of a name, to derive a named stream from a seed.
constexpr std::uint64_t nameHash(std::string_view name) {
  std::uint64_t h = 0xCBF29CE484222325ULL;
  for (const char c : name) {
    h ^= static_cast<unsigned char>(c);
    h *= 0x100000001B3ULL;
  }
  return h;
}
/// Uniform double in [0, 1) from 64 random bits (53-bit mantissa).
inline double unitFromBits(std::uint64_t x) { return static_cast<double>(x >> 11) * 0x1.0p-53; }

class Rng {
 public:
  /// Independent streams of one seed: Rng(seed, nameHash("imu")), Rng(seed, nameHash("camera")) ...
  explicit Rng(std::uint64_t seed = 0, std::uint64_t stream = 0) {
    std::uint64_t sm = hashCombine(seed, stream);
    for (auto& s : s_) s = splitmix64(sm);
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
  /// Uniform in [0, 1).
  double uniform() { return unitFromBits(next()); }
  double uniform(double lo, double hi) { return lo + (hi - lo) * uniform(); }
  /// Uniform integer in [0, n) for 0 < n < 2^32, by multiply-shift (Lemire, "Fast random
  /// integer generation in an interval", ACM TOMS 2019; bias < n / 2^32).
  std::uint32_t below(std::uint32_t n) {
    return static_cast<std::uint32_t>(((next() >> 32) * static_cast<std::uint64_t>(n)) >> 32);
  }
  /// Standard normal variate (Marsaglia polar method), using only +,*,log,sqrt so results are
  /// identical wherever IEEE double and a correctly rounded sqrt are used (log from libm).
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

 private:
  static std::uint64_t rotl(std::uint64_t x, int k) { return (x << k) | (x >> (64 - k)); }
  std::uint64_t s_[4];
  double spare_ = 0.0;
  bool haveSpare_ = false;
};

}  // namespace gvins::sim
