// Ephemerides decoded from the RXM-SFRBX subframes of the bundled u-blox logs against RTKLIB
// 2.4.3's convbin decoding of the same subframes (tests/data/reference/rtklib-2.4.3/ubx_*_convbin.nav,
// commands in tests/data/README.md): every record convbin gives must come out of the assembler with
// every field equal within the RINEX print resolution (12 significant digits).
#include <gtest/gtest.h>

#include <cctype>
#include <cmath>

#include "gvins/ephemeris/ephemeris_store.hpp"
#include "gvins/ephemeris/rinex_nav.hpp"
#include "sfrbx_log.hpp"

namespace gvins::ubx {
namespace {

using testing::dataDir;
using testing::decodeLog;

// RINEX D19.12: 12 significant digits, so half a unit of the last printed digit is at most
// 5e-12 of the value.
void expectPrinted(double ours, double ref, const char* field, SatId sat) {
  EXPECT_LE(std::fabs(ours - ref), 5e-12 * std::fabs(ref) + 1e-300)
      << field << " of " << systemLetter(sat.system) << static_cast<int>(sat.prn) << ": ours " << ours << ", convbin " << ref;
}

const KeplerEphemeris* findKepler(const std::vector<KeplerEphemeris>& list, const KeplerEphemeris& r) {
  for (const auto& e : list)
    if (e.sat == r.sat && e.toe == r.toe) return &e;
  return nullptr;
}

void compareKepler(const KeplerEphemeris& e, const KeplerEphemeris& r) {
  const SatId s = r.sat;
  EXPECT_EQ(e.message, r.message);
  EXPECT_EQ(e.toc, r.toc);
  EXPECT_EQ(e.toeSeconds, r.toeSeconds);
  EXPECT_EQ(e.week, r.week);
  EXPECT_EQ(e.iode, r.iode);
  EXPECT_EQ(e.iodc, r.iodc);
  EXPECT_EQ(e.health, r.health);
  EXPECT_EQ(e.l2pDataFlag, r.l2pDataFlag);
  if (s.system == System::Galileo) {
    // convbin decodes E1-B only (bits 0 and 9); we add bit 2 when words came from E5b-I.
    EXPECT_EQ(e.codesOnL2 & ~(1 << 2), r.codesOnL2);
  } else {
    EXPECT_EQ(e.codesOnL2, r.codesOnL2);
  }
  if (s.system == System::Gps) {
    EXPECT_EQ(e.fitInterval, r.fitInterval);
  }
  // Transmission time: convbin stamps a GPS set when subframe 3 completes it, we when any
  // subframe does (up to a few 30-s frames earlier); BeiDou and Galileo: the message's own time.
  if (s.system == System::Gps) {
    EXPECT_LE(e.ttr - r.ttr, 0.01);
    EXPECT_GE(e.ttr - r.ttr, -150.0);
  } else {
    EXPECT_NEAR(e.ttr - r.ttr, 0.0, 1e-6);
  }
  expectPrinted(e.ura, r.ura, "SV accuracy", s);
  expectPrinted(e.sqrtA, r.sqrtA, "sqrtA", s);
  expectPrinted(e.e, r.e, "e", s);
  expectPrinted(e.i0, r.i0, "i0", s);
  expectPrinted(e.omega0, r.omega0, "OMEGA0", s);
  expectPrinted(e.omega, r.omega, "omega", s);
  expectPrinted(e.m0, r.m0, "M0", s);
  expectPrinted(e.deltaN, r.deltaN, "Delta n", s);
  expectPrinted(e.omegaDot, r.omegaDot, "OMEGA DOT", s);
  expectPrinted(e.iDot, r.iDot, "IDOT", s);
  expectPrinted(e.cuc, r.cuc, "Cuc", s);
  expectPrinted(e.cus, r.cus, "Cus", s);
  expectPrinted(e.crc, r.crc, "Crc", s);
  expectPrinted(e.crs, r.crs, "Crs", s);
  expectPrinted(e.cic, r.cic, "Cic", s);
  expectPrinted(e.cis, r.cis, "Cis", s);
  expectPrinted(e.af0, r.af0, "af0", s);
  expectPrinted(e.af1, r.af1, "af1", s);
  expectPrinted(e.af2, r.af2, "af2", s);
  expectPrinted(e.tgd[0], r.tgd[0], "TGD", s);
  expectPrinted(e.tgd[1], r.tgd[1], "TGD2/BGD E5b", s);
}

void compareGlonass(const GlonassEphemeris& g, const GlonassEphemeris& r) {
  const SatId s = r.sat;
  EXPECT_EQ(g.frequencyChannel, r.frequencyChannel);
  EXPECT_EQ(g.health, r.health);
  EXPECT_EQ(g.age, r.age);
  EXPECT_NEAR(g.tof - r.tof, 0.0, 1e-6);
  for (int k = 0; k < 3; ++k) {
    expectPrinted(g.position[k], r.position[k], "position", s);
    expectPrinted(g.velocity[k], r.velocity[k], "velocity", s);
    expectPrinted(g.acceleration[k], r.acceleration[k], "acceleration", s);
  }
  expectPrinted(g.tauN, r.tauN, "tauN", s);
  expectPrinted(g.gammaN, r.gammaN, "gammaN", s);
  // RINEX 3.04 has no delta tau_n / F_T: those two fields are not compared.
}

struct Expect {
  const char* log;
  int kepler, glonass;  // records convbin gives (without SBAS)
};

class SfrbxVsConvbin : public ::testing::TestWithParam<Expect> {};

TEST_P(SfrbxVsConvbin, EveryConvbinRecordReproduced) {
  const Expect x = GetParam();
  const auto log = decodeLog(dataDir() / "ubx" / x.log);
  std::string stem = x.log;
  stem = stem.substr(0, stem.rfind('.'));
  const NavData ref = readRinexNav((dataDir() / "reference" / "rtklib-2.4.3" / ("ubx_" + stem + "_convbin.nav")).string());
  int kepler = 0;
  for (const KeplerEphemeris& r : ref.kepler) {
    if (r.sat.system == System::Sbas) continue;
    ++kepler;
    SCOPED_TRACE(std::string(1, systemLetter(r.sat.system)) + std::to_string(r.sat.prn));
    const KeplerEphemeris* e = findKepler(log.kepler, r);
    ASSERT_NE(e, nullptr) << "no record with convbin's toe " << r.toe.toString(0);
    compareKepler(*e, r);
  }
  for (const GlonassEphemeris& r : ref.glonass) {
    const GlonassEphemeris* g = nullptr;
    for (const auto& o : log.glonass)
      if (o.sat == r.sat && o.toe == r.toe) g = &o;
    ASSERT_NE(g, nullptr) << "R" << r.sat.prn << " " << r.toe.toString(0);
    compareGlonass(*g, r);
  }
  EXPECT_EQ(kepler, x.kepler);
  EXPECT_EQ(static_cast<int>(ref.glonass.size()), x.glonass);
  // The ephemerides convbin decodes are all there and no system shows a check failure.
  const NavigationCounts t = log.assembler.total();
  EXPECT_EQ(t.parityFailures, 0u);
  EXPECT_EQ(t.crcFailures, 0u);
  EXPECT_EQ(t.messages, log.sfrbx);
  // Every record goes into the store (what the tools do with an update).
  EphemerisStore store;
  for (const NavDataUpdate& u : log.updates) u.addTo(store);
  EXPECT_EQ(store.size(), log.kepler.size() + log.glonass.size());
}

// Without any receive time the GLONASS set is dated by NT (string 4) and N4 (string 5), and BeiDou
// and Galileo by their own week numbers: the same records as with the time.
TEST(SfrbxWithoutTime, GlonassBeidouGalileoDatedByTheirOwnMessages) {
  const auto path = dataDir() / "ubx" / "gpsd_ublox-zed-f9p-sfrbx.log";
  const NavData ref = readRinexNav((dataDir() / "reference" / "rtklib-2.4.3" / "ubx_gpsd_ublox-zed-f9p-sfrbx_convbin.nav").string());
  ASSERT_EQ(ref.glonass.size(), 1u);
  const auto bytes = testing::readBytes(path);
  Framer framer;
  framer.feed(bytes);
  framer.finish();
  NavigationAssembler a;
  std::vector<KeplerEphemeris> kepler;
  std::vector<GlonassEphemeris> glonass;
  Frame f;
  while (framer.next(f)) {
    if (f.type() != 0x0213) continue;
    const NavDataUpdate u = a.add(parseSfrbx(f.payload), GpsTime{});
    kepler.insert(kepler.end(), u.kepler.begin(), u.kepler.end());
    glonass.insert(glonass.end(), u.glonass.begin(), u.glonass.end());
  }
  ASSERT_EQ(glonass.size(), 1u);
  EXPECT_EQ(glonass[0].toe, ref.glonass[0].toe);
  compareGlonass(glonass[0], ref.glonass[0]);
  int matched = 0;
  for (const KeplerEphemeris& r : ref.kepler) {
    if (const KeplerEphemeris* e = findKepler(kepler, r)) {
      compareKepler(*e, r);
      ++matched;
    }
  }
  EXPECT_EQ(matched, 2);  // E21 and C29
}

INSTANTIATE_TEST_SUITE_P(Logs, SfrbxVsConvbin,
                         ::testing::Values(Expect{"gpsd_ublox-zed-f9p-sfrbx.log", 2, 1},
                                           Expect{"gpsd_ublox-x20p.log", 6, 0},
                                           Expect{"gnss_1730.ubx", 12, 0}),
                         [](const ::testing::TestParamInfo<Expect>& i) {
                           std::string n = i.param.log;
                           for (char& c : n)
                             if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
                           return n;
                         });

}  // namespace
}  // namespace gvins::ubx
