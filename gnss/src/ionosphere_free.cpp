#include "gvins/gnss/ionosphere_free.hpp"

#include <cmath>

namespace gvins {

IonosphereFreeCoefficients ionosphereFreeCoefficients(double f1, double f2) {
  const double d = f1 * f1 - f2 * f2;
  return {f1 * f1 / d, -f2 * f2 / d};
}

double IonosphereFreeCoefficients::noiseFactor() const { return std::sqrt(a1 * a1 + a2 * a2); }

double ionosphereFree(double p1, double p2, double f1, double f2) {
  const auto c = ionosphereFreeCoefficients(f1, f2);
  return c.a1 * p1 + c.a2 * p2;
}

}  // namespace gvins
