// GPS/QZSS LNAV decoding: IS-GPS-200N 20.3.2-20.3.5 (subframe layouts, figure 20-1; parameters and
// scale factors, tables 20-I, 20-III, 20-X; parity, table 20-XIV), IS-QZSS-PNT-005 (the same LNAV
// layout). The record is filled as the RTCM 1019/1044 decoder fills it.
#include "gps_lnav.hpp"

#include "../broadcast_times.hpp"
#include "gvins/rtcm/accuracy_tables.hpp"

namespace gvins::ubx::detail {
namespace {

// Data bits d1..d24 taking part in each parity bit D25..D30 (IS-GPS-200 table 20-XIV), as masks
// over the 24 data bits with d1 the most significant.
constexpr std::array<std::uint32_t, 6> kParityMasks = [] {
  constexpr int taps[6][16] = {{1, 2, 3, 5, 6, 10, 11, 12, 13, 14, 17, 18, 20, 23},
                               {2, 3, 4, 6, 7, 11, 12, 13, 14, 15, 18, 19, 21, 24},
                               {1, 3, 4, 5, 7, 8, 12, 13, 14, 15, 16, 19, 20, 22},
                               {2, 4, 5, 6, 8, 9, 13, 14, 15, 16, 17, 20, 21, 23},
                               {1, 3, 5, 6, 7, 9, 10, 14, 15, 16, 17, 18, 21, 22, 24},
                               {3, 5, 6, 8, 9, 10, 11, 13, 15, 19, 22, 23, 24}};
  std::array<std::uint32_t, 6> m{};
  for (int k = 0; k < 6; ++k)
    for (int t : taps[k])
      if (t > 0) m[k] |= 1u << (24 - t);
  return m;
}();

int parity(std::uint32_t v) { return __builtin_popcount(v) & 1; }

/// Parity bits D25..D30 of data bits d (24 bits) after D29*, D30* of the previous word.
std::uint32_t lnavParity(std::uint32_t d, int d29, int d30) {
  const int prev[6] = {d29, d30, d29, d30, d30, d29};
  std::uint32_t p = 0;
  for (int k = 0; k < 6; ++k) p = (p << 1) | static_cast<std::uint32_t>(prev[k] ^ parity(d & kParityMasks[k]));
  return p;
}

int iodcOf(const NavBits& sf1) { return static_cast<int>((sf1.u(70, 2) << 8) | sf1.u(168, 8)); }

}  // namespace

std::optional<NavBits> lnavDataBits(const std::vector<std::uint32_t>& words) {
  if (words.size() != 10) return std::nullopt;
  NavBits bits;
  for (std::uint32_t w : words) {
    w &= 0x3fffffffu;                   // the two most significant bits are padding
    const std::uint32_t data = w >> 6;  // already non-inverted
    // The receiver inverts whole words (data and parity) where the transmitted D30* was set, so a
    // delivered word satisfies the parity equations with D30* = 0 and D29* = D29* xor D30*. That
    // term is taken from neither the padding nor the previous word (words of one subframe may
    // follow a gap): both values are accepted. Every single bit error is still detected, since
    // no data bit enters exactly the parity bits D25, D27 and D30 that D29* enters.
    const std::uint32_t p = w & 0x3fu;
    if (lnavParity(data, 0, 0) != p && lnavParity(data, 1, 0) != p) return std::nullopt;
    bits.push(data, 24);
  }
  return bits;
}

void GpsLnavDecoder::add(const SfrbxMessage& msg, SatId sat, const GpsTime& receiveTime, NavDataUpdate& out,
                         NavigationCounts& counts) {
  const std::optional<NavBits> bits = lnavDataBits(msg.words);
  if (!bits) {
    ++(msg.words.size() == 10 ? counts.parityFailures : counts.unknownMessages);
    return;
  }
  const NavBits& b = *bits;
  if (b.u(0, 8) != 0x8b) {  // TLM preamble
    ++counts.unknownMessages;
    return;
  }
  const int id = static_cast<int>(b.u(43, 3));  // HOW subframe ID
  Partial& p = sats_[sat];
  if (id == 4) {
    // Page 18 (SV ID 56): ionosphere and UTC (IS-GPS-200 20.3.3.5.1.7, figure 20-1 sheet 8).
    if (b.u(50, 6) != 56) return;
    KlobucharParameters k;
    const int alphaExp[4] = {-30, -27, -24, -24}, betaExp[4] = {11, 14, 16, 16};
    for (int i = 0; i < 4; ++i) {
      k.alpha[i] = scaled(b.s(56 + 8 * i, 8), alphaExp[i]);
      k.beta[i] = scaled(b.s(88 + 8 * i, 8), betaExp[i]);
    }
    (sat.system == System::Qzss ? out.ionosphere.qzss : out.ionosphere.gps) = k;
    ++counts.ionosphere;
    return;
  }
  if (id < 1 || id > 3) return;  // subframe 5 and other pages of 4: almanac, not needed
  auto& slot = p.subframe[static_cast<std::size_t>(id - 1)];
  slot = b;
  // Issue of data: IODE of subframes 2 and 3 equal to the 8 LSBs of IODC (IS-GPS-200 20.3.4.4).
  const auto& s1 = p.subframe[0];
  const auto& s2 = p.subframe[1];
  const auto& s3 = p.subframe[2];
  const int iode2 = s2 ? static_cast<int>(s2->u(48, 8)) : -1;
  const int iode3 = s3 ? static_cast<int>(s3->u(216, 8)) : -1;
  const int iodc8 = s1 ? (iodcOf(*s1) & 0xff) : -1;
  const int mine = id == 1 ? iodc8 : id == 2 ? iode2 : iode3;
  // A part with another issue of data than the parts kept: those belong to another set.
  bool dropped = false;
  for (int k = 0; k < 3; ++k) {
    if (k == id - 1 || !p.subframe[static_cast<std::size_t>(k)]) continue;
    const int other = k == 0 ? iodc8 : k == 1 ? iode2 : iode3;
    if (other != mine) {
      p.subframe[static_cast<std::size_t>(k)].reset();
      dropped = true;
    }
  }
  if (dropped) ++counts.incompleteSets;
  if (!s1 || !s2 || !s3) return;
  const int iodc = iodcOf(*s1);
  const std::uint32_t toeRaw = s2->u(216, 16);
  if (iodc == p.lastIodc && toeRaw == p.lastToe) {  // this set was emitted already
    p.subframe = {};
    return;
  }
  if (receiveTime.week() < kFirstValidWeek) return;  // no time yet for the 10-bit week: keep the set

  KeplerEphemeris e;
  e.sat = sat;
  e.message = sat.system == System::Qzss ? NavMessage::QzssLnav : NavMessage::GpsLnav;
  // Subframe 1.
  const int week10 = static_cast<int>(s1->u(48, 10));
  e.codesOnL2 = static_cast<int>(s1->u(58, 2));
  e.ura = rtcm::uraMetres(static_cast<int>(s1->u(60, 4)));
  e.health = static_cast<int>(s1->u(64, 6));
  e.iodc = iodc;
  e.l2pDataFlag = static_cast<int>(s1->u(72, 1));
  e.tgd[0] = scaled(s1->s(160, 8), -31);
  const double toc = scaled(s1->u(176, 16), 4);
  e.af2 = scaled(s1->s(192, 8), -55);
  e.af1 = scaled(s1->s(200, 16), -43);
  e.af0 = scaled(s1->s(216, 22), -31);
  // Subframe 2.
  e.iode = static_cast<int>(s2->u(48, 8));
  e.crs = scaled(s2->s(56, 16), -5);
  e.deltaN = scaled(s2->s(72, 16), -43) * kSemicircle;
  e.m0 = scaled(s2->s(88, 32), -31) * kSemicircle;
  e.cuc = scaled(s2->s(120, 16), -29);
  e.e = scaled(s2->u(136, 32), -33);
  e.cus = scaled(s2->s(168, 16), -29);
  e.sqrtA = scaled(s2->u(184, 32), -19);
  const double toe = scaled(toeRaw, 4);
  const bool fitFlag = s2->u(232, 1) != 0;
  // Subframe 3.
  e.cic = scaled(s3->s(48, 16), -29);
  e.omega0 = scaled(s3->s(64, 32), -31) * kSemicircle;
  e.cis = scaled(s3->s(96, 16), -29);
  e.i0 = scaled(s3->s(112, 32), -31) * kSemicircle;
  e.crc = scaled(s3->s(144, 16), -5);
  e.omega = scaled(s3->s(160, 32), -31) * kSemicircle;
  e.omegaDot = scaled(s3->s(192, 24), -43) * kSemicircle;
  e.iDot = scaled(s3->s(224, 14), -43) * kSemicircle;
  // Fit interval as the RTCM decoder stores it (QZSS: 0 = 2 h, 1 = longer, kept as unknown).
  e.fitInterval = sat.system == System::Qzss ? (fitFlag ? 0.0 : 2.0) : rtcm::gpsFitHours(fitFlag, iodc);
  if (toe >= kSecondsPerWeek || toc >= kSecondsPerWeek) {
    ++counts.unknownMessages;
    p.subframe = {};
    return;
  }
  // Times: the week of subframe 1 is the week of transmission modulo 1024 (HOW TOW count = start
  // of the next subframe, 20.3.3.2). The transmission time is the time the set became complete,
  // as the RTCM decoder uses the reception time.
  e.ttr = receiveTime;
  const int week = resolveWeek(week10, 10, receiveTime);
  const GpsTime sf1Start = GpsTime::fromWeekTow(week, static_cast<double>(s1->u(24, 17)) * 6.0 - 6.0);
  e.toe = rtcm::nearWeek(GpsTime::fromWeekTow(week, toe), sf1Start);
  e.toc = rtcm::nearWeek(GpsTime::fromWeekTow(week, toc), e.toe);
  e.toeSeconds = toe;
  e.week = e.toe.week();
  p.lastIodc = iodc;
  p.lastToe = toeRaw;
  p.subframe = {};  // parts of an emitted set never count as incomplete
  ++counts.ephemerides;
  out.kepler.push_back(e);
}

}  // namespace gvins::ubx::detail
