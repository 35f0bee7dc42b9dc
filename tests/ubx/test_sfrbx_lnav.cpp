// GPS LNAV from subframes built here with the IS-GPS-200N parity algorithm (20.3.5.2, table
// 20-XIV) and delivered as u-blox does (whole word inverted where D30* is set): subframe 4 page 18
// (no page 18 in the bundled logs) with the ICD scale factors, mixed issues of data, cold start
// without a receive time.
#include <gtest/gtest.h>

#include <array>
#include <cmath>

#include "gvins/ubx/navigation_assembler.hpp"

namespace gvins::ubx {
namespace {

// Parity bit D25..D30 from the data bits d1..d24 and D29*, D30* of the previous word: the bit
// lists of IS-GPS-200N table 20-XIV.
std::uint32_t icdParity(std::uint32_t d, int d29, int d30) {
  auto x = [&](std::initializer_list<int> bits, int start) {
    int v = start;
    for (int b : bits) v ^= static_cast<int>((d >> (24 - b)) & 1u);
    return static_cast<std::uint32_t>(v);
  };
  const std::uint32_t p25 = x({1, 2, 3, 5, 6, 10, 11, 12, 13, 14, 17, 18, 20, 23}, d29);
  const std::uint32_t p26 = x({2, 3, 4, 6, 7, 11, 12, 13, 14, 15, 18, 19, 21, 24}, d30);
  const std::uint32_t p27 = x({1, 3, 4, 5, 7, 8, 12, 13, 14, 15, 16, 19, 20, 22}, d29);
  const std::uint32_t p28 = x({2, 4, 5, 6, 8, 9, 13, 14, 15, 16, 17, 20, 21, 23}, d30);
  const std::uint32_t p29 = x({1, 3, 5, 6, 7, 9, 10, 14, 15, 16, 17, 18, 21, 22, 24}, d30);
  const std::uint32_t p30 = x({3, 5, 6, 8, 9, 10, 11, 13, 15, 19, 22, 23, 24}, d29);
  return p25 << 5 | p26 << 4 | p27 << 3 | p28 << 2 | p29 << 1 | p30;
}

/// 240 data bits of a subframe, fields set at their bit positions (bit 0 = d1 of word 1).
struct Subframe {
  std::array<std::uint32_t, 10> data{};
  void set(int pos, int len, std::int64_t value) {
    for (int k = 0; k < len; ++k) {
      const int bit = pos + k;
      const std::uint32_t mask = 1u << (23 - bit % 24);
      auto& w = data[static_cast<std::size_t>(bit / 24)];
      w = ((value >> (len - 1 - k)) & 1) ? (w | mask) : (w & ~mask);
    }
  }
  /// The ten words as a u-blox receiver delivers them.
  SfrbxMessage message(int prn, int* invertedWords = nullptr) const {
    SfrbxMessage m;
    m.gnssId = 0;
    m.svId = static_cast<std::uint8_t>(prn);
    // As transmitted (20.3.5.2): data bits inverted where D30* is set, parity from D29*, D30*.
    std::vector<std::uint32_t> sent;
    int d29 = 0, d30 = 0;  // word 10 of the previous subframe ends in zeros
    for (std::uint32_t d : data) {
      sent.push_back(((d30 ? d ^ 0xffffffu : d) << 6) | icdParity(d, d29, d30));
      d29 = static_cast<int>((sent.back() >> 1) & 1u);
      d30 = static_cast<int>(sent.back() & 1u);
    }
    // As u-blox delivers them: the whole word inverted after a transmitted D30 = 1.
    std::vector<std::uint32_t> out(10);
    for (std::size_t k = 0; k < 10; ++k) {
      const bool invert = k > 0 && (sent[k - 1] & 1u);
      out[k] = invert ? sent[k] ^ 0x3fffffffu : sent[k];
      if (invert && invertedWords) ++*invertedWords;
    }
    m.words = out;
    return m;
  }
};

Subframe header(int id, int towCount) {
  Subframe s;
  s.set(0, 8, 0x8b);         // TLM preamble
  s.set(24, 17, towCount);   // HOW: TOW count of the next subframe
  s.set(43, 3, id);          // subframe ID
  return s;
}

Subframe subframe1(int iodc, int towCount) {
  Subframe s = header(1, towCount);
  s.set(48, 10, 2381 % 1024);  // week
  s.set(70, 2, iodc >> 8);
  s.set(168, 8, iodc & 0xff);
  s.set(176, 16, 64800 / 16);  // toc
  s.set(216, 22, -12345);      // af0
  return s;
}
Subframe subframe2(int iode, int towCount) {
  Subframe s = header(2, towCount);
  s.set(48, 8, iode);
  s.set(184, 32, static_cast<std::int64_t>(5153.6 * 524288.0));  // sqrtA, 2^-19
  s.set(216, 16, 64800 / 16);                                   // toe
  return s;
}
Subframe subframe3(int iode, int towCount) {
  Subframe s = header(3, towCount);
  s.set(216, 8, iode);
  s.set(224, 14, -100);  // IDOT
  return s;
}

const GpsTime kTime = GpsTime::fromWeekTow(2381, 63000.0);

TEST(SfrbxLnav, BuiltSubframesPassParityWithInvertedWords) {
  NavigationAssembler a;
  int inverted = 0, invertedWords = 0;
  for (int id = 1; id <= 3; ++id) {
    const Subframe s = id == 1 ? subframe1(0x15a, 10500) : id == 2 ? subframe2(0x5a, 10501) : subframe3(0x5a, 10502);
    const SfrbxMessage m = s.message(5, &invertedWords);
    for (std::size_t k = 0; k < 10; ++k) inverted += (m.words[k] >> 6) == s.data[k] ? 0 : 1;
    const NavDataUpdate u = a.add(m, kTime);
    if (id < 3) {
      EXPECT_TRUE(u.kepler.empty());
    }
    if (id == 3) {
      ASSERT_EQ(u.kepler.size(), 1u);
      const KeplerEphemeris& e = u.kepler[0];
      EXPECT_EQ(e.iodc, 0x15a);
      EXPECT_EQ(e.iode, 0x5a);
      EXPECT_EQ(e.week, 2381);
      EXPECT_EQ(e.toeSeconds, 64800.0);
      EXPECT_EQ(e.af0, -12345 * std::ldexp(1.0, -31));
      EXPECT_EQ(e.iDot, -100 * std::ldexp(1.0, -43) * 3.1415926535898);
      EXPECT_NEAR(e.sqrtA, 5153.6, std::ldexp(1.0, -19));
    }
  }
  EXPECT_GT(invertedWords, 3);  // words delivered inverted (after D30* = 1) were among them
  EXPECT_EQ(inverted, 0);        // the delivered data bits are the true ones
  EXPECT_EQ(a.counts(System::Gps).parityFailures, 0u);
}

TEST(SfrbxLnav, Page18KlobucharWithIcdScaleFactors) {
  Subframe s = header(4, 10503);
  s.set(48, 2, 1);   // data ID
  s.set(50, 6, 56);  // SV ID 56 = page 18
  const int alpha[4] = {12, -1, -8, 16}, beta[4] = {98, -2, -128, 127};
  for (int i = 0; i < 4; ++i) {
    s.set(56 + 8 * i, 8, alpha[i]);
    s.set(88 + 8 * i, 8, beta[i]);
  }
  NavigationAssembler a;
  const NavDataUpdate u = a.add(s.message(7), kTime);
  ASSERT_TRUE(u.ionosphere.gps.has_value());
  // IS-GPS-200N table 20-X: alpha 2^-30, 2^-27, 2^-24, 2^-24; beta 2^11, 2^14, 2^16, 2^16.
  const int ae[4] = {-30, -27, -24, -24}, be[4] = {11, 14, 16, 16};
  for (int i = 0; i < 4; ++i) {
    EXPECT_EQ(u.ionosphere.gps->alpha[i], std::ldexp(alpha[i], ae[i]));
    EXPECT_EQ(u.ionosphere.gps->beta[i], std::ldexp(beta[i], be[i]));
  }
  // Another page of subframe 4 (SV ID 57) carries no ionosphere.
  s.set(50, 6, 57);
  EXPECT_FALSE(a.add(s.message(7), kTime).ionosphere.gps.has_value());
}

TEST(SfrbxLnav, MixedIssuesOfDataGiveNoRecordUntilConsistent) {
  NavigationAssembler a;
  EXPECT_TRUE(a.add(subframe1(0x15a, 10500).message(9), kTime).kepler.empty());
  EXPECT_TRUE(a.add(subframe2(0x5a, 10501).message(9), kTime).kepler.empty());
  EXPECT_TRUE(a.add(subframe3(0x5b, 10502).message(9), kTime).kepler.empty());  // new upload
  EXPECT_EQ(a.counts(System::Gps).incompleteSets, 1u);
  EXPECT_TRUE(a.add(subframe1(0x15b, 10505).message(9), kTime).kepler.empty());
  const NavDataUpdate u = a.add(subframe2(0x5b, 10506).message(9), kTime);
  ASSERT_EQ(u.kepler.size(), 1u);
  EXPECT_EQ(u.kepler[0].iode, 0x5b);
  EXPECT_EQ(u.kepler[0].iodc, 0x15b);
  // The same set again: not emitted twice.
  EXPECT_TRUE(a.add(subframe3(0x5b, 10507).message(9), kTime).kepler.empty());
  EXPECT_EQ(a.counts(System::Gps).ephemerides, 1u);
}

TEST(SfrbxLnav, ColdStartWaitsForAReceiveTime) {
  NavigationAssembler a;
  EXPECT_TRUE(a.add(subframe1(0x15a, 10500).message(3), GpsTime{}).kepler.empty());
  EXPECT_TRUE(a.add(subframe2(0x5a, 10501).message(3), GpsTime{}).kepler.empty());
  EXPECT_TRUE(a.add(subframe3(0x5a, 10502).message(3), GpsTime{}).kepler.empty());
  const NavDataUpdate u = a.add(subframe1(0x15a, 10505).message(3), kTime);
  ASSERT_EQ(u.kepler.size(), 1u);
  EXPECT_EQ(u.kepler[0].toe, GpsTime::fromWeekTow(2381, 64800.0));
  EXPECT_EQ(u.kepler[0].ttr, kTime);
}

TEST(SfrbxLnav, OneBitErrorAnywhereIsCaught) {
  const SfrbxMessage good = subframe2(0x5a, 10501).message(4);
  for (int word = 0; word < 10; ++word) {
    for (int bit = 0; bit < 30; ++bit) {
      SfrbxMessage m = good;
      m.words[static_cast<std::size_t>(word)] ^= 1u << bit;
      NavigationAssembler a;
      a.add(m, kTime);
      EXPECT_EQ(a.counts(System::Gps).parityFailures, 1u) << "word " << word << " bit " << bit;
    }
  }
}

}  // namespace
}  // namespace gvins::ubx
