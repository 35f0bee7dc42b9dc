// RINEX 3.04 writer: writing and reading back gives the same records, to the printed precision
// (13 significant digits, i.e. exactly for files written with 12- or 13-digit mantissas), for
// every bundled navigation file (RINEX 2.10, 2.11, 3.02, 3.04, 4.00 sources).
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <sstream>
#include <string>

#include "gvins/ephemeris/rinex_nav.hpp"

using namespace gvins;

namespace {

const std::string kData = GVINS_TEST_DATA;

// Equal to the printed precision: `rel` is half a unit of the last printed digit relative to the
// value (13 digits for records; the 3.04 header has D12.4 ionosphere and D17.10/D16.9 time-system
// fields, which sources with more digits, e.g. RINEX 4 ION records, cannot keep).
void expectClose(double a, double b, const std::string& what, double rel = 1e-12) {
  EXPECT_LE(std::fabs(a - b), rel * std::fabs(a) + 1e-300) << what << ": " << a << " vs " << b;
}

void expectSame(const KeplerEphemeris& a, const KeplerEphemeris& b) {
  const std::string id = a.sat.str() + " " + a.toe.toString(0);
  EXPECT_EQ(a.sat, b.sat) << id;
  EXPECT_EQ(a.message, b.message) << id;
  EXPECT_EQ(a.toe, b.toe) << id;
  EXPECT_EQ(a.toc, b.toc) << id;
  EXPECT_NEAR(a.ttr - b.ttr, 0.0, 1e-9) << id;
  EXPECT_EQ(a.week, b.week) << id;
  EXPECT_EQ(a.toeSeconds, b.toeSeconds) << id;
  EXPECT_EQ(a.iode, b.iode) << id;
  EXPECT_EQ(a.iodc, b.iodc) << id;
  EXPECT_EQ(a.health, b.health) << id;
  EXPECT_EQ(a.codesOnL2, b.codesOnL2) << id;
  EXPECT_EQ(a.l2pDataFlag, b.l2pDataFlag) << id;
  EXPECT_EQ(a.fitInterval, b.fitInterval) << id;
  const double fa[] = {a.ura, a.sqrtA, a.e, a.i0, a.omega0, a.omega, a.m0, a.deltaN, a.omegaDot, a.iDot, a.cuc,
                       a.cus, a.crc, a.crs, a.cic, a.cis, a.af0, a.af1, a.af2, a.tgd[0], a.tgd[1]};
  const double fb[] = {b.ura, b.sqrtA, b.e, b.i0, b.omega0, b.omega, b.m0, b.deltaN, b.omegaDot, b.iDot, b.cuc,
                       b.cus, b.crc, b.crs, b.cic, b.cis, b.af0, b.af1, b.af2, b.tgd[0], b.tgd[1]};
  for (std::size_t i = 0; i < std::size(fa); ++i) expectClose(fa[i], fb[i], id + " field " + std::to_string(i));
}

void expectSame(const GlonassEphemeris& a, const GlonassEphemeris& b) {
  const std::string id = a.sat.str() + " " + a.toe.toString(0);
  EXPECT_EQ(a.sat, b.sat) << id;
  EXPECT_EQ(a.toe, b.toe) << id;
  EXPECT_NEAR(a.tof - b.tof, 0.0, 1e-9) << id;
  EXPECT_EQ(a.iode, b.iode) << id;
  EXPECT_EQ(a.health, b.health) << id;
  EXPECT_EQ(a.age, b.age) << id;
  EXPECT_EQ(a.frequencyChannel, b.frequencyChannel) << id;
  expectClose(a.tauN, b.tauN, id + " tauN");
  expectClose(a.gammaN, b.gammaN, id + " gammaN");
  for (int i = 0; i < 3; ++i) {
    expectClose(a.position[i], b.position[i], id + " position");
    expectClose(a.velocity[i], b.velocity[i], id + " velocity");
    expectClose(a.acceleration[i], b.acceleration[i], id + " acceleration");
  }
}

// Records of `a` with a system the 3.04 writer supports, in file order of (toc, sat).
void roundTrip(const std::string& path, bool hasExtraGlonassLine = false) {
  SCOPED_TRACE(path);
  const NavData a = readRinexNav(path);
  std::ostringstream out;
  writeRinexNav(out, a, "gvins-test");
  const std::string text = out.str();
  const NavData b = parseRinexNav(text, "written.nav");
  EXPECT_DOUBLE_EQ(b.version, 3.04);
  ASSERT_EQ(a.kepler.size(), b.kepler.size());
  ASSERT_EQ(a.glonass.size(), b.glonass.size());
  // The writer orders records by time and satellite; match them by key.
  for (const auto& ea : a.kepler) {
    int found = 0;
    for (const auto& eb : b.kepler) {
      // (Real files hold copies of one issue of data with different BGDs or transmission times.)
      if (ea.sat == eb.sat && ea.toe == eb.toe && ea.message == eb.message && ea.iode == eb.iode &&
          ea.af0 == eb.af0 && ea.tgd == eb.tgd && std::fabs(ea.ttr - eb.ttr) < 1e-6) {
        if (found++ == 0) expectSame(ea, eb);
      }
    }
    EXPECT_GE(found, 1) << ea.sat.str() << " " << ea.toe.toString(0);
  }
  for (const auto& ga : a.glonass) {
    bool found = false;
    for (const auto& gb : b.glonass) {
      if (ga.sat == gb.sat && ga.toe == gb.toe && ga.position == gb.position) {
        expectSame(ga, gb);
        found = true;
        break;
      }
    }
    EXPECT_TRUE(found) << ga.sat.str();
    // RINEX 3.04 has no line for the L1/L2 delay difference and the accuracy index (3.05+).
    if (!hasExtraGlonassLine) {
      EXPECT_EQ(ga.deltaTauN, 0.0);
    }
  }
  // Header values.
  EXPECT_EQ(a.leapSeconds, b.leapSeconds);
  EXPECT_EQ(a.iono.gps.has_value(), b.iono.gps.has_value());
  if (a.iono.gps) {
    for (int i = 0; i < 4; ++i) {
      expectClose(a.iono.gps->alpha[i], b.iono.gps->alpha[i], "alpha", 5e-5);
      expectClose(a.iono.gps->beta[i], b.iono.gps->beta[i], "beta", 5e-5);
    }
  }
  EXPECT_EQ(a.iono.galileo.has_value(), b.iono.galileo.has_value());
  if (a.iono.galileo) {
    for (int i = 0; i < 3; ++i) expectClose(a.iono.galileo->ai[i], b.iono.galileo->ai[i], "ai", 5e-5);
  }
  EXPECT_EQ(a.iono.qzss.has_value(), b.iono.qzss.has_value());
  EXPECT_EQ(a.iono.beidou.has_value(), b.iono.beidou.has_value());
  ASSERT_EQ(a.timeCorrections.size(), b.timeCorrections.size());
  for (std::size_t i = 0; i < a.timeCorrections.size(); ++i) {
    EXPECT_EQ(std::string(a.timeCorrections[i].type, 4), std::string(b.timeCorrections[i].type, 4));
    expectClose(a.timeCorrections[i].a0, b.timeCorrections[i].a0, "A0", 5e-11);
    expectClose(a.timeCorrections[i].a1, b.timeCorrections[i].a1, "A1", 5e-10);
  }
  // Writing what was read back reproduces the text (apart from the date in PGM / RUN BY / DATE).
  std::ostringstream again;
  writeRinexNav(again, b, "gvins-test");
  auto dropDate = [](std::string s) {
    const auto p = s.find("PGM / RUN BY / DATE");
    return s.erase(p - 20, 20);
  };
  EXPECT_EQ(dropDate(text), dropDate(again.str()));
  // Every line is at most 80 columns and every record line has the 3.04 layout.
  std::istringstream lines(text);
  std::string line;
  while (std::getline(lines, line)) EXPECT_LE(line.size(), 80u) << line;
}

}  // namespace

