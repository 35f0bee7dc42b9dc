// .pos writer/reader and accuracy statistics: round trips, RTKLIB's own files, malformed rows,
// percentile estimates against exact order statistics.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <random>
#include <sstream>

#include "gvins/base/constants.hpp"
#include "gvins/base/parse_error.hpp"
#include "gvins/base/geodetic.hpp"
#include "gvins/base/local_frame.hpp"
#include "gvins/gnss/accuracy_statistics.hpp"
#include "gvins/gnss/pos_reader.hpp"
#include "gvins/gnss/pos_writer.hpp"

using namespace gvins;

namespace {
const std::string kData = GVINS_TEST_DATA;

PositionSolution sample(int i) {
  PositionSolution s;
  s.time = GpsTime::fromCalendar({2024, 6, 24, 8, 20, 0.0}) + i * 0.5 + 1e-4;
  s.quality = SolutionQuality::Single;
  s.position = geodeticToEcef(geodeticFromDegrees(35.13469901 + 1e-6 * i, 136.97757549, 104.8626 + 0.01 * i));
  Eigen::Matrix3d a;
  a << 1.2, 0.3, -0.2, 0.0, 0.9, 0.4, 0.0, 0.0, 1.5;
  s.positionCovariance = a.transpose() * a;
  s.numSatellites = 20 + i;
  if (i % 2 == 0) {
    s.velocity = Eigen::Vector3d(0.01 * i, -0.02, 0.003);
    s.velocityCovariance = 1e-4 * s.positionCovariance;
  }
  return s;
}
}  // namespace

TEST(PosIo, RoundTripInBothLayouts) {
  for (PosCoordinates layout : {PosCoordinates::Xyz, PosCoordinates::Llh}) {
    std::ostringstream os;
    PosWriterOptions o;
    o.coordinates = layout;
    o.headerFields.emplace_back("inp file", "rover.obs");
    {
      PosWriter w(os, o);
      for (int i = 0; i < 5; ++i) w.write(sample(i));
      w.finish();
    }
    const PosFile f = parsePosText(os.str(), "mem.pos");
    EXPECT_EQ(f.ecef, layout == PosCoordinates::Xyz);
    ASSERT_EQ(f.solutions.size(), 5u);
    for (int i = 0; i < 5; ++i) {
      const PositionSolution a = sample(i), &b = f.solutions[i];
      EXPECT_NEAR(b.time - a.time, 0.0, 0.0006);  // 3 decimals
      EXPECT_EQ(b.quality, a.quality);
      EXPECT_EQ(b.numSatellites, a.numSatellites);
      // Positions printed to 0.1 mm (xyz) or 1e-9 deg / 0.1 mm (llh).
      EXPECT_LT((b.position - a.position).norm(), 3e-4);
      // sd columns carry 4 decimals: covariance to ~1e-4 m^2 relative scale.
      EXPECT_LT((b.positionCovariance - a.positionCovariance).cwiseAbs().maxCoeff(), 5e-4);
      // Zero velocity columns (written for epochs without velocity) read back as none.
      EXPECT_EQ(b.velocity.has_value(), a.velocity.has_value());
      if (a.velocity) {
        EXPECT_LT((*b.velocity - *a.velocity).norm(), 2e-5);
      }
    }
  }
}

