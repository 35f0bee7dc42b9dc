#include "gvins/gnss/chi_square.hpp"

#include <cmath>
#include <limits>

namespace gvins {

namespace {
/// Regularised lower incomplete gamma P(a, x): series for x < a + 1, continued fraction otherwise
/// (Abramowitz & Stegun 6.5.29 and 6.5.31; Lentz's method for the fraction).
double lowerGammaP(double a, double x) {
  if (x <= 0.0) return 0.0;
  const double lnPrefix = a * std::log(x) - x - std::lgamma(a);
  if (x < a + 1.0) {
    double term = 1.0 / a, sum = term;
    for (int n = 1; n < 1000; ++n) {
      term *= x / (a + n);
      sum += term;
      if (std::abs(term) < std::abs(sum) * 1e-16) break;
    }
    return std::exp(lnPrefix) * sum;
  }
  constexpr double kTiny = 1e-300;
  double b = x + 1.0 - a, c = 1.0 / kTiny, d = 1.0 / b, h = d;
  for (int i = 1; i < 1000; ++i) {
    const double an = -i * (i - a);
    b += 2.0;
    d = an * d + b;
    if (std::abs(d) < kTiny) d = kTiny;
    c = b + an / c;
    if (std::abs(c) < kTiny) c = kTiny;
    d = 1.0 / d;
    const double del = d * c;
    h *= del;
    if (std::abs(del - 1.0) < 1e-16) break;
  }
  return 1.0 - std::exp(lnPrefix) * h;
}
}  // namespace

double chiSquareCdf(double x, int dof) {
  if (dof < 1) return std::numeric_limits<double>::quiet_NaN();
  return lowerGammaP(0.5 * dof, 0.5 * x);
}

double chiSquareQuantile(double p, int dof) {
  if (dof < 1 || !(p > 0.0 && p < 1.0)) return std::numeric_limits<double>::quiet_NaN();
  // Bracket, then bisection (the CDF is monotone); 200 halvings reach double resolution.
  double lo = 0.0, hi = std::max(1.0, static_cast<double>(dof));
  while (chiSquareCdf(hi, dof) < p) hi *= 2.0;
  for (int i = 0; i < 200 && hi - lo > 1e-12 * hi; ++i) {
    const double mid = 0.5 * (lo + hi);
    (chiSquareCdf(mid, dof) < p ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

}  // namespace gvins
