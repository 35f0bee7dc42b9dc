// RINEX navigation reader: every supported version on the bundled real files, values checked
// against the text of the files (and the ICD conventions for time scales), plus the format
// variants real writers produce.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <string>

#include "gvins/ephemeris/rinex_nav.hpp"

using namespace gvins;

namespace {

const std::string kData = GVINS_TEST_DATA;

int count(const NavData& nav, System s) {
  if (s == System::Glonass) return static_cast<int>(nav.glonass.size());
  return static_cast<int>(std::count_if(nav.kepler.begin(), nav.kepler.end(),
                                        [s](const KeplerEphemeris& e) { return e.sat.system == s; }));
}

const KeplerEphemeris& firstOf(const NavData& nav, const char* sat) {
  const SatId id = *SatId::parse(sat);
  for (const auto& e : nav.kepler) {
    if (e.sat == id) return e;
  }
  throw std::runtime_error(std::string("no record of ") + sat);
}

GpsTime gpst(int y, int mo, int d, int h, int mi, double s) {
  CalendarTime c;
  c.year = y;
  c.month = mo;
  c.day = d;
  c.hour = h;
  c.minute = mi;
  c.second = s;
  return GpsTime::fromCalendar(c);
}

const TimeSystemCorrection* correction(const NavData& nav, const char* type) {
  for (const auto& c : nav.timeCorrections) {
    if (std::strncmp(c.type, type, 4) == 0) return &c;
  }
  return nullptr;
}

}  // namespace