TEST(PosIo, RowsAreCharacterForCharacterPrintf) {
  // The writer formats numbers itself; every row must equal the printf layout
  // "%15.4f%15.4f%15.4f%4d%4d%9.4f..." (xyz) including rounding ties, negative zero, values that
  // round to zero, wide values, and zero-padded seconds.
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const double ties[] = {0.03125, -0.03125, 0.00005, -0.00005, 0.0, -0.0, -0.00004, 1e9 + 0.5, 2.5e-5};
  for (int decimals : {0, 1, 3, 6}) {
    PosWriterOptions o;
    o.coordinates = PosCoordinates::Xyz;
    o.timeDecimals = decimals;
    o.header = false;
    std::ostringstream os;
    PosWriter w(os, o);
    std::string expected;
    for (int i = 0; i < 400; ++i) {
      PositionSolution s;
      s.time = GpsTime::fromCalendar({2024, 6, 24, 8, 20, 0.0}) + i * 0.731 + u(rng) * 1e-3;
      s.quality = SolutionQuality::Single;
      const double pick = i < 9 ? ties[i] : u(rng) * std::pow(10.0, static_cast<int>(rng() % 12) - 4);
      s.position = Eigen::Vector3d(pick, -3.9e6 + u(rng), 1e7 * u(rng));
      Eigen::Matrix3d c;
      c << pick * pick, u(rng), -pick * std::abs(pick), u(rng), 2.0, u(rng), u(rng), -0.0, 1e-12;
      s.positionCovariance = c;
      s.numSatellites = i % 60;
      s.age = u(rng) * 30.0;
      s.ratio = i % 3 == 0 ? pick : 999.95;
      if (i % 2 == 0) {
        s.velocity = Eigen::Vector3d(pick, u(rng) * 1e3, -1e-7);
        s.velocityCovariance = c * 1e-4;
      }
      w.write(s);
      // Expected row: the writer's time rounding, then printf.
      const double scale = std::pow(10.0, decimals);
      const CalendarTime t =
          GpsTime::fromSeconds(s.time.wholeSeconds(), std::round(s.time.fraction() * scale) / scale).toCalendar();
      char buf[600];
      std::snprintf(buf, sizeof buf, "%04d/%02d/%02d %02d:%02d:%0*.*f", t.year, t.month, t.day, t.hour, t.minute,
                    decimals > 0 ? decimals + 3 : 2, decimals, std::floor(t.second * scale + 0.5) / scale);
      expected += buf;
      // printf's "%<w>.<p>f", with one blank more before a value that fills its field (the writer
      // keeps a separator there).
      auto f = [&](double x, int width, int p) {
        if (std::snprintf(nullptr, 0, "%.*f", p, x) >= width) expected += ' ';
        std::snprintf(buf, sizeof buf, "%*.*f", width, p, x);
        expected += buf;
      };
      const Eigen::Matrix3d& P = s.positionCovariance;
      for (int k = 0; k < 3; ++k) f(s.position[k], 15, 4);
      std::snprintf(buf, sizeof buf, "%4d%4d", 5, s.numSatellites);
      expected += buf;
      for (int k = 0; k < 3; ++k) f(std::sqrt(std::max(P(k, k), 0.0)), 9, 4);
      f(signedSqrt(P(0, 1)), 9, 4);
      f(signedSqrt(P(1, 2)), 9, 4);
      f(signedSqrt(P(2, 0)), 9, 4);
      f(s.age, 7, 2);
      f(s.ratio, 7, 1);
      // No velocity: nan in all six columns.
      const double nan = std::numeric_limits<double>::quiet_NaN();
      const Eigen::Vector3d v = s.velocity.value_or(Eigen::Vector3d::Constant(nan));
      const Eigen::Matrix3d V = s.velocity ? s.velocityCovariance : Eigen::Matrix3d::Constant(nan);
      for (int k = 0; k < 3; ++k) f(v[k], 11, 5);
      expected += ' ';
      for (int k = 0; k < 3; ++k) f(std::sqrt(std::max(V(k, k), 0.0)), 9, 5);
      f(signedSqrt(V(0, 1)), 9, 5);
      f(signedSqrt(V(1, 2)), 9, 5);
      f(signedSqrt(V(2, 0)), 9, 5);
      expected += '\n';
    }
    w.finish();
    EXPECT_EQ(os.str(), expected) << "time decimals " << decimals;
  }
}

/// The whitespace-separated fields of the data rows of a .pos text.
std::vector<std::vector<std::string>> dataRows(const std::string& text) {
  std::vector<std::vector<std::string>> rows;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) {
    if (line.empty() || line[0] == '%') continue;
    std::istringstream ls(line);
    std::vector<std::string> f;
    for (std::string t; ls >> t;) f.push_back(t);
    rows.push_back(f);
  }
  return rows;
}

