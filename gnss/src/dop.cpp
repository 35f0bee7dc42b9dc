#include "gvins/gnss/dop.hpp"

#include <cmath>

#include <Eigen/Cholesky>

namespace gvins {

Dop computeDop(const std::vector<Eigen::Vector3d>& los, const std::vector<int>& clockIndex, int numClocks) {
  Dop d;
  const int m = 3 + numClocks;
  const int n = static_cast<int>(los.size());
  if (numClocks < 1 || numClocks > kNumSystems || n < m || static_cast<int>(clockIndex.size()) != n) return d;
  // Sizes bounded by one clock per constellation: no heap allocation.
  constexpr int kMax = 3 + kNumSystems;
  using Mat = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kMax, kMax>;
  Mat ata = Mat::Zero(m, m);
  double row[kMax];
  for (int i = 0; i < n; ++i) {
    if (clockIndex[i] < 0 || clockIndex[i] >= numClocks) return d;
    for (int k = 0; k < m; ++k) row[k] = 0.0;
    row[0] = -los[i][0];
    row[1] = -los[i][1];
    row[2] = -los[i][2];
    row[3 + clockIndex[i]] = 1.0;
    // The rank-1 update ata += row row^T element by element: the same product and sum per
    // element as Eigen's outer product (no heap, no expression set-up per row).
    for (int c = 0; c < m; ++c) {
      for (int r = 0; r < m; ++r) ata(r, c) += row[c] * row[r];
    }
  }
  Eigen::LDLT<Mat> ldlt(ata);
  if (ldlt.info() != Eigen::Success || !(ldlt.vectorD().array() > 1e-12).all()) return d;
  const Mat q = ldlt.solve(Mat::Identity(m, m));
  if (!q.allFinite() || (q.diagonal().array() < 0.0).any()) return d;
  d.gdop = std::sqrt(q.trace());
  d.pdop = std::sqrt(q(0, 0) + q(1, 1) + q(2, 2));
  d.hdop = std::sqrt(q(0, 0) + q(1, 1));
  d.vdop = std::sqrt(q(2, 2));
  d.tdop = std::sqrt(q(3, 3));
  d.valid = true;
  return d;
}

}  // namespace gvins
