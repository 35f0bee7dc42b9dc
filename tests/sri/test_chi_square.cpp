// Chi-square CDF and quantile against closed forms (dof 1–4) and numerical integration of the
// density (large dof).
#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

#include "gvins/sri/chi_square.hpp"

namespace gvins::sri {
namespace {

constexpr double kPi = 3.14159265358979323846;

double closedFormCdf(double x, int k) {
  switch (k) {
    case 1: return std::erf(std::sqrt(x / 2));
    case 2: return 1 - std::exp(-x / 2);
    case 3: return std::erf(std::sqrt(x / 2)) - std::sqrt(2 * x / kPi) * std::exp(-x / 2);
    case 4: return 1 - std::exp(-x / 2) * (1 + x / 2);
  }
  return -1;
}

/// ∫₀ˣ density by composite Simpson on a fine grid.
double integratedCdf(double x, int k) {
  const double logNorm = 0.5 * k * std::log(2.0) + std::lgamma(0.5 * k);
  auto pdf = [&](double t) { return t <= 0 ? 0.0 : std::exp((0.5 * k - 1) * std::log(t) - t / 2 - logNorm); };
  const int n = 200000;
  const double h = x / n;
  double s = pdf(0) + pdf(x);
  for (int i = 1; i < n; ++i) s += (i % 2 ? 4 : 2) * pdf(i * h);
  return s * h / 3;
}

TEST(ChiSquare, CdfClosedFormsAndIntegration) {
  for (int k = 1; k <= 4; ++k) {
    for (double x : {1e-3, 0.1, 0.5, 1.0, 2.5, 5.0, 7.8, 12.0, 30.0, 80.0}) {
      EXPECT_NEAR(chiSquareCdf(x, k), closedFormCdf(x, k), 1e-13) << k << " " << x;
    }
  }
  for (int k : {6, 15, 60, 200}) {
    for (double f : {0.5, 0.9, 1.0, 1.2, 1.6}) {
      const double x = f * k;
      EXPECT_NEAR(chiSquareCdf(x, k), integratedCdf(x, k), 1e-9) << k << " " << x;
    }
  }
  EXPECT_EQ(chiSquareCdf(0.0, 3), 0.0);
  EXPECT_EQ(chiSquareCdf(-1.0, 3), 0.0);
}

TEST(ChiSquare, QuantileInvertsTheCdf) {
  for (double p : {0.5, 0.9, 0.95, 0.99, 0.999}) {
    EXPECT_NEAR(chiSquareQuantile(p, 2), -2 * std::log(1 - p), 1e-11);  // closed form
    for (int k : {1, 3, 4, 6, 10, 37, 120, 400}) {
      const double q = chiSquareQuantile(p, k);
      EXPECT_NEAR(chiSquareCdf(q, k), p, 1e-12) << k << " " << p;
    }
  }
  // 95 % for one dof is the square of the 97.5 % normal quantile (1.959963984540054).
  EXPECT_NEAR(chiSquareQuantile(0.95, 1), 1.959963984540054 * 1.959963984540054, 1e-10);
  EXPECT_THROW(chiSquareQuantile(1.0, 3), std::invalid_argument);
  EXPECT_THROW(chiSquareQuantile(0.5, 0), std::invalid_argument);
}

TEST(ChiSquare, QuantilesMatchPublishedTables) {
  // NIST/SEMATECH e-Handbook of Statistical Methods, table 1.3.6.7.4 (upper critical values).
  EXPECT_NEAR(chiSquareQuantile(0.95, 5), 11.070, 1e-3);
  EXPECT_NEAR(chiSquareQuantile(0.99, 10), 23.209, 1e-3);
  EXPECT_NEAR(chiSquareQuantile(0.999, 1), 10.828, 1e-3);
  EXPECT_NEAR(chiSquareQuantile(0.999, 20), 45.315, 1e-3);
  EXPECT_NEAR(chiSquareQuantile(0.999, 100), 149.449, 1e-3);
  EXPECT_NEAR(chiSquareCdf(2.0, 2), 1.0 - std::exp(-1.0), 1e-14);  // exponential with mean 2
}

// ChiSquareQuantiles (the gates' table): the values of chiSquareQuantile whatever the order of
// the dofs asked for and across changes of the probability; the same errors.
TEST(ChiSquare, QuantileTableGivesTheDirectValues) {
  ChiSquareQuantiles t;
  for (const double p : {0.99, 0.999, 0.99}) {
    for (const int dof : {5, 1, 40, 5, 2, 40}) EXPECT_EQ(t(p, dof), chiSquareQuantile(p, dof)) << p << " " << dof;
  }
  EXPECT_THROW(t(0.99, 0), std::invalid_argument);
  EXPECT_THROW(t(1.0, 3), std::invalid_argument);
  EXPECT_EQ(t(0.95, 3), chiSquareQuantile(0.95, 3));  // usable after the errors
}

}  // namespace
}  // namespace gvins::sri
