#include "gvins/gnss/niell_mapping.hpp"

#include <algorithm>
#include <cmath>

#include "gvins/base/constants.hpp"

namespace gvins {

namespace {
// Niell (1996), table 3 (hydrostatic: average and amplitude) and table 4 (wet), at latitudes
// 15, 30, 45, 60, 75 degrees; height correction coefficients from the same paper.
constexpr double kLat[5] = {15.0, 30.0, 45.0, 60.0, 75.0};
constexpr double kHydAvg[3][5] = {
    {1.2769934e-3, 1.2683230e-3, 1.2465397e-3, 1.2196049e-3, 1.2045996e-3},
    {2.9153695e-3, 2.9152299e-3, 2.9288445e-3, 2.9022565e-3, 2.9024912e-3},
    {62.610505e-3, 62.837393e-3, 63.721774e-3, 63.824265e-3, 64.258455e-3}};
constexpr double kHydAmp[3][5] = {
    {0.0, 1.2709626e-5, 2.6523662e-5, 3.4000452e-5, 4.1202191e-5},
    {0.0, 2.1414979e-5, 3.0160779e-5, 7.2562722e-5, 11.723375e-5},
    {0.0, 9.0128400e-5, 4.3497037e-5, 84.795348e-5, 170.37206e-5}};
constexpr double kWet[3][5] = {
    {5.8021897e-4, 5.6794847e-4, 5.8118019e-4, 5.9727542e-4, 6.1641693e-4},
    {1.4275268e-3, 1.5138625e-3, 1.4572752e-3, 1.5007428e-3, 1.7599082e-3},
    {4.3472961e-2, 4.6729510e-2, 4.3908931e-2, 4.4626982e-2, 5.4736038e-2}};
constexpr double kAht = 2.53e-5, kBht = 5.49e-3, kCht = 1.14e-3;

/// Linear interpolation in |latitude| (deg), constant outside 15..75.
double interpolate(const double (&v)[5], double absLatDeg) {
  if (absLatDeg <= kLat[0]) return v[0];
  if (absLatDeg >= kLat[4]) return v[4];
  const int i = std::min(3, static_cast<int>((absLatDeg - 15.0) / 15.0));
  const double f = (absLatDeg - kLat[i]) / 15.0;
  return v[i] + f * (v[i + 1] - v[i]);
}
}  // namespace

double mariniContinuedFraction(double s, double a, double b, double c) {
  const double top = 1.0 + a / (1.0 + b / (1.0 + c));
  const double bottom = s + a / (s + b / (s + c));
  return top / bottom;
}

NiellCoefficients niellCoefficients(const Geodetic& station, double dayOfYear) {
  const double absLat = std::abs(station.lat) * constants::kRadToDeg;
  // Annual term referred to DOY 28; the southern hemisphere is half a year out of phase.
  double doy = dayOfYear - 28.0;
  if (station.lat < 0.0) doy += 365.25 / 2.0;
  const double season = std::cos(2.0 * 3.14159265358979323846 * doy / 365.25);
  NiellCoefficients c;
  for (int k = 0; k < 3; ++k) {
    c.hydrostatic[k] = interpolate(kHydAvg[k], absLat) - interpolate(kHydAmp[k], absLat) * season;
    c.wet[k] = interpolate(kWet[k], absLat);
  }
  c.heightKm = station.height / 1000.0;
  return c;
}

MappingFactors niellMapping(const NiellCoefficients& c, double elevation) {
  const double el = std::max(elevation, 1.0 * constants::kDegToRad);
  const double s = std::sin(el);
  MappingFactors m;
  const double dm = (1.0 / s - mariniContinuedFraction(s, kAht, kBht, kCht)) * c.heightKm;
  m.hydrostatic = mariniContinuedFraction(s, c.hydrostatic[0], c.hydrostatic[1], c.hydrostatic[2]) + dm;
  m.wet = mariniContinuedFraction(s, c.wet[0], c.wet[1], c.wet[2]);
  return m;
}

MappingFactors niellMapping(const Geodetic& station, double elevation, double dayOfYear) {
  return niellMapping(niellCoefficients(station, dayOfYear), elevation);
}

}  // namespace gvins
