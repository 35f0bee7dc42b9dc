// BeiDou D1 decoding: BDS-SIS-ICD-B1I 3.0 (2019), 5.1.3 (BCH(15,11,1) with generator
// g(x) = x^4 + x + 1; word 1: 15 uncoded bits then one code word; words 2-10: two code words of
// 11 information bits each, delivered by u-blox de-interleaved as 22 information bits then the
// 4 + 4 parity bits), 5.2.4 (D1 subframes 1-3, figure 5-4; scale factors, tables 5-9 to 5-13).
// The record is filled as the RTCM 1042 decoder fills it.
#include "beidou_d1.hpp"

#include "gvins/rtcm/accuracy_tables.hpp"
#include "../broadcast_times.hpp"

namespace gvins::ubx::detail {
namespace {

/// True when the 15-bit code word (11 information bits, 4 parity bits) is divisible by x^4+x+1.
bool bchOk(std::uint32_t cw) {
  for (int i = 14; i >= 4; --i)
    if ((cw >> i) & 1u) cw ^= 0x13u << (i - 4);
  return cw == 0;
}

constexpr int kPreamble = 0x712;  // 11100010010, 5.2.2

}  // namespace

std::optional<NavBits> beidouInfoBits(const std::vector<std::uint32_t>& words) {
  if (words.size() != 10) return std::nullopt;
  NavBits bits;
  for (std::size_t k = 0; k < 10; ++k) {
    const std::uint32_t w = words[k] & 0x3fffffffu;  // two padding bits above
    if (k == 0) {
      if (!bchOk(w & 0x7fffu)) return std::nullopt;
      bits.push(w >> 4, 26);
      continue;
    }
    const std::uint32_t c1 = (((w >> 19) & 0x7ffu) << 4) | ((w >> 4) & 0xfu);
    const std::uint32_t c2 = (((w >> 8) & 0x7ffu) << 4) | (w & 0xfu);
    if (!bchOk(c1) || !bchOk(c2)) return std::nullopt;
    bits.push(w >> 8, 22);
  }
  return bits;
}

void BeidouD1Decoder::add(const SfrbxMessage& msg, SatId sat, const GpsTime& receiveTime, NavDataUpdate& out,
                          NavigationCounts& counts) {
  (void)receiveTime;  // D1 carries the full BDT week
  if (isBeiDouGeo(sat)) {  // D2 pages: not decoded
    ++counts.unknownMessages;
    return;
  }
  const std::optional<NavBits> bits = beidouInfoBits(msg.words);
  if (!bits) {
    ++(msg.words.size() == 10 ? counts.parityFailures : counts.unknownMessages);
    return;
  }
  const NavBits& b = *bits;
  if (static_cast<int>(b.u(0, 11)) != kPreamble) {
    ++counts.unknownMessages;
    return;
  }
  const int id = static_cast<int>(b.u(15, 3));
  if (id < 1 || id > 3) return;  // subframes 4-5: almanac
  Partial& p = sats_[sat];
  p.subframe[static_cast<std::size_t>(id - 1)] = b;
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
  const int aode = static_cast<int>(s1.u(219, 5));
  const std::uint32_t tocRaw = s1.u(61, 17);
  if (aode == p.lastAode && tocRaw == p.lastToc) {  // this set was emitted already
    p.subframe = {};
    return;
  }

  KeplerEphemeris e;
  e.sat = sat;
  e.message = NavMessage::BeiDouD1;
  // Subframe 1.
  const double sow1 = static_cast<double>(s1.u(18, 20));
  e.health = static_cast<int>(s1.u(38, 1));
  e.iodc = static_cast<int>(s1.u(39, 5));
  e.ura = rtcm::uraMetres(static_cast<int>(s1.u(44, 4)));
  const int week = static_cast<int>(s1.u(48, 13));
  const double toc = scaled(tocRaw, 3);
  e.tgd[0] = static_cast<double>(s1.s(78, 10)) * 1e-10;
  e.tgd[1] = static_cast<double>(s1.s(88, 10)) * 1e-10;
  KlobucharParameters k;
  const int alphaExp[4] = {-30, -27, -24, -24}, betaExp[4] = {11, 14, 16, 16};
  for (int i = 0; i < 4; ++i) {
    k.alpha[i] = scaled(s1.s(98 + 8 * i, 8), alphaExp[i]);
    k.beta[i] = scaled(s1.s(130 + 8 * i, 8), betaExp[i]);
  }
  e.af2 = scaled(s1.s(162, 11), -66);
  e.af0 = scaled(s1.s(173, 24), -33);
  e.af1 = scaled(s1.s(197, 22), -50);
  e.iode = aode;
  // Subframe 2.
  e.deltaN = scaled(s2.s(38, 16), -43) * kSemicircle;
  e.cuc = scaled(s2.s(54, 18), -31);
  e.m0 = scaled(s2.s(72, 32), -31) * kSemicircle;
  e.e = scaled(s2.u(104, 32), -33);
  e.cus = scaled(s2.s(136, 18), -31);
  e.crc = scaled(s2.s(154, 18), -6);
  e.crs = scaled(s2.s(172, 18), -6);
  e.sqrtA = scaled(s2.u(190, 32), -19);
  const double toe = scaled((s2.u(222, 2) << 15) | s3.u(38, 15), 3);
  // Subframe 3.
  e.i0 = scaled(s3.s(53, 32), -31) * kSemicircle;
  e.cic = scaled(s3.s(85, 18), -31);
  e.omegaDot = scaled(s3.s(103, 24), -43) * kSemicircle;
  e.cis = scaled(s3.s(127, 18), -31);
  e.iDot = scaled(s3.s(145, 14), -43) * kSemicircle;
  e.omega0 = scaled(s3.s(159, 32), -31) * kSemicircle;
  e.omega = scaled(s3.s(191, 32), -31) * kSemicircle;
  if (toe >= kSecondsPerWeek || toc >= kSecondsPerWeek || sow1 >= kSecondsPerWeek) {
    ++counts.unknownMessages;
    p.subframe = {};
    return;
  }
  // Times in BDT (week and SOW of subframe 1, 5.2.4.2-5.2.4.3), converted to GPST.
  e.ttr = bdtToGpst(week, sow1);
  e.toe = rtcm::nearWeek(bdtToGpst(week, toe), e.ttr);
  e.toc = rtcm::nearWeek(bdtToGpst(week, toc), e.toe);
  e.toeSeconds = toe;
  int toeWeek = 0;
  double toeSow = 0.0;
  gpstToBdt(e.toe, toeWeek, toeSow);
  e.week = toeWeek;
  p.lastAode = aode;
  p.lastToc = tocRaw;
  p.subframe = {};  // parts of an emitted set never count as incomplete
  ++counts.ephemerides;
  out.kepler.push_back(e);
  out.ionosphere.beidou = k;
  ++counts.ionosphere;
}

}  // namespace gvins::ubx::detail
