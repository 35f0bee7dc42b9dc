// NMEA 0183 GGA/RMC and KML output (nmea_writer.hpp, kml_writer.hpp). Truth: the checksum of
// the widely published NMEA example sentence, the GPST-UTC leap seconds of IERS Bulletin C, and
// an independent parse of the written sentences back to a position (compared with the input
// position through the project's geodetic conversion).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <sstream>
#include <string>
#include <vector>

#include "gvins/base/constants.hpp"
#include "gvins/base/geodetic.hpp"
#include "gvins/base/local_frame.hpp"
#include "gvins/gnss/kml_writer.hpp"
#include "gvins/gnss/nmea_writer.hpp"

using namespace gvins;

namespace {

std::vector<std::string> split(const std::string& s) {
  std::vector<std::string> f;
  std::string cur;
  for (char c : s) {
    if (c == ',') {
      f.push_back(cur);
      cur.clear();
    } else {
      cur += c;
    }
  }
  f.push_back(cur);
  return f;
}

// Independent check of a sentence: '$', '*', two hex digits equal to the XOR, CR LF; returns
// the fields between '$' and '*'.
std::vector<std::string> parseSentence(const std::string& s) {
  EXPECT_GE(s.size(), 6u);
  EXPECT_EQ(s.front(), '$');
  EXPECT_EQ(s.substr(s.size() - 2), "\r\n");
  const std::size_t star = s.rfind('*');
  EXPECT_NE(star, std::string::npos);
  int x = 0;
  for (std::size_t i = 1; i < star; ++i) x ^= static_cast<unsigned char>(s[i]);
  EXPECT_EQ(std::strtol(s.substr(star + 1, 2).c_str(), nullptr, 16), x) << s;
  EXPECT_LE(s.size(), 82u + 12u);  // 82 characters in the standard; 7-decimal minutes add a few
  return split(s.substr(1, star - 1));
}

double angle(const std::string& v, const std::string& hemi, int degDigits) {
  const double d = std::stod(v.substr(0, static_cast<std::size_t>(degDigits)));
  const double m = std::stod(v.substr(static_cast<std::size_t>(degDigits)));
  const double a = d + m / 60.0;
  return (hemi == "S" || hemi == "W") ? -a : a;
}

PositionSolution solutionAt(double latDeg, double lonDeg, double h, SolutionQuality q) {
  PositionSolution s;
  s.time = GpsTime::fromCalendar({2023, 6, 15, 12, 34, 56.789});
  s.quality = q;
  s.position = geodeticToEcef(geodeticFromDegrees(latDeg, lonDeg, h));
  s.numSatellites = 17;
  s.age = 1.3;
  return s;
}

}  // namespace

TEST(Nmea, ChecksumOfPublishedExample) {
  // The classic GGA example of NMEA documentation with its published checksum 47.
  EXPECT_EQ(nmeaChecksum("GPGGA,123519,4807.038,N,01131.000,E,1,08,0.9,545.4,M,46.9,M,,"), 0x47u);
  EXPECT_EQ(nmeaSentence("GPGGA,123519,4807.038,N,01131.000,E,1,08,0.9,545.4,M,46.9,M,,"),
            "$GPGGA,123519,4807.038,N,01131.000,E,1,08,0.9,545.4,M,46.9,M,,*47\r\n");
}

TEST(Nmea, QualityMapping) {
  EXPECT_EQ(nmeaGgaQuality(SolutionQuality::Fix), 4);
  EXPECT_EQ(nmeaGgaQuality(SolutionQuality::Float), 5);
  EXPECT_EQ(nmeaGgaQuality(SolutionQuality::Single), 1);
  EXPECT_EQ(nmeaGgaQuality(SolutionQuality::Dgps), 2);
  EXPECT_EQ(nmeaGgaQuality(SolutionQuality::None), 0);
  EXPECT_EQ(nmeaModeIndicator(SolutionQuality::Fix), 'R');
  EXPECT_EQ(nmeaModeIndicator(SolutionQuality::Float), 'F');
  EXPECT_EQ(nmeaModeIndicator(SolutionQuality::Single), 'A');
}

