// Reads big-endian bit fields (RTCM 10403.3, 3.3: most significant bit first) from a message
// payload, never past its end: reading beyond the payload throws MessageError naming the field.
#pragma once

#include <bit>
#include <cstddef>
#include <cstring>
#include <cstdint>
#include <span>

#include "gvins/rtcm/message_error.hpp"

namespace gvins::rtcm {

class BitReader {
 public:
  explicit BitReader(std::span<const std::uint8_t> data) : data_(data), bits_(data.size() * 8) {}

  /// Unsigned field of 1..64 bits (RTCM "uint").
  std::uint64_t u(int bits, const char* field) {
    need(static_cast<std::size_t>(bits), field);
    if (bits <= 0) return 0;
    std::uint64_t v = 0;
    if (bits > 56) {
      v = peek(bits - 32) << 32;
      pos_ += static_cast<std::size_t>(bits - 32);
      v |= peek(32);
      pos_ += 32;
      return v;
    }
    v = peek(bits);
    pos_ += static_cast<std::size_t>(bits);
    return v;
  }
  /// Two's complement signed field of 2..64 bits (RTCM "int").
  std::int64_t s(int bits, const char* field) {
    const std::uint64_t v = u(bits, field);
    if (bits == 64) return static_cast<std::int64_t>(v);
    const std::uint64_t sign = std::uint64_t{1} << (bits - 1);
    return static_cast<std::int64_t>(v ^ sign) - static_cast<std::int64_t>(sign);
  }
  /// Sign-magnitude field (RTCM "intS", used by GLONASS 1020): MSB is the sign.
  std::int64_t sm(int bits, const char* field) {
    const std::uint64_t v = u(bits, field);
    const std::uint64_t sign = std::uint64_t{1} << (bits - 1);
    const auto mag = static_cast<std::int64_t>(v & (sign - 1));
    return (v & sign) ? -mag : mag;
  }
  bool flag(const char* field) { return u(1, field) != 0; }
  void skip(int bits, const char* field) {
    need(static_cast<std::size_t>(bits), field);
    pos_ += static_cast<std::size_t>(bits);
  }
  /// Throws unless `bits` more bits are available (checks a whole block at once).
  void need(std::size_t bits, const char* field) const;

  std::size_t position() const { return pos_; }
  std::size_t remaining() const { return bits_ - pos_; }
  std::size_t size() const { return bits_; }

 private:
  // Reads `bits` (1..56) bits at pos_ without bounds checks beyond the payload (bytes beyond the
  // end read as zero).
  std::uint64_t peek(int bits) const {
    const std::size_t byte = pos_ >> 3;
    const int shift = static_cast<int>(pos_ & 7);
    std::uint64_t w = 0;
    const std::size_t n = data_.size();
    if (byte + 8 <= n) {
      std::memcpy(&w, data_.data() + byte, 8);
      if constexpr (std::endian::native == std::endian::little) w = __builtin_bswap64(w);
    } else {
      for (std::size_t k = 0; k < 8; ++k) w = (w << 8) | (byte + k < n ? data_[byte + k] : 0u);
    }
    return (w << shift) >> (64 - bits);
  }

  std::span<const std::uint8_t> data_;
  std::size_t bits_;
  std::size_t pos_ = 0;
};

}  // namespace gvins::rtcm