TEST(RinexNavReader, Rinex304MixedNagoya) {
  const NavData nav = readRinexNav(kData + "/gnss/nagoya_static_2024/base.nav.gz");
  EXPECT_DOUBLE_EQ(nav.version, 3.04);
  EXPECT_EQ(count(nav, System::Gps), 13);
  EXPECT_EQ(count(nav, System::Glonass), 19);
  EXPECT_EQ(count(nav, System::Galileo), 67);
  EXPECT_EQ(count(nav, System::BeiDou), 32);
  EXPECT_EQ(count(nav, System::Qzss), 3);
  EXPECT_TRUE(nav.skipped.empty());
  // Header.
  ASSERT_TRUE(nav.iono.gps);
  EXPECT_DOUBLE_EQ(nav.iono.gps->alpha[0], 1.8626e-08);
  EXPECT_DOUBLE_EQ(nav.iono.gps->beta[3], -2.6214e+05);
  ASSERT_TRUE(nav.iono.galileo);
  EXPECT_DOUBLE_EQ(nav.iono.galileo->ai[0], 1.6175e+02);
  EXPECT_DOUBLE_EQ(nav.iono.galileo->ai[2], 1.9379e-02);
  EXPECT_FALSE(nav.iono.beidou);
  ASSERT_TRUE(nav.leapSeconds);
  EXPECT_EQ(*nav.leapSeconds, 18);
  const auto* gput = correction(nav, "GPUT");
  ASSERT_NE(gput, nullptr);
  EXPECT_DOUBLE_EQ(gput->a0, -9.3132257462E-10);
  EXPECT_DOUBLE_EQ(gput->a1, -7.993605777E-15);
  EXPECT_EQ(gput->referenceTow, 319488);
  EXPECT_EQ(gput->referenceWeek, 2320);
  ASSERT_NE(correction(nav, "GAGP"), nullptr);
  EXPECT_DOUBLE_EQ(correction(nav, "GAGP")->a0, -3.6961864680E-09);

  // G05: toe 122400 s of GPS week 2320 = 2024-06-24 10:00:00 GPST, ttr 115218 s = 08:00:18.
  const auto& g05 = firstOf(nav, "G05");
  EXPECT_EQ(g05.message, NavMessage::GpsLnav);
  EXPECT_EQ(g05.toc, gpst(2024, 6, 24, 10, 0, 0));
  EXPECT_EQ(g05.toe, gpst(2024, 6, 24, 10, 0, 0));
  EXPECT_EQ(g05.ttr, gpst(2024, 6, 24, 8, 0, 18));
  EXPECT_EQ(g05.week, 2320);
  EXPECT_DOUBLE_EQ(g05.toeSeconds, 122400.0);
  EXPECT_DOUBLE_EQ(g05.af0, -1.774230040610E-04);
  EXPECT_DOUBLE_EQ(g05.af1, -1.364242052659E-12);
  EXPECT_DOUBLE_EQ(g05.crs, -9.821875000000E+01);
  EXPECT_DOUBLE_EQ(g05.sqrtA, 5.153635631561E+03);
  EXPECT_DOUBLE_EQ(g05.omegaDot, -8.275344701323E-09);
  EXPECT_DOUBLE_EQ(g05.iDot, -2.610823036973E-10);
  EXPECT_EQ(g05.iode, 72);
  EXPECT_EQ(g05.iodc, 72);
  EXPECT_EQ(g05.codesOnL2, 1);
  EXPECT_DOUBLE_EQ(g05.ura, 2.0);
  EXPECT_EQ(g05.health, 0);
  EXPECT_DOUBLE_EQ(g05.tgd[0], -1.071020960808E-08);
  EXPECT_DOUBLE_EQ(g05.fitInterval, 4.0);

  // C01 (GEO, D2): epoch and toe in BDT; GPST = BDT + 14 s; BDT week 964.
  const auto& c01 = firstOf(nav, "C01");
  EXPECT_EQ(c01.message, NavMessage::BeiDouD2);
  EXPECT_EQ(c01.toc, gpst(2024, 6, 24, 8, 0, 14));
  EXPECT_EQ(c01.toe, gpst(2024, 6, 24, 8, 0, 14));
  EXPECT_EQ(c01.week, 964);
  EXPECT_DOUBLE_EQ(c01.toeSeconds, 115200.0);
  EXPECT_NEAR(c01.ttr - gpst(2024, 6, 24, 8, 0, 41.6), 0.0, 1e-9);
  EXPECT_EQ(c01.iode, 1);
  EXPECT_EQ(c01.iodc, 0);
  EXPECT_DOUBLE_EQ(c01.tgd[0], -4.9e-09);
  EXPECT_DOUBLE_EQ(c01.tgd[1], -1.0e-08);
  EXPECT_EQ(firstOf(nav, "C06").message, NavMessage::BeiDouD1);

  // Galileo: 39 I/NAV (data sources 517) and 28 F/NAV (258) records, kept apart.
  int inav = 0, fnav = 0;
  for (const auto& e : nav.kepler) {
    if (e.sat.system != System::Galileo) continue;
    if (e.message == NavMessage::GalileoInav) {
      ++inav;
      EXPECT_EQ(e.codesOnL2, 517);
    } else {
      ++fnav;
      EXPECT_EQ(e.message, NavMessage::GalileoFnav);
      EXPECT_EQ(e.codesOnL2, 258);
    }
    EXPECT_EQ(e.iodc, e.iode);
  }
  EXPECT_EQ(inav, 39);
  EXPECT_EQ(fnav, 28);

  // R01: epoch 08:15:00 UTC = 08:15:18 GPST; -TauN written in the file; km -> m; frame time
  // 115200 s of the UTC week = Monday 08:00:00 UTC.
  const auto& r01 = nav.glonass.front();
  EXPECT_EQ(r01.sat.str(), "R01");
  EXPECT_EQ(r01.toe, gpst(2024, 6, 24, 8, 15, 18));
  EXPECT_EQ(r01.tof, gpst(2024, 6, 24, 8, 0, 18));
  EXPECT_DOUBLE_EQ(r01.tauN, -8.934084326029E-05);
  EXPECT_DOUBLE_EQ(r01.gammaN, 9.094947017729E-13);
  EXPECT_DOUBLE_EQ(r01.position.x(), -1.373688769531E+04 * 1e3);
  EXPECT_DOUBLE_EQ(r01.velocity.y(), -2.458472251892E+00 * 1e3);
  EXPECT_DOUBLE_EQ(r01.acceleration.z(), -1.862645149231E-09 * 1e3);
  EXPECT_EQ(r01.frequencyChannel, 1);
  EXPECT_EQ(r01.health, 0);
  // tb index: 08:15 UTC = 11:15 Moscow time = 45 quarter hours.
  EXPECT_EQ(r01.iode, 45);
}

