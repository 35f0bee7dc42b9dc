// GLONASS string decoding: GLONASS ICD edition 5.1 (2008), 4.4 (strings 1-4 of the immediate
// data, table 4.5: fields, sign-magnitude scale factors) and 4.7 (Hamming code: data bits b9..b85
// take the positions of a Hamming code that skip the powers of two; check bit k (bit k of the
// string) covers the positions with bit k-1 set, bit 8 the whole string). The record is filled as
// the RTCM 1020 decoder fills it.
#include "glonass_strings.hpp"

#include <cmath>

#include "gvins/rtcm/accuracy_tables.hpp"
#include "../broadcast_times.hpp"

namespace gvins::ubx::detail {
namespace {

// Buffer position of ICD bit number n (85 = first bit delivered).
constexpr int at(int n) { return 85 - n; }

bool hammingOk(const NavBits& s) {
  int syndrome = 0;
  int all = 0;
  int position = 1;
  for (int n = 9; n <= 85; ++n) {
    while ((position & (position - 1)) == 0) ++position;  // skip the check positions 1, 2, 4, ...
    const int b = static_cast<int>(s.u(at(n), 1));
    if (b) syndrome ^= position;
    all ^= b;
    ++position;
  }
  for (int k = 1; k <= 7; ++k) {
    const int beta = static_cast<int>(s.u(at(k), 1));
    if (beta) syndrome ^= 1 << (k - 1);
    all ^= beta;
  }
  all ^= static_cast<int>(s.u(at(8), 1));
  return syndrome == 0 && all == 0;
}

}  // namespace

std::optional<NavBits> glonassString(const std::vector<std::uint32_t>& words) {
  if (words.size() < 3) return std::nullopt;
  NavBits s;
  s.push(words[0], 32);
  s.push(words[1], 32);
  s.push(words[2] >> 11, 21);
  if (!hammingOk(s)) return std::nullopt;
  return s;
}

void GlonassDecoder::add(const SfrbxMessage& msg, SatId sat, const GpsTime& receiveTime, NavDataUpdate& out,
                         NavigationCounts& counts) {
  if (msg.words.size() != 4 || msg.freqId > 13) {
    ++counts.unknownMessages;
    return;
  }
  const std::optional<NavBits> str = glonassString(msg.words);
  if (!str) {
    ++counts.parityFailures;
    return;
  }
  const NavBits& s = *str;
  const int m = static_cast<int>(s.u(1, 4));
  if (m < 1 || m > 5) return;  // almanac strings
  Partial& p = sats_[sat];
  if (m == 5) {
    // N4, the four-year interval since 1996 (string 5, 4.5): with NT of string 4 it dates the set
    // when no receive time is known.
    p.n4 = static_cast<int>(s.u(49, 5));
  } else {
    p.string[static_cast<std::size_t>(m - 1)] = s;
    p.received[static_cast<std::size_t>(m - 1)] = receiveTime;
    // Strings 1-4 of one frame are sent within 8 s (4.3.2); frames are 30 s apart.
    bool dropped = false;
    for (int k = 0; k < 4; ++k) {
      auto& o = p.string[static_cast<std::size_t>(k)];
      if (k != m - 1 && o && std::fabs(p.received[static_cast<std::size_t>(k)] - receiveTime) > 10.0) {
        o.reset();
        dropped = true;
      }
    }
    if (dropped) ++counts.incompleteSets;
  }
  for (const auto& o : p.string)
    if (!o) return;
  const NavBits& s1 = *p.string[0];
  const NavBits& s2 = *p.string[1];
  const NavBits& s3 = *p.string[2];
  const NavBits& s4 = *p.string[3];
  const int tb = static_cast<int>(s2.u(9, 7));
  if (tb == p.lastTb) {  // this set was emitted already
    p.string = {};
    return;
  }
  const int tkH = static_cast<int>(s1.u(9, 5));
  const int tkM = static_cast<int>(s1.u(14, 6));
  const int tkS = static_cast<int>(s1.u(20, 1));
  if (tb < 1 || tb > 96 || tkH > 23 || tkM > 59) {
    ++counts.unknownMessages;
    p.string = {};
    return;
  }
  // The day: from the receive time, else from NT (string 4) and N4 (string 5) as the RTCM 1020
  // decoder does; neither yet: keep the set.
  GpsTime reference = receiveTime;
  if (reference.week() < kFirstValidWeek) {
    const int nt = static_cast<int>(s4.u(59, 11));
    if (!p.n4 || *p.n4 < 1 || nt < 1 || nt > 1461) return;
    CalendarTime c;
    civilFromDays(daysFromCivil(1996 + 4 * (*p.n4 - 1), 1, 1) + (nt - 1), c.year, c.month, c.day);
    c.second = tb * 900.0;  // normalised by the conversion
    reference = glonassToGpst(c);
  }
  GlonassEphemeris g;
  g.sat = sat;
  g.frequencyChannel = static_cast<int>(msg.freqId) - 7;
  const NavBits* axes[3] = {&s1, &s2, &s3};
  for (int k = 0; k < 3; ++k) {
    g.velocity[k] = scaled(axes[k]->sm(21, 24), -20) * 1e3;
    g.acceleration[k] = scaled(axes[k]->sm(45, 5), -30) * 1e3;
    g.position[k] = scaled(axes[k]->sm(50, 27), -11) * 1e3;
  }
  const int bnMsb = static_cast<int>(s2.u(5, 1));
  g.gammaN = scaled(s3.sm(6, 11), -40);
  const int ln3 = static_cast<int>(s3.u(20, 1));
  g.tauN = scaled(s4.sm(5, 22), -30);
  g.deltaTauN = scaled(s4.sm(27, 5), -30);
  g.age = static_cast<int>(s4.u(32, 5));
  g.accuracy = rtcm::glonassFtMetres(static_cast<int>(s4.u(52, 4)));
  g.health = bnMsb | ln3;
  g.iode = tb;
  g.toe = rtcm::glonassTodNear(tb * 900.0, reference);
  g.tof = rtcm::glonassTodNear(tkH * 3600.0 + tkM * 60.0 + tkS * 30.0, g.toe);
  p.lastTb = tb;
  p.string = {};  // parts of an emitted set never count as incomplete
  ++counts.ephemerides;
  out.glonass.push_back(g);
}

}  // namespace gvins::ubx::detail
