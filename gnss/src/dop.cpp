#include "gvins/gnss/dop.hpp"

#include <cmath>

#include <Eigen/Core>

#include "normal_equations.hpp"

namespace gvins {

Dop computeDop(const std::vector<Eigen::Vector3d>& los, const std::vector<int>& clockIndex, int numClocks) {
  Dop d;
  const int m = 3 + numClocks;
  const int n = static_cast<int>(los.size());
  if (numClocks < 1 || numClocks > kNumSystems || n < m || static_cast<int>(clockIndex.size()) != n) return d;
  // Sizes bounded by one clock per constellation: fixed-size arrays, rows with 4 non-zeros.
  constexpr int kMax = 3 + kNumSystems;
  detail::NormalEquations<kMax> ne(m);
  for (int i = 0; i < n; ++i) {
    if (clockIndex[i] < 0 || clockIndex[i] >= numClocks) return d;
    detail::NormalEquations<kMax>::SparseRow row;
    row.push(0, -los[i][0]);
    row.push(1, -los[i][1]);
    row.push(2, -los[i][2]);
    row.push(3 + clockIndex[i], 1.0);
    ne.addRow(row, 0.0, 1.0);
  }
  if (!ne.factor(0.0, 1e-12)) return d;
  Eigen::Matrix<double, kMax, kMax> q;
  ne.inverse(q.data(), kMax);
  for (int i = 0; i < m; ++i) {
    if (!std::isfinite(q(i, i)) || q(i, i) < 0.0) return d;
  }
  double trace = 0.0;
  for (int i = 0; i < m; ++i) trace += q(i, i);
  d.gdop = std::sqrt(trace);
  d.pdop = std::sqrt(q(0, 0) + q(1, 1) + q(2, 2));
  d.hdop = std::sqrt(q(0, 0) + q(1, 1));
  d.vdop = std::sqrt(q(2, 2));
  d.tdop = std::sqrt(q(3, 3));
  d.valid = true;
  return d;
}

}  // namespace gvins