TEST(RinexNavWriter, RoundTripRinex304Nagoya) { roundTrip(kData + "/gnss/nagoya_static_2024/base.nav.gz"); }
TEST(RinexNavWriter, RoundTripRinex304Kamakura) { roundTrip(kData + "/gnss/kamakura_static_2021/SEPT078M.21P.gz"); }
TEST(RinexNavWriter, RoundTripRinex302Qzss) { roundTrip(kData + "/gnss/kamakura_static_2021/30340780.21q.gz"); }
TEST(RinexNavWriter, RoundTripRinex210Gps) { roundTrip(kData + "/gnss/geonet_0759_3040_2005/30400920.05n.gz"); }
TEST(RinexNavWriter, RoundTripRinex211Glonass) {
  roundTrip(kData + "/reference/rtklib-2.4.3/satpos/testglo_rinex211.gnav.gz");
}
TEST(RinexNavWriter, RoundTripRinex400) {
  roundTrip(kData + "/gnss/brd400dlr_2022_rinex4/BRD400DLR_S_20222780000_extract.rnx.gz", true);
}

TEST(RinexNavWriter, GalileoDataSourcesFollowTheMessage) {
  // A record from another source (e.g. RTCM 1046 = I/NAV) without data-source bits gets the
  // bits of its message, so that readers (RTKLIB among them) keep I/NAV and F/NAV apart.
  NavData nav = readRinexNav(kData + "/gnss/nagoya_static_2024/base.nav.gz");
  NavData gal;
  for (auto e : nav.kepler) {
    if (e.sat.system != System::Galileo) continue;
    e.codesOnL2 = 0;
    gal.kepler.push_back(e);
  }
  std::ostringstream out;
  writeRinexNav(out, gal);
  const NavData back = parseRinexNav(out.str(), "gal.nav");
  ASSERT_EQ(back.kepler.size(), gal.kepler.size());
  int inav = 0, fnav = 0;
  for (const auto& e : back.kepler) {
    if (e.message == NavMessage::GalileoInav) {
      ++inav;
      EXPECT_EQ(e.codesOnL2, 0x205);
    } else {
      ++fnav;
      EXPECT_EQ(e.codesOnL2, 0x102);
    }
  }
  EXPECT_EQ(inav, 39);
  EXPECT_EQ(fnav, 28);
}
