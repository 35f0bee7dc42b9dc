// Measurement standard deviations of pseudoranges and Doppler range rates as functions of
// elevation and carrier-to-noise density.
#pragma once

#include <array>

#include "gvins/base/satellite.hpp"

namespace gvins {

enum class WeightingScheme {
  Elevation,     ///< sigma^2 = f_sys^2 (a^2 + b^2 / sin^2 el)
  Snr,           ///< sigma^2 = f_sys^2 (a^2 + b^2) 10^((C0 - C/N0) / 10)
  ElevationSnr,  ///< sigma^2 = f_sys^2 (a^2 10^((C0 - C/N0) / 10) + b^2 / sin^2 el)
};

/// The elevation model is the common "a + b / sin(el)" form in variance (e.g. Eueler & Goad 1991,
/// Bull. Geod. 65); the C/N0 model follows the SIGMA-epsilon idea of Hartinger & Brunner (1999,
/// GPS Solutions 2(4)): variance proportional to 10^(-C/N0 / 10), here normalised to equal a^2 + b^2
/// at the reference C/N0 C0. Without a C/N0 value the C/N0 schemes fall back to the elevation model.
struct MeasurementWeighting {
  WeightingScheme scheme = WeightingScheme::Elevation;
  double a = 0.3;                ///< m, elevation-independent part (pseudorange)
  double b = 0.3;                ///< m, elevation-dependent part (pseudorange)
  double snrReference = 45.0;    ///< dB-Hz, C0
  double dopplerSigma = 0.05;    ///< m/s, range-rate sigma at zenith / reference C/N0
  /// Per-system factor f_sys (index systemIndex): GLONASS FDMA codes and SBAS are noisier.
  std::array<double, kNumSystems> systemFactor{1.0, 1.5, 1.0, 1.0, 1.0, 3.0, 1.5};

  /// The model of one zenith sigma (m, at the reference C/N0) split evenly between the two parts,
  /// a = b = sigma / sqrt(2) (Elevation: sigma^2 (1/2 + 1/2 / sin^2 el)), without system factors
  /// (for users that carry the system's part elsewhere, e.g. in the ephemeris error).
  static MeasurementWeighting evenSplit(WeightingScheme scheme, double sigma);
  /// Pseudorange variance (m^2) for a system, elevation (rad) and C/N0 (dB-Hz, <= 0: unknown).
  double codeVariance(System sys, double elevation, double snr) const;
  /// Variance (m^2) of the combination a1 P1 + a2 P2 of two pseudoranges of one satellite with
  /// independent errors (e.g. the ionosphere-free one, ionosphere_free.hpp), each weighted by this
  /// model with its own C/N0: a1^2 var(P1) + a2^2 var(P2). For L1/L2 that is (2.55^2 + 1.55^2) =
  /// 8.9 times one code's variance when both are equal, more when the second is weaker.
  double combinationCodeVariance(System sys, double elevation, double a1, double snr1, double a2, double snr2) const;
  /// Range-rate variance ((m/s)^2) from Doppler, same shape with dopplerSigma for sqrt(a^2+b^2).
  double dopplerVariance(System sys, double elevation, double snr) const;
};

}  // namespace gvins
