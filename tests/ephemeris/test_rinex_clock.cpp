// RINEX clock: excerpts laid out as the 3.00/3.02 document's example (A4 names) and as 3.04
// files (A9 names), field-by-field numbers, skipped receiver/calibration records, time systems,
// and write -> parse round trips in both layouts.
#include <gtest/gtest.h>

#include <cmath>
#include <sstream>
#include <string>

#include "gvins/ephemeris/rinex_clock.hpp"

using namespace gvins;

namespace {

std::string label(std::string body, const std::string& text) {
  body.resize(60, ' ');
  return body + text + "\n";
}

// Header and records in the layout of the RINEX clock 3.02 document's example (section 8):
// A2,1X,A4,1X,I4,4I3,F10.6,I3,2X,E19.12,E20.12 and the continuation line for 6 values.
std::string v300(const std::string& timeSystem) {
  std::string s;
  s += label("     3.00           C                   M", "RINEX VERSION / TYPE");
  s += label("TESTPROG            TESTAGENCY          20240625 000000 UTC", "PGM / RUN BY / DATE");
  s += label("   " + timeSystem, "TIME SYSTEM ID");
  s += label("    18", "LEAP SECONDS");
  s += label("     2    AS    AR", "# / TYPES OF DATA");
  s += label("     2", "# OF SOLN SATS");
  s += label("G16 R05", "PRN LIST");
  s += label("", "END OF HEADER");
  s += "AR AREQ 2024 06 24 00 00  0.000000  6   -0.123456789012E+00  0.123456789012E+01\n";
  s += "-0.123456789012E+02  0.123456789012E+03 -0.123456789012E+04  0.123456789012E+05\n";
  s += "AS G16  2024 06 24 00 00 30.000000  2   -0.123456789012E-03  0.123456789012E-10\n";
  s += "CR USNO 2024 06 24 00 00  0.000000  2   -0.123456789012E+00  0.123456789012E+01\n";
  s += "DR USNO 2024 06 24 00 00  0.000000  2   -0.123456789012E+00  0.123456789012E+01\n";
  s += "AS G16  2024 06 24 00 00  0.000000  1    0.223456789012E-03\n";
  s += "AS R05  2024 06 24 00 00  0.000000  4    0.100000000000D-03  0.200000000000D-11\n";
  s += " 0.300000000000E-10  0.400000000000E-12\n";
  s += "MS USNO 2024 06 24 00 00  0.000000  1    0.100000000000E-08\n";
  return s;
}

}  // namespace

TEST(RinexClock, ParsesVersion300Layout) {
  const ClockData d = parseRinexClock(v300("GPS"), "v300.clk");
  EXPECT_DOUBLE_EQ(d.version, 3.00);
  EXPECT_EQ(d.timeSystem, "GPS");
  EXPECT_EQ(d.skippedRecords, 4u);  // AR, CR, DR, MS
  ASSERT_EQ(d.satellites.size(), 2u);
  const auto* g = d.find(SatId(System::Gps, 16));
  ASSERT_NE(g, nullptr);
  ASSERT_EQ(g->size(), 2u);  // sorted by time although the file had them the other way round
  const GpsTime t0 = GpsTime::fromCalendar({2024, 6, 24, 0, 0, 0.0});
  EXPECT_EQ((*g)[0].time, t0);
  EXPECT_DOUBLE_EQ((*g)[0].bias, 0.223456789012e-3);
  EXPECT_EQ((*g)[0].sigma, 0.0);
  EXPECT_EQ((*g)[1].time, t0 + 30.0);
  EXPECT_DOUBLE_EQ((*g)[1].bias, -0.123456789012e-3);
  EXPECT_DOUBLE_EQ((*g)[1].sigma, 0.123456789012e-10);
  const auto* r = d.find(SatId(System::Glonass, 5));
  ASSERT_NE(r, nullptr);
  ASSERT_EQ(r->size(), 1u);
  EXPECT_DOUBLE_EQ((*r)[0].bias, 1e-4);  // Fortran D exponent
  EXPECT_DOUBLE_EQ((*r)[0].sigma, 2e-12);
  EXPECT_EQ(d.find(SatId(System::Galileo, 1)), nullptr);
}

