#include "gvins/gnss/dop.hpp"

#include <cmath>

#include <Eigen/Cholesky>

namespace gvins {

Dop computeDop(const std::vector<Eigen::Vector3d>& los, const std::vector<int>& clockIndex, int numClocks) {
  Dop d;
  const int m = 3 + numClocks;
  const int n = static_cast<int>(los.size());
  if (numClocks < 1 || n < m || static_cast<int>(clockIndex.size()) != n) return d;
  Eigen::MatrixXd ata = Eigen::MatrixXd::Zero(m, m);
  Eigen::VectorXd row(m);
  for (int i = 0; i < n; ++i) {
    row.setZero();
    row.head<3>() = -los[i];
    if (clockIndex[i] < 0 || clockIndex[i] >= numClocks) return d;
    row[3 + clockIndex[i]] = 1.0;
    ata.noalias() += row * row.transpose();
  }
  Eigen::LDLT<Eigen::MatrixXd> ldlt(ata);
  if (ldlt.info() != Eigen::Success || !(ldlt.vectorD().array() > 1e-12).all()) return d;
  const Eigen::MatrixXd q = ldlt.solve(Eigen::MatrixXd::Identity(m, m));
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
