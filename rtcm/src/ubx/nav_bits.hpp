// Bit buffer for navigation data: fields are appended and read most significant bit first at
// absolute bit positions, as the ICDs number them. Scaling helpers shared by the SFRBX decoders.
// Not installed.
#pragma once

#include <array>
#include <cmath>
#include <cstdint>

#include "gvins/base/constants.hpp"

namespace gvins::ubx::detail {

class NavBits {
 public:
  static constexpr int kCapacity = 512;
  /// Appends the `bits` (1..32) low bits of v; bits beyond the capacity are dropped.
  void push(std::uint32_t v, int bits);
  /// Appends `len` bits of `src` starting at its bit `pos`.
  void append(const NavBits& src, int pos, int len) {
    for (int k = 0; k < len; ++k) push(src.u(pos + k, 1), 1);
  }
  /// Unsigned field of 1..32 bits at bit `pos` (bits beyond the end read as zero).
  std::uint32_t u(int pos, int len) const;
  /// Two's complement field.
  std::int64_t s(int pos, int len) const;
  /// Sign-magnitude field (GLONASS).
  std::int64_t sm(int pos, int len) const;
  int size() const { return n_; }
  const std::array<std::uint8_t, kCapacity / 8>& bytes() const { return buf_; }

 private:
  std::array<std::uint8_t, kCapacity / 8> buf_{};
  int n_ = 0;
};

/// Receive times before this GPS week (1999) stand for "no time known yet" (e.g. GpsTime{}).
inline constexpr int kFirstValidWeek = 1024;

inline constexpr double kSemicircle = constants::kPi;  // semicircles to radians (ICD value of pi)
inline double scaled(std::int64_t v, int e) { return std::ldexp(static_cast<double>(v), e); }

}  // namespace gvins::ubx::detail