TEST(RinexNavReader, Rinex304SeptentrioStyleNumbersKamakura) {
  // " .1118D-07": no leading zero, Fortran D exponents (written by RTKCONV).
  const NavData nav = readRinexNav(kData + "/gnss/kamakura_static_2021/SEPT078M.21P.gz");
  EXPECT_EQ(count(nav, System::Gps), 24);
  EXPECT_EQ(count(nav, System::Galileo), 210);
  EXPECT_EQ(count(nav, System::Qzss), 8);
  ASSERT_TRUE(nav.iono.gps && nav.iono.qzss && nav.iono.galileo);
  EXPECT_DOUBLE_EQ(nav.iono.gps->alpha[0], 0.1118e-07);
  EXPECT_DOUBLE_EQ(nav.iono.gps->beta[2], -0.1966e+06);
  EXPECT_DOUBLE_EQ(nav.iono.qzss->beta[3], -0.2163e+07);
  EXPECT_DOUBLE_EQ(nav.iono.galileo->ai[1], 0.5859e-01);
  EXPECT_EQ(nav.leapSeconds.value_or(0), 18);
  const auto& e08 = firstOf(nav, "E08");
  EXPECT_DOUBLE_EQ(e08.af0, 0.603088719072e-02);
  EXPECT_EQ(e08.iode, 16);
  EXPECT_EQ(e08.message, NavMessage::GalileoInav);  // data sources 516
  EXPECT_DOUBLE_EQ(e08.tgd[0], -0.395812094212e-08);
  EXPECT_DOUBLE_EQ(e08.tgd[1], -0.442378222942e-08);
  EXPECT_EQ(e08.week, 2149 - 1024);  // GST week; the file's week is GPS-aligned
  EXPECT_EQ(e08.toe, gpst(2021, 3, 19, 10, 40, 0));
  // QZSS fit interval flag 1 ("more than 2 h") is kept as 4 h.
  EXPECT_DOUBLE_EQ(firstOf(nav, "J02").fitInterval, 4.0);
  EXPECT_EQ(firstOf(nav, "J02").message, NavMessage::QzssLnav);
}

TEST(RinexNavReader, Rinex302QzssKamakura) {
  const NavData nav = readRinexNav(kData + "/gnss/kamakura_static_2021/30340780.21q.gz");
  EXPECT_DOUBLE_EQ(nav.version, 3.02);
  EXPECT_EQ(count(nav, System::Qzss), 95);
  EXPECT_EQ(static_cast<int>(nav.kepler.size()), 95);
  const auto& j07 = firstOf(nav, "J07");
  EXPECT_EQ(j07.toc, gpst(2021, 3, 19, 0, 0, 0));
  EXPECT_DOUBLE_EQ(j07.af0, -1.536682248116E-08);
  EXPECT_DOUBLE_EQ(j07.sqrtA, 6.493424846649E+03);
  EXPECT_EQ(j07.iodc, 797);
  EXPECT_DOUBLE_EQ(j07.fitInterval, 2.0);  // flag 0
  EXPECT_EQ(j07.ttr, gpst(2021, 3, 18, 23, 59, 36));
}

