// SP3-c/d: hand-made excerpts laid out as in the format documents (Hilla 2010, 2016) with their
// numbers checked field by field, time-system conversion (BDT, UTC, GLO epochs land at the right
// GPST), and write -> parse round trips of both versions, including more than 85 satellites.
#include <gtest/gtest.h>

#include <cmath>
#include <sstream>
#include <string>

#include "gvins/ephemeris/sp3.hpp"

using namespace gvins;

namespace {

// SP3-d header of a 2-epoch, 3-satellite file (2024-06-24 = GPS week 2320, day 1), in the layout
// of the SP3-d document's example: columns 1-2 "#d", 3 P/V, 4-31 start epoch, 33-39 epochs, ...
std::string header(const std::string& timeSystem, char version = 'd', char pv = 'P') {
  std::string h;
  h += std::string("#") + version + pv + "2024  6 24  0  0  0.00000000       2 ORBIT IGb20 FIT  IGS\n";
  h += "## 2320  86400.00000000   900.00000000 60485 0.0000000000000\n";
  h += "+    3   G01R02E11  0  0  0  0  0  0  0  0  0  0  0  0  0  0\n";
  for (int i = 0; i < 4; ++i) h += "+          0  0  0  0  0  0  0  0  0  0  0  0  0  0  0  0  0\n";
  h += "++         2  3  0  0  0  0  0  0  0  0  0  0  0  0  0  0  0\n";
  for (int i = 0; i < 4; ++i) h += "++         0  0  0  0  0  0  0  0  0  0  0  0  0  0  0  0  0\n";
  h += "%c M  cc " + timeSystem + " ccc cccc cccc cccc cccc ccccc ccccc ccccc ccccc\n";
  h += "%c cc cc ccc ccc cccc cccc cccc cccc ccccc ccccc ccccc ccccc\n";
  h += "%f  1.2500000  1.025000000  0.00000000000  0.000000000000000\n";
  h += "%f  0.0000000  0.000000000  0.00000000000  0.000000000000000\n";
  h += "%i    0    0    0    0      0      0      0      0         0\n";
  h += "%i    0    0    0    0      0      0      0      0         0\n";
  h += "/* HAND-MADE EXCERPT FOR TESTS\n";
  h += "/* LAYOUT OF THE SP3-D DOCUMENT\n";
  h += "/*\n";
  h += "/*\n";
  return h;
}

const std::string kBody =
    "*  2024  6 24  0  0  0.00000000\n"
    "PG01 -11044.805800 -10475.672350  21929.418200    189.163300 18 18 18 219\n"
    "PR02      0.000000      0.000000      0.000000 999999.999999\n"
    "PE11  15588.362712  -8713.514367  23598.110926    -55.000001\n"
    "*  2024  6 24  0 15  0.00000000\n"
    "PG01 -11260.155700  -8372.384600  22588.022400    189.163700\n"
    "PR02  12000.000001  13000.000002  14000.000003 999999.999999\n"
    "PE11  15000.000000  -9000.000000  24000.000000    -55.000002\n"
    "EOF\n";

}  // namespace

TEST(Sp3, ParsesDocumentLayoutNumbers) {
  const Sp3Data d = parseSp3(header("GPS") + kBody, "excerpt.sp3");
  EXPECT_EQ(d.version, 'd');
  EXPECT_EQ(d.timeSystem, "GPS");
  EXPECT_EQ(d.coordinateSystem, "IGb20");
  EXPECT_EQ(d.orbitType, "FIT");
  EXPECT_EQ(d.agency, "IGS");
  EXPECT_EQ(d.dataUsed, "ORBIT");
  EXPECT_DOUBLE_EQ(d.interval, 900.0);
  ASSERT_EQ(d.satellites.size(), 3u);
  EXPECT_EQ(d.satellites[0], SatId(System::Gps, 1));
  EXPECT_EQ(d.satellites[1], SatId(System::Glonass, 2));
  EXPECT_EQ(d.satellites[2], SatId(System::Galileo, 11));
  EXPECT_EQ(d.accuracyExponent, (std::vector<int>{2, 3, 0}));
  ASSERT_EQ(d.comments.size(), 4u);
  EXPECT_EQ(d.comments[0], "HAND-MADE EXCERPT FOR TESTS");
  ASSERT_EQ(d.epochs.size(), 2u);
  EXPECT_EQ(d.epochs[0].time, GpsTime::fromWeekTow(2320, 86400.0));
  EXPECT_EQ(d.epochs[1].time - d.epochs[0].time, 900.0);
  const Sp3Record& g = d.epochs[0].records[0];
  EXPECT_EQ(g.sat, SatId(System::Gps, 1));
  EXPECT_NEAR(g.position.x(), -11044805.800, 1e-6);
  EXPECT_NEAR(g.position.y(), -10475672.350, 1e-6);
  EXPECT_NEAR(g.position.z(), 21929418.200, 1e-6);
  EXPECT_NEAR(g.clock, 189.1633e-6, 1e-18);
  EXPECT_FALSE(g.velocity.has_value());
  const Sp3Record& r = d.epochs[0].records[1];
  EXPECT_TRUE(r.position.array().isNaN().all());
  EXPECT_TRUE(std::isnan(r.clock));
  EXPECT_NEAR(d.epochs[1].records[1].position.z(), 14000000.003, 1e-6);
  EXPECT_TRUE(std::isnan(d.epochs[1].records[1].clock));
  EXPECT_NEAR(d.epochs[1].records[2].clock, -55.000002e-6, 1e-18);
}

