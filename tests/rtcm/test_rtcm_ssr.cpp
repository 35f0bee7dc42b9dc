// SSR messages (RTCM 10403.3, 3.5.12): encoder -> frame -> decoder round trips of every kind and
// system with values at the field limits; frames built bit by bit in the test from the field
// table (so encoder and decoder cannot share a mistake); the real SSR streams of tests/data/rtcm;
// malformed messages; epoch-time resolution (GLONASS day boundary, BeiDou BDT); encoder range
// errors.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <stdexcept>

#include "gvins/base/parse_error.hpp"
#include "gvins/rtcm/bit_writer.hpp"
#include "gvins/rtcm/decoder.hpp"
#include "gvins/rtcm/encoder.hpp"
#include "gvins/rtcm/message_types.hpp"
#include "independent_frame_scan.hpp"
#include "ssr_field_checks.hpp"

namespace gvins::rtcm {
namespace {

using testing::dataDir;
using testing::readBytes;

constexpr System kSystems[] = {System::Gps, System::Glonass, System::Galileo, System::Qzss, System::BeiDou};
constexpr SsrKind kKinds[] = {SsrKind::kOrbit, SsrKind::kClock,  SsrKind::kCodeBias,
                              SsrKind::kCombined, SsrKind::kUra, SsrKind::kHighRateClock};

/// Message numbers written out from RTCM 10403.3 table 3.5-1 (not from the library's tables).
int expectedType(System s, SsrKind k) {
  const int base = s == System::Gps       ? 1057
                   : s == System::Glonass ? 1063
                   : s == System::Galileo ? 1240
                   : s == System::Qzss    ? 1246
                                          : 1258;
  return base + static_cast<int>(k);  // SsrKind lists the kinds in message-number order
}

/// A frame around a payload, framed and CRC'd by the test's own bitwise CRC.
std::vector<std::uint8_t> independentFrame(const std::vector<std::uint8_t>& payload) {
  std::vector<std::uint8_t> f;
  f.reserve(payload.size() + 6);
  f.push_back(0xD3);
  f.push_back(static_cast<std::uint8_t>(payload.size() >> 8));
  f.push_back(static_cast<std::uint8_t>(payload.size() & 0xFF));
  for (const std::uint8_t b : payload) f.push_back(b);
  const std::uint32_t crc = testing::bitwiseCrc24q(f.data(), f.size());
  f.push_back(static_cast<std::uint8_t>(crc >> 16));
  f.push_back(static_cast<std::uint8_t>(crc >> 8));
  f.push_back(static_cast<std::uint8_t>(crc));
  return f;
}

struct Result {
  std::vector<SsrMessage> ssr;
  DecoderStats stats;
};

Result decode(const std::vector<std::uint8_t>& bytes, const GpsTime& ref) {
  DecoderOptions opt;
  opt.referenceTime = ref;
  Decoder dec(opt);
  Result out;
  dec.feed(bytes);
  dec.finish();
  while (auto item = dec.poll()) {
    if (auto* m = std::get_if<SsrMessage>(&*item)) out.ssr.push_back(std::move(*m));
  }
  out.stats = dec.stats();
  return out;
}

GpsTime moscow(int y, int mo, int d, int h, int mi, double s) {
  CalendarTime c;
  c.year = y;
  c.month = mo;
  c.day = d;
  c.hour = h;
  c.minute = mi;
  c.second = s;
  return glonassToGpst(c);
}

// Field limits: largest and smallest value of a two's complement field of `bits` at `lsb`.
double maxOf(int bits, double lsb) { return (std::ldexp(1.0, bits - 1) - 1) * lsb; }
double minOf(int bits, double lsb) { return -std::ldexp(1.0, bits - 1) * lsb; }

/// Values at, near and between the limits: j = 0 just below the maximum (rounds to it), 1 just
/// above the minimum (rounds to it), otherwise random within the field.
double probe(int j, int bits, double lsb, std::mt19937& rng) {
  if (j == 0) return maxOf(bits, lsb) + 0.49 * lsb;
  if (j == 1) return minOf(bits, lsb) - 0.49 * lsb;
  std::uniform_real_distribution<double> u(minOf(bits, lsb), maxOf(bits, lsb));
  return u(rng);
}

// The RINEX codes of every defined code-bias identifier (RTCM 10403.3 DF380, DF381, DF382,
// DF461, DF467), written out here independently of the library's table.
std::vector<std::pair<int, ObsCode>> signalsOf(System s) {
  auto c = [](const char* t) { return ObsCode{t[0], t[1]}; };
  switch (s) {
    case System::Gps:
      return {{0, c("1C")},  {1, c("1P")},  {2, c("1W")},  {5, c("2C")},  {6, c("2D")},  {7, c("2S")},
              {8, c("2L")},  {9, c("2X")},  {10, c("2P")}, {11, c("2W")}, {14, c("5I")}, {15, c("5Q")},
              {16, c("5X")}, {17, c("1S")}, {18, c("1L")}, {19, c("1X")}};
    case System::Glonass: return {{0, c("1C")}, {1, c("1P")}, {2, c("2C")}, {3, c("2P")}};
    case System::Galileo:
      return {{0, c("1A")},  {1, c("1B")},  {2, c("1C")},  {3, c("1X")},  {4, c("1Z")},
              {5, c("5I")},  {6, c("5Q")},  {7, c("5X")},  {8, c("7I")},  {9, c("7Q")},
              {10, c("7X")}, {11, c("8I")}, {12, c("8Q")}, {13, c("8X")}, {14, c("6A")},
              {15, c("6B")}, {16, c("6C")}, {17, c("6X")}, {18, c("6Z")}};
    case System::Qzss:
      return {{0, c("1C")}, {1, c("1S")}, {2, c("1L")}, {3, c("2S")},  {4, c("2L")},  {5, c("2X")}, {6, c("5I")},
              {7, c("5Q")}, {8, c("5X")}, {9, c("6S")}, {10, c("6L")}, {11, c("6X")}, {12, c("1X")}};
    case System::BeiDou:
      return {{0, c("2I")},  {1, c("2Q")},  {2, c("2X")},  {3, c("6I")},  {4, c("6Q")},  {5, c("6X")},
              {6, c("7I")},  {7, c("7Q")},  {8, c("7X")},  {9, c("1D")},  {10, c("1P")}, {11, c("1X")},
              {12, c("5D")}, {13, c("5P")}, {14, c("5X")}, {15, c("7D")}};
    default: return {};
  }
}

int iodBits(System s) { return s == System::Galileo || s == System::BeiDou ? 10 : 8; }

SsrMessage sampleMessage(System sys, SsrKind kind, const GpsTime& epoch, std::mt19937& rng) {
  SsrMessage m;
  m.header.system = sys;
  m.header.kind = kind;
  m.header.epoch = epoch;
  m.header.updateInterval = std::array<double, 16>{1, 2, 5, 10, 15, 30, 60, 120, 240, 300, 600, 900,
                                                   1800, 3600, 7200, 10800}[rng() % 16];
  m.header.multipleMessage = (rng() & 1) != 0;
  m.header.regionalDatum = kind == SsrKind::kOrbit || kind == SsrKind::kCombined;
  m.header.iodSsr = 15;
  m.header.providerId = 65535;
  m.header.solutionId = 15;
  // First, last and a middle satellite number of the system.
  const int prns[] = {minPrn(sys), maxPrn(sys), (minPrn(sys) + maxPrn(sys)) / 2};
  const auto signals = signalsOf(sys);
  for (int j = 0; j < 3; ++j) {
    SsrSatellite s;
    s.sat = SatId(sys, prns[j]);
    if (kind == SsrKind::kOrbit || kind == SsrKind::kCombined) {
      SsrOrbitCorrection o;
      o.issueOfData = j == 0 ? (1 << iodBits(sys)) - 1 : j == 1 ? 0 : static_cast<int>(rng() % 256);
      if (sys == System::BeiDou) o.iodCrc = j == 0 ? 255 : j == 1 ? 0 : 77;
      o.rac = {probe(j, 22, 1e-4, rng), probe(j, 20, 4e-4, rng), probe(1 - j % 2, 20, 4e-4, rng)};
      o.racRate = {probe(j, 21, 1e-6, rng), probe(j, 19, 4e-6, rng), probe(j, 19, 4e-6, rng)};
      s.orbit = o;
    }
    if (kind == SsrKind::kClock || kind == SsrKind::kCombined) {
      s.clock = SsrClockCorrection{probe(j, 22, 1e-4, rng), probe(j, 21, 1e-6, rng), probe(j, 27, 2e-8, rng)};
    }
    if (kind == SsrKind::kCodeBias) {
      for (std::size_t k = 0; k < signals.size(); ++k) {
        s.codeBiases.emplace_back(signals[k].second, probe(static_cast<int>((k + j) % 3), 14, 0.01, rng));
      }
    }
    if (kind == SsrKind::kUra) s.uraIndex = j == 0 ? 63 : j == 1 ? 0 : 27;
    if (kind == SsrKind::kHighRateClock) s.highRateClock = probe(j, 22, 1e-4, rng);
    m.satellites.push_back(s);
  }
  return m;
}

// Quantisation error at most half an LSB (plus rounding noise of the double arithmetic).

TEST(Ssr, RoundTripEveryKindAndSystemAtFieldLimits) {
  std::mt19937 rng(11);
  const GpsTime epoch = GpsTime::fromWeekTow(2277, 345678.0);
  Encoder enc;
  for (System sys : kSystems) {
    for (SsrKind kind : kKinds) {
      SCOPED_TRACE(std::string(systemName(sys)) + " " + std::to_string(expectedType(sys, kind)));
      const SsrMessage sent = sampleMessage(sys, kind, epoch, rng);
      const auto frame = enc.ssr(sent);
      const Result got = decode(frame, epoch + 5000.0);
      ASSERT_EQ(got.stats.malformed, 0);
      ASSERT_EQ(got.ssr.size(), 1u);
      EXPECT_EQ(got.stats.ssrMessages, 1);
      const SsrMessage& m = got.ssr[0];
      EXPECT_EQ(m.header.messageType, expectedType(sys, kind));
      EXPECT_EQ(m.header.system, sys);
      EXPECT_EQ(m.header.kind, kind);
      EXPECT_EQ(m.header.epoch, epoch);
      EXPECT_EQ(m.header.updateInterval, sent.header.updateInterval);
      EXPECT_EQ(m.header.multipleMessage, sent.header.multipleMessage);
      EXPECT_EQ(m.header.regionalDatum, sent.header.regionalDatum);
      EXPECT_EQ(m.header.iodSsr, 15);
      EXPECT_EQ(m.header.providerId, 65535);
      EXPECT_EQ(m.header.solutionId, 15);
      gvins::test::expectSameSatellites(m.satellites, sent.satellites);
      EXPECT_EQ(got.stats.unknownBiasSignals, 0);
    }
  }
}

// ---- frames built bit by bit from the field table -------------------------------------------

TEST(Ssr, HandBuiltGps1060) {
  // 1060 GPS combined orbit and clock, two satellites; raw field values chosen by hand.
  BitWriter w;
  w.u(12, 1060, "DF002");
  w.u(20, 345600, "DF385");  // Thursday 00:00:00 GPST
  w.u(4, 2, "DF391");        // 5 s
  w.u(1, 0, "DF388");
  w.u(1, 1, "DF375");        // regional
  w.u(4, 7, "DF413");
  w.u(16, 1234, "DF414");
  w.u(4, 3, "DF415");
  w.u(6, 2, "DF387");
  // G05, IODE 77
  w.u(6, 5, "DF068");
  w.u(8, 77, "DF071");
  w.s(22, 12345, "DF365");   // 1.2345 m
  w.s(20, -2500, "DF366");   // -1.0 m
  w.s(20, 1, "DF367");       // 0.0004 m
  w.s(21, 1000, "DF368");    // 0.001 m/s
  w.s(19, -250, "DF369");    // -0.001 m/s
  w.s(19, 0, "DF370");
  w.s(22, -10000, "DF376");  // -1.0 m
  w.s(21, 1000, "DF377");    // 0.001 m/s
  w.s(27, 50, "DF378");      // 1e-6 m/s^2
  // G32, IODE 255, every field at its negative limit
  w.u(6, 32, "DF068");
  w.u(8, 255, "DF071");
  w.s(22, -(1 << 21), "DF365");
  w.s(20, -(1 << 19), "DF366");
  w.s(20, (1 << 19) - 1, "DF367");
  w.s(21, -(1 << 20), "DF368");
  w.s(19, -(1 << 18), "DF369");
  w.s(19, (1 << 18) - 1, "DF370");
  w.s(22, -(1 << 21), "DF376");
  w.s(21, (1 << 20) - 1, "DF377");
  w.s(27, -(1 << 26), "DF378");
  const auto frame = independentFrame(w.bytes());

  const GpsTime t = GpsTime::fromWeekTow(2277, 345600.0);
  const Result got = decode(frame, t - 86400.0);
  ASSERT_EQ(got.stats.malformed, 0);
  ASSERT_EQ(got.ssr.size(), 1u);
  const SsrMessage& m = got.ssr[0];
  EXPECT_EQ(m.header.messageType, 1060);
  EXPECT_EQ(m.header.kind, SsrKind::kCombined);
  EXPECT_EQ(m.header.epoch, t);
  EXPECT_EQ(m.header.updateInterval, 5.0);
  EXPECT_FALSE(m.header.multipleMessage);
  EXPECT_TRUE(m.header.regionalDatum);
  EXPECT_EQ(m.header.iodSsr, 7);
  EXPECT_EQ(m.header.providerId, 1234);
  EXPECT_EQ(m.header.solutionId, 3);
  ASSERT_EQ(m.satellites.size(), 2u);
  const SsrSatellite& a = m.satellites[0];
  EXPECT_EQ(a.sat, SatId(System::Gps, 5));
  ASSERT_TRUE(a.orbit && a.clock);
  EXPECT_EQ(a.orbit->issueOfData, 77);
  EXPECT_NEAR(a.orbit->rac.x(), 1.2345, 1e-12);
  EXPECT_NEAR(a.orbit->rac.y(), -1.0, 1e-12);
  EXPECT_NEAR(a.orbit->rac.z(), 0.0004, 1e-12);
  EXPECT_NEAR(a.orbit->racRate.x(), 0.001, 1e-15);
  EXPECT_NEAR(a.orbit->racRate.y(), -0.001, 1e-15);
  EXPECT_EQ(a.orbit->racRate.z(), 0.0);
  EXPECT_NEAR(a.clock->c0, -1.0, 1e-12);
  EXPECT_NEAR(a.clock->c1, 0.001, 1e-15);
  EXPECT_NEAR(a.clock->c2, 1e-6, 1e-18);
  const SsrSatellite& b = m.satellites[1];
  EXPECT_EQ(b.sat, SatId(System::Gps, 32));
  EXPECT_EQ(b.orbit->issueOfData, 255);
  EXPECT_NEAR(b.orbit->rac.x(), -209.7152, 1e-9);
  EXPECT_NEAR(b.orbit->rac.y(), -209.7152, 1e-9);
  EXPECT_NEAR(b.orbit->rac.z(), 209.7148, 1e-9);
  EXPECT_NEAR(b.orbit->racRate.x(), -1.048576, 1e-12);
  EXPECT_NEAR(b.orbit->racRate.y(), -1.048576, 1e-12);
  EXPECT_NEAR(b.orbit->racRate.z(), 1.048572, 1e-12);
  EXPECT_NEAR(b.clock->c0, -209.7152, 1e-9);
  EXPECT_NEAR(b.clock->c1, 1.048575, 1e-12);
  EXPECT_NEAR(b.clock->c2, -1.34217728, 1e-12);

  // The encoder writes the same bits for the same content.
  SsrMessage same = m;
  EXPECT_EQ(Encoder().ssr(same), frame);
}

TEST(Ssr, HandBuiltBeidou1258UsesBdtAndToeModuloPlusIod) {
  // 1258 BeiDou orbit: DF465 in BDT; per satellite DF488 ID, DF470 toe modulo (10 bits), DF471 IOD
  // (8 bits), then the orbit fields.
  BitWriter w;
  w.u(12, 1258, "DF002");
  w.u(20, 338746, "DF465");
  w.u(4, 0, "DF391");  // 1 s
  w.u(1, 1, "DF388");
  w.u(1, 0, "DF375");
  w.u(4, 0, "DF413");
  w.u(16, 0, "DF414");
  w.u(4, 0, "DF415");
  w.u(6, 1, "DF387");
  w.u(6, 1, "DF488");   // C01
  w.u(10, 316, "DF470");  // (toe mod 8192) / 8 for toe = 338400 s of the BDT week
  w.u(8, 230, "DF471");   // (toe / 720) mod 240
  w.s(22, -12444, "DF365");
  w.s(20, 2025, "DF366");
  w.s(20, 28881, "DF367");
  w.s(21, -2, "DF368");
  w.s(19, 1, "DF369");
  w.s(19, -28, "DF370");
  const auto frame = independentFrame(w.bytes());
  const Result got = decode(frame, GpsTime::fromWeekTow(2200, 300000.0));
  ASSERT_EQ(got.stats.malformed, 0);
  ASSERT_EQ(got.ssr.size(), 1u);
  const SsrMessage& m = got.ssr[0];
  EXPECT_EQ(m.header.system, System::BeiDou);
  EXPECT_EQ(m.header.kind, SsrKind::kOrbit);
  EXPECT_EQ(m.header.epoch, GpsTime::fromWeekTow(2200, 338746.0 + 14.0));  // BDT = GPST - 14 s
  EXPECT_EQ(m.header.updateInterval, 1.0);
  EXPECT_TRUE(m.header.multipleMessage);
  ASSERT_EQ(m.satellites.size(), 1u);
  const SsrSatellite& s = m.satellites[0];
  EXPECT_EQ(s.sat, SatId(System::BeiDou, 1));
  EXPECT_EQ(s.orbit->issueOfData, 316);
  EXPECT_EQ(s.orbit->iodCrc, 230);
  EXPECT_NEAR(s.orbit->rac.x(), -1.2444, 1e-12);
  EXPECT_NEAR(s.orbit->rac.y(), 0.81, 1e-12);
  EXPECT_NEAR(s.orbit->rac.z(), 11.5524, 1e-12);
  EXPECT_NEAR(s.orbit->racRate.x(), -2e-6, 1e-18);
  EXPECT_NEAR(s.orbit->racRate.y(), 4e-6, 1e-18);
  EXPECT_NEAR(s.orbit->racRate.z(), -112e-6, 1e-18);
  EXPECT_EQ(Encoder().ssr(m), frame);
}

TEST(Ssr, HandBuiltCodeBiasesGlonass1065AndQzss1248) {
  // 1065: GLONASS epoch DF386 (17 bits), 5-bit satellite ID (DF384), DF381 identifiers 0-3 and
  // a reserved one (7), which is skipped and counted.
  const GpsTime ref = moscow(2023, 8, 17, 12, 0, 0.0);
  BitWriter w;
  w.u(12, 1065, "DF002");
  w.u(17, 43210, "DF386");
  w.u(4, 15, "DF391");  // 10800 s
  w.u(1, 0, "DF388");
  w.u(4, 1, "DF413");
  w.u(16, 2, "DF414");
  w.u(4, 3, "DF415");
  w.u(6, 1, "DF387");
  w.u(5, 24, "DF384");  // R24
  w.u(5, 5, "DF379");
  const int ids[] = {0, 1, 2, 3, 7};
  const int raw[] = {123, -456, 8191, -8192, 5};
  for (int k = 0; k < 5; ++k) {
    w.u(5, static_cast<std::uint64_t>(ids[k]), "DF381");
    w.s(14, raw[k], "DF383");
  }
  Result got = decode(independentFrame(w.bytes()), ref);
  ASSERT_EQ(got.stats.malformed, 0);
  ASSERT_EQ(got.ssr.size(), 1u);
  EXPECT_EQ(got.stats.unknownBiasSignals, 1);
  {
    const SsrMessage& m = got.ssr[0];
    EXPECT_EQ(m.header.system, System::Glonass);
    EXPECT_EQ(m.header.kind, SsrKind::kCodeBias);
    EXPECT_EQ(m.header.epoch, moscow(2023, 8, 17, 12, 0, 10.0));  // 43210 s = 12:00:10 Moscow
    EXPECT_EQ(m.header.updateInterval, 10800.0);
    ASSERT_EQ(m.satellites.size(), 1u);
    EXPECT_EQ(m.satellites[0].sat, SatId(System::Glonass, 24));
    const auto& cb = m.satellites[0].codeBiases;
    ASSERT_EQ(cb.size(), 4u);
    EXPECT_EQ(cb[0].first, ObsCode('1', 'C'));
    EXPECT_EQ(cb[1].first, ObsCode('1', 'P'));
    EXPECT_EQ(cb[2].first, ObsCode('2', 'C'));
    EXPECT_EQ(cb[3].first, ObsCode('2', 'P'));
    EXPECT_NEAR(cb[0].second, 1.23, 1e-12);
    EXPECT_NEAR(cb[1].second, -4.56, 1e-12);
    EXPECT_NEAR(cb[2].second, 81.91, 1e-12);
    EXPECT_NEAR(cb[3].second, -81.92, 1e-12);
  }

  // 1248: QZSS with its 4-bit satellite ID (DF429) and DF461 identifiers.
  BitWriter q;
  q.u(12, 1248, "DF002");
  q.u(20, 389925, "DF460");
  q.u(4, 2, "DF391");
  q.u(1, 0, "DF388");
  q.u(4, 0, "DF413");
  q.u(16, 267, "DF414");
  q.u(4, 7, "DF415");
  q.u(6, 2, "DF387");
  q.u(4, 2, "DF429");  // J02
  q.u(5, 2, "DF379");
  q.u(5, 12, "DF461");  // L1C D+P
  q.s(14, -115, "DF383");
  q.u(5, 8, "DF461");  // L5 I+Q
  q.s(14, -157, "DF383");
  q.u(4, 7, "DF429");  // J07
  q.u(5, 1, "DF379");
  q.u(5, 0, "DF461");  // L1 C/A
  q.s(14, 172, "DF383");
  got = decode(independentFrame(q.bytes()), GpsTime::fromWeekTow(2270, 390000.0));
  ASSERT_EQ(got.stats.malformed, 0);
  ASSERT_EQ(got.ssr.size(), 1u);
  const SsrMessage& m = got.ssr[0];
  EXPECT_EQ(m.header.epoch, GpsTime::fromWeekTow(2270, 389925.0));
  EXPECT_EQ(m.header.providerId, 267);
  ASSERT_EQ(m.satellites.size(), 2u);
  EXPECT_EQ(m.satellites[0].sat, SatId(System::Qzss, 2));
  EXPECT_EQ(m.satellites[1].sat, SatId(System::Qzss, 7));
  ASSERT_EQ(m.satellites[0].codeBiases.size(), 2u);
  EXPECT_EQ(m.satellites[0].codeBiases[0].first, ObsCode('1', 'X'));
  EXPECT_NEAR(m.satellites[0].codeBiases[0].second, -1.15, 1e-12);
  EXPECT_EQ(m.satellites[0].codeBiases[1].first, ObsCode('5', 'X'));
  EXPECT_NEAR(m.satellites[0].codeBiases[1].second, -1.57, 1e-12);
  ASSERT_EQ(m.satellites[1].codeBiases.size(), 1u);
  EXPECT_EQ(m.satellites[1].codeBiases[0].first, ObsCode('1', 'C'));
  EXPECT_NEAR(m.satellites[1].codeBiases[0].second, 1.72, 1e-12);
  EXPECT_EQ(Encoder().ssr(m), independentFrame(q.bytes()));
}

TEST(Ssr, EverySignalIdentifierMapsBothWays) {
  // Encode one code bias per defined identifier and check the identifier on the wire: the bits
  // after the 67-bit header (64 for GLONASS), the satellite ID and DF379.
  for (System sys : kSystems) {
    for (const auto& [id, code] : signalsOf(sys)) {
      SsrMessage m;
      m.header.system = sys;
      m.header.kind = SsrKind::kCodeBias;
      m.header.epoch = GpsTime::fromWeekTow(2277, 3600.0);
      SsrSatellite s;
      s.sat = SatId(sys, 3);
      s.codeBiases.emplace_back(code, 0.5);
      m.satellites.push_back(s);
      const auto f = Encoder().ssr(m);
      const int satBits = sys == System::Glonass ? 5 : sys == System::Qzss ? 4 : 6;
      const int pos = 8 * 3 + (sys == System::Glonass ? 64 : 67) + satBits + 5;
      int v = 0;
      for (int b = 0; b < 5; ++b) v = (v << 1) | ((f[static_cast<std::size_t>((pos + b) / 8)] >> (7 - (pos + b) % 8)) & 1);
      EXPECT_EQ(v, id) << systemName(sys) << " " << code.str();
      const Result got = decode(f, m.header.epoch);
      ASSERT_EQ(got.ssr.size(), 1u);
      ASSERT_EQ(got.ssr[0].satellites[0].codeBiases.size(), 1u);
      EXPECT_EQ(got.ssr[0].satellites[0].codeBiases[0].first, code);
    }
  }
}

// ---- real streams ---------------------------------------------------------------------------

TEST(Ssr, RealStreamsDecodeCleanly) {
  // IGS/BKG and other casters' SSR streams in tests/data/rtcm: every SSR frame decodes without an
  // issue (with a 24-bit BeiDou IOD the 1258/1261 messages would run past their end).
  struct File {
    const char* name;
    GpsTime ref;
  };
  const File files[] = {{"pyrtcm_pygpsdata-1240-1264.log", GpsTime::fromWeekTow(2200, 338760.0)},
                        {"pyrtcm_pygpsdata-NTRIP-1300-1302.log", GpsTime::fromWeekTow(2200, 315360.0)},
                        {"pyrtcm_pygpsdata-RTCM3.log", GpsTime::fromWeekTow(2200, 466480.0)},
                        {"cssrlib_idd2023229c.rtc", GpsTime::fromWeekTow(2275, 352752.0)}};
  for (const File& f : files) {
    SCOPED_TRACE(f.name);
    const auto bytes = readBytes(dataDir() / "rtcm" / f.name);
    const auto scan = testing::independentScan(bytes);
    std::int64_t ssrFrames = 0;
    for (const auto& [type, n] : scan.types) {
      if ((type >= 1057 && type <= 1068) || (type >= 1240 && type <= 1251) || (type >= 1258 && type <= 1263)) {
        ssrFrames += n;
      }
    }
    const Result got = decode(bytes, f.ref);
    EXPECT_EQ(got.stats.malformed, 0);
    for (const auto& is : got.stats.issues) ADD_FAILURE() << is.what;
    EXPECT_GT(ssrFrames, 0);
    EXPECT_EQ(static_cast<std::int64_t>(got.ssr.size()), ssrFrames);
    for (const SsrMessage& m : got.ssr) {
      EXPECT_LT(std::abs(m.header.epoch - f.ref), 2.0 * 86400.0);
      for (const SsrSatellite& s : m.satellites) {
        EXPECT_TRUE(s.sat.valid());
        if (s.orbit) {
          EXPECT_LT(s.orbit->rac.norm(), 100.0) << s.sat.str();  // metres, not garbage
        }
      }
    }
  }
  // Spot check: the first Galileo orbit message of the pyrtcm log (E02, IODnav 50).
  const Result got = decode(readBytes(dataDir() / "rtcm/pyrtcm_pygpsdata-1240-1264.log"),
                             GpsTime::fromWeekTow(2200, 338760.0));
  const SsrMessage* e = nullptr;
  for (const auto& m : got.ssr) {
    if (m.header.messageType == 1240) e = &m;
  }
  ASSERT_NE(e, nullptr);
  EXPECT_EQ(e->header.epoch, GpsTime::fromWeekTow(2200, 338760.0));
  EXPECT_EQ(e->satellites.size(), 28u);
  EXPECT_EQ(e->satellites[0].sat, SatId(System::Galileo, 2));
  EXPECT_EQ(e->satellites[0].orbit->issueOfData, 50);
  EXPECT_NEAR(e->satellites[0].orbit->rac.x(), -0.6676, 1e-9);
  EXPECT_NEAR(e->satellites[0].orbit->rac.y(), 0.4356, 1e-9);
  EXPECT_NEAR(e->satellites[0].orbit->rac.z(), 0.0444, 1e-9);
}

// ---- epoch times ----------------------------------------------------------------------------

SsrMessage glonassClock(const GpsTime& epoch) {
  SsrMessage m;
  m.header.system = System::Glonass;
  m.header.kind = SsrKind::kClock;
  m.header.epoch = epoch;
  SsrSatellite s;
  s.sat = SatId(System::Glonass, 1);
  s.clock = SsrClockCorrection{0.5, 0.0, 0.0};
  m.satellites.push_back(s);
  return m;
}

TEST(Ssr, GlonassTimeOfDayAcrossTheDayBoundary) {
  // Reference 10 s before Moscow midnight, correction 5 s after it (DF386 = 5): the next day.
  const GpsTime after = moscow(2023, 8, 18, 0, 0, 5.0);
  Result got = decode(Encoder().ssr(glonassClock(after)), moscow(2023, 8, 17, 23, 59, 50.0));
  ASSERT_EQ(got.ssr.size(), 1u);
  EXPECT_EQ(got.ssr[0].header.epoch, after);
  // Reference just after midnight, correction from 5 s before it (DF386 = 86395): the day before.
  const GpsTime before = moscow(2023, 8, 17, 23, 59, 55.0);
  got = decode(Encoder().ssr(glonassClock(before)), moscow(2023, 8, 18, 0, 0, 5.0));
  ASSERT_EQ(got.ssr.size(), 1u);
  EXPECT_EQ(got.ssr[0].header.epoch, before);
  // Moscow midnight is 21:00 UTC: the raw field is the Moscow time of day.
  BitWriter w;
  w.u(12, 1064, "DF002");
  w.u(17, 86395, "DF386");
  w.u(4 + 1 + 4 + 16 + 4, 0, "header");
  w.u(6, 0, "DF387");
  got = decode(independentFrame(w.bytes()), moscow(2023, 8, 18, 0, 0, 5.0));
  ASSERT_EQ(got.ssr.size(), 1u);
  EXPECT_EQ(got.ssr[0].header.epoch, before);
  EXPECT_TRUE(got.ssr[0].satellites.empty());
}

TEST(Ssr, GpsTimeOfWeekAcrossTheWeekRollover) {
  SsrMessage m = glonassClock(GpsTime::fromWeekTow(2278, 3.0));
  m.header.system = System::Gps;
  m.satellites[0].sat = SatId(System::Gps, 1);
  const Result got = decode(Encoder().ssr(m), GpsTime::fromWeekTow(2277, 604790.0));
  ASSERT_EQ(got.ssr.size(), 1u);
  EXPECT_EQ(got.ssr[0].header.epoch, GpsTime::fromWeekTow(2278, 3.0));
}

// ---- malformed messages ---------------------------------------------------------------------

struct Bad {
  std::vector<std::uint8_t> payload;
  std::string field;
};

/// GPS clock message header (1058) with `n` satellites announced.
BitWriter gpsClockHeader(int n, std::uint64_t tow = 100) {
  BitWriter w;
  w.u(12, 1058, "DF002");
  w.u(20, tow, "DF385");
  w.u(4, 0, "DF391");
  w.u(1, 0, "DF388");
  w.u(4, 0, "DF413");
  w.u(16, 0, "DF414");
  w.u(4, 0, "DF415");
  w.u(6, static_cast<std::uint64_t>(n), "DF387");
  return w;
}

TEST(Ssr, MalformedMessagesBecomeIssuesNamingTheField) {
  std::vector<Bad> cases;
  {  // 3 satellites announced, data for 2.
    BitWriter w = gpsClockHeader(3);
    for (int i = 0; i < 2; ++i) {
      w.u(6, static_cast<std::uint64_t>(i + 1), "DF068");
      w.u(70, 0, "clock");
    }
    cases.push_back({w.bytes(), "DF387 number of satellites"});
  }
  {  // GPS satellite ID 0.
    BitWriter w = gpsClockHeader(1);
    w.u(6, 0, "DF068");
    w.u(70, 0, "clock");
    cases.push_back({w.bytes(), "DF068 GPS satellite ID"});
  }
  {  // GLONASS satellite ID 30 (5 bits, slots 1-27).
    BitWriter w;
    w.u(12, 1067, "DF002");
    w.u(17, 100, "DF386");
    w.u(4 + 1 + 4 + 16 + 4, 0, "header");
    w.u(6, 1, "DF387");
    w.u(5, 30, "DF384");
    w.u(6, 3, "DF389");
    cases.push_back({w.bytes(), "DF384 GLONASS satellite ID"});
  }
  {  // QZSS satellite ID 12 (4 bits, J01-J10).
    BitWriter w;
    w.u(12, 1250, "DF002");
    w.u(20, 100, "DF460");
    w.u(4 + 1 + 4 + 16 + 4, 0, "header");
    w.u(6, 1, "DF387");
    w.u(4, 12, "DF429");
    w.u(6, 3, "DF389");
    cases.push_back({w.bytes(), "DF429 QZSS satellite ID"});
  }
  {  // Code-bias list cut short: 4 biases announced, 2 present.
    BitWriter w;
    w.u(12, 1242, "DF002");
    w.u(20, 100, "DF458");
    w.u(4 + 1 + 4 + 16 + 4, 0, "header");
    w.u(6, 1, "DF387");
    w.u(6, 11, "DF252");
    w.u(5, 4, "DF379");
    for (int k = 0; k < 2; ++k) {
      w.u(5, 2, "DF382");
      w.s(14, 100, "DF383");
    }
    cases.push_back({w.bytes(), "DF379 number of code biases"});
  }
  {  // Time of week beyond a week.
    BitWriter w = gpsClockHeader(0, 604800);
    cases.push_back({w.bytes(), "DF385 GPS epoch time 1s"});
  }
  {  // GLONASS time of day beyond a day.
    BitWriter w;
    w.u(12, 1064, "DF002");
    w.u(17, 90000, "DF386");
    w.u(4 + 1 + 4 + 16 + 4 + 6, 0, "header");
    cases.push_back({w.bytes(), "DF386 GLONASS epoch time 1s"});
  }
  {  // Header cut short: 36 bits, padded to 40, end in DF413 (after DF388 and DF375).
    BitWriter w;
    w.u(12, 1243, "DF002");
    w.u(20, 100, "DF458");
    w.u(4, 0, "DF391");
    cases.push_back({w.bytes(), "DF413 IOD SSR"});
  }
  for (const Bad& c : cases) {
    SCOPED_TRACE(c.field);
    DecoderOptions opt;
    opt.referenceTime = GpsTime::fromWeekTow(2277, 1000.0);
    opt.streamName = "bad.rtcm3";
    Decoder dec(opt);
    const auto junk = independentFrame({0xFF, 0xF0, 0x00});  // a 4095 (not decoded) first
    std::vector<std::uint8_t> stream = junk;
    const auto f = independentFrame(c.payload);
    stream.insert(stream.end(), f.begin(), f.end());
    dec.feed(stream);
    dec.finish();
    EXPECT_EQ(dec.stats().malformed, 1);
    ASSERT_EQ(dec.stats().issues.size(), 1u);
    const DecodeIssue& is = dec.stats().issues[0];
    EXPECT_EQ(is.field, c.field) << is.what;
    EXPECT_EQ(is.offset, static_cast<std::int64_t>(junk.size()));
    EXPECT_EQ(is.type, (c.payload[0] << 4) | (c.payload[1] >> 4));
    EXPECT_NE(is.what.find("byte " + std::to_string(junk.size())), std::string::npos) << is.what;
    while (auto item = dec.poll()) EXPECT_FALSE(std::holds_alternative<SsrMessage>(*item));

    opt.strict = true;
    Decoder strict(opt);
    try {
      strict.feed(stream);
      ADD_FAILURE() << "no ParseError";
    } catch (const ParseError& e) {
      EXPECT_EQ(e.file(), "bad.rtcm3");
      EXPECT_EQ(e.field(), c.field);
    }
  }
}

TEST(Ssr, TruncationsAndBitFlipsNeverCrash) {
  // Every prefix of every kind's payload, and random bit flips: an SsrMessage or an issue, never
  // a crash, and never more satellites than the payload can hold.
  std::mt19937 rng(5);
  const GpsTime epoch = GpsTime::fromWeekTow(2277, 345678.0);
  std::int64_t issues = 0, messages = 0;
  for (System sys : kSystems) {
    for (SsrKind kind : kKinds) {
      const auto frame = Encoder().ssr(sampleMessage(sys, kind, epoch, rng));
      const std::vector<std::uint8_t> payload(frame.begin() + 3, frame.end() - 3);
      for (std::size_t n = 0; n <= payload.size(); ++n) {
        DecoderOptions opt;
        opt.referenceTime = epoch;
        Decoder dec(opt);
        dec.decodeMessage({payload.data(), n});
        for (int flip = 0; flip < 4 && n > 2; ++flip) {
          std::vector<std::uint8_t> p(payload.begin(), payload.begin() + static_cast<std::ptrdiff_t>(n));
          p[2 + rng() % (n - 2)] ^= static_cast<std::uint8_t>(1u << (rng() % 8));
          dec.decodeMessage(p);
        }
        while (auto item = dec.poll()) {
          if (auto* m = std::get_if<SsrMessage>(&*item)) {
            EXPECT_LE(m->satellites.size() * 10, n * 8);
          }
        }
        issues += dec.stats().malformed;
        messages += dec.stats().ssrMessages;
      }
    }
  }
  EXPECT_GT(issues, 100);
  EXPECT_GT(messages, 30);
}

// ---- encoder errors -------------------------------------------------------------------------

void expectInvalid(const SsrMessage& m, const std::string& field) {
  try {
    Encoder().ssr(m);
    ADD_FAILURE() << "no exception for " << field;
  } catch (const std::invalid_argument& e) {
    EXPECT_EQ(std::string(e.what()).rfind(field, 0), 0u) << e.what();
  }
}

TEST(Ssr, EncoderRejectsValuesOutsideTheirFields) {
  std::mt19937 rng(3);
  const GpsTime epoch = GpsTime::fromWeekTow(2277, 345678.0);
  const SsrMessage combined = sampleMessage(System::Gps, SsrKind::kCombined, epoch, rng);
  SsrMessage m = combined;
  m.satellites[0].orbit->rac.x() = 209.72;  // DF365 reaches 209.7151 m
  expectInvalid(m, "DF365 delta radial");
  m = combined;
  m.satellites[1].orbit->rac.y() = -209.73;
  expectInvalid(m, "DF366 delta along-track");
  m = combined;
  m.satellites[2].orbit->racRate.z() = std::nan("");
  expectInvalid(m, "DF370 dot delta cross-track");
  m = combined;
  m.satellites[0].clock->c2 = 1.35;
  expectInvalid(m, "DF378 delta clock C2");
  m = combined;
  m.satellites[0].orbit->issueOfData = 256;
  expectInvalid(m, "DF071 GPS IODE");
  m = combined;
  m.header.updateInterval = 3.0;
  expectInvalid(m, "DF391 SSR update interval");
  m = combined;
  m.header.epoch = epoch + 0.5;
  expectInvalid(m, "DF385 GPS epoch time 1s");
  m = combined;
  m.header.providerId = 65536;
  expectInvalid(m, "DF414 SSR provider ID");
  m = combined;
  m.header.iodSsr = 16;
  expectInvalid(m, "DF413 IOD SSR");
  m = combined;
  m.satellites[1].sat = SatId(System::Galileo, 5);
  expectInvalid(m, "DF068 GPS satellite ID");
  m = combined;
  m.satellites[1].clock.reset();
  expectInvalid(m, "clock correction");
  m = combined;
  m.header.messageType = 1057;
  expectInvalid(m, "DF002 message number");
  m = combined;
  m.header.system = System::Sbas;
  expectInvalid(m, "DF002 message number");

  SsrMessage bd = sampleMessage(System::BeiDou, SsrKind::kOrbit, epoch, rng);
  bd.satellites[0].orbit->iodCrc = 256;  // DF471 has 8 bits
  expectInvalid(bd, "DF471 BeiDou IOD");
  bd = sampleMessage(System::BeiDou, SsrKind::kOrbit, epoch, rng);
  bd.satellites[0].orbit->issueOfData = 1024;
  expectInvalid(bd, "DF470 BeiDou toe modulo");

  SsrMessage cb = sampleMessage(System::Glonass, SsrKind::kCodeBias, epoch, rng);
  cb.satellites[0].codeBiases.emplace_back(ObsCode('3', 'I'), 0.0);
  expectInvalid(cb, "DF381 GLONASS signal and tracking mode identifier");
  cb = sampleMessage(System::Glonass, SsrKind::kCodeBias, epoch, rng);
  cb.satellites[0].codeBiases[0].second = 81.925;
  expectInvalid(cb, "DF383 code bias");

  SsrMessage ura = sampleMessage(System::Qzss, SsrKind::kUra, epoch, rng);
  ura.satellites[0].uraIndex = 64;
  expectInvalid(ura, "DF389 SSR URA");
  SsrMessage hr = sampleMessage(System::Galileo, SsrKind::kHighRateClock, epoch, rng);
  hr.satellites[0].highRateClock = -209.72;
  expectInvalid(hr, "DF390 high rate clock correction");

  SsrMessage many = sampleMessage(System::BeiDou, SsrKind::kClock, epoch, rng);
  many.satellites.resize(64, many.satellites[0]);
  expectInvalid(many, "DF387 number of satellites");
  // 63 satellites of code biases with 16 signals each do not fit 1023 bytes.
  SsrMessage big = sampleMessage(System::BeiDou, SsrKind::kCodeBias, epoch, rng);
  big.satellites.resize(63, big.satellites[0]);
  expectInvalid(big, "message length");
}

}  // namespace
}  // namespace gvins::rtcm