TEST(Nmea, GgaFieldsAndRoundTrip) {
  // Four hemispheres; the parsed sentence must give the position back to < 1 mm.
  const double pts[][3] = {{48.1173, 11.5166667, 545.4}, {-33.8688, 151.2093, 58.123},
                           {40.7128, -74.006, -12.5}, {-0.000001, -0.000001, 3.2}};
  for (const auto& p : pts) {
    PositionSolution s = solutionAt(p[0], p[1], p[2], SolutionQuality::Fix);
    const auto f = parseSentence(nmeaGga(s, NmeaExtras{0.87, 42}));
    ASSERT_EQ(f.size(), 15u);
    EXPECT_EQ(f[0], "GNGGA");
    // 2023-06-15: GPST - UTC = 18 s.
    EXPECT_EQ(f[1], "123438.79");
    EXPECT_EQ(f[6], "4");
    EXPECT_EQ(f[7], "17");
    EXPECT_EQ(f[8], "0.9");
    EXPECT_EQ(f[10], "M");
    EXPECT_EQ(f[12], "M");
    EXPECT_EQ(f[13], "1.3");
    EXPECT_EQ(f[14], "0042");
    const double lat = angle(f[2], f[3], 2), lon = angle(f[4], f[5], 3);
    const double h = std::stod(f[9]) + std::stod(f[11]);
    const Eigen::Vector3d back = geodeticToEcef(geodeticFromDegrees(lat, lon, h));
    EXPECT_LT((back - s.position).norm(), 1e-3) << p[0] << " " << p[1];
  }
}

TEST(Nmea, SinglePointHasNoDifferentialFields) {
  PositionSolution s = solutionAt(48.0, 11.0, 500.0, SolutionQuality::Single);
  const auto f = parseSentence(nmeaGga(s, NmeaExtras{1.2, 42}, "GP"));
  ASSERT_EQ(f.size(), 15u);
  EXPECT_EQ(f[0], "GPGGA");
  EXPECT_EQ(f[6], "1");
  EXPECT_EQ(f[13], "");
  EXPECT_EQ(f[14], "");
}

TEST(Nmea, InvalidSolution) {
  PositionSolution s;
  s.time = GpsTime::fromCalendar({2023, 6, 15, 0, 0, 18.0});
  const auto f = parseSentence(nmeaGga(s));
  ASSERT_EQ(f.size(), 15u);
  EXPECT_EQ(f[1], "000000.00");
  EXPECT_EQ(f[2], "");
  EXPECT_EQ(f[6], "0");
  const auto r = parseSentence(nmeaRmc(s));
  ASSERT_EQ(r.size(), 14u);
  EXPECT_EQ(r[2], "V");
  EXPECT_EQ(r[9], "150623");
  EXPECT_EQ(r[12], "N");
}

TEST(Nmea, UtcRoundingAndLeapSeconds) {
  PositionSolution s = solutionAt(10.0, 20.0, 0.0, SolutionQuality::Single);
  // 2016-12-31 23:59:59.996 UTC + 17 s (before the 2017 leap second) in GPST: rounds up to
  // hundredths at 23:59:60.00 -> must not print seconds 60.
  s.time = GpsTime::fromCalendar({2017, 1, 1, 0, 0, 16.996});
  const auto f = parseSentence(nmeaGga(s));
  EXPECT_TRUE(f[1] == "235959.99" || f[1] == "000000.00") << f[1];
  EXPECT_NE(f[1].substr(4, 2), "60");
  s.time = GpsTime::fromCalendar({2017, 1, 1, 0, 0, 18.0});  // 18 s after the leap: 00:00:00 UTC
  EXPECT_EQ(parseSentence(nmeaGga(s))[1], "000000.00");
  // Minutes that would round to 60.0000000 carry into the degrees.
  s.position = geodeticToEcef(geodeticFromDegrees(10.0 - 1e-12, 20.0, 0.0));
  const auto g = parseSentence(nmeaGga(s));
  EXPECT_EQ(g[2], "1000.0000000");
}

