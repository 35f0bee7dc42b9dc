#include "gvins/rtcm/crc24q.hpp"

#include <array>

namespace gvins::rtcm {
namespace {

// Generator polynomial of CRC-24Q (RTCM 10403.3, 4.2): x^24 + x^23 + x^18 + x^17 + x^14 + x^11 +
// x^10 + x^7 + x^6 + x^5 + x^4 + x^3 + x + 1.
constexpr std::uint32_t kPoly = 0x1864CFBu;

using Table = std::array<std::uint32_t, 256>;

// kTables[k][x]: the register after feeding byte x and then k zero bytes into a zero register.
// Because the CRC is linear and a 24-bit register is replaced entirely by three bytes, three bytes
// b0 b1 b2 update a register (r2 r1 r0) to T2[r2^b0] ^ T1[r1^b1] ^ T0[r0^b2].
constexpr std::array<Table, 3> makeTables() {
  std::array<Table, 3> t{};
  for (std::uint32_t b = 0; b < 256; ++b) {
    std::uint32_t r = b << 16;
    for (int k = 0; k < 8; ++k) {
      r <<= 1;
      if (r & 0x1000000u) r ^= kPoly;
    }
    t[0][b] = r & 0xFFFFFFu;
  }
  for (int k = 1; k < 3; ++k) {
    for (std::uint32_t b = 0; b < 256; ++b) {
      const std::uint32_t r = t[k - 1][b];
      t[k][b] = ((r << 8) & 0xFFFFFFu) ^ t[0][r >> 16];
    }
  }
  return t;
}

constexpr std::array<Table, 3> kTables = makeTables();

}  // namespace

std::uint32_t crc24q(std::span<const std::uint8_t> data, std::uint32_t crc) {
  const std::uint8_t* p = data.data();
  std::size_t n = data.size();
  crc &= 0xFFFFFFu;
  for (; n >= 3; n -= 3, p += 3) {
    crc = kTables[2][((crc >> 16) ^ p[0]) & 0xFFu] ^ kTables[1][((crc >> 8) ^ p[1]) & 0xFFu] ^
          kTables[0][(crc ^ p[2]) & 0xFFu];
  }
  for (; n > 0; --n, ++p) crc = ((crc << 8) & 0xFFFFFFu) ^ kTables[0][((crc >> 16) ^ *p) & 0xFFu];
  return crc;
}

}  // namespace gvins::rtcm
