// BeiDou D1 decoding: BDS-SIS-ICD-B1I 3.0, 5.2.4 (D1 subframes 1-3, figure 5-4). Word check and
// scaling shared with D2 (beidou_ephemeris.cpp).
#include "beidou_d1.hpp"

#include "beidou_ephemeris.hpp"

namespace gvins::ubx::detail {

void BeidouD1Decoder::add(const SfrbxMessage& msg, SatId sat, NavDataUpdate& out, NavigationCounts& counts) {
  const std::optional<NavBits> bits = beidouSubframe(msg, counts);
  if (!bits) return;
  const int id = static_cast<int>(bits->u(15, 3));
  if (id < 1 || id > 3) return;  // subframes 4-5: almanac
  Partial& p = sats_[sat];
  p.subframe[static_cast<std::size_t>(id - 1)] = *bits;
  // One set = subframes 1-3 of one 30-s frame: SOW of subframe k is that of subframe 1 + 6 (k-1).
  auto sow = [&](int k) { return p.subframe[static_cast<std::size_t>(k)]->u(18, 20); };
  const std::uint32_t mine = sow(id - 1) - 6u * static_cast<std::uint32_t>(id - 1);
  bool dropped = false;
  for (int k = 0; k < 3; ++k) {
    auto& o = p.subframe[static_cast<std::size_t>(k)];
    if (k != id - 1 && o && sow(k) - 6u * static_cast<std::uint32_t>(k) != mine) {
      o.reset();
      dropped = true;
    }
  }
  if (dropped) ++counts.incompleteSets;
  for (const auto& s : p.subframe)
    if (!s) return;
  const NavBits& s1 = *p.subframe[0];
  const NavBits& s2 = *p.subframe[1];
  const NavBits& s3 = *p.subframe[2];
  BeidouBroadcast b;
  b.aode = static_cast<int>(s1.u(219, 5));
  b.toc = s1.u(61, 17);
  if (b.aode == p.lastAode && b.toc == p.lastToc) {  // this set was emitted already
    p.subframe = {};
    return;
  }
  // Subframe 1.
  b.sow = s1.u(18, 20);
  b.health = static_cast<int>(s1.u(38, 1));
  b.aodc = static_cast<int>(s1.u(39, 5));
  b.urai = static_cast<int>(s1.u(44, 4));
  b.week = static_cast<int>(s1.u(48, 13));
  b.tgd1 = s1.s(78, 10);
  b.tgd2 = s1.s(88, 10);
  b.a2 = s1.s(162, 11);
  b.a0 = s1.s(173, 24);
  b.a1 = s1.s(197, 22);
  // Subframe 2.
  b.deltaN = s2.s(38, 16);
  b.cuc = s2.s(54, 18);
  b.m0 = s2.s(72, 32);
  b.e = s2.u(104, 32);
  b.cus = s2.s(136, 18);
  b.crc = s2.s(154, 18);
  b.crs = s2.s(172, 18);
  b.sqrtA = s2.u(190, 32);
  b.toe = (s2.u(222, 2) << 15) | s3.u(38, 15);
  // Subframe 3.
  b.i0 = s3.s(53, 32);
  b.cic = s3.s(85, 18);
  b.omegaDot = s3.s(103, 24);
  b.cis = s3.s(127, 18);
  b.iDot = s3.s(145, 14);
  b.omega0 = s3.s(159, 32);
  b.omega = s3.s(191, 32);
  const std::optional<KeplerEphemeris> e = beidouEphemeris(b, sat, NavMessage::BeiDouD1);
  const KlobucharParameters iono = beidouKlobuchar(s1, 98, 130);
  p.subframe = {};  // parts of an emitted (or rejected) set never count as incomplete
  if (!emitBeidouEphemeris(e, b, p.lastAode, p.lastToc, out, counts)) return;
  out.ionosphere.beidou = iono;
  ++counts.ionosphere;
}

}  // namespace gvins::ubx::detail
