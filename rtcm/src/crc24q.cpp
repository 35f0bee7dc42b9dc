#include "gvins/rtcm/crc24q.hpp"

#include <array>

namespace gvins::rtcm {
namespace {

// Generator polynomial of CRC-24Q (RTCM 10403.3, 4.2): x^24 + x^23 + x^18 + x^17 + x^14 + x^11 +
// x^10 + x^7 + x^6 + x^5 + x^4 + x^3 + x + 1.
constexpr std::uint32_t kPoly = 0x1864CFBu;

constexpr std::array<std::uint32_t, 256> makeTable() {
  std::array<std::uint32_t, 256> t{};
  for (std::uint32_t b = 0; b < 256; ++b) {
    std::uint32_t r = b << 16;
    for (int k = 0; k < 8; ++k) {
      r <<= 1;
      if (r & 0x1000000u) r ^= kPoly;
    }
    t[b] = r & 0xFFFFFFu;
  }
  return t;
}

constexpr std::array<std::uint32_t, 256> kTable = makeTable();

}  // namespace

std::uint32_t crc24q(std::span<const std::uint8_t> data, std::uint32_t crc) {
  for (std::uint8_t byte : data) {
    crc = ((crc << 8) & 0xFFFFFFu) ^ kTable[((crc >> 16) ^ byte) & 0xFFu];
  }
  return crc;
}

}  // namespace gvins::rtcm