TEST(Sp3, TimeSystemsConvertToGpst) {
  const GpsTime gps = GpsTime::fromWeekTow(2320, 86400.0);
  // BDT = GPST - 14 s: a BDT epoch of 00:00:00 is 00:00:14 GPST.
  EXPECT_EQ(parseSp3(header("BDT") + kBody, "bdt.sp3").epochs[0].time, gps + 14.0);
  // UTC: GPST - UTC = 18 s in 2024.
  EXPECT_EQ(parseSp3(header("UTC") + kBody, "utc.sp3").epochs[0].time, gps + 18.0);
  // GLO = UTC + 3 h.
  EXPECT_EQ(parseSp3(header("GLO") + kBody, "glo.sp3").epochs[0].time, gps + 18.0 - 3 * 3600.0);
  // TAI = GPST + 19 s.
  EXPECT_EQ(parseSp3(header("TAI") + kBody, "tai.sp3").epochs[0].time, gps - 19.0);
  EXPECT_EQ(parseSp3(header("GAL") + kBody, "gal.sp3").epochs[0].time, gps);
  // "ccc" (files written before SP3-c defined the field) means GPS.
  const Sp3Data old = parseSp3(header("ccc", 'c') + kBody, "old.sp3");
  EXPECT_EQ(old.timeSystem, "GPS");
  EXPECT_EQ(old.version, 'c');
  EXPECT_EQ(old.epochs[0].time, gps);
}

TEST(Sp3, VelocityRecordsAndBareGpsIds) {
  std::string body =
      "*  2024  6 24  0  0  0.00000000\n"
      "P 01 -11044.805800 -10475.672350  21929.418200    189.163300\n"
      "EP  55  55  55     222   1234567 -1234567   5999999      -30      -20 -5999999\n"
      "V 01  20298.880364 -18462.044804   1381.387685     -4.534317\n"
      "EV  22  22  22     111   1234567  1234567   1234567  1234567  1234567  1234567\n"
      "PR02      0.000000      0.000000      0.000000 999999.999999\n"
      "VR02      0.000000      0.000000      0.000000 999999.999999\n"
      "*  2024  6 24  0 15  0.00000000\n"
      "EOF\n";
  const Sp3Data d = parseSp3(header("GPS", 'c', 'V') + body, "vel.sp3");
  const Sp3Record& g = d.epochs[0].records[0];
  EXPECT_EQ(g.sat, SatId(System::Gps, 1));
  ASSERT_TRUE(g.velocity && g.clockRate);
  EXPECT_NEAR(g.velocity->x(), 2029.8880364, 1e-9);  // dm/s -> m/s
  EXPECT_NEAR(g.velocity->y(), -1846.2044804, 1e-9);
  EXPECT_NEAR(*g.clockRate, -4.534317e-10, 1e-22);  // 1e-4 us/s -> s/s
  const Sp3Record& r = d.epochs[0].records[1];
  ASSERT_TRUE(r.velocity && r.clockRate);
  EXPECT_TRUE(r.velocity->array().isNaN().all());
  EXPECT_TRUE(std::isnan(*r.clockRate));
  EXPECT_TRUE(d.epochs[1].records.empty());
}

