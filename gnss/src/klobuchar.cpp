#include "gvins/gnss/klobuchar.hpp"

#include <algorithm>
#include <cmath>

#include "gvins/base/constants.hpp"

namespace gvins {

namespace {
constexpr double kPiIcd = constants::kPi;  // semicircle conversion as prescribed by the ICDs
}

double klobucharObliquity(double elevation) {
  const double e = elevation / kPiIcd;
  const double d = 0.53 - e;
  return 1.0 + 16.0 * d * d * d;  // (0.53 - E)^3, IS-GPS-200N 20.3.3.5.2.5
}

double klobucharDelayL1(const KlobucharParameters& p, const Geodetic& rx, const AzEl& azel, const GpsTime& t) {
  return klobucharDelayL1(p, rx, azel, t, klobucharObliquity(azel.elevation));
}

double klobucharDelayL1(const KlobucharParameters& p, const Geodetic& rx, const AzEl& azel, const GpsTime& t,
                        double obliquity) {
  // IS-GPS-200N figure 20-4; angles in semicircles.
  const double e = azel.elevation / kPiIcd;
  const double phiU = rx.lat / kPiIcd;
  const double lamU = rx.lon / kPiIcd;
  const double psi = 0.0137 / (e + 0.11) - 0.022;  // Earth-centred angle
  double phiI = phiU + psi * std::cos(azel.azimuth);
  phiI = std::clamp(phiI, -0.416, 0.416);
  const double lamI = lamU + psi * std::sin(azel.azimuth) / std::cos(phiI * kPiIcd);
  const double phiM = phiI + 0.064 * std::cos((lamI - 1.617) * kPiIcd);  // geomagnetic latitude
  double tLocal = 4.32e4 * lamI + t.tow();
  tLocal = std::fmod(tLocal, 86400.0);
  if (tLocal < 0.0) tLocal += 86400.0;
  const double f = obliquity;
  double amp = 0.0, per = 0.0, pm = 1.0;
  for (int n = 0; n < 4; ++n) {
    amp += p.alpha[n] * pm;
    per += p.beta[n] * pm;
    pm *= phiM;
  }
  amp = std::max(amp, 0.0);
  per = std::max(per, 72000.0);
  const double x = 2.0 * kPiIcd * (tLocal - 50400.0) / per;
  double delay = 5.0e-9;
  if (std::abs(x) < 1.57) delay += amp * (1.0 - x * x / 2.0 + x * x * x * x / 24.0);
  return constants::kSpeedOfLight * f * delay;
}

double beidouKlobucharDelayB1I(const KlobucharParameters& p, const Geodetic& rx, const AzEl& azel,
                               const GpsTime& t) {
  // BDS-SIS-ICD-B1I 3.0, 5.2.4.7: thin shell at 375 km above a sphere of radius 6378 km.
  constexpr double kR = 6378.0, kH = 375.0;
  const double e = azel.elevation;
  const double cosE = std::cos(e);
  const double psi = 0.5 * kPiIcd - e - std::asin(kR / (kR + kH) * cosE);  // rad
  const double phiM = std::asin(std::sin(rx.lat) * std::cos(psi) + std::cos(rx.lat) * std::sin(psi) * std::cos(azel.azimuth));
  const double lamM = rx.lon + std::asin(std::sin(psi) * std::sin(azel.azimuth) / std::cos(phiM));
  // Local time at the pierce point from BDT seconds of day.
  int week;
  double bdtTow;
  gpstToBdt(t, week, bdtTow);
  double tLocal = std::fmod(bdtTow, 86400.0) + lamM * 43200.0 / kPiIcd;
  tLocal = std::fmod(tLocal, 86400.0);
  if (tLocal < 0.0) tLocal += 86400.0;
  const double phi = std::abs(phiM / kPiIcd);  // semicircles
  double a2 = 0.0, a4 = 0.0, pm = 1.0;
  for (int n = 0; n < 4; ++n) {
    a2 += p.alpha[n] * pm;
    a4 += p.beta[n] * pm;
    pm *= phi;
  }
  a2 = std::max(a2, 0.0);
  a4 = std::clamp(a4, 72000.0, 172800.0);
  double iz = 5.0e-9;
  if (std::abs(tLocal - 50400.0) < a4 / 4.0) iz += a2 * std::cos(2.0 * kPiIcd * (tLocal - 50400.0) / a4);
  const double k = kR / (kR + kH) * cosE;
  return constants::kSpeedOfLight * iz / std::sqrt(1.0 - k * k);
}

double ionosphereFrequencyScale(double referenceFrequency, double frequency) {
  const double r = referenceFrequency / frequency;
  return r * r;
}

}  // namespace gvins
