#include "gvins/sri/chi_square.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace gvins::sri {

namespace {

/// Regularized lower incomplete gamma P(a, x), a > 0, x ≥ 0.
double lowerGammaP(double a, double x) {
  if (x <= 0) return 0.0;
  const double logPrefix = a * std::log(x) - x - std::lgamma(a);
  if (x < a + 1.0) {
    // P(a, x) = e^{−x} x^a / Γ(a+1) · Σ_{n≥0} x^n / ((a+1)(a+2)⋯(a+n))   (A&S 6.5.29)
    double term = 1.0 / a;
    double sum = term;
    for (int n = 1; n < 1000; ++n) {
      term *= x / (a + n);
      sum += term;
      if (std::abs(term) < std::abs(sum) * 1e-17) break;
    }
    return std::min(1.0, std::exp(logPrefix) * sum);
  }
  // Q(a, x) = e^{−x} x^a / Γ(a) · 1/(x+1−a− 1·(1−a)/(x+3−a− 2·(2−a)/(x+5−a− …)))
  // (A&S 6.5.31), evaluated by the modified Lentz method.
  constexpr double kTiny = 1e-300;
  double b = x + 1.0 - a;
  double c = 1.0 / kTiny;
  double d = 1.0 / b;
  double h = d;
  for (int i = 1; i < 1000; ++i) {
    const double an = -i * (i - a);
    b += 2.0;
    d = an * d + b;
    if (std::abs(d) < kTiny) d = kTiny;
    c = b + an / c;
    if (std::abs(c) < kTiny) c = kTiny;
    d = 1.0 / d;
    const double delta = d * c;
    h *= delta;
    if (std::abs(delta - 1.0) < 1e-16) break;
  }
  return std::max(0.0, 1.0 - std::exp(logPrefix) * h);
}

}  // namespace

double chiSquareCdf(double x, int dof) {
  if (dof < 1) throw std::invalid_argument("chiSquareCdf: dof must be ≥ 1");
  return lowerGammaP(0.5 * dof, 0.5 * x);
}

double ChiSquareQuantiles::operator()(double p, int dof) {
  if (dof < 1) return chiSquareQuantile(p, dof);  // throws
  if (p != p_) {
    p_ = p;
    q_.clear();
  }
  if (static_cast<std::size_t>(dof) >= q_.size()) q_.resize(static_cast<std::size_t>(dof) + 1, 0.0);
  double& q = q_[static_cast<std::size_t>(dof)];
  if (q == 0.0) q = chiSquareQuantile(p, dof);  // throws for p outside (0, 1)
  return q;
}

double chiSquareQuantile(double p, int dof) {
  if (dof < 1 || !(p > 0.0 && p < 1.0)) {
    throw std::invalid_argument("chiSquareQuantile: need 0 < p < 1 and dof ≥ 1");
  }
  const double k = dof;
  // Bracket [lo, hi] with F(lo) ≤ p ≤ F(hi).
  double lo = 0.0;
  double hi = std::max(1.0, k);
  while (chiSquareCdf(hi, dof) < p) {
    lo = hi;
    hi *= 2.0;
  }
  double x = 0.5 * (lo + hi);
  const double logNorm = 0.5 * k * std::log(2.0) + std::lgamma(0.5 * k);
  for (int it = 0; it < 200; ++it) {
    const double f = chiSquareCdf(x, dof) - p;
    if (f < 0) lo = x; else hi = x;
    // Density of χ²(k): x^{k/2−1} e^{−x/2} / (2^{k/2} Γ(k/2)).
    const double pdf = std::exp((0.5 * k - 1.0) * std::log(x) - 0.5 * x - logNorm);
    double next = x - f / pdf;
    if (!(next > lo && next < hi) || !std::isfinite(next)) next = 0.5 * (lo + hi);  // bisect
    if (std::abs(next - x) <= 1e-13 * x || hi - lo <= 1e-13 * hi) return next;
    x = next;
  }
  return x;
}

}  // namespace gvins::sri