TEST(RinexNavReader, Rinex210GpsGeonet) {
  const NavData nav = readRinexNav(kData + "/gnss/geonet_0759_3040_2005/07590920.05n.gz");
  EXPECT_DOUBLE_EQ(nav.version, 2.10);
  EXPECT_EQ(count(nav, System::Gps), static_cast<int>(nav.kepler.size()));
  EXPECT_EQ(nav.kepler.size(), 1296u / 8u);  // 1308 lines - 12 header lines, 8 per record
  ASSERT_TRUE(nav.iono.gps);
  EXPECT_DOUBLE_EQ(nav.iono.gps->alpha[0], 1.1180e-08);
  EXPECT_DOUBLE_EQ(nav.iono.gps->alpha[3], -5.9600e-08);
  EXPECT_DOUBLE_EQ(nav.iono.gps->beta[0], 8.8060e+04);
  const auto* utc = correction(nav, "GPUT");
  ASSERT_NE(utc, nullptr);
  EXPECT_DOUBLE_EQ(utc->a0, -2.793967723850e-09);
  EXPECT_DOUBLE_EQ(utc->a1, -5.329070518200e-15);
  EXPECT_EQ(utc->referenceTow, 61440);
  EXPECT_EQ(utc->referenceWeek, 1061);
  EXPECT_EQ(nav.leapSeconds.value_or(0), 13);
  // " 1 05  4  2  2  0  0.0": two-digit year; toe 525600 s of week 1316.
  const auto& g01 = firstOf(nav, "G01");
  EXPECT_EQ(g01.toc, gpst(2005, 4, 2, 2, 0, 0));
  EXPECT_EQ(g01.toe, GpsTime::fromWeekTow(1316, 525600.0));
  EXPECT_DOUBLE_EQ(g01.af0, 3.966595977540e-04);
  EXPECT_DOUBLE_EQ(g01.m0, 2.871534990340e+00);
  EXPECT_EQ(g01.iode, 140);
  EXPECT_EQ(g01.iodc, 396);
  EXPECT_EQ(g01.ttr, GpsTime::fromWeekTow(1316, 519576.0));
}

TEST(RinexNavReader, Rinex211GlonassWrittenByRtklib) {
  const std::string dir = kData + "/reference/rtklib-2.4.3/satpos/";
  const NavData nav = readRinexNav(dir + "testglo_rinex211.gnav.gz");
  ASSERT_EQ(nav.glonass.size(), 6u);
  EXPECT_TRUE(nav.kepler.empty());
  const auto& r08 = nav.glonass.front();
  EXPECT_EQ(r08.sat.str(), "R08");
  // 2009-12-18 23:15:00 UTC; GPST - UTC = 15 s in 2009.
  EXPECT_EQ(r08.toe, gpst(2009, 12, 18, 23, 15, 15));
  // Frame time 83130 s of the UTC day = 23:05:30 UTC.
  EXPECT_EQ(r08.tof, gpst(2009, 12, 18, 23, 5, 45));
  EXPECT_DOUBLE_EQ(r08.tauN, 0.794976949692e-04);
  EXPECT_DOUBLE_EQ(r08.position.z(), 0.163287265625e+05 * 1e3);
  EXPECT_EQ(r08.frequencyChannel, 6);
  EXPECT_EQ(nav.glonass[1].frequencyChannel, -2);
  const NavData gps = readRinexNav(dir + "testglo_rinex211.nav.gz");
  EXPECT_EQ(count(gps, System::Gps), static_cast<int>(gps.kepler.size()));
  EXPECT_GT(gps.kepler.size(), 10u);
}

