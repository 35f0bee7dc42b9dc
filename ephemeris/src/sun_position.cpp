#include "gvins/ephemeris/sun_position.hpp"

#include <cmath>

namespace gvins {

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kDeg = kPi / 180.0;
constexpr double kArcsec = kDeg / 3600.0;
constexpr double kMjdGpsEpoch = 44244.0;  // 1980-01-06 00:00
constexpr double kMjdJ2000 = 51544.5;     // 2000-01-01 12:00

/// Days since J2000 of a GPST instant shifted by `offset` seconds (e.g. to TT or UTC).
double daysSinceJ2000(const GpsTime& t, double offset) {
  const double days = static_cast<double>(t.wholeSeconds()) / 86400.0 + (t.fraction() + offset) / 86400.0;
  return kMjdGpsEpoch + days - kMjdJ2000;
}

}  // namespace

double greenwichMeanSiderealTime(const GpsTime& t) {
  // IAU 1982 GMST as a function of UT1 (here UTC = GPST - leap seconds):
  // GMST = 280.46061837 deg + 360.98564736629 deg d + 0.000387933 deg T² - T³/38710000 deg.
  const double d = daysSinceJ2000(t, -static_cast<double>(leapSecondsAtGpst(t)));
  const double T = d / 36525.0;
  double g = std::fmod(280.46061837 + 360.98564736629 * d + T * T * (0.000387933 - T / 38710000.0), 360.0);
  if (g < 0.0) g += 360.0;
  return g * kDeg;
}

Eigen::Vector3d sunPositionEcef(const GpsTime& t) {
  // Terrestrial time: TT = GPST + 51.184 s (TAI - GPST = 19 s, TT - TAI = 32.184 s).
  const double T = daysSinceJ2000(t, 51.184) / 36525.0;
  const double M = (357.5256 + 35999.049 * T) * kDeg;
  const double lambda = (282.9400 + 1.3972 * T) * kDeg + M + 6892.0 * kArcsec * std::sin(M) +
                        72.0 * kArcsec * std::sin(2.0 * M);
  const double r = (149.619 - 2.499 * std::cos(M) - 0.021 * std::cos(2.0 * M)) * 1e9;  // m
  const double eps = 23.43929111 * kDeg;
  const Eigen::Vector3d eq(r * std::cos(lambda), r * std::sin(lambda) * std::cos(eps), r * std::sin(lambda) * std::sin(eps));
  const double g = greenwichMeanSiderealTime(t);
  const double c = std::cos(g), s = std::sin(g);
  return Eigen::Vector3d(c * eq.x() + s * eq.y(), -s * eq.x() + c * eq.y(), eq.z());
}

}  // namespace gvins
