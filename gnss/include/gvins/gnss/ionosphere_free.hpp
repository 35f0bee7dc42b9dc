// Dual-frequency ionosphere-free combination of pseudoranges.
#pragma once

namespace gvins {

/// Coefficients (a1, a2) with a1 + a2 = 1 that remove the first-order ionospheric delay:
/// a1 = f1^2 / (f1^2 - f2^2), a2 = -f2^2 / (f1^2 - f2^2) (e.g. IS-GPS-200N 20.3.3.3.3.3).
struct IonosphereFreeCoefficients {
  double a1 = 1.0;
  double a2 = 0.0;
  /// Standard deviation amplification for independent equal noise on both: sqrt(a1^2 + a2^2).
  double noiseFactor() const;
};
IonosphereFreeCoefficients ionosphereFreeCoefficients(double f1, double f2);

/// a1 * p1 + a2 * p2.
double ionosphereFree(double p1, double p2, double f1, double f2);

}  // namespace gvins
