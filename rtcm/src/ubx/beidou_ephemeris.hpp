// Shared by the BeiDou D1 and D2 decoders (BDS-SIS-ICD-B1I 3.0): the BCH(15,11,1) word check
// (5.1.3) and the step from the broadcast integers to a KeplerEphemeris (scale factors of tables
// 5-9 to 5-13, identical for D1 and D2; times in BDT). Only the bit positions differ between D1
// (subframes 1-3) and D2 (subframe 1 pages 1-10). Not installed.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <vector>

#include "gvins/ubx/navigation_assembler.hpp"
#include "nav_bits.hpp"

namespace gvins::ubx::detail {

/// The 224 information bits of a D1/D2 subframe (26 of word 1, 22 of each further word) after the
/// BCH(15,11,1) check of BDS-SIS-ICD-B1I 3.0, 5.1.3; std::nullopt when a code word fails.
std::optional<NavBits> beidouInfoBits(const std::vector<std::uint32_t>& words);

/// The checked subframe of a D1/D2 message: ten words passing BCH, with the preamble (5.2.2). A
/// failing check is counted (parityFailures, or unknownMessages for a wrong word count or
/// preamble) and gives std::nullopt. Bits 15-17 are FraID, 18-37 the SOW (20 bits, D1 and D2).
std::optional<NavBits> beidouSubframe(const SfrbxMessage& msg, NavigationCounts& counts);

/// The broadcast integers of one BeiDou ephemeris set, before scaling (D1 and D2 alike).
struct BeidouBroadcast {
  std::uint32_t sow = 0;  ///< SOW of subframe 1 (D1) or of page 1 of subframe 1 (D2)
  int health = 0, aodc = 0, urai = 0, week = 0, aode = 0;
  std::uint32_t toc = 0, toe = 0, e = 0, sqrtA = 0;
  std::int64_t tgd1 = 0, tgd2 = 0, a0 = 0, a1 = 0, a2 = 0;
  std::int64_t deltaN = 0, cuc = 0, m0 = 0, cus = 0, crc = 0, crs = 0, cic = 0, cis = 0, i0 = 0,
               omegaDot = 0, iDot = 0, omega0 = 0, omega = 0;
};

/// The record as the RTCM 1042 decoder fills it; std::nullopt when toe, toc or SOW are not within
/// a week.
std::optional<KeplerEphemeris> beidouEphemeris(const BeidouBroadcast& b, SatId sat, NavMessage message);

/// Klobuchar alpha0-3 and beta0-3, eight signed bits each from bits `alphaBit` and `betaBit` of a
/// subframe (D1 subframe 1: 98, 130; D2 page 2: 42, 74), scaled by table 5-9 (alpha 2^-30,
/// 2^-27, 2^-24, 2^-24; beta 2^11, 2^14, 2^16, 2^16).
KlobucharParameters beidouKlobuchar(const NavBits& bits, int alphaBit, int betaBit);

/// Hands a decoded set on: a record that failed beidouEphemeris() counts as an unknown message;
/// else the set's AODE and toc become `lastAode`/`lastToc` (so that its repetitions are not sent
/// again) and the record goes to `out`. True when a record was sent.
bool emitBeidouEphemeris(const std::optional<KeplerEphemeris>& e, const BeidouBroadcast& b, int& lastAode,
                         std::uint32_t& lastToc, NavDataUpdate& out, NavigationCounts& counts);

}  // namespace gvins::ubx::detail
