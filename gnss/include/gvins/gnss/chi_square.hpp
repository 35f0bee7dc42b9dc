// Chi-square distribution: CDF and quantiles for residual tests.
#pragma once

namespace gvins {

/// P(X <= x) for X ~ chi-square with `dof` degrees of freedom (regularised lower incomplete gamma
/// function P(dof/2, x/2), series/continued fraction as in Abramowitz & Stegun 6.5.29 / 6.5.31).
double chiSquareCdf(double x, int dof);

/// x such that chiSquareCdf(x, dof) = p, 0 < p < 1 (bisection/Newton on the CDF, relative accuracy
/// 1e-10). dof >= 1.
double chiSquareQuantile(double p, int dof);

}  // namespace gvins
