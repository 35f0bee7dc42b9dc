// upperTriangularInverse against the definition: U X = I and X upper triangular, for sizes
// below, at and above the recursion's leaf and odd splits, in float and double, and for a
// row-major view with an outer stride (the filter passes a trailing block of its factor).
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "gvins/sri/square_root.hpp"

namespace gvins::sri {
namespace {

template <typename S>
void checkInverse(int k, int stride, unsigned seed, double tol) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> g(0.0, 1.0);
  // A factor of the kind the filter holds: diagonal of either sign and mixed magnitudes.
  RowMatrix<S> store = RowMatrix<S>::Constant(k, stride, S(7));  // junk below the diagonal and past k
  for (int i = 0; i < k; ++i) {
    for (int j = i; j < k; ++j) store(i, j) = static_cast<S>(0.3 * g(rng));
    store(i, i) = static_cast<S>((i % 2 ? -1.0 : 1.0) * (1.0 + std::abs(g(rng))) * std::pow(10.0, (i % 5) - 2));
  }
  const Eigen::Map<const RowMatrix<S>, Eigen::Unaligned, Eigen::OuterStride<>> U(store.data(), k, k,
                                                                                  Eigen::OuterStride<>(stride));
  const DenseMatrix<S> X = upperTriangularInverse<S>(U);
  ASSERT_EQ(X.rows(), k);
  ASSERT_EQ(X.cols(), k);
  for (int j = 0; j < k; ++j)
    for (int i = j + 1; i < k; ++i) EXPECT_EQ(X(i, j), S(0)) << "k " << k << " (" << i << ", " << j << ")";
  const Eigen::MatrixXd Ud = DenseMatrix<S>(U.template triangularView<Eigen::Upper>()).template cast<double>();
  const Eigen::MatrixXd E = Ud * X.template cast<double>() - Eigen::MatrixXd::Identity(k, k);
  // Relative to the conditioning: ‖U‖ ‖X‖ ε bounds the residual of a backward-stable inverse.
  const double scale = Ud.norm() * X.template cast<double>().norm();
  EXPECT_LE(E.norm(), tol * scale) << "k " << k;
  // Against Eigen's triangular solve of the identity (an independent computation).
  Eigen::MatrixXd ref = Eigen::MatrixXd::Identity(k, k);
  Ud.triangularView<Eigen::Upper>().solveInPlace(ref);
  EXPECT_LE((X.template cast<double>() - ref).norm(), tol * scale * ref.norm()) << "k " << k;
}

TEST(UpperTriangularInverse, IsTheInverseAtEverySizeDouble) {
  for (int k : {0, 1, 2, 7, 24, 25, 49, 97, 200}) checkInverse<double>(k, k + 3, 11u + static_cast<unsigned>(k), 1e-13);
}

TEST(UpperTriangularInverse, IsTheInverseAtEverySizeFloat) {
  for (int k : {1, 3, 24, 25, 64, 131}) checkInverse<float>(k, k + 1, 5u + static_cast<unsigned>(k), 2e-5);
}

}  // namespace
}  // namespace gvins::sri