TEST(RinexClock, ParsesVersion200And304Layouts) {
  // 2.00: no TIME SYSTEM ID (GPS), same A4 record layout.
  std::string v2 = label("     2.00           C", "RINEX VERSION / TYPE") + label("", "END OF HEADER") +
                   "AS G05  1999 06 16 12 00  0.000000  2    0.123456789012E-04  0.1E-11\n";
  const ClockData d2 = parseRinexClock(v2, "v200.clk");
  ASSERT_NE(d2.find(SatId(System::Gps, 5)), nullptr);
  EXPECT_EQ(d2.find(SatId(System::Gps, 5))->front().time, GpsTime::fromCalendar({1999, 6, 16, 12, 0, 0.0}));
  // 3.04: A9 names shift the epoch by five columns.
  std::string v304 = label("     3.04           C                   G", "RINEX VERSION / TYPE") +
                     label("   GPS", "TIME SYSTEM ID") + label("", "END OF HEADER") +
                     "AS G01       2024 06 24 00 05  0.000000  2   -3.419004519528E-04  1.234000000000E-11\n"
                     "AR ALGO00CAN 2024 06 24 00 05  0.000000  1    1.000000000000E-06\n";
  const ClockData d4 = parseRinexClock(v304, "v304.clk");
  EXPECT_DOUBLE_EQ(d4.version, 3.04);
  EXPECT_EQ(d4.skippedRecords, 1u);
  const auto* g = d4.find(SatId(System::Gps, 1));
  ASSERT_NE(g, nullptr);
  EXPECT_EQ(g->front().time, GpsTime::fromCalendar({2024, 6, 24, 0, 5, 0.0}));
  EXPECT_DOUBLE_EQ(g->front().bias, -3.419004519528e-4);
  EXPECT_DOUBLE_EQ(g->front().sigma, 1.234e-11);
}

TEST(RinexClock, TimeSystemsConvertToGpst) {
  const GpsTime t0 = GpsTime::fromCalendar({2024, 6, 24, 0, 0, 0.0});
  EXPECT_EQ(parseRinexClock(v300("BDT"), "bdt.clk").find(SatId(System::Gps, 16))->front().time, t0 + 14.0);
  EXPECT_EQ(parseRinexClock(v300("UTC"), "utc.clk").find(SatId(System::Gps, 16))->front().time, t0 + 18.0);
  EXPECT_EQ(parseRinexClock(v300("GLO"), "glo.clk").find(SatId(System::Gps, 16))->front().time,
            t0 + 18.0 - 10800.0);
  EXPECT_EQ(parseRinexClock(v300("GAL"), "gal.clk").find(SatId(System::Gps, 16))->front().time, t0);
}

TEST(RinexClock, RoundTripBothLayouts) {
  ClockData d;
  d.timeSystem = "UTC";
  const GpsTime t0 = GpsTime::fromCalendar({2024, 6, 24, 0, 0, 0.0});
  for (System s : {System::Gps, System::Galileo, System::BeiDou, System::Navic}) {
    for (int p = 1; p <= 3; ++p) {
      std::vector<ClockRecord> recs;
      for (int k = 0; k < 5; ++k) {
        recs.push_back({t0 + 30.0 * k + 0.25, 1.23456789012345e-4 * std::cos(p + k) * (k == 2 ? -1 : 1),
                        k % 2 ? 0.0 : 2.5e-11 * p});
      }
      d.satellites.push_back({SatId(s, p), recs});
    }
  }
  for (double version : {3.04, 3.00}) {
    d.version = version;
    std::ostringstream out;
    writeRinexClock(out, d);
    const ClockData back = parseRinexClock(out.str(), "written.clk");
    EXPECT_DOUBLE_EQ(back.version, version);
    EXPECT_EQ(back.timeSystem, "UTC");
    EXPECT_EQ(back.skippedRecords, 0u);
    ASSERT_EQ(back.satellites.size(), d.satellites.size());
    for (const auto& [sat, recs] : d.satellites) {
      const auto* b = back.find(sat);
      ASSERT_NE(b, nullptr) << sat.str();
      ASSERT_EQ(b->size(), recs.size());
      for (std::size_t k = 0; k < recs.size(); ++k) {
        EXPECT_EQ((*b)[k].time, recs[k].time);
        // E19.12: 13 significant digits.
        EXPECT_NEAR((*b)[k].bias, recs[k].bias, 1e-12 * std::fabs(recs[k].bias));
        EXPECT_NEAR((*b)[k].sigma, recs[k].sigma, 1e-12 * recs[k].sigma);
      }
    }
  }
}

TEST(RinexClock, ValueCutInsideItsExponentIsAnError) {
  // A file cut inside its last value ("-0.123456789012E-03" -> "-0.1234567890") must not read as
  // a clock 1000 times larger: the record is rejected with its line and field.
  std::string text = v300("GPS");
  const std::string full = "-0.123456789012E-03";
  const std::size_t at = text.find(full);
  ASSERT_NE(at, std::string::npos);
  for (const std::size_t keep : {std::size_t{12}, std::size_t{16}, std::size_t{17}, std::size_t{18}}) {
    std::string cut = text.substr(0, at) + full.substr(0, keep) + "  0.123456789012E-10\n";
    try {
      parseRinexClock(cut, "cut.clk");
      ADD_FAILURE() << "accepted " << full.substr(0, keep);
    } catch (const ParseError& e) {
      EXPECT_EQ(e.line(), 11) << e.what();  // 8 header lines, AR and its continuation, then AS G16
      EXPECT_EQ(e.field(), "clock bias") << e.what();
    }
  }
  // The complete value still reads.
  EXPECT_DOUBLE_EQ(parseRinexClock(text, "full.clk").find(SatId(System::Gps, 16))->back().bias, -0.123456789012e-3);
}
