// BeiDou BCH(15,11,1) word check and broadcast-integer scaling: BDS-SIS-ICD-B1I 3.0, 5.1.3 (code
// words with generator g(x) = x^4 + x + 1; word 1: 15 uncoded bits then one code word; words
// 2-10: two code words of 11 information bits each, delivered by u-blox de-interleaved as 22
// information bits then the 4 + 4 parity bits) and 5.2.4 / 5.3.3 (scale factors, tables 5-9 to
// 5-13). The record is filled as the RTCM 1042 decoder fills it.
#include "beidou_ephemeris.hpp"

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

constexpr int kPreamble = 0x712;  // 11100010010, 5.2.2 (D1) and 5.3.2 (D2)

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

std::optional<NavBits> beidouSubframe(const SfrbxMessage& msg, NavigationCounts& counts) {
  std::optional<NavBits> bits = beidouInfoBits(msg.words);
  if (!bits) {
    ++(msg.words.size() == 10 ? counts.parityFailures : counts.unknownMessages);
    return std::nullopt;
  }
  if (static_cast<int>(bits->u(0, 11)) != kPreamble) {
    ++counts.unknownMessages;
    return std::nullopt;
  }
  return bits;
}

std::optional<KeplerEphemeris> beidouEphemeris(const BeidouBroadcast& b, SatId sat, NavMessage message) {
  const double toe = scaled(b.toe, 3), toc = scaled(b.toc, 3), sow = static_cast<double>(b.sow);
  if (toe >= kSecondsPerWeek || toc >= kSecondsPerWeek || sow >= kSecondsPerWeek) return std::nullopt;
  KeplerEphemeris e;
  e.sat = sat;
  e.message = message;
  e.health = b.health;
  e.iodc = b.aodc;
  e.iode = b.aode;
  e.ura = rtcm::uraMetres(b.urai);
  e.tgd[0] = static_cast<double>(b.tgd1) * 1e-10;  // 0.1 ns
  e.tgd[1] = static_cast<double>(b.tgd2) * 1e-10;
  e.af0 = scaled(b.a0, -33);
  e.af1 = scaled(b.a1, -50);
  e.af2 = scaled(b.a2, -66);
  e.deltaN = scaled(b.deltaN, -43) * kSemicircle;
  e.cuc = scaled(b.cuc, -31);
  e.m0 = scaled(b.m0, -31) * kSemicircle;
  e.e = scaled(b.e, -33);
  e.cus = scaled(b.cus, -31);
  e.crc = scaled(b.crc, -6);
  e.crs = scaled(b.crs, -6);
  e.sqrtA = scaled(b.sqrtA, -19);
  e.i0 = scaled(b.i0, -31) * kSemicircle;
  e.cic = scaled(b.cic, -31);
  e.omegaDot = scaled(b.omegaDot, -43) * kSemicircle;
  e.cis = scaled(b.cis, -31);
  e.iDot = scaled(b.iDot, -43) * kSemicircle;
  e.omega0 = scaled(b.omega0, -31) * kSemicircle;
  e.omega = scaled(b.omega, -31) * kSemicircle;
  // Times in BDT (week and SOW of subframe 1 / page 1, 5.2.4.2-5.2.4.3), converted to GPST.
  e.ttr = bdtToGpst(b.week, sow);
  e.toe = rtcm::nearWeek(bdtToGpst(b.week, toe), e.ttr);
  e.toc = rtcm::nearWeek(bdtToGpst(b.week, toc), e.toe);
  e.toeSeconds = toe;
  int toeWeek = 0;
  double toeSow = 0.0;
  gpstToBdt(e.toe, toeWeek, toeSow);
  e.week = toeWeek;
  return e;
}

KlobucharParameters beidouKlobuchar(const NavBits& bits, int alphaBit, int betaBit) {
  KlobucharParameters k;
  const int alphaExp[4] = {-30, -27, -24, -24}, betaExp[4] = {11, 14, 16, 16};
  for (std::size_t i = 0; i < 4; ++i) {
    const int at = 8 * static_cast<int>(i);
    k.alpha[i] = scaled(bits.s(alphaBit + at, 8), alphaExp[i]);
    k.beta[i] = scaled(bits.s(betaBit + at, 8), betaExp[i]);
  }
  return k;
}

bool emitBeidouEphemeris(const std::optional<KeplerEphemeris>& e, const BeidouBroadcast& b, int& lastAode,
                         std::uint32_t& lastToc, NavDataUpdate& out, NavigationCounts& counts) {
  if (!e) {
    ++counts.unknownMessages;
    return false;
  }
  lastAode = b.aode;
  lastToc = b.toc;
  ++counts.ephemerides;
  out.kepler.push_back(*e);
  return true;
}

}  // namespace gvins::ubx::detail
