// .pos writer/reader and accuracy statistics: round trips, RTKLIB's own files, malformed rows,
// percentile estimates against exact order statistics.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
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
      const Eigen::Matrix3d& P = s.positionCovariance;
      std::snprintf(buf, sizeof buf, "%15.4f%15.4f%15.4f%4d%4d%9.4f%9.4f%9.4f%9.4f%9.4f%9.4f%7.2f%7.1f", s.position.x(),
                    s.position.y(), s.position.z(), 5, s.numSatellites, std::sqrt(std::max(P(0, 0), 0.0)),
                    std::sqrt(std::max(P(1, 1), 0.0)), std::sqrt(std::max(P(2, 2), 0.0)), signedSqrt(P(0, 1)),
                    signedSqrt(P(1, 2)), signedSqrt(P(2, 0)), s.age, s.ratio);
      expected += buf;
      const Eigen::Vector3d v = s.velocity.value_or(Eigen::Vector3d::Zero());
      const Eigen::Matrix3d V = s.velocity ? s.velocityCovariance : Eigen::Matrix3d::Zero();
      std::snprintf(buf, sizeof buf, "%11.5f%11.5f%11.5f %9.5f%9.5f%9.5f%9.5f%9.5f%9.5f\n", v.x(), v.y(), v.z(),
                    std::sqrt(std::max(V(0, 0), 0.0)), std::sqrt(std::max(V(1, 1), 0.0)),
                    std::sqrt(std::max(V(2, 2), 0.0)), signedSqrt(V(0, 1)), signedSqrt(V(1, 2)), signedSqrt(V(2, 0)));
      expected += buf;
    }
    w.finish();
    EXPECT_EQ(os.str(), expected) << "time decimals " << decimals;
  }
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
  EXPECT_THROW(parsePosText("%  JST    x-ecef(m)\n", "t.pos"), ParseError);
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
