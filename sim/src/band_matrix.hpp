// A symmetric positive definite band matrix (half bandwidth kB = 7, the support of a septic
// B-spline) with an in-place Cholesky factorisation and solves: the normal equations of the
// penalised B-spline fits of sim/ (recorded_trajectory.cpp, track_trajectory.cpp).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <stdexcept>
#include <vector>

namespace gvins::sim::detail {

/// Symmetric positive definite band matrix (half bandwidth kB) with an in-place Cholesky
/// factorisation and solves; enough for the normal equations of a B-spline fit.
class BandMatrix {
 public:
  static constexpr int kB = 7;
  explicit BandMatrix(std::size_t n) : n_(n), a_(n * (kB + 1), 0.0) {}
  double& at(std::size_t i, std::size_t j) {  // j <= i <= j + kB
    return a_[j * (kB + 1) + (i - j)];
  }
  void add(std::size_t i, std::size_t j, double v) {
    if (i < j) std::swap(i, j);
    at(i, j) += v;
  }
  void factor() {
    for (std::size_t j = 0; j < n_; ++j) {
      double d = at(j, j);
      for (std::size_t k = (j > kB ? j - kB : 0); k < j; ++k) d -= at(j, k) * at(j, k);
      if (!(d > 0.0)) throw std::invalid_argument("B-spline fit: singular normal equations (too few samples)");
      d = std::sqrt(d);
      at(j, j) = d;
      for (std::size_t i = j + 1; i <= std::min(n_ - 1, j + kB); ++i) {
        double s = at(i, j);
        for (std::size_t k = (i > kB ? i - kB : 0); k < j; ++k) s -= at(i, k) * at(j, k);
        at(i, j) = s / d;
      }
    }
  }
  void solve(std::vector<double>& b) {
    for (std::size_t i = 0; i < n_; ++i) {
      double s = b[i];
      for (std::size_t k = (i > kB ? i - kB : 0); k < i; ++k) s -= at(i, k) * b[k];
      b[i] = s / at(i, i);
    }
    for (std::size_t i = n_; i-- > 0;) {
      double s = b[i];
      for (std::size_t k = i + 1; k <= std::min(n_ - 1, i + kB); ++k) s -= at(k, i) * b[k];
      b[i] = s / at(i, i);
    }
  }

 private:
  std::size_t n_;
  std::vector<double> a_;
};


}  // namespace gvins::sim::detail