TEST(Nmea, RmcSpeedCourse) {
  PositionSolution s = solutionAt(45.0, 7.0, 300.0, SolutionQuality::Float);
  const Geodetic g = geodeticFromDegrees(45.0, 7.0, 300.0);
  const Eigen::Matrix3d r = ecefToEnuRotation(g.lat, g.lon);
  // 3 m/s east, 4 m/s north: 5 m/s = 9.719 kn, course atan2(3, 4) = 36.87 deg.
  s.velocity = r.transpose() * Eigen::Vector3d(3.0, 4.0, 0.5);
  const auto f = parseSentence(nmeaRmc(s));
  ASSERT_EQ(f.size(), 14u);
  EXPECT_EQ(f[0], "GNRMC");
  EXPECT_EQ(f[1], "123438.79");
  EXPECT_EQ(f[2], "A");
  EXPECT_NEAR(std::stod(f[7]), 5.0 * 3600.0 / 1852.0, 1e-3);
  EXPECT_NEAR(std::stod(f[8]), std::atan2(3.0, 4.0) * 180.0 / M_PI, 0.01);
  EXPECT_EQ(f[9], "150623");
  EXPECT_EQ(f[12], "F");
  EXPECT_EQ(f[13], "S");
  s.velocity.reset();
  const auto n = parseSentence(nmeaRmc(s));
  EXPECT_EQ(n[7], "");
  EXPECT_EQ(n[8], "");
  // 50 km/s west is still written (97192.0 kn, course 270); a horizontal velocity beyond 99999.999
  // kn is no ground speed: speed and course are left empty, not cut to the field buffer (found by
  // fuzz_nmea_writer: 1e88 m/s gave a 163-character sentence with a truncated number).
  s.velocity = r.transpose() * Eigen::Vector3d(-50000.0, 0.0, 0.0);
  const auto fast = parseSentence(nmeaRmc(s));
  ASSERT_EQ(fast.size(), 14u);
  EXPECT_NEAR(std::stod(fast[7]), 50000.0 * 3600.0 / 1852.0, 1e-3);
  EXPECT_NEAR(std::stod(fast[8]), 270.0, 0.01);
  for (double v : {52000.0, 1e88, 1e300}) {
    s.velocity = r.transpose() * Eigen::Vector3d(v, v, 0.0);
    const std::string sentence = nmeaRmc(s);
    const auto huge = parseSentence(sentence);
    ASSERT_EQ(huge.size(), 14u) << sentence;
    EXPECT_EQ(huge[7], "") << sentence;
    EXPECT_EQ(huge[8], "") << sentence;
    EXPECT_EQ(huge[2], "A");  // the position is still valid
  }
}

TEST(Nmea, WriterWritesBothSentencesPerEpoch) {
  std::ostringstream o;
  NmeaWriter w(o);
  w.write(solutionAt(1.0, 2.0, 3.0, SolutionQuality::Fix));
  w.write(solutionAt(1.0, 2.0, 3.0, SolutionQuality::Single));
  EXPECT_EQ(w.sentences(), 4);
  std::istringstream in(o.str());
  std::string line;
  std::vector<std::string> types;
  while (std::getline(in, line)) types.push_back(line.substr(0, 6));
  EXPECT_EQ(types, (std::vector<std::string>{"$GNGGA", "$GNRMC", "$GNGGA", "$GNRMC"}));
}

TEST(Kml, TrackCoordinatesAndEscaping) {
  std::ostringstream o;
  writeKmlTrack(o, {geodeticFromDegrees(48.5, -11.25, 100.0)}, "a<b & c");
  const std::string k = o.str();
  EXPECT_NE(k.find("<name>a&lt;b &amp; c</name>"), std::string::npos);
  EXPECT_NE(k.find("-11.250000000,48.500000000,100.000"), std::string::npos);
}
