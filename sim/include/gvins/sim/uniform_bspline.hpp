// Uniform septic (degree 7) B-spline curves in time: C^6 smooth, with exact derivatives up to
// the 4th order (snap), which a multirotor's angular acceleration needs.
//
// Control point i sits at time t0 + i dt and weighs N7((t - t0)/dt - i + 4), N7 the cardinal
// B-spline of degree 7 on [0, 8] (de Boor, "A Practical Guide to Splines", 2001, ch. IX; the
// truncated-power form N_k(y) = 1/k! sum_l (-1)^l C(k+1, l) (y - l)_+^k). The curve is thus a
// smoothing of the control polygon with a bell-shaped kernel of half-width 4 dt (standard
// deviation dt sqrt(2/3)); it does not interpolate. Indices beyond the ends are clamped, so the
// curve is defined for every t and is at rest where 8 consecutive control points coincide.
#pragma once

#include <vector>

#include <Eigen/Core>

namespace gvins::sim {

template <int Dim>
class UniformBSpline {
 public:
  using Vector = Eigen::Matrix<double, Dim, 1>;
  static constexpr int kDegree = 7;
  static constexpr int kMaxDerivative = 4;

  UniformBSpline() = default;
  /// Throws std::invalid_argument for dt <= 0, non-finite values or no control points.
  UniformBSpline(double t0, double dt, std::vector<Vector> controls);

  /// Value and derivatives d^k/dt^k for k = 0..order (order <= 4) at time t, into out[0..order].
  void evaluate(double t, int order, Vector* out) const;
  Vector value(double t) const {
    Vector v;
    evaluate(t, 0, &v);
    return v;
  }

  /// The 8 weights (or their d-th derivatives w.r.t. the normalised time, d <= 4) of the
  /// control points k-3 .. k+4 active at (t - t0)/dt = k + u, u in [0, 1).
  static void basis(double u, int derivative, double w[8]);

  double t0() const { return t0_; }
  double dt() const { return dt_; }
  const std::vector<Vector>& controls() const { return c_; }

 private:
  double t0_ = 0.0, dt_ = 1.0;
  std::vector<Vector> c_;
};

extern template class UniformBSpline<1>;
extern template class UniformBSpline<3>;
extern template class UniformBSpline<4>;

}  // namespace gvins::sim