TEST(PosIo, WideValuesStaySeparatedAndRoundTrip) {
  // Values as wide as their fields or wider (a diverged velocity, a huge sd, a negative ratio):
  // printf's layout runs them into the field before ("0.0-1475.85308"); ours keeps a blank.
  PositionSolution s = sample(0);
  s.position = Eigen::Vector3d(-3817679.8533, 3562838.2326, 3650159.8842);
  s.ratio = -123456.7;
  s.age = 99999.99;
  s.positionCovariance = Eigen::Matrix3d::Identity() * 1e10;  // sd 100000.0000: 11 characters in %9.4f
  s.velocity = Eigen::Vector3d(-1475.85308, 582.16883, -3156.54187);
  s.velocityCovariance = Eigen::Matrix3d::Identity() * 1e6;  // sd 1000.00000 in %9.5f
  s.residualTest = ResidualTest::Failed;
  for (PosCoordinates layout : {PosCoordinates::Xyz, PosCoordinates::Llh}) {
    std::ostringstream os;
    PosWriterOptions o;
    o.coordinates = layout;
    o.testColumn = true;
    {
      PosWriter w(os, o);
      w.write(s);
      w.write(sample(2));
    }
    const auto rows = dataRows(os.str());
    ASSERT_EQ(rows.size(), 2u);
    // date time, 3 coordinates, Q ns, 6 sd, age ratio, 3 velocities, 6 sd, test
    EXPECT_EQ(rows[0].size(), 25u) << os.str();
    EXPECT_EQ(rows[1].size(), 25u) << os.str();
    if (layout == PosCoordinates::Xyz) {
      EXPECT_EQ(rows[0][14], "-123456.7");
      EXPECT_EQ(rows[0][15], "-1475.85308");
      EXPECT_EQ(rows[0][16], "582.16883");
      EXPECT_EQ(rows[0][17], "-3156.54187");
    }
    const PosFile f = parsePosText(os.str(), "wide.pos");
    ASSERT_EQ(f.solutions.size(), 2u);
    const PositionSolution& b = f.solutions[0];
    EXPECT_DOUBLE_EQ(b.ratio, s.ratio);
    EXPECT_DOUBLE_EQ(b.age, s.age);
    EXPECT_NEAR(std::sqrt(b.positionCovariance(2, 2)), 1e5, 1e-3);
    ASSERT_TRUE(b.velocity);
    EXPECT_LT((*b.velocity - *s.velocity).norm(), 2e-5);
    EXPECT_NEAR(std::sqrt(b.velocityCovariance(1, 1)), 1e3, 1e-4);
    EXPECT_EQ(b.residualTest, ResidualTest::Failed);
    EXPECT_EQ(f.solutions[1].residualTest, ResidualTest::Untestable);  // not set: written as 2
  }
}

TEST(PosIo, AbsentVelocityIsNanAndReadsBackAbsent) {
  // An epoch without velocity: nan in the six velocity columns (not 0 with sd 0, a measured
  // standstill), read back as no velocity; the header says what nan means.
  PositionSolution s = sample(1);
  ASSERT_FALSE(s.velocity);
  std::ostringstream os;
  PosWriterOptions o;
  o.coordinates = PosCoordinates::Xyz;
  {
    PosWriter w(os, o);
    w.write(s);
    w.write(sample(0));
  }
  EXPECT_NE(os.str().find("% (velocity columns nan: no velocity in that epoch)"), std::string::npos) << os.str();
  const auto rows = dataRows(os.str());
  ASSERT_EQ(rows.size(), 2u);
  ASSERT_EQ(rows[0].size(), 24u);
  for (int i = 15; i < 24; ++i) EXPECT_EQ(rows[0][i], "nan") << i;
  EXPECT_NE(rows[1][15], "nan");
  const PosFile f = parsePosText(os.str(), "nan.pos");
  ASSERT_EQ(f.solutions.size(), 2u);
  EXPECT_FALSE(f.solutions[0].velocity.has_value());
  EXPECT_TRUE(f.solutions[0].velocityCovariance.isZero(0.0));
  ASSERT_TRUE(f.solutions[1].velocity.has_value());
  EXPECT_FALSE(f.solutions[0].residualTest.has_value());  // no test column
  // A velocity that is nan on one axis only is malformed.
  std::string text = os.str();
  const std::size_t at = text.rfind('\n', text.size() - 2) + 1;
  std::string row = text.substr(at);
  const auto nrow = dataRows(row)[0];
  std::string broken;
  for (std::size_t i = 0; i < nrow.size(); ++i) broken += (i ? " " : "") + (i == 16 ? std::string("nan") : nrow[i]);
  EXPECT_THROW(parsePosText(text.substr(0, at) + broken + "\n", "partial.pos"), ParseError);
}

