#include "gvins/gnss/nmea_writer.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <optional>
#include <ostream>

#include "gvins/base/constants.hpp"
#include "gvins/base/geodetic.hpp"
#include "gvins/base/gnss_time.hpp"
#include "gvins/base/local_frame.hpp"

namespace gvins {

namespace {

constexpr double kKnotsPerMps = 3600.0 / 1852.0;  // 1 international nautical mile = 1852 m
// Largest speed over ground written (knots, 51 km/s): a larger horizontal velocity is no ground
// speed, and its digits would overflow the field; speed and course are then left empty.
constexpr double kMaxSpeedKnots = 99999.999;

/// UTC of a GPST instant rounded to hundredths of a second (rounded before the calendar split so
/// that seconds never read 60).
CalendarTime utcHundredths(const GpsTime& t) {
  const double frac = std::round(t.fraction() * 100.0) / 100.0;
  CalendarTime c = gpstToUtc(GpsTime::fromSeconds(t.wholeSeconds(), frac));
  c.second = std::round(c.second * 100.0) / 100.0;
  if (c.second >= 60.0) c.second = 59.99;  // only reachable through float noise
  return c;
}

void appendTime(std::string& s, const CalendarTime& c) {
  char b[32];
  std::snprintf(b, sizeof b, "%02d%02d%05.2f", c.hour, c.minute, c.second);
  s += b;
}

/// "ddmm.mmmmmmm,N" (digits = 2) or "dddmm.mmmmmmm,E" (digits = 3).
void appendAngle(std::string& s, double deg, int digits, char pos, char neg) {
  const char hemi = deg < 0.0 ? neg : pos;
  double a = std::fabs(deg);
  // Round to the written resolution first so that minutes never read 60.
  constexpr double kScale = 1e7;
  double minutesTotal = std::round(a * 60.0 * kScale) / kScale;
  int d = static_cast<int>(std::floor(minutesTotal / 60.0));
  double m = minutesTotal - 60.0 * d;
  if (m < 0.0) m = 0.0;
  if (m >= 60.0) {
    m -= 60.0;
    ++d;
  }
  char b[48];
  std::snprintf(b, sizeof b, "%0*d%010.7f,%c", digits, d, m, hemi);
  s += b;
}

/// A position that has a meaning on or above the Earth (within 1e9 m of its centre: any orbit).
bool usable(const PositionSolution& s) {
  return s.quality != SolutionQuality::None && s.position.allFinite() && s.position.norm() >= 1.0 && s.position.norm() < 1e9;
}

bool differential(SolutionQuality q) {
  return q == SolutionQuality::Fix || q == SolutionQuality::Float || q == SolutionQuality::Dgps ||
         q == SolutionQuality::Sbas;
}

}  // namespace

unsigned nmeaChecksum(std::string_view body) {
  unsigned c = 0;
  for (const char ch : body) c ^= static_cast<unsigned char>(ch);
  return c;
}

std::string nmeaSentence(std::string_view body) {
  char tail[8];
  std::snprintf(tail, sizeof tail, "*%02X\r\n", nmeaChecksum(body));
  std::string s = "$";
  s += body;
  s += tail;
  return s;
}

int nmeaGgaQuality(SolutionQuality q) {
  switch (q) {
    case SolutionQuality::Fix: return 4;
    case SolutionQuality::Float: return 5;
    case SolutionQuality::Ppp: return 5;
    case SolutionQuality::Dgps: return 2;
    case SolutionQuality::Sbas: return 2;
    case SolutionQuality::Single: return 1;
    default: return 0;
  }
}

char nmeaModeIndicator(SolutionQuality q) {
  switch (q) {
    case SolutionQuality::Fix: return 'R';
    case SolutionQuality::Float: return 'F';
    case SolutionQuality::Ppp: return 'F';
    case SolutionQuality::Dgps: return 'D';
    case SolutionQuality::Sbas: return 'D';
    case SolutionQuality::Single: return 'A';
    default: return 'N';
  }
}

std::string nmeaGga(const PositionSolution& s, const NmeaExtras& extras, std::string_view talker) {
  std::string b(talker);
  b += "GGA,";
  appendTime(b, utcHundredths(s.time));
  const int q = nmeaGgaQuality(s.quality);
  char f[96];
  if (q == 0 || !usable(s)) {
    b += ",,,,,0,00,,,,,,,";
    return nmeaSentence(b);
  }
  const Geodetic g = ecefToGeodetic(s.position);
  b += ',';
  appendAngle(b, g.lat * constants::kRadToDeg, 2, 'N', 'S');
  b += ',';
  appendAngle(b, g.lon * constants::kRadToDeg, 3, 'E', 'W');
  std::snprintf(f, sizeof f, ",%d,%02d,", q, std::clamp(s.numSatellites, 0, 99));
  b += f;
  if (extras.hdop && std::isfinite(*extras.hdop)) {
    std::snprintf(f, sizeof f, "%.1f", std::clamp(*extras.hdop, 0.0, 99.9));
    b += f;
  }
  std::snprintf(f, sizeof f, ",%.4f,M,0.0,M,", g.height);
  b += f;
  if (differential(s.quality) && s.age >= 0.0 && std::isfinite(s.age)) {
    std::snprintf(f, sizeof f, "%.1f,", std::min(s.age, 999.9));
    b += f;
    if (extras.stationId && *extras.stationId >= 0 && *extras.stationId <= 1023) {
      std::snprintf(f, sizeof f, "%04d", *extras.stationId);
      b += f;
    }
  } else {
    b += ',';
  }
  return nmeaSentence(b);
}

std::string nmeaRmc(const PositionSolution& s, std::string_view talker) {
  std::string b(talker);
  b += "RMC,";
  const CalendarTime c = utcHundredths(s.time);
  appendTime(b, c);
  const bool valid = usable(s);
  char f[96];
  if (!valid) {
    std::snprintf(f, sizeof f, ",V,,,,,,,%02d%02d%02d,,,N,V", c.day, c.month, c.year % 100);
    b += f;
    return nmeaSentence(b);
  }
  const Geodetic g = ecefToGeodetic(s.position);
  b += ",A,";
  appendAngle(b, g.lat * constants::kRadToDeg, 2, 'N', 'S');
  b += ',';
  appendAngle(b, g.lon * constants::kRadToDeg, 3, 'E', 'W');
  b += ',';
  std::optional<Eigen::Vector3d> enu;
  if (s.velocity && s.velocity->allFinite()) enu = ecefToEnuRotation(g.lat, g.lon) * *s.velocity;
  const double knots = enu ? std::hypot((*enu)[0], (*enu)[1]) * kKnotsPerMps : 0.0;
  if (enu && knots <= kMaxSpeedKnots) {  // false for NaN too
    double course = std::atan2((*enu)[0], (*enu)[1]) * constants::kRadToDeg;
    if (course < 0.0) course += 360.0;
    std::snprintf(f, sizeof f, "%.3f,%.2f", knots, course >= 359.995 ? 0.0 : course);
    b += f;
  } else {
    b += ',';
  }
  std::snprintf(f, sizeof f, ",%02d%02d%02d,,,%c,S", c.day, c.month, c.year % 100, nmeaModeIndicator(s.quality));
  b += f;
  return nmeaSentence(b);
}

NmeaWriter::NmeaWriter(std::ostream& out, NmeaOptions options) : out_(out), opt_(std::move(options)) {}

void NmeaWriter::write(const PositionSolution& s, const NmeaExtras& extras) {
  if (opt_.gga) {
    out_ << nmeaGga(s, extras, opt_.talker);
    ++sentences_;
  }
  if (opt_.rmc) {
    out_ << nmeaRmc(s, opt_.talker);
    ++sentences_;
  }
  out_.flush();
}

}  // namespace gvins