TEST(RinexNavReader, Rinex400AllRecordTypes) {
  const NavData nav =
      readRinexNav(kData + "/gnss/brd400dlr_2022_rinex4/BRD400DLR_S_20222780000_extract.rnx.gz");
  EXPECT_DOUBLE_EQ(nav.version, 4.00);
  EXPECT_EQ(count(nav, System::Gps), 2);      // LNAV; the CNAV record is skipped
  EXPECT_EQ(count(nav, System::Galileo), 2);  // INAV
  EXPECT_EQ(count(nav, System::BeiDou), 3);   // D1 + 2 x D2; CNV1 skipped
  EXPECT_EQ(count(nav, System::Qzss), 1);
  EXPECT_EQ(count(nav, System::Glonass), 2);
  // Skipped with reasons: G01 CNAV, C19 CNV1, ION I02 (NavIC), EOP.
  ASSERT_EQ(nav.skipped.size(), 4u);
  EXPECT_NE(nav.skipped[0].find("G01 CNAV"), std::string::npos);
  EXPECT_NE(nav.skipped[1].find("C19 CNV1"), std::string::npos);
  EXPECT_NE(nav.skipped[2].find("ION I02"), std::string::npos);
  EXPECT_NE(nav.skipped[3].find("EOP"), std::string::npos);
  EXPECT_EQ(nav.leapSeconds.value_or(0), 18);

  const auto& g01 = firstOf(nav, "G01");
  EXPECT_EQ(g01.toe, gpst(2022, 10, 5, 0, 0, 0));
  EXPECT_DOUBLE_EQ(g01.af0, 2.727881073952e-04);
  EXPECT_EQ(g01.iodc, 70);
  const auto& e01 = firstOf(nav, "E01");
  EXPECT_EQ(e01.message, NavMessage::GalileoInav);
  EXPECT_EQ(e01.health, 65);
  EXPECT_DOUBLE_EQ(e01.tgd[0], 2.328306436539e-10);
  const auto& c01 = firstOf(nav, "C01");
  EXPECT_EQ(c01.message, NavMessage::BeiDouD2);
  EXPECT_EQ(firstOf(nav, "C06").message, NavMessage::BeiDouD1);
  EXPECT_DOUBLE_EQ(firstOf(nav, "C06").af2, 2.574980159653e-19);

  // GLONASS FDMA: fourth line with status flags, L1/L2 delay difference, URAI, health flags.
  const auto& r01 = nav.glonass.front();
  EXPECT_DOUBLE_EQ(r01.deltaTauN, 8.381903171539e-09);
  EXPECT_DOUBLE_EQ(r01.accuracy, 2.5);  // F_T = 2
  EXPECT_EQ(r01.frequencyChannel, 1);
  EXPECT_EQ(r01.toe, gpst(2022, 10, 5, 0, 15, 18));

  // ION records: Klobuchar (GPS LNAV, QZSS LNAV, BDS D1D2) and NeQuick-G (Galileo IFNV).
  ASSERT_TRUE(nav.iono.gps && nav.iono.qzss && nav.iono.beidou && nav.iono.galileo);
  EXPECT_DOUBLE_EQ(nav.iono.gps->alpha[0], 2.514570951462e-08);
  EXPECT_DOUBLE_EQ(nav.iono.gps->alpha[3], -5.960464477539e-08);
  EXPECT_DOUBLE_EQ(nav.iono.gps->beta[3], 1.966080000000e+05);
  EXPECT_DOUBLE_EQ(nav.iono.qzss->beta[3], 8.519680000000e+05);
  EXPECT_DOUBLE_EQ(nav.iono.beidou->beta[0], 1.044480000000e+05);
  EXPECT_DOUBLE_EQ(nav.iono.galileo->ai[0], 1.207500000000e+02);
  EXPECT_DOUBLE_EQ(nav.iono.galileo->ai[2], -7.629394531250e-04);

  // STO records become time-system corrections.
  const auto* gagp = correction(nav, "GAGP");
  ASSERT_NE(gagp, nullptr);
  EXPECT_DOUBLE_EQ(gagp->a0, 1.309672370553e-09);
  EXPECT_DOUBLE_EQ(gagp->a1, 5.329070518201e-15);
  const auto* bdut = correction(nav, "BDUT");
  ASSERT_NE(bdut, nullptr);
  EXPECT_DOUBLE_EQ(bdut->a0, -9.895302355289e-10);
  ASSERT_NE(correction(nav, "GPUT"), nullptr);
  ASSERT_NE(correction(nav, "GLUT"), nullptr);
}