TEST(PosIo, ReadsRtklibSolutionFiles) {
  const PosFile f = readPosFile(kData + "/reference/rtklib-2.4.3/nagoya_rover_spp.pos");
  EXPECT_TRUE(f.ecef);
  ASSERT_EQ(f.solutions.size(), 301u);
  // First row: 2024/06/24 08:20:00.000  -3817679.8533   3562838.2326   3650159.8842   5  42
  //            3.6606 3.8467 2.9478 -3.2345 2.8281 -2.7410 ... 0.00787 -0.00562 -0.00502 0.10617 ...
  const PositionSolution& s = f.solutions.front();
  EXPECT_EQ(s.time, GpsTime::fromCalendar({2024, 6, 24, 8, 20, 0.0}));
  EXPECT_DOUBLE_EQ(s.position.x(), -3817679.8533);
  EXPECT_DOUBLE_EQ(s.position.z(), 3650159.8842);
  EXPECT_EQ(s.quality, SolutionQuality::Single);
  EXPECT_EQ(s.numSatellites, 42);
  EXPECT_NEAR(std::sqrt(s.positionCovariance(0, 0)), 3.6606, 1e-12);
  EXPECT_NEAR(s.positionCovariance(0, 1), -3.2345 * 3.2345, 1e-9);
  ASSERT_TRUE(s.velocity);
  EXPECT_DOUBLE_EQ(s.velocity->x(), 0.00787);
  EXPECT_NEAR(std::sqrt(s.velocityCovariance(0, 0)), 0.10617, 1e-12);
  // kamakura has no Doppler: RTKLIB wrote zero velocity columns, read as "no velocity".
  const PosFile km = readPosFile(kData + "/reference/rtklib-2.4.3/kamakura_sept078_spp.pos");
  ASSERT_EQ(km.solutions.size(), 900u);
  EXPECT_FALSE(km.solutions[0].velocity.has_value());
  const PosFile k = readPosFile(kData + "/reference/rtklib-2.4.3/geonet_0759_rtk_static.pos");
  ASSERT_FALSE(k.solutions.empty());
  EXPECT_EQ(k.solutions[0].quality, SolutionQuality::Fix);
  EXPECT_FALSE(k.solutions[0].velocity.has_value());  // no velocity columns
}

