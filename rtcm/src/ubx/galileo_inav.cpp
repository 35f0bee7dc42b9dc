// Galileo I/NAV decoding: Galileo OS SIS ICD issue 2.1, 4.3.2.3 (nominal page layout: even part
// even/odd, page type, data j 112 bits, tail 6; odd part even/odd, page type, data k 16 bits,
// reserved 1 (40), SAR (22), spare (2), CRC (24), reserved 2 (8), tail 6), 4.3.2.4 (CRC-24Q over
// the 196 bits from the even part's first bit to the odd part's spare bits), 4.3.5 (word types 1-5,
// table 40-42) and 5.1 (scale factors, table 60). The record is filled as RTCM 1046 is decoded.
#include "galileo_inav.hpp"

#include "gvins/rtcm/accuracy_tables.hpp"
#include "gvins/rtcm/crc24q.hpp"
#include "../broadcast_times.hpp"

namespace gvins::ubx::detail {

std::optional<InavWord> inavWord(const std::vector<std::uint32_t>& words) {
  if (words.size() != 8 && words.size() != 9) return std::nullopt;  // F9 firmware adds a pad word
  NavBits even, odd;
  for (int k = 0; k < 4; ++k) even.push(words[static_cast<std::size_t>(k)], 32);
  for (int k = 4; k < 8; ++k) odd.push(words[static_cast<std::size_t>(k)], 32);
  if (even.u(0, 1) != 0 || odd.u(0, 1) != 1) return std::nullopt;  // not an even-odd pair
  InavWord w;
  // CRC input: 4 zero bits (which leave a zero-initialised CRC unchanged), the 114 first bits
  // of the even part, the 82 first bits of the odd part: 200 bits = 25 bytes.
  NavBits crcIn;
  crcIn.push(0, 4);
  crcIn.append(even, 0, 114);
  crcIn.append(odd, 0, 82);
  const std::uint32_t crc = rtcm::crc24q(std::span<const std::uint8_t>(crcIn.bytes().data(), 25));
  w.crcOk = crc == odd.u(82, 24) && even.u(1, 1) == 0 && odd.u(1, 1) == 0;
  w.data.append(even, 2, 112);
  w.data.append(odd, 2, 16);
  return w;
}

void GalileoInavDecoder::add(const SfrbxMessage& msg, SatId sat, const GpsTime& receiveTime, NavDataUpdate& out,
                             NavigationCounts& counts) {
  const std::optional<InavWord> page = inavWord(msg.words);
  if (!page) {
    ++counts.unknownMessages;
    return;
  }
  if (!page->crcOk) {
    ++counts.crcFailures;
    return;
  }
  const NavBits& d = page->data;
  const int type = static_cast<int>(d.u(0, 6));
  if (type < 1 || type > 5) return;  // 0 (spare/time), 6 (UTC), 7-10 almanac, 16+ reduced/other
  Partial& p = sats_[sat];
  if (type == 5) {
    // NeQuick ai0 (11 bits, 2^-2 sfu), ai1 (11, 2^-8), ai2 (14, 2^-15), table 60.
    NeQuickParameters q;
    q.ai[0] = scaled(d.u(6, 11), -2);
    q.ai[1] = scaled(d.s(17, 11), -8);
    q.ai[2] = scaled(d.s(28, 14), -15);
    out.ionosphere.galileo = q;
    ++counts.ionosphere;
  }
  p.word[static_cast<std::size_t>(type - 1)] = d;
  p.fromE5b[static_cast<std::size_t>(type - 1)] = msg.sigId == 5;
  // IODnav of words 1-4 must agree (5.1.9.2).
  if (type <= 4) {
    bool dropped = false;
    for (int k = 0; k < 4; ++k) {
      auto& o = p.word[static_cast<std::size_t>(k)];
      if (k != type - 1 && o && o->u(6, 10) != d.u(6, 10)) {
        o.reset();
        dropped = true;
      }
    }
    if (dropped) ++counts.incompleteSets;
  }
  for (const auto& w : p.word)
    if (!w) return;
  const NavBits& w1 = *p.word[0];
  const NavBits& w2 = *p.word[1];
  const NavBits& w3 = *p.word[2];
  const NavBits& w4 = *p.word[3];
  const NavBits& w5 = *p.word[4];
  const int iod = static_cast<int>(w1.u(6, 10));
  const std::uint32_t toeRaw = w1.u(16, 14);
  if (iod == p.lastIod && toeRaw == p.lastToe) {  // this set was emitted already
    p.word = {};
    return;
  }

  KeplerEphemeris e;
  e.sat = sat;
  e.message = NavMessage::GalileoInav;
  e.iode = e.iodc = iod;
  // Word type 1.
  const double toe = static_cast<double>(toeRaw) * 60.0;
  e.m0 = scaled(w1.s(30, 32), -31) * kSemicircle;
  e.e = scaled(w1.u(62, 32), -33);
  e.sqrtA = scaled(w1.u(94, 32), -19);
  // Word type 2.
  e.omega0 = scaled(w2.s(16, 32), -31) * kSemicircle;
  e.i0 = scaled(w2.s(48, 32), -31) * kSemicircle;
  e.omega = scaled(w2.s(80, 32), -31) * kSemicircle;
  e.iDot = scaled(w2.s(112, 14), -43) * kSemicircle;
  // Word type 3.
  e.omegaDot = scaled(w3.s(16, 24), -43) * kSemicircle;
  e.deltaN = scaled(w3.s(40, 16), -43) * kSemicircle;
  e.cuc = scaled(w3.s(56, 16), -29);
  e.cus = scaled(w3.s(72, 16), -29);
  e.crc = scaled(w3.s(88, 16), -5);
  e.crs = scaled(w3.s(104, 16), -5);
  e.ura = rtcm::sisaMetres(static_cast<int>(w3.u(120, 8)));
  // Word type 4 (SVID at 16 is the transmitting satellite's).
  e.cic = scaled(w4.s(22, 16), -29);
  e.cis = scaled(w4.s(38, 16), -29);
  const double toc = static_cast<double>(w4.u(54, 14)) * 60.0;
  e.af0 = scaled(w4.s(68, 31), -34);
  e.af1 = scaled(w4.s(99, 21), -46);
  e.af2 = scaled(w4.s(120, 6), -59);
  // Word type 5: BGDs, signal health and data validity, GST week and time of week.
  e.tgd[0] = scaled(w5.s(47, 10), -32);
  e.tgd[1] = scaled(w5.s(57, 10), -32);
  const int e5bHs = static_cast<int>(w5.u(67, 2));
  const int e1bHs = static_cast<int>(w5.u(69, 2));
  const int e5bDvs = static_cast<int>(w5.u(71, 1));
  const int e1bDvs = static_cast<int>(w5.u(72, 1));
  const int wn = static_cast<int>(w5.u(73, 12));
  const double tow = static_cast<double>(w5.u(85, 20));
  // RINEX 3.04 table A8 bit fields, as the RTCM 1046 decoder sets them; data sources: bit 0 when
  // a word came from E1-B, bit 2 when one came from E5b-I, bit 9 (clock for E5b,E1) always.
  e.health = e1bDvs | (e1bHs << 1) | (e5bDvs << 6) | (e5bHs << 7);
  bool e1b = false, e5b = false;
  for (bool f : p.fromE5b) (f ? e5b : e1b) = true;
  e.codesOnL2 = (e1b ? 1 << 0 : 0) | (e5b ? 1 << 2 : 0) | (1 << 9);
  if (toe >= kSecondsPerWeek || toc >= kSecondsPerWeek || tow >= kSecondsPerWeek) {
    ++counts.unknownMessages;
    p.word = {};
    return;
  }
  // Times: GST week (12 bits, 5.1.2) placed nearest the receive time; toe/toc nearest the
  // transmission time of word type 5.
  int gstWeek = 0;
  double gstTow = 0.0;
  gpstToGst(receiveTime, gstWeek, gstTow);
  int diff = ((wn - gstWeek) % 4096 + 4096) % 4096;
  if (diff >= 2048) diff -= 4096;
  // Without a receive time the GST week count is taken as it is (valid until 2077).
  const int week = receiveTime.week() < kFirstValidWeek ? wn : gstWeek + diff;
  e.ttr = gstToGpst(week, tow);
  e.toe = rtcm::nearWeek(gstToGpst(week, toe), e.ttr);
  e.toc = rtcm::nearWeek(gstToGpst(week, toc), e.toe);
  e.toeSeconds = toe;
  int toeWeek = 0;
  double toeTow = 0.0;
  gpstToGst(e.toe, toeWeek, toeTow);
  e.week = toeWeek;
  p.lastIod = iod;
  p.lastToe = toeRaw;
  p.word = {};  // parts of an emitted set never count as incomplete
  ++counts.ephemerides;
  out.kepler.push_back(e);
}

}  // namespace gvins::ubx::detail