TEST(RinexNavReader, FormatVariantsOfRealWriters) {
  // One GPS record written in several styles that occur in the wild: lower-case 'd' exponent,
  // missing leading zeros, letterless three-digit exponent, blank spare fields, trailing
  // blanks dropped, CRLF line ends, the final orbit line missing, no newline at the end.
  const std::string header =
      "     3.04           N: GNSS NAV DATA    G: GPS              RINEX VERSION / TYPE\r\n"
      "                                                            END OF HEADER\r\n";
  const std::string rec =
      "G05 2024 06 24 10 00 00-1.774230040610d-04 -.136424205266D-11 .123456789012-100\r\n"
      "     7.200000000000E+01-9.821875000000E+01 4.293035965037E-09 1.714815412488E+00\r\n"
      "    -5.291774868965E-06 5.927642923780E-03 1.830980181694E-06 5.153635631561E+03\r\n"
      "     1.224000000000E+05 3.352761268616E-08 2.520897825810E+00-5.774199962616E-08\r\n"
      "     9.719266524177E-01 3.536250000000E+02 1.273307347665E+00-8.275344701323E-09\r\n"
      "    -2.610823036973E-10 1.000000000000E+00 2.320000000000E+03\r\n"
      "     2.000000000000E+00                   -1.071020960808E-08 7.200000000000E+01";
  const NavData nav = parseRinexNav(header + rec, "variants.nav");
  ASSERT_EQ(nav.kepler.size(), 1u);
  const auto& e = nav.kepler[0];
  EXPECT_DOUBLE_EQ(e.af0, -1.774230040610e-04);
  EXPECT_DOUBLE_EQ(e.af1, -0.136424205266e-11);
  EXPECT_DOUBLE_EQ(e.af2, 0.123456789012e-100);
  EXPECT_EQ(e.l2pDataFlag, 0);   // field missing at the end of a short line
  EXPECT_EQ(e.health, 0);        // blank field
  EXPECT_EQ(e.iodc, 72);
  EXPECT_EQ(e.ttr, GpsTime{});   // final line missing: transmission time unknown
  EXPECT_DOUBLE_EQ(e.fitInterval, 0.0);
  EXPECT_DOUBLE_EQ(e.sqrtA, 5.153635631561E+03);
}

TEST(RinexNavReader, MergeKeepsFirstHeaderValues) {
  NavData a = readRinexNav(kData + "/gnss/kamakura_static_2021/SEPT078M.21P.gz");
  const NavData b = readRinexNav(kData + "/gnss/kamakura_static_2021/30340780.21q.gz");
  const std::size_t n = a.kepler.size();
  const double alpha0 = a.iono.gps->alpha[0];
  mergeNavData(a, b);
  EXPECT_EQ(a.kepler.size(), n + b.kepler.size());
  EXPECT_DOUBLE_EQ(a.iono.gps->alpha[0], alpha0);
}

TEST(RinexNavReader, Rinex305GlonassFourthLineAndRecordAfterIt) {
  const std::string text =
      "     3.05           N: GNSS NAV DATA    M: MIXED            RINEX VERSION / TYPE\n"
      "    18                                                      LEAP SECONDS\n"
      "                                                            END OF HEADER\n"
      "R01 2022 10 05 00 15 00 1.574866473675e-05 0.000000000000e+00 2.592300000000e+05\n"
      "    -6.686352539062e+03 3.702297210693e-01 9.313225746155e-10 0.000000000000e+00\n"
      "    -1.537300634766e+04-2.607774734497e+00 9.313225746155e-10 1.000000000000e+00\n"
      "     1.922300781250e+04-1.955271720886e+00-2.793967723846e-09 0.000000000000e+00\n"
      "     1.790000000000e+02 8.381903171539e-09 1.500000000000e+01 3.000000000000e+00\n"
      "R02 2022 10 05 00 15 00 1.574866473675e-05 0.000000000000e+00 2.592300000000e+05\n"
      "    -6.686352539062e+03 3.702297210693e-01 9.313225746155e-10 0.000000000000e+00\n"
      "    -1.537300634766e+04-2.607774734497e+00 9.313225746155e-10-4.000000000000e+00\n"
      "     1.922300781250e+04-1.955271720886e+00-2.793967723846e-09 0.000000000000e+00\n";
  const NavData nav = parseRinexNav(text, "v305.rnx");
  ASSERT_EQ(nav.glonass.size(), 2u);
  EXPECT_DOUBLE_EQ(nav.glonass[0].deltaTauN, 8.381903171539e-09);
  EXPECT_DOUBLE_EQ(nav.glonass[0].accuracy, 0.0);  // F_T = 15: not given
  EXPECT_EQ(nav.glonass[1].frequencyChannel, -4);
  EXPECT_EQ(nav.glonass[1].deltaTauN, 0.0);  // three-line record (3.04 style) accepted too
}

