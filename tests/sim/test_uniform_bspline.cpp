// Uniform septic B-spline: partition of unity, reproduction of straight lines, derivatives
// against finite differences, rest where the control points coincide, C^6 continuity at knots.
#include <gtest/gtest.h>

#include <cmath>

#include "gvins/sim/uniform_bspline.hpp"

namespace gvins::sim {
namespace {

using V3 = Eigen::Vector3d;

std::vector<V3> randomControls(int n, unsigned seed) {
  std::srand(seed);
  std::vector<V3> c;
  for (int i = 0; i < n; ++i) c.push_back(V3::Random() * 10.0);
  return c;
}

TEST(UniformBSpline, ConstantControlsGiveConstantCurve) {
  UniformBSpline<3> s(0.0, 0.3, std::vector<V3>(12, V3(1.5, -2.0, 7.0)));
  V3 d[5];
  for (double t = -1.0; t < 5.0; t += 0.0371) {
    s.evaluate(t, 4, d);
    EXPECT_NEAR((d[0] - V3(1.5, -2.0, 7.0)).norm(), 0.0, 1e-13);
    for (int k = 1; k <= 4; ++k) EXPECT_NEAR(d[k].norm(), 0.0, 1e-9) << k;
  }
}

TEST(UniformBSpline, ReproducesStraightLinesAtConstantSpeed) {
  // Centred B-splines reproduce linear functions: c_i = a + b t_i  =>  p(t) = a + b t.
  const double dt = 0.25, t0 = 1.0;
  const V3 a(3, -1, 2), b(8, 0.5, -1.5);
  std::vector<V3> c;
  for (int i = 0; i < 40; ++i) c.push_back(a + b * (t0 + i * dt));
  UniformBSpline<3> s(t0, dt, c);
  V3 d[5];
  for (double t = t0 + 4 * dt; t < t0 + 35 * dt; t += 0.0123) {
    s.evaluate(t, 4, d);
    EXPECT_NEAR((d[0] - (a + b * t)).norm(), 0.0, 1e-11);
    EXPECT_NEAR((d[1] - b).norm(), 0.0, 1e-10);
    EXPECT_NEAR(d[2].norm(), 0.0, 1e-8);
  }
}

TEST(UniformBSpline, DerivativesMatchFiniteDifferences) {
  UniformBSpline<3> s(-0.5, 0.2, randomControls(30, 3));
  const double h = 1e-4;
  V3 d[5], dp[5], dm[5];
  for (double t = 0.0; t < 4.5; t += 0.0917) {
    s.evaluate(t, 4, d);
    s.evaluate(t + h, 4, dp);
    s.evaluate(t - h, 4, dm);
    for (int k = 0; k < 4; ++k) {
      const V3 fd = (dp[k] - dm[k]) / (2 * h);
      EXPECT_LT((fd - d[k + 1]).norm(), 1e-5 * (1.0 + d[k + 1].norm())) << "order " << k + 1 << " t " << t;
    }
  }
}

TEST(UniformBSpline, ContinuousUpToSixthDerivativeAtKnots) {
  // Derivatives 0..4 are evaluated exactly; their values from both sides of a knot agree.
  UniformBSpline<3> s(0.0, 0.5, randomControls(20, 7));
  V3 l[5], r[5];
  for (int k = 5; k < 15; ++k) {
    const double t = k * 0.5;
    s.evaluate(std::nextafter(t, -1e9), 4, l);
    s.evaluate(t, 4, r);
    for (int n = 0; n <= 4; ++n) EXPECT_LT((l[n] - r[n]).norm(), 1e-8 * (1 + r[n].norm())) << n;
  }
}

TEST(UniformBSpline, KernelWeightsArePositiveAndSumToOne) {
  // A single unit control among zeros traces the cardinal B-spline: non-negative, area dt,
  // symmetric about its centre, maximum 2416/5040 (N7(4) = 151/315).
  std::vector<Eigen::Matrix<double, 1, 1>> c(21, Eigen::Matrix<double, 1, 1>::Zero());
  c[10](0) = 1.0;
  UniformBSpline<1> s(0.0, 1.0, c);
  double area = 0.0;
  for (double t = 5.0; t < 15.0; t += 0.001) {
    const double v = s.value(t)(0);
    EXPECT_GE(v, -1e-15);
    area += v * 0.001;
    EXPECT_NEAR(v, s.value(20.0 - t)(0), 1e-13);
  }
  EXPECT_NEAR(area, 1.0, 1e-6);
  EXPECT_NEAR(s.value(10.0)(0), 151.0 / 315.0, 1e-14);
  EXPECT_NEAR(s.value(6.0)(0), 0.0, 1e-15);
}

TEST(UniformBSpline, RejectsBadInput) {
  EXPECT_THROW(UniformBSpline<3>(0.0, 0.0, randomControls(3, 1)), std::invalid_argument);
  EXPECT_THROW(UniformBSpline<3>(0.0, 0.1, {}), std::invalid_argument);
  EXPECT_THROW(UniformBSpline<3>(0.0, 0.1, {V3(NAN, 0, 0)}), std::invalid_argument);
  UniformBSpline<3> s(0.0, 0.1, randomControls(3, 1));
  V3 d[6];
  EXPECT_THROW(s.evaluate(0.0, 5, d), std::invalid_argument);
}

}  // namespace
}  // namespace gvins::sim
