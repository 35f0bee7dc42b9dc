// Niell (1996) hydrostatic and wet tropospheric mapping functions.
#pragma once

#include "gvins/base/geodetic.hpp"

namespace gvins {

struct MappingFactors {
  double hydrostatic = 1.0;
  double wet = 1.0;
};

/// Niell mapping functions (A. E. Niell, "Global mapping functions for the atmosphere delay at
/// radio wavelengths", JGR 101(B2), 1996, tables 3-4 and eq. 4): Marini continued fraction with
/// latitude-interpolated coefficients, the annual term of the hydrostatic coefficients (phase
/// DOY 28, shifted by half a year in the southern hemisphere) and the hydrostatic height
/// correction. `elevation` in radians (values below 1 degree are treated as 1 degree),
/// `dayOfYear` may be fractional.
MappingFactors niellMapping(const Geodetic& station, double elevation, double dayOfYear);

/// The elevation-independent part of niellMapping for one station and day: the continued-fraction
/// coefficients interpolated in latitude (with the annual term) and the height in km. Computed
/// once, it serves every satellite seen from that station (same results as niellMapping).
struct NiellCoefficients {
  double hydrostatic[3] = {0.0, 0.0, 0.0};  ///< a, b, c of the hydrostatic function
  double wet[3] = {0.0, 0.0, 0.0};          ///< a, b, c of the wet function
  double heightKm = 0.0;
};
NiellCoefficients niellCoefficients(const Geodetic& station, double dayOfYear);
/// niellMapping from precomputed coefficients.
MappingFactors niellMapping(const NiellCoefficients& coefficients, double elevation);

/// The Marini (1972) continued fraction normalised to 1 at zenith, as used by Niell.
double mariniContinuedFraction(double sinElevation, double a, double b, double c);

}  // namespace gvins
