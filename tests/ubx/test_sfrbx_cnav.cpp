// GPS/QZSS CNAV (L2C, L5) from RXM-SFRBX: a message type 30 built here bit by bit from the ICD
// (IS-GPS-200N figure 30-3 / IS-GPS-705J figure 20-3, bit numbers 1-300 as there) with a CRC-24Q
// computed by a bit-serial division by the ICD's generator polynomial (30.3.5.1), decoded back;
// every single flipped bit caught; malformed layouts counted; the walk log's CNAV against itself
// (the same message on L2C and L5), against its LNAV (T_GD, clock) and against the values an
// independent Python decoder read from it; the two ionosphere-free pairs of each satellite.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <map>
#include <variant>

#include "gvins/base/parse_error.hpp"
#include "gvins/ephemeris/ephemeris_store.hpp"
#include "gvins/ephemeris/satellite_state.hpp"
#include "gvins/ubx/navigation_assembler.hpp"
#include "gvins/ubx/ubx_decoder.hpp"
#include "independent_ubx_scan.hpp"
#include "sfrbx_log.hpp"

namespace gvins::ubx {
namespace {

using testing::dataDir;
using testing::decodeLog;

/// One CNAV message, bits numbered 1..300 as in the ICD.
struct CnavBits {
  std::array<int, 300> bit{};
  void set(int first, int len, std::int64_t v) {
    for (int k = 0; k < len; ++k) bit[static_cast<std::size_t>(first - 1 + k)] = static_cast<int>((v >> (len - 1 - k)) & 1);
  }
  /// CRC-24Q of bits 1-276: remainder of the division by g(X) = X^24 + X^23 + X^18 + X^17 + X^14 +
  /// X^11 + X^10 + X^7 + X^6 + X^5 + X^4 + X^3 + X + 1 (IS-GPS-200N 30.3.5.1), one bit at a time.
  std::uint32_t crc() const {
    std::uint32_t g = 0;
    for (int e : {23, 18, 17, 14, 11, 10, 7, 6, 5, 4, 3, 1, 0}) g |= 1u << e;  // X^24 implicit
    std::uint32_t r = 0;
    for (int k = 0; k < 276; ++k) {
      const bool out = ((r >> 23) & 1u) != static_cast<std::uint32_t>(bit[static_cast<std::size_t>(k)]);
      r = (r << 1) & 0xffffffu;
      if (out) r ^= g;
    }
    return r;
  }
  void seal() { set(277, 24, crc()); }
  /// As u-blox delivers it: ten 32-bit words, message bit 1 the most significant bit of word 1,
  /// the last 20 bits of word 10 padding (here `pad`).
  SfrbxMessage message(std::uint8_t gnssId, std::uint8_t svId, std::uint8_t sigId, std::uint32_t pad = 0) const {
    SfrbxMessage m;
    m.gnssId = gnssId;
    m.svId = svId;
    m.sigId = sigId;
    m.version = 2;
    m.words.assign(10, 0);
    for (int k = 0; k < 320; ++k) {
      const int b = k < 300 ? bit[static_cast<std::size_t>(k)] : static_cast<int>((pad >> (319 - k)) & 1u);
      if (b) m.words[static_cast<std::size_t>(k / 32)] |= 1u << (31 - k % 32);
    }
    return m;
  }
};

const double k35 = std::ldexp(1.0, -35);
const GpsTime kReceive = GpsTime::fromWeekTow(2381, 408645.25);

/// Message type 30 of PRN 10, TOW count 68107 (408642 s), with known clock and group delays.
CnavBits type30(int prn = 10) {
  CnavBits c;
  c.set(1, 8, 0x8b);        // preamble
  c.set(9, 6, prn);         // PRN
  c.set(15, 6, 30);         // message type ID
  c.set(21, 17, 68107);     // message TOW count, 6 s
  c.set(38, 1, 0);          // alert flag
  c.set(39, 11, 1361);      // top, 300 s
  c.set(50, 5, -2);         // URA_NED0
  c.set(55, 3, 1);          // URA_NED1
  c.set(58, 3, 2);          // URA_NED2
  c.set(61, 11, 1362);      // toc, 300 s: 408600 s
  c.set(72, 26, -1234567);  // af0, 2^-35 s
  c.set(98, 20, 98765);     // af1, 2^-48 s/s
  c.set(118, 10, -37);      // af2, 2^-60 s/s^2
  c.set(128, 13, 68);       // T_GD
  c.set(141, 13, -24);      // ISC_L1C/A
  c.set(154, 13, -4096);    // ISC_L2C: not available
  c.set(167, 13, 308);      // ISC_L5I5
  c.set(180, 13, -4095);    // ISC_L5Q5: the most negative value that is one
  for (int k = 0; k < 8; ++k) c.set(193 + 8 * k, 8, 17 * k - 60);  // alpha0..3, beta0..3
  c.set(257, 8, 99);        // WN_OP
  c.seal();
  return c;
}

TEST(SfrbxCnav, Type30BuiltFromTheIcdDecodesBack) {
  for (std::uint8_t sig : {std::uint8_t{4}, std::uint8_t{6}}) {  // L2 CM, L5 I
    NavigationAssembler a;
    const NavDataUpdate u = a.add(type30().message(0, 10, sig, 0xabcde), kReceive);
    ASSERT_EQ(u.cnav.size(), 1u);
    const CnavGroupDelays& c = u.cnav[0];
    EXPECT_EQ(c.sat, SatId(System::Gps, 10));
    EXPECT_EQ(c.time, GpsTime::fromWeekTow(2381, 408642.0));
    EXPECT_EQ(c.toc, GpsTime::fromWeekTow(2381, 408600.0));
    EXPECT_EQ(c.af0, -1234567 * k35);
    EXPECT_EQ(c.af1, 98765 * std::ldexp(1.0, -48));
    EXPECT_EQ(c.af2, -37 * std::ldexp(1.0, -60));
    EXPECT_EQ(c.tgd, 68 * k35);
    EXPECT_EQ(c.iscL1ca, -24 * k35);
    EXPECT_FALSE(c.iscL2c.has_value());
    EXPECT_EQ(c.iscL5i5, 308 * k35);
    EXPECT_EQ(c.iscL5q5, -4095 * k35);
    EXPECT_EQ(a.counts(System::Gps).groupDelays, 1u);
    EXPECT_FALSE(u.empty());
    // Into the store: found from the message's time on.
    EphemerisStore s;
    u.addTo(s);
    EXPECT_EQ(s.cnavGroupDelays(c.sat, c.time - 1.0), nullptr);
    ASSERT_NE(s.cnavGroupDelays(c.sat, c.time + 1.0), nullptr);
    EXPECT_EQ(s.cnavGroupDelays(c.sat, c.time + 1.0)->iscL5i5, 308 * k35);
  }
  // QZSS (gnssId 5, L5 I sigId 8): the same layout; its PRN field is not checked.
  NavigationAssembler q;
  const NavDataUpdate uq = q.add(type30(1).message(5, 3, 8), kReceive);
  ASSERT_EQ(uq.cnav.size(), 1u);
  EXPECT_EQ(uq.cnav[0].sat, SatId(System::Qzss, 3));
  EXPECT_EQ(uq.cnav[0].iscL1ca, -24 * k35);
}

TEST(SfrbxCnav, EveryFlippedBitFailsTheCrc) {
  const CnavBits good = type30();
  NavigationAssembler a;
  for (int k = 0; k < 300; ++k) {
    CnavBits c = good;
    c.bit[static_cast<std::size_t>(k)] ^= 1;
    EXPECT_TRUE(a.add(c.message(0, 10, 6), kReceive).cnav.empty()) << "bit " << k + 1;
  }
  EXPECT_EQ(a.counts(System::Gps).crcFailures, 300u);
  EXPECT_EQ(a.counts(System::Gps).groupDelays, 0u);
  // The padding after bit 300 is not part of the message.
  EXPECT_EQ(a.add(good.message(0, 10, 6, 0xfffff), kReceive).cnav.size(), 1u);
}

TEST(SfrbxCnav, MalformedMessagesAreCountedNotDecoded) {
  NavigationAssembler a;
  SfrbxMessage shortMsg = type30().message(0, 10, 6);
  shortMsg.words.pop_back();  // nine words
  SfrbxMessage longMsg = type30().message(0, 10, 6);
  longMsg.words.push_back(0);  // eleven
  CnavBits preamble = type30();
  preamble.set(1, 8, 0x8a);
  preamble.seal();  // a valid CRC over a wrong preamble
  CnavBits tow = type30();
  tow.set(21, 17, 100800);  // one week of 6 s counts: not a time of week
  tow.seal();
  for (const SfrbxMessage& m : {shortMsg, longMsg, preamble.message(0, 10, 6), type30(11).message(0, 10, 6),
                                tow.message(0, 10, 6)}) {
    EXPECT_TRUE(a.add(m, kReceive).empty());
  }
  EXPECT_EQ(a.counts(System::Gps).unknownMessages, 5u);  // PRN 11 in a message tagged svId 10 too
  EXPECT_EQ(a.counts(System::Gps).crcFailures, 0u);
  // Other message types are checked and left alone.
  CnavBits t10 = type30();
  t10.set(15, 6, 10);
  t10.seal();
  EXPECT_TRUE(a.add(t10.message(0, 10, 6), kReceive).empty());
  EXPECT_EQ(a.counts(System::Gps).unknownMessages, 5u);
  EXPECT_EQ(a.counts(System::Gps).messages, 6u);
}

TEST(SfrbxCnav, TruncatedPayloadIsAParseErrorAtItsOffset) {
  // An SFRBX of a CNAV signal announcing ten words and carrying nine, after a complete one.
  const SfrbxMessage m = type30().message(0, 10, 6);
  std::vector<std::uint8_t> p{0, 10, 6, 0, 10, 3, 2, 0};
  for (std::size_t k = 0; k < 9; ++k)
    for (int i = 0; i < 4; ++i) p.push_back(static_cast<std::uint8_t>(m.words[k] >> (8 * i)));
  std::vector<std::uint8_t> good = p;  // the whole message first
  for (int i = 0; i < 4; ++i) good.push_back(static_cast<std::uint8_t>(m.words[9] >> (8 * i)));
  std::vector<std::uint8_t> s = testing::makeFrame(0x02, 0x13, good);
  const std::int64_t offset = static_cast<std::int64_t>(s.size());
  const auto bad = testing::makeFrame(0x02, 0x13, p);
  s.insert(s.end(), bad.begin(), bad.end());
  DecoderOptions o;
  o.strict = true;
  o.streamName = "cnav.ubx";
  Decoder d(o);
  try {
    d.feed(s);
    FAIL() << "no error";
  } catch (const ParseError& e) {
    EXPECT_EQ(e.file(), "cnav.ubx");
    EXPECT_EQ(e.line(), offset);
    EXPECT_NE(e.field().find("numWords"), std::string::npos) << e.field();
  }
}

TEST(SfrbxCnav, MessagesBeforeAnyTimeAreDatedLater) {
  NavigationAssembler a;
  EXPECT_TRUE(a.add(type30().message(0, 10, 6), GpsTime{}).empty());
  CnavBits other = type30(12);
  other.set(15, 6, 33);  // type 33 of another satellite brings the time
  other.seal();
  const NavDataUpdate u = a.add(other.message(0, 12, 6), kReceive);
  ASSERT_EQ(u.cnav.size(), 1u);
  EXPECT_EQ(u.cnav[0].sat, SatId(System::Gps, 10));
  EXPECT_EQ(u.cnav[0].time, GpsTime::fromWeekTow(2381, 408642.0));
}

// The walk log: every CNAV message passes its CRC; the type 30 sets are the ones an independent
// Python decoder (UBX frames, words MSB first, the ICD bit positions) read from the log; the
// same satellite's message on L2C and on L5 carries the same values; the group delays are
// physically plausible; T_GD and the clock agree with the satellite's LNAV.
TEST(SfrbxCnav, WalkLogType30) {
  const auto log = decodeLog(dataDir() / "ubx" / "gnss_1730.ubx");
  const NavigationCounts& n = log.assembler.counts(System::Gps);
  EXPECT_EQ(n.crcFailures, 0u);
  EXPECT_EQ(n.parityFailures, 0u);
  EXPECT_EQ(n.groupDelays, 44u);  // 12 on L2 CM, 32 on L5 I (the Python tally)
  std::map<int, std::vector<CnavGroupDelays>> bySat;
  for (const auto& u : log.updates)
    for (const auto& c : u.cnav) bySat[c.sat.prn].push_back(c);
  ASSERT_EQ(bySat.size(), 7u);  // G08, G10, G18, G23, G24, G27, G32
  for (const auto& [prn, list] : bySat) {
    for (const auto& c : list) {
      EXPECT_TRUE(c.sameCorrections(list.front())) << prn;
      for (const auto& v : {c.tgd, c.iscL1ca, c.iscL2c, c.iscL5i5, c.iscL5q5}) {
        ASSERT_TRUE(v.has_value()) << prn;
        EXPECT_LT(std::abs(*v), 30e-9) << prn;
      }
    }
  }
  // Raw 13-bit values (units of 2^-35 s) of T_GD, ISC_L1C/A, ISC_L2C, ISC_L5I5, ISC_L5Q5.
  const std::map<int, std::array<int, 5>> python{{10, {80, -28, -16, 364, 379}},
                                                 {23, {-288, -7, 193, -18, -17}},
                                                 {27, {64, -31, -47, 242, 195}},
                                                 {32, {32, -10, -65, 296, 311}}};
  for (const auto& [prn, raw] : python) {
    const CnavGroupDelays& c = bySat.at(prn).front();
    const std::array<std::optional<double>, 5> got{c.tgd, c.iscL1ca, c.iscL2c, c.iscL5i5, c.iscL5q5};
    for (std::size_t k = 0; k < 5; ++k) EXPECT_EQ(*got[k], raw[k] * k35) << prn << " field " << k;
  }
  // LNAV of the same satellites: T_GD in 2^-31 s steps, the CNAV one in 2^-35 s steps; the two
  // clocks (both referred to the L1/L2 P(Y) pair) at the LNAV toc.
  int compared = 0;
  for (const KeplerEphemeris& e : log.kepler) {
    if (e.sat.system != System::Gps || !bySat.count(e.sat.prn)) continue;
    const CnavGroupDelays& c = bySat.at(e.sat.prn).front();
    EXPECT_LE(std::abs(*c.tgd - e.tgd[0]), std::ldexp(1.0, -32) + 1e-15) << e.sat.prn;
    const double dt = e.toc - c.toc;
    const double cnavClock = c.af0 + c.af1 * dt + c.af2 * dt * dt;
    EXPECT_LT(std::abs(cnavClock - e.af0), 2e-9) << e.sat.prn;
    ++compared;
  }
  EXPECT_GE(compared, 2);
}

// The walk log through the decoder: per GPS satellite with L1 C/A, L2C and L5 Q, the difference of
// its two ionosphere-free pairs after the group delays, P_IF(L1,L5) − P_IF(L1,L2C), is the
// receiver's inter-frequency bias, one constant for all satellites (plus code noise and
// multipath, averaged over the epochs). With the CNAV ISCs the per-satellite means agree to about
// a metre; with T_GD alone on L5 (no ISC) they spread by metres.
TEST(SfrbxCnav, WalkLogPairsAgreeAcrossSatellites) {
  Decoder dec;
  dec.feed(testing::readBytes(dataDir() / "ubx" / "gnss_1730.ubx"));
  dec.finish();
  EphemerisStore store;
  std::vector<ObsEpoch> epochs;
  while (auto d = dec.poll()) {
    if (auto* u = std::get_if<NavDataUpdate>(&*d)) u->addTo(store);
    if (auto* e = std::get_if<ObsEpoch>(&*d)) epochs.push_back(std::move(*e));
  }
  const double kC = 299792458.0, f1 = 1575.42e6, f2 = 1227.60e6, f5 = 1176.45e6;
  const double g12 = f1 * f1 / (f2 * f2), g15 = f1 * f1 / (f5 * f5);
  const ObsCode c1('1', 'C'), c2('2', 'L'), c5('5', 'Q');
  std::map<int, std::array<double, 3>> sum;  // with ISCs, T_GD alone, epochs
  for (const ObsEpoch& e : epochs) {
    for (const SatObs& so : e.sats) {
      if (so.sat.system != System::Gps) continue;
      const SignalObs *s1 = so.find(c1), *s2 = so.find(c2), *s5 = so.find(c5);
      const KeplerEphemeris* k = store.selectKepler(so.sat, e.time);
      const CnavGroupDelays* c = store.cnavGroupDelays(so.sat, e.time);
      if (!s1 || !s2 || !s5 || !s1->hasCode() || !s2->hasCode() || !s5->hasCode() || !k || !c) continue;
      auto pair = [&](const SignalObs& s, double g, const CnavGroupDelays* isc) {
        const double p1 = s1->pseudorange - kC * broadcastGroupDelay(*k, c1, isc);
        const double p2 = s.pseudorange - kC * broadcastGroupDelay(*k, s.code, isc);
        return (g * p1 - p2) / (g - 1.0);
      };
      auto& a = sum[so.sat.prn];
      a[0] += pair(*s5, g15, c) - pair(*s2, g12, c);
      a[1] += pair(*s5, g15, nullptr) - pair(*s2, g12, nullptr);
      a[2] += 1.0;
    }
  }
  ASSERT_GE(sum.size(), 4u);
  double lo[2] = {1e9, 1e9}, hi[2] = {-1e9, -1e9};
  for (const auto& [prn, a] : sum) {
    ASSERT_GE(a[2], 50.0) << prn;
    for (int k = 0; k < 2; ++k) {
      const double m = a[static_cast<std::size_t>(k)] / a[2];
      std::printf("G%02d %s %.2f m over %.0f epochs\n", prn, k == 0 ? "with ISCs " : "T_GD alone", m, a[2]);
      lo[k] = std::min(lo[k], m);
      hi[k] = std::max(hi[k], m);
    }
  }
  std::printf("spread: with ISCs %.2f m, T_GD alone %.2f m\n", hi[0] - lo[0], hi[1] - lo[1]);
  EXPECT_LT(hi[0] - lo[0], 1.5);
  EXPECT_GT(hi[1] - lo[1], 4.0);
}

}  // namespace
}  // namespace gvins::ubx
