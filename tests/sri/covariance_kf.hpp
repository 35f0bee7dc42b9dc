// Textbook covariance-form Kalman filter over the same block operations as the SRI filter,
// used as independent truth in the tests (and as the covariance-form competitor in the
// benchmarks). Deliberately plain: dense P, the standard update P ← (I − KH)P (or the Joseph
// form), augmentation for propagation, deletion of rows/columns for marginalization
// (Maybeck 1979, "Stochastic Models, Estimation, and Control", vol. 1, ch. 5).
#pragma once

#include <algorithm>
#include <cstdint>
#include <stdexcept>
#include <vector>

#include <Eigen/Cholesky>
#include <Eigen/Core>

namespace gvins::sri::test {

template <typename T>
class CovarianceKf {
 public:
  using Matrix = Eigen::Matrix<T, Eigen::Dynamic, Eigen::Dynamic>;
  using Vector = Eigen::Matrix<T, Eigen::Dynamic, 1>;

  struct Block {
    std::uint64_t key;
    int dim;
  };

  bool joseph = false;

  int dim() const { return static_cast<int>(x.size()); }
  int offset(std::uint64_t key) const {
    int o = 0;
    for (const Block& b : blocks) {
      if (b.key == key) return o;
      o += b.dim;
    }
    throw std::out_of_range("CovarianceKf: unknown block");
  }
  int blockDim(std::uint64_t key) const {
    for (const Block& b : blocks) {
      if (b.key == key) return b.dim;
    }
    throw std::out_of_range("CovarianceKf: unknown block");
  }

  /// Inserts an independent block before position `index` (in blocks).
  void addBlock(std::uint64_t key, int index, const Vector& x0, const Matrix& P0) {
    int o = 0;
    for (int i = 0; i < index; ++i) o += blocks[static_cast<std::size_t>(i)].dim;
    const int n = dim();
    const int d = static_cast<int>(x0.size());
    Vector xn(n + d);
    xn << x.head(o), x0, x.tail(n - o);
    Matrix Pn = Matrix::Zero(n + d, n + d);
    Pn.topLeftCorner(o, o) = P.topLeftCorner(o, o);
    Pn.topRightCorner(o, n - o) = P.topRightCorner(o, n - o);
    Pn.bottomLeftCorner(n - o, o) = P.bottomLeftCorner(n - o, o);
    Pn.bottomRightCorner(n - o, n - o) = P.bottomRightCorner(n - o, n - o);
    Pn.block(o, o, d, d) = P0;
    x = xn;
    P = Pn;
    blocks.insert(blocks.begin() + index, Block{key, d});
  }

  /// x_new = Φ x + e_offset (Φ: d × n over the whole state), cov Q; the new block is placed
  /// before position `index`.
  void propagate(std::uint64_t key, int index, const Matrix& Phi, const Vector& xnew,
                 const Matrix& Q) {
    const int n = dim();
    const int d = static_cast<int>(xnew.size());
    // Augment at the end, then move into place by a permutation.
    Vector xa(n + d);
    xa << x, xnew;
    Matrix Pa(n + d, n + d);
    Pa.topLeftCorner(n, n) = P;
    Pa.topRightCorner(n, d) = P * Phi.transpose();
    Pa.bottomLeftCorner(d, n) = Phi * P;
    Pa.bottomRightCorner(d, d) = Phi * P * Phi.transpose() + Q;
    int o = 0;
    for (int i = 0; i < index; ++i) o += blocks[static_cast<std::size_t>(i)].dim;
    std::vector<int> perm;  // new index → old index
    for (int i = 0; i < o; ++i) perm.push_back(i);
    for (int i = 0; i < d; ++i) perm.push_back(n + i);
    for (int i = o; i < n; ++i) perm.push_back(i);
    x.resize(n + d);
    P.resize(n + d, n + d);
    for (int i = 0; i < n + d; ++i) {
      x(i) = xa(perm[static_cast<std::size_t>(i)]);
      for (int j = 0; j < n + d; ++j) {
        P(i, j) = Pa(perm[static_cast<std::size_t>(i)], perm[static_cast<std::size_t>(j)]);
      }
    }
    blocks.insert(blocks.begin() + index, Block{key, d});
  }

  /// Standard (or Joseph) update with full H (m × n), measurement z, noise covariance Rn.
  /// Returns the innovation chi-square νᵀ S⁻¹ ν.
  T update(const Matrix& H, const Vector& z, const Matrix& Rn) {
    const Vector nu = z - H * x;
    const Matrix PHt = P * H.transpose();
    const Matrix S = H * PHt + Rn;
    const Eigen::LDLT<Matrix> ldlt(S);
    const Matrix K = ldlt.solve(PHt.transpose()).transpose();
    x += K * nu;
    const int n = dim();
    const Matrix IKH = Matrix::Identity(n, n) - K * H;
    if (joseph) {
      P = IKH * P * IKH.transpose() + K * Rn * K.transpose();
    } else {
      P = IKH * P;
    }
    P = T(0.5) * (P + P.transpose()).eval();
    return nu.dot(ldlt.solve(nu));
  }

  void marginalize(std::uint64_t key) {
    const int o = offset(key);
    const int d = blockDim(key);
    const int n = dim();
    Vector xn(n - d);
    xn << x.head(o), x.tail(n - o - d);
    Matrix Pn(n - d, n - d);
    Pn.topLeftCorner(o, o) = P.topLeftCorner(o, o);
    Pn.topRightCorner(o, n - o - d) = P.topRightCorner(o, n - o - d);
    Pn.bottomLeftCorner(n - o - d, o) = P.bottomLeftCorner(n - o - d, o);
    Pn.bottomRightCorner(n - o - d, n - o - d) = P.bottomRightCorner(n - o - d, n - o - d);
    x = xn;
    P = Pn;
    blocks.erase(std::find_if(blocks.begin(), blocks.end(),
                              [key](const Block& b) { return b.key == key; }));
  }

  /// Reorders the blocks (keys lists every block once).
  void reorder(const std::vector<std::uint64_t>& keys) {
    std::vector<int> perm;  // new index → old index
    std::vector<Block> nb;
    for (std::uint64_t k : keys) {
      const int o = offset(k);
      const int d = blockDim(k);
      for (int q = 0; q < d; ++q) perm.push_back(o + q);
      nb.push_back(Block{k, d});
    }
    const int n = dim();
    Vector xn(n);
    Matrix Pn(n, n);
    for (int i = 0; i < n; ++i) {
      xn(i) = x(perm[static_cast<std::size_t>(i)]);
      for (int j = 0; j < n; ++j) {
        Pn(i, j) = P(perm[static_cast<std::size_t>(i)], perm[static_cast<std::size_t>(j)]);
      }
    }
    x = xn;
    P = Pn;
    blocks = nb;
  }

  Vector x;
  Matrix P;
  std::vector<Block> blocks;
};

}  // namespace gvins::sri::test
