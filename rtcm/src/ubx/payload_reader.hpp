// Little-endian field reads from a UBX payload with bounds checks (u-blox interface description,
// "UBX data types": U1/I1/X1, U2/I2, U4/I4, R4 IEEE 754 single, R8 double). A read past the end
// throws rtcm::MessageError naming the field.
#pragma once

#include <bit>
#include <cstdint>
#include <cstring>
#include <span>
#include <string>

#include "gvins/rtcm/message_error.hpp"

namespace gvins::ubx::detail {

class PayloadReader {
 public:
  explicit PayloadReader(std::span<const std::uint8_t> p) : p_(p) {}
  std::size_t size() const { return p_.size(); }
  void need(std::size_t offset, std::size_t n, const char* field) const {
    if (offset + n > p_.size()) {
      throw rtcm::MessageError(field, "payload of " + std::to_string(p_.size()) +
                                          " bytes ends before byte " + std::to_string(offset + n));
    }
  }
  std::uint8_t u1(std::size_t o, const char* f) const { need(o, 1, f); return p_[o]; }
  std::int8_t i1(std::size_t o, const char* f) const { return static_cast<std::int8_t>(u1(o, f)); }
  std::uint16_t u2(std::size_t o, const char* f) const {
    need(o, 2, f);
    return static_cast<std::uint16_t>(p_[o] | (p_[o + 1] << 8));
  }
  std::int16_t i2(std::size_t o, const char* f) const { return static_cast<std::int16_t>(u2(o, f)); }
  std::uint32_t u4(std::size_t o, const char* f) const {
    need(o, 4, f);
    return static_cast<std::uint32_t>(p_[o]) | (static_cast<std::uint32_t>(p_[o + 1]) << 8) |
           (static_cast<std::uint32_t>(p_[o + 2]) << 16) | (static_cast<std::uint32_t>(p_[o + 3]) << 24);
  }
  std::int32_t i4(std::size_t o, const char* f) const { return static_cast<std::int32_t>(u4(o, f)); }
  float r4(std::size_t o, const char* f) const { return std::bit_cast<float>(u4(o, f)); }
  double r8(std::size_t o, const char* f) const {
    const std::uint64_t lo = u4(o, f), hi = u4(o + 4, f);
    return std::bit_cast<double>(lo | (hi << 32));
  }

 private:
  std::span<const std::uint8_t> p_;
};

}  // namespace gvins::ubx::detail
