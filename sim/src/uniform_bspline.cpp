#include "gvins/sim/uniform_bspline.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>

namespace gvins::sim {
namespace {

// kBasis[n][m][p]: coefficient of u^p in the n-th derivative (w.r.t. u) of the weight of the
// m-th of the 8 control points active on one knot interval (u in [0, 1)).
struct BasisTable {
  std::array<std::array<std::array<double, 8>, 8>, 5> c{};
  BasisTable() {
    auto binom = [](int n, int k) {
      double r = 1.0;
      for (int i = 1; i <= k; ++i) r = r * (n - k + i) / i;
      return r;
    };
    // weight_m(u) = N7(u + 7 - m) = 1/7! sum_{l=0}^{7-m} (-1)^l C(8,l) (u + 7 - m - l)^7.
    for (int m = 0; m < 8; ++m) {
      for (int l = 0; l <= 7 - m; ++l) {
        const double a = 7 - m - l;
        const double s = (l % 2 ? -1.0 : 1.0) * binom(8, l);
        for (int p = 0; p <= 7; ++p) c[0][m][p] += s * binom(7, p) * std::pow(a, 7 - p);
      }
      for (int p = 0; p <= 7; ++p) c[0][m][p] /= 5040.0;
    }
    for (int n = 1; n <= 4; ++n)
      for (int m = 0; m < 8; ++m)
        for (int p = 0; p + 1 <= 7; ++p) c[n][m][p] = c[n - 1][m][p + 1] * (p + 1);
  }
};
const BasisTable& basisTable() {
  static const BasisTable table;
  return table;
}

}  // namespace

template <int Dim>
UniformBSpline<Dim>::UniformBSpline(double t0, double dt, std::vector<Vector> controls)
    : t0_(t0), dt_(dt), c_(std::move(controls)) {
  if (!(dt > 0.0) || !std::isfinite(dt) || !std::isfinite(t0))
    throw std::invalid_argument("UniformBSpline: bad knot spacing or start");
  if (c_.empty()) throw std::invalid_argument("UniformBSpline: no control points");
  for (const auto& c : c_)
    if (!c.allFinite()) throw std::invalid_argument("UniformBSpline: non-finite control point");
}

template <int Dim>
void UniformBSpline<Dim>::evaluate(double t, int order, Vector* out) const {
  if (order < 0 || order > kMaxDerivative) throw std::invalid_argument("UniformBSpline: derivative order");
  const BasisTable& b = basisTable();
  const double x = (t - t0_) / dt_;
  const long n = static_cast<long>(c_.size());
  // Far outside the control range the curve is constant; clamp x to keep k in range.
  const double xc = std::clamp(x, -8.0, static_cast<double>(n) + 8.0);
  const double kf = std::floor(xc);
  const long k = static_cast<long>(kf);
  const double u = xc - kf;
  auto ctrl = [&](long i) -> const Vector& { return c_[static_cast<std::size_t>(std::clamp(i, 0L, n - 1))]; };
  // Relative to a local reference point: the weights sum to 1 and their derivatives to 0, so
  // this removes the large common part before the alternating sums.
  const Vector ref = ctrl(k);
  Vector d[8];
  for (int m = 0; m < 8; ++m) d[m] = ctrl(k - 3 + m) - ref;
  double scale = 1.0;
  for (int nd = 0; nd <= order; ++nd) {
    Vector acc = Vector::Zero();
    for (int m = 0; m < 8; ++m) {
      const auto& cf = b.c[nd][m];
      double w = 0.0;
      for (int p = 7 - nd; p >= 0; --p) w = w * u + cf[p];
      acc += w * d[m];
    }
    out[nd] = acc * scale;
    if (nd == 0) out[nd] += ref;
    scale /= dt_;
  }
}

template <int Dim>
void UniformBSpline<Dim>::basis(double u, int derivative, double w[8]) {
  if (derivative < 0 || derivative > kMaxDerivative) throw std::invalid_argument("UniformBSpline: derivative order");
  const BasisTable& b = basisTable();
  for (int m = 0; m < 8; ++m) {
    const auto& cf = b.c[derivative][m];
    double v = 0.0;
    for (int p = 7 - derivative; p >= 0; --p) v = v * u + cf[p];
    w[m] = v;
  }
}

template class UniformBSpline<1>;
template class UniformBSpline<3>;
template class UniformBSpline<4>;

}  // namespace gvins::sim
