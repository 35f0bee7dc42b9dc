// The structured QR kernels against the definition: the new factor must carry the information
// of the stack, R'ᵀR' = RᵀR + WᵀW, R'ᵀr' = Rᵀr + Wᵀz, ‖r'‖² + ‖e‖² = ‖r‖² + ‖z‖² (orthogonal
// transformations), and be upper triangular; sizes cover partial panels, zero rows, rows
// touching nothing, more rows than columns, and float. The column sweep is checked the same
// way against the permuted information.
#include <gtest/gtest.h>

#include <algorithm>
#include <numeric>
#include <random>
#include <vector>

#include "gvins/sri/qr_update.hpp"

namespace gvins::sri {
namespace {

template <typename S>
using Mat = Eigen::Matrix<S, Eigen::Dynamic, Eigen::Dynamic>;
template <typename S>
using Vec = Eigen::Matrix<S, Eigen::Dynamic, 1>;

template <typename S>
void checkRowUpdate(RotationScheme scheme, int k, int m, unsigned seed, double tol) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> g(0.0, 1.0);
  std::uniform_int_distribution<int> leadDist(0, k);  // k: an all-zero row
  RowMatrix<S> R = RowMatrix<S>::Zero(k, k);
  for (int i = 0; i < k; ++i) {
    for (int j = i; j < k; ++j) R(i, j) = static_cast<S>(g(rng));
    R(i, i) += static_cast<S>(i % 5 == 3 ? 0.0 : 2.0);  // some weak pivots
  }
  if (k > 2) R.row(1).setZero();  // a block without information
  // Garbage below the diagonal must be ignored.
  for (int i = 1; i < k; ++i) R(i, i - 1) = static_cast<S>(1e30);
  std::vector<int> lead(static_cast<std::size_t>(m));
  for (int& l : lead) l = leadDist(rng);
  std::sort(lead.begin(), lead.end());
  RowMatrix<S> W = RowMatrix<S>::Zero(m, k);
  for (int i = 0; i < m; ++i) {
    for (int j = lead[static_cast<std::size_t>(i)]; j < k; ++j) W(i, j) = static_cast<S>(g(rng));
  }
  Vec<S> r(k);
  Vec<S> z(m);
  for (int i = 0; i < k; ++i) r(i) = static_cast<S>(g(rng));
  for (int i = 0; i < m; ++i) z(i) = static_cast<S>(g(rng));
  const Mat<double> R0 = R.template cast<double>().template triangularView<Eigen::Upper>();
  const Mat<double> W0 = W.template cast<double>();
  const Vec<double> r0 = r.template cast<double>();
  const Vec<double> z0 = z.template cast<double>();

