// Appends big-endian bit fields to a message payload (the encoder's counterpart of BitReader).
// Values that do not fit their field throw MessageError naming the field, so an encoder never
// silently wraps a number.
#pragma once

#include <cstdint>
#include <vector>

#include "gvins/rtcm/message_error.hpp"

namespace gvins::rtcm {

class BitWriter {
 public:
  /// Unsigned field of 1..64 bits (wider: zeros above bit 63); throws if v >= 2^bits.
  void u(int bits, std::uint64_t v, const char* field);
  /// Two's complement field; throws if v is outside [-2^(bits-1), 2^(bits-1)).
  void s(int bits, std::int64_t v, const char* field);
  /// Sign-magnitude field (GLONASS 1020); throws if |v| >= 2^(bits-1).
  void sm(int bits, std::int64_t v, const char* field);
  void flag(bool b) { put(1, b ? 1u : 0u); }
  /// Number of bits written.
  std::size_t size() const { return bits_; }
  /// The payload, zero-padded to whole bytes.
  const std::vector<std::uint8_t>& bytes() const { return buf_; }

 private:
  void put(int bits, std::uint64_t v);
  std::vector<std::uint8_t> buf_;
  std::size_t bits_ = 0;
};

}  // namespace gvins::rtcm