TEST(RinexNavReader, Rinex2OtherSingleSystemFiles) {
  // SBAS (file type H): records are skipped with a reason, three orbit lines each.
  const std::string sbas =
      "     2.11           H: GEO NAV MSG DATA                     RINEX VERSION / TYPE\n"
      "                                                            END OF HEADER\n"
      "20 09 12 18 23 07 28.0 0.000000000000D+00 0.000000000000D+00 3.395520000000D+05\n"
      "    4.073740000000D+04 0.000000000000D+00 0.000000000000D+00 0.000000000000D+00\n"
      "    0.000000000000D+00 0.000000000000D+00 0.000000000000D+00 3.200000000000D+01\n"
      "    0.000000000000D+00 0.000000000000D+00 0.000000000000D+00 0.000000000000D+00\n"
      "27 09 12 18 23 07 28.0 0.000000000000D+00 0.000000000000D+00 3.395520000000D+05\n"
      "    4.073740000000D+04 0.000000000000D+00 0.000000000000D+00 0.000000000000D+00\n"
      "    0.000000000000D+00 0.000000000000D+00 0.000000000000D+00 3.200000000000D+01\n"
      "    0.000000000000D+00 0.000000000000D+00 0.000000000000D+00 0.000000000000D+00\n";
  const NavData s = parseRinexNav(sbas, "sbas.09h");
  EXPECT_TRUE(s.kepler.empty());
  ASSERT_EQ(s.skipped.size(), 2u);
  EXPECT_NE(s.skipped[0].find("S20 SBAS"), std::string::npos);
  EXPECT_NE(s.skipped[1].find("line 7"), std::string::npos);
  // A RINEX 2 file of another system whose records start with the satellite letter (the RINEX 3
  // first-line layout, as RINEX 2.12 Galileo files and RTKLIB's reader have it).
  const std::string gal =
      "     2.12           N: GNSS NAV DATA    E: GALILEO          RINEX VERSION / TYPE\n"
      "                                                            END OF HEADER\n"
      "E12 2024 06 24 08 20 00-1.095227780752D-03-1.594457899046D-11 0.000000000000D+00\n"
      "    6.700000000000D+01 1.359062500000D+02 2.740828452221D-09 1.818462909708D+00\n"
      "    6.115064024925D-06 4.236079985276D-04 7.338821887970D-07 5.440608266830D+03\n"
      "    1.164000000000D+05-3.539025783539D-08 1.566556240144D+00 5.587935447693D-09\n"
      "    9.967372953892D-01 3.393125000000D+02 8.146038365252D-01-5.710952169795D-09\n"
      "    8.214627886510D-11 5.170000000000D+02 2.320000000000D+03\n"
      "    3.120000000000D+00 0.000000000000D+00-8.614733815193D-09-8.847564458847D-09\n"
      "    1.170650000000D+05\n";
  const NavData g = parseRinexNav(gal, "gal.24l");
  ASSERT_EQ(g.kepler.size(), 1u);
  EXPECT_EQ(g.kepler[0].sat, SatId(System::Galileo, 12));
  EXPECT_EQ(g.kepler[0].message, NavMessage::GalileoInav);
  EXPECT_DOUBLE_EQ(g.kepler[0].sqrtA, 5.440608266830e+03);
  EXPECT_DOUBLE_EQ(g.kepler[0].tgd[1], -8.847564458847e-09);
  EXPECT_EQ(g.kepler[0].toe, gpst(2024, 6, 24, 8, 20, 0));
}