namespace {

Sp3Data synthetic(char version, int nSats, bool velocity, const std::string& ts) {
  Sp3Data d;
  d.version = version;
  d.timeSystem = ts;
  d.coordinateSystem = "IGb20";
  d.orbitType = "FIT";
  d.agency = "TST";
  d.interval = 300.0;
  d.comments = {"round trip", "second comment"};
  for (System s : {System::Gps, System::Glonass, System::Galileo, System::BeiDou}) {
    for (int p = minPrn(s); p <= maxPrn(s) && static_cast<int>(d.satellites.size()) < nSats; ++p) {
      d.satellites.push_back(SatId(s, p));
      d.accuracyExponent.push_back(p % 7);
    }
  }
  const GpsTime t0 = GpsTime::fromCalendar({2024, 6, 24, 0, 0, 0.0});
  for (int k = 0; k < 3; ++k) {
    Sp3Epoch e{t0 + 300.0 * k, {}};
    for (std::size_t i = 0; i < d.satellites.size(); ++i) {
      Sp3Record r;
      r.sat = d.satellites[i];
      const double a = 0.7 * static_cast<double>(i) + 0.05 * k;
      r.position = Eigen::Vector3d(26.6e6 * std::cos(a), 26.6e6 * std::sin(a), 1.3e7 * std::sin(2 * a)) +
                   Eigen::Vector3d(0.1234567, -0.7654321, 0.3333333);
      r.clock = (i % 5 == 3) ? std::numeric_limits<double>::quiet_NaN() : 1.234567890123e-4 * std::sin(a + 1.0);
      if (i % 11 == 4) r.position.setConstant(std::numeric_limits<double>::quiet_NaN());
      if (velocity) {
        r.velocity = Eigen::Vector3d(-3000.0 * std::sin(a), 3000.0 * std::cos(a), 777.7777777);
        r.clockRate = 1.23456e-11 * std::cos(a);
      }
      e.records.push_back(r);
    }
    d.epochs.push_back(e);
  }
  return d;
}

void expectSame(const Sp3Data& a, const Sp3Data& b) {
  EXPECT_EQ(a.satellites, b.satellites);
  EXPECT_EQ(a.accuracyExponent, b.accuracyExponent);
  EXPECT_EQ(a.timeSystem, b.timeSystem);
  EXPECT_EQ(a.coordinateSystem, b.coordinateSystem);
  EXPECT_EQ(a.agency, b.agency);
  EXPECT_EQ(a.interval, b.interval);
  ASSERT_EQ(a.epochs.size(), b.epochs.size());
  for (std::size_t k = 0; k < a.epochs.size(); ++k) {
    EXPECT_EQ(a.epochs[k].time, b.epochs[k].time);
    ASSERT_EQ(a.epochs[k].records.size(), b.epochs[k].records.size());
    for (std::size_t i = 0; i < a.epochs[k].records.size(); ++i) {
      const Sp3Record& x = a.epochs[k].records[i];
      const Sp3Record& y = b.epochs[k].records[i];
      EXPECT_EQ(x.sat, y.sat);
      if (x.position.allFinite()) {
        EXPECT_LE((x.position - y.position).cwiseAbs().maxCoeff(), 0.5e-3 + 1e-9);  // 1 mm resolution
      } else {
        EXPECT_TRUE(y.position.array().isNaN().all());
      }
      if (std::isfinite(x.clock)) {
        EXPECT_NEAR(x.clock, y.clock, 0.5e-12 + 1e-18);  // 1e-12 s resolution
      } else {
        EXPECT_TRUE(std::isnan(y.clock));
      }
      ASSERT_EQ(x.velocity.has_value(), y.velocity.has_value());
      if (x.velocity) {
        EXPECT_LE((*x.velocity - *y.velocity).cwiseAbs().maxCoeff(), 0.5e-7 + 1e-12);  // 1e-6 dm/s
        EXPECT_NEAR(*x.clockRate, *y.clockRate, 0.5e-16 + 1e-22);                      // 1e-6 * 1e-4 us/s
      }
    }
  }
}

}  // namespace

TEST(Sp3, RoundTripSp3dWithMoreThan85Satellites) {
  const Sp3Data d = synthetic('d', 95, true, "GPS");
  ASSERT_EQ(d.satellites.size(), 95u);
  std::ostringstream out;
  writeSp3(out, d);
  const std::string text = out.str();
  EXPECT_EQ(text.substr(0, 3), "#dV");
  EXPECT_NE(text.find("\n+   95   G01"), std::string::npos);
  const Sp3Data back = parseSp3(text, "written.sp3");
  EXPECT_EQ(back.version, 'd');
  EXPECT_EQ(back.comments[0], "round trip");
  expectSame(d, back);
}

TEST(Sp3, RoundTripSp3cAndTimeSystems) {
  for (const std::string ts : {"GPS", "UTC", "BDT", "GLO", "TAI"}) {
    const Sp3Data d = synthetic('c', 40, false, ts);
    std::ostringstream out;
    writeSp3(out, d);
    const Sp3Data back = parseSp3(out.str(), "written-c.sp3");
    EXPECT_EQ(back.version, 'c') << ts;
    EXPECT_EQ(back.comments.size(), 4u);
    expectSame(d, back);
  }
  // SP3-c cannot hold more than 85 satellites: written as SP3-d.
  std::ostringstream out;
  writeSp3(out, synthetic('c', 90, false, "GPS"));
  EXPECT_EQ(parseSp3(out.str(), "forced-d.sp3").version, 'd');
}