TEST(PosIo, MalformedRowsNameLineAndColumn) {
  const std::string head = "%  GPST                      x-ecef(m)      y-ecef(m)      z-ecef(m)   Q  ns\n";
  auto expectError = [&](const std::string& body, std::int64_t line, const std::string& field) {
    try {
      parsePosText(head + body, "bad.pos");
      FAIL() << body;
    } catch (const ParseError& e) {
      EXPECT_EQ(e.line(), line) << e.what();
      EXPECT_NE(e.field().find(field), std::string::npos) << e.what();
    }
  };
  expectError("2024/06/24 08:20:00.000  -3817679.8533   3562838.2326\n", 2, "row");
  expectError("2024/06/24 08:20:00.000  -3817679.8533   3562838.2326   365x0159.8842   5  42\n", 2, "z-ecef");
  expectError("2024/13/24 08:20:00.000  -3817679.8533   3562838.2326   3650159.8842   5  42\n", 2, "time");
  expectError("2024/06/24 08:20:00.000  -3817679.8533   3562838.2326   3650159.8842   9  42\n", 2, "Q");
  expectError("2024-06-24 08:20:00.000  -3817679.8533   3562838.2326   3650159.8842   5  42\n", 2, "week");
  expectError("2024/06/24 08:20:00.000  -3817679.8533   3562838.2326   3650159.8842   5  42 nan 1 1 1 1 1\n", 2, "sd1");
  expectError("2024/06/24 08:20:00.000  -3817679.8533   3562838.2326   3650159.8842   1.5  42\n", 2, "Q");
  EXPECT_THROW(parsePosText("%  JST    x-ecef(m)\n", "t.pos"), ParseError);
  // Integer columns printed with decimals (the rtklibexplorer GNSS_IMU reference tracks).
  const PosFile dec = parsePosText(head + "2024/06/24 08:20:00.000  -3817679.8533   3562838.2326   3650159.8842   1.0000000  25.0000000\n", "d.pos");
  EXPECT_EQ(dec.solutions.at(0).quality, SolutionQuality::Fix);
  EXPECT_EQ(dec.solutions.at(0).numSatellites, 25);
  const PosFile walk = readPosFile(std::string(GVINS_TEST_DATA) + "/gnss_imu/walk_0827/gnss_1730_sf.pos");
  ASSERT_EQ(walk.solutions.size(), 536u);
  EXPECT_EQ(std::count_if(walk.solutions.begin(), walk.solutions.end(),
                          [](const PositionSolution& x) { return x.quality == SolutionQuality::Fix; }),
            349);
  // Week/tow times and UTC files.
  const PosFile wk = parsePosText(head + "2320 116400.000  -3817679.8533   3562838.2326   3650159.8842   5  42\n", "w.pos");
  EXPECT_EQ(wk.solutions.at(0).time, GpsTime::fromWeekTow(2320, 116400.0));
  const PosFile utc = parsePosText("%  UTC   x-ecef(m)\n2024/06/24 08:19:42.000  -3817679.8533   3562838.2326   3650159.8842   5  42\n", "u.pos");
  EXPECT_EQ(utc.solutions.at(0).time, GpsTime::fromCalendar({2024, 6, 24, 8, 20, 0.0}));
}

TEST(Accuracy, StatisticsMatchDirectComputation) {
  const Eigen::Vector3d truth = geodeticToEcef(geodeticFromDegrees(35.0, 137.0, 50.0));
  const Geodetic g = ecefToGeodetic(truth);
  const Eigen::Matrix3d r = ecefToEnuRotation(g.lat, g.lon);
  std::mt19937 rng(3);
  std::normal_distribution<double> n(0.0, 1.0);
  AccuracyStatistics st(truth);
  std::vector<Eigen::Vector3d> enu;
  for (int i = 0; i < 5000; ++i) {
    const Eigen::Vector3d e(0.5 + 0.3 * n(rng), -0.2 + 0.4 * n(rng), 1.0 + 2.0 * n(rng));
    enu.push_back(e);
    st.addPosition(truth + r.transpose() * e);
  }
  const AccuracySummary s = st.position();
  EXPECT_EQ(s.count, 5000);
  double sh = 0, sv = 0, me = 0;
  std::vector<double> h, v;
  for (const auto& e : enu) {
    sh += e.x() * e.x() + e.y() * e.y();
    sv += e.z() * e.z();
    me += e.x();
    h.push_back(std::hypot(e.x(), e.y()));
    v.push_back(std::abs(e.z()));
  }
  EXPECT_NEAR(s.horizontalRms, std::sqrt(sh / 5000), 1e-9);
  EXPECT_NEAR(s.verticalRms, std::sqrt(sv / 5000), 1e-9);
  EXPECT_NEAR(s.enu[0].mean, me / 5000, 1e-9);
  std::sort(h.begin(), h.end());
  std::sort(v.begin(), v.end());
  // 95th percentile as the 4750th order statistic; histogram resolution 0.1 %.
  EXPECT_NEAR(s.horizontal95, h[4749], 2e-3 * h[4749]);
  EXPECT_NEAR(s.vertical95, v[4749], 2e-3 * v[4749]);
  EXPECT_NEAR(s.horizontalMax, h.back(), 1e-9);
  const std::string t = st.table();
  EXPECT_NE(t.find("horizontal"), std::string::npos);
  EXPECT_EQ(t.find("velocity"), std::string::npos);
}
