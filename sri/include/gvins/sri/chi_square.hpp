// Chi-square distribution function and quantiles, for gating measurements with
// SriFilter::chiSquare (e.g. accept if χ² < chiSquareQuantile(0.99, dof)).
#pragma once

#include <vector>

namespace gvins::sri {

/// P(X ≤ x) for X ~ χ²(dof): the regularized lower incomplete gamma function P(dof/2, x/2),
/// by its series for x < dof/2 + 1 and by the continued fraction of the complement otherwise
/// (Abramowitz & Stegun 6.5.29 and 6.5.31). dof ≥ 1; 0 for x ≤ 0.
double chiSquareCdf(double x, int dof);

/// x with P(X ≤ x) = p for X ~ χ²(dof), 0 < p < 1 (safeguarded Newton iteration on the CDF,
/// relative accuracy ~1e-12). Throws std::invalid_argument for p outside (0, 1) or dof < 1.
double chiSquareQuantile(double p, int dof);

/// chiSquareQuantile(p, dof) computed once per dof (each costs ~100 CDF evaluations), for gates
/// whose probability changes rarely: a new p starts the table again. Same values and errors as
/// chiSquareQuantile.
class ChiSquareQuantiles {
 public:
  double operator()(double p, int dof);

 private:
  double p_ = -1.0;
  std::vector<double> q_;  // by dof; 0: not computed yet (every quantile is > 0)
};

}  // namespace gvins::sri
