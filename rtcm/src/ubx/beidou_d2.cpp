// BeiDou D2 decoding: BDS-SIS-ICD-B1I 3.0, 5.3 (D2 frame structure: a 3-s frame of five 0.6-s
// subframes; subframe 1 cycles through pages 1-10 in 30 s; page layout figure 5-12 "bit allocation
// for pages 1-10 of subframe 1 in format D2"; scale factors as D1, 5.3.3). Positions below are of
// the 224 information bits (parity removed): Pre 0-10, Rev 11-14, FraID 15-17, SOW 18-37,
// Pnum 38-41, page content from bit 42. Fields split between pages are joined MSB page first.
#include "beidou_d2.hpp"

#include "beidou_ephemeris.hpp"

namespace gvins::ubx::detail {
namespace {

/// The `hiLen` bits `hi` followed by the `loLen` bits `lo`, as an unsigned integer.
std::uint64_t join(std::uint32_t hi, int loLen, std::uint32_t lo) {
  return (static_cast<std::uint64_t>(hi) << loLen) | lo;
}
/// Two's complement value of a `len`-bit field.
std::int64_t signedOf(std::uint64_t v, int len) {
  const std::int64_t sign = std::int64_t{1} << (len - 1);
  return (static_cast<std::int64_t>(v) ^ sign) - sign;
}

}  // namespace

void BeidouD2Decoder::add(const SfrbxMessage& msg, SatId sat, NavDataUpdate& out, NavigationCounts& counts) {
  const std::optional<NavBits> bits = beidouSubframe(msg, counts);
  if (!bits) return;
  if (bits->u(15, 3) != 1) return;  // subframes 2-5: integrity, differential corrections, almanac
  const int pnum = static_cast<int>(bits->u(38, 4));
  if (pnum < 1 || pnum > 10) {
    ++counts.unknownMessages;
    return;
  }
  Partial& p = sats_[sat];
  p.page[static_cast<std::size_t>(pnum - 1)] = *bits;
  // One set = pages of one 30-s cycle: SOW of page k is that of page 1 + 3 (k-1).
  auto cycle = [&](int k) {
    return p.page[static_cast<std::size_t>(k)]->u(18, 20) - 3u * static_cast<std::uint32_t>(k);
  };
  const std::uint32_t mine = cycle(pnum - 1);
  bool dropped = false;
  for (int k = 0; k < 10; ++k) {
    auto& o = p.page[static_cast<std::size_t>(k)];
    if (k != pnum - 1 && o && cycle(k) != mine) {
      o.reset();
      dropped = true;
    }
  }
  if (dropped) ++counts.incompleteSets;
  for (int k = 0; k < 10; ++k)  // page 2 (ionosphere) is not needed for the ephemeris
    if (k != 1 && !p.page[static_cast<std::size_t>(k)]) return;
  emit(p, sat, out, counts);
}

void BeidouD2Decoder::emit(Partial& p, SatId sat, NavDataUpdate& out, NavigationCounts& counts) {
  auto pg = [&](int k) -> const NavBits& { return *p.page[static_cast<std::size_t>(k - 1)]; };
  BeidouBroadcast b;
  b.toc = pg(1).u(65, 17);
  b.aode = static_cast<int>(pg(4).u(71, 5));
  if (b.aode == p.lastAode && b.toc == p.lastToc) {  // this set was emitted already
    p.page = {};
    return;
  }
  // Page 1: clock reference, health, accuracy, group delays.
  b.sow = pg(1).u(18, 20);
  b.health = static_cast<int>(pg(1).u(42, 1));
  b.aodc = static_cast<int>(pg(1).u(43, 5));
  b.urai = static_cast<int>(pg(1).u(48, 4));
  b.week = static_cast<int>(pg(1).u(52, 13));
  b.tgd1 = pg(1).s(82, 10);
  b.tgd2 = pg(1).s(92, 10);
  // Pages 3-4: clock polynomial and AODE.
  b.a0 = pg(3).s(80, 24);
  b.a1 = signedOf(join(pg(3).u(104, 4), 18, pg(4).u(42, 18)), 22);
  b.a2 = pg(4).s(60, 11);
  b.deltaN = pg(4).s(76, 16);
  // Pages 4-10: orbit.
  b.cuc = signedOf(join(pg(4).u(92, 14), 4, pg(5).u(42, 4)), 18);
  b.m0 = pg(5).s(46, 32);
  b.cus = pg(5).s(78, 18);
  b.e = static_cast<std::uint32_t>(join(pg(5).u(96, 10), 22, pg(6).u(42, 22)));
  b.sqrtA = pg(6).u(64, 32);
  b.cic = signedOf(join(pg(6).u(96, 10), 8, pg(7).u(42, 8)), 18);
  b.cis = pg(7).s(50, 18);
  b.toe = pg(7).u(68, 17);
  b.i0 = signedOf(join(pg(7).u(85, 21), 11, pg(8).u(42, 11)), 32);
  b.crc = pg(8).s(53, 18);
  b.crs = pg(8).s(71, 18);
  b.omegaDot = signedOf(join(pg(8).u(89, 19), 5, pg(9).u(42, 5)), 24);
  b.omega0 = pg(9).s(47, 32);
  b.omega = signedOf(join(pg(9).u(79, 27), 5, pg(10).u(42, 5)), 32);
  b.iDot = pg(10).s(47, 14);
  const std::optional<KeplerEphemeris> e = beidouEphemeris(b, sat, NavMessage::BeiDouD2);
  const std::optional<NavBits> iono = p.page[1];
  p.page = {};  // parts of an emitted (or rejected) set never count as incomplete
  if (!emitBeidouEphemeris(e, b, p.lastAode, p.lastToc, out, counts)) return;
  if (iono) {  // page 2: alpha0-3, beta0-3, 8 bits each from bit 42
    out.ionosphere.beidou = beidouKlobuchar(*iono, 42, 74);
    ++counts.ionosphere;
  }
}

}  // namespace gvins::ubx::detail