  RowMatrixView<S> Rv(R.data(), k, k, Eigen::OuterStride<>(k));
  RowMatrixView<S> Wv(W.data(), m, k, Eigen::OuterStride<>(k));
  if (scheme == RotationScheme::kGivens) {
    givensRowUpdate<S>(Rv, VectorView<S>(r.data(), k), Wv, VectorView<S>(z.data(), m), lead);
  } else {
    householderRowUpdate<S>(Rv, VectorView<S>(r.data(), k), Wv, VectorView<S>(z.data(), m), lead);
  }
  const Mat<double> R1 = R.template cast<double>().template triangularView<Eigen::Upper>();
  const Vec<double> r1 = r.template cast<double>();
  const Vec<double> e = z.template cast<double>();
  const Mat<double> info = R0.transpose() * R0 + W0.transpose() * W0;
  const double scale = std::max(1.0, info.norm());
  EXPECT_LT((R1.transpose() * R1 - info).norm(), tol * scale) << "k=" << k << " m=" << m;
  EXPECT_LT((R1.transpose() * r1 - (R0.transpose() * r0 + W0.transpose() * z0)).norm(), tol * scale);
  EXPECT_NEAR(r1.squaredNorm() + e.squaredNorm(), r0.squaredNorm() + z0.squaredNorm(),
              tol * (r0.squaredNorm() + z0.squaredNorm()));
}

TEST(QrUpdate, HouseholderAndGivensCarryTheInformation) {
  unsigned seed = 1;
  // k = 40 and 101: AVX2 chunks of 3 vectors, then 2, 1 and a scalar tail of every width.
  for (int k : {1, 2, 3, 4, 5, 7, 8, 9, 13, 40, 101}) {
    for (int m : {1, 3, 4, 5, 17, 60}) {
      for (auto s : {RotationScheme::kBlockedHouseholder, RotationScheme::kGivens}) {
        checkRowUpdate<double>(s, k, m, seed, 1e-12);
        checkRowUpdate<float>(s, k, m, seed, 2e-5);
        ++seed;
      }
    }
  }
}

TEST(QrUpdate, EmptyInputsAreNoOps) {
  RowMatrix<double> R = RowMatrix<double>::Identity(3, 3);
  Vec<double> r = Vec<double>::Ones(3);
  RowMatrix<double> W(0, 3);
  Vec<double> z(0);
  std::vector<int> lead;
  householderRowUpdate<double>(RowMatrixView<double>(R.data(), 3, 3, Eigen::OuterStride<>(3)),
                               VectorView<double>(r.data(), 3),
                               RowMatrixView<double>(W.data(), 0, 3, Eigen::OuterStride<>(3)),
                               VectorView<double>(z.data(), 0), lead);
  EXPECT_EQ(R, RowMatrix<double>::Identity(3, 3));
  // Rows that are all zero (lead = k) leave R alone and keep their residual.
  RowMatrix<double> W2 = RowMatrix<double>::Zero(2, 3);
  Vec<double> z2 = Vec<double>::Constant(2, 5.0);
  std::vector<int> lead2{3, 3};
  givensRowUpdate<double>(RowMatrixView<double>(R.data(), 3, 3, Eigen::OuterStride<>(3)),
                          VectorView<double>(r.data(), 3),
                          RowMatrixView<double>(W2.data(), 2, 3, Eigen::OuterStride<>(3)),
                          VectorView<double>(z2.data(), 2), lead2);
  EXPECT_EQ(R, RowMatrix<double>::Identity(3, 3));
  EXPECT_EQ(z2, Vec<double>::Constant(2, 5.0));
}

template <typename S>
void checkSweep(int n, int c, int d, int t, unsigned seed, double tol) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> g(0.0, 1.0);
  RowMatrix<S> R = RowMatrix<S>::Zero(n, n);
  for (int i = 0; i < n; ++i) {
    for (int j = i; j < n; ++j) R(i, j) = static_cast<S>(g(rng));
    R(i, i) += S(3);
    for (int j = 0; j < i; ++j) R(i, j) = S(-7);  // garbage below the diagonal is not read
  }
  Vec<S> r(n);
  for (int i = 0; i < n; ++i) r(i) = static_cast<S>(g(rng));
  const Mat<double> R0 = R.template cast<double>().template triangularView<Eigen::Upper>();
  const Vec<double> r0 = r.template cast<double>();
  sweepColumnsToFront<S>(RowMatrixView<S>(R.data(), n, n, Eigen::OuterStride<>(n)),
                         VectorView<S>(r.data(), n), c, d, t);
  // New column order: [0, t) [c, c+d) [t, c) [c+d, n); new row i of the factor must be zero in
  // the new columns before i.
  std::vector<int> order;
  for (int j = 0; j < t; ++j) order.push_back(j);
  for (int j = c; j < c + d; ++j) order.push_back(j);
  for (int j = t; j < c; ++j) order.push_back(j);
  for (int j = c + d; j < n; ++j) order.push_back(j);
  Mat<double> F(n, n);
  for (int i = 0; i < n; ++i) {
    for (int jn = 0; jn < n; ++jn) {
      const int j = order[static_cast<std::size_t>(jn)];
      // Storage the kernel defines (qr_update.hpp); everything else is zero by structure.
      bool stored;
      if (i < t || i >= c + d) {
        stored = j >= i;  // untouched rows
      } else if (i < t + d) {  // rows of the moved block: triangular within it, dense elsewhere
        stored = (j >= t && j < c) || j >= c + d || (j >= c && j < c + d && j - c >= i - t);
      } else {  // row t+d+q starts at column t+q and is zero in the moved columns
        stored = (j >= i - d && j < c) || j >= c + d;
      }
      F(i, jn) = stored ? static_cast<double>(R(i, j)) : 0.0;
    }
  }
  for (int i = 0; i < n; ++i) {
    for (int jn = 0; jn < i; ++jn) {
      EXPECT_NEAR(F(i, jn), 0.0, tol * 10) << "not triangular at " << i << "," << jn;
      F(i, jn) = 0.0;
    }
  }
  Mat<double> Pm = Mat<double>::Zero(n, n);
  for (int jn = 0; jn < n; ++jn) Pm(order[static_cast<std::size_t>(jn)], jn) = 1.0;
  const Mat<double> info = Pm.transpose() * R0.transpose() * R0 * Pm;
  EXPECT_LT((F.transpose() * F - info).norm(), tol * info.norm());
  EXPECT_LT((F.transpose() * r.template cast<double>() - Pm.transpose() * R0.transpose() * r0).norm(),
            tol * info.norm());
}

TEST(QrUpdate, SweepColumnsToFront) {
  unsigned seed = 1;
  // Odd and even numbers of rows passed over (steps run in fused pairs), and n = 60 for the
  // 2-vector chunks of float.
  for (int n : {4, 9, 25, 60}) {
    for (int d : {1, 3, 6, 9}) {
      for (int c = 0; c + d <= n; c += std::max(1, n / 5)) {
        for (int t : {0, c / 2, c}) {
          checkSweep<double>(n, c, d, t, seed, 1e-12);
          checkSweep<float>(n, c, d, t, seed, 1e-5);
          ++seed;
        }
      }
    }
  }
}

}  // namespace
}  // namespace gvins::sri
