#include "gvins/sri/square_root.hpp"

#include <cmath>
#include <numeric>
#include <vector>

#include "gvins/sri/qr_update.hpp"

namespace gvins::sri {

template <typename Scalar>
std::optional<DenseMatrix<Scalar>> choleskyLower(const DenseMatrix<Scalar>& A) {
  const Eigen::Index n = A.rows();
  if (A.cols() != n || !A.allFinite()) return std::nullopt;
  DenseMatrix<Scalar> L = DenseMatrix<Scalar>::Zero(n, n);
  for (Eigen::Index j = 0; j < n; ++j) {
    Scalar d = A(j, j);
    if (j > 0) d -= L.row(j).head(j).squaredNorm();
    if (!(d > Scalar(0))) return std::nullopt;
    const Scalar ljj = std::sqrt(d);
    L(j, j) = ljj;
    for (Eigen::Index i = j + 1; i < n; ++i) {
      Scalar s = A(i, j);
      if (j > 0) s -= L.row(i).head(j).dot(L.row(j).head(j));
      L(i, j) = s / ljj;
    }
  }
  return L;
}

template <typename Scalar>
void solveLowerInPlace(const DenseMatrix<Scalar>& L, DenseMatrix<Scalar>& M) {
  if (M.size() == 0) return;
  L.template triangularView<Eigen::Lower>().solveInPlace(M);
}

template <typename Scalar>
DenseMatrix<Scalar> triangularFactor(const DenseMatrix<Scalar>& S) {
  const int d = static_cast<int>(S.cols());
  const int m = static_cast<int>(S.rows());
  RowMatrix<Scalar> U = RowMatrix<Scalar>::Zero(d, d);
  if (d == 0 || m == 0) return DenseMatrix<Scalar>(U);
  // QR of S as a stacked update onto an empty factor.
  RowMatrix<Scalar> W = S;
  Eigen::Matrix<Scalar, Eigen::Dynamic, 1> r = Eigen::Matrix<Scalar, Eigen::Dynamic, 1>::Zero(d);
  Eigen::Matrix<Scalar, Eigen::Dynamic, 1> z = Eigen::Matrix<Scalar, Eigen::Dynamic, 1>::Zero(m);
  std::vector<int> lead(static_cast<std::size_t>(m), 0);
  householderRowUpdate<Scalar>(RowMatrixView<Scalar>(U.data(), d, d, Eigen::OuterStride<>(d)),
                               VectorView<Scalar>(r.data(), d),
                               RowMatrixView<Scalar>(W.data(), m, d, Eigen::OuterStride<>(d)),
                               VectorView<Scalar>(z.data(), m), lead);
  return DenseMatrix<Scalar>(U.template triangularView<Eigen::Upper>());
}

namespace {

/// X ← U⁻¹ in place on the upper triangle of X (X holds U on entry; the strict lower triangle
/// stays zero), recursive halving down to column solves.
template <typename Scalar>
void invertUpperInPlace(Eigen::Ref<DenseMatrix<Scalar>> X) {
  const Eigen::Index k = X.rows();
  constexpr Eigen::Index kLeaf = 24;
  if (k <= kLeaf) {
    const DenseMatrix<Scalar> U = X.template triangularView<Eigen::Upper>();
    X.setIdentity();
    U.template triangularView<Eigen::Upper>().solveInPlace(X);
    return;
  }
  const Eigen::Index h = k / 2;
  invertUpperInPlace<Scalar>(X.topLeftCorner(h, h));
  invertUpperInPlace<Scalar>(X.bottomRightCorner(k - h, k - h));
  // B ← −A⁻¹ (B C⁻¹).
  auto B = X.topRightCorner(h, k - h);
  const DenseMatrix<Scalar> BC = B * X.bottomRightCorner(k - h, k - h).template triangularView<Eigen::Upper>();
  B.noalias() = -(X.topLeftCorner(h, h).template triangularView<Eigen::Upper>() * BC);
}

}  // namespace

template <typename Scalar>
DenseMatrix<Scalar> upperTriangularInverse(
    const Eigen::Map<const RowMatrix<Scalar>, Eigen::Unaligned, Eigen::OuterStride<>>& U) {
  const Eigen::Index k = U.rows();
  DenseMatrix<Scalar> X = U.template triangularView<Eigen::Upper>();
  if (k > 0) invertUpperInPlace<Scalar>(X);
  return X;
}

template <typename Scalar>
std::optional<DenseMatrix<Scalar>> sqrtInformationFromCovariance(const DenseMatrix<Scalar>& P) {
  auto L = choleskyLower<Scalar>(P);
  if (!L) return std::nullopt;
  // P = L Lᵀ → P⁻¹ = L⁻ᵀ L⁻¹: L⁻¹ is a (lower-triangular) square root of the information.
  DenseMatrix<Scalar> S = DenseMatrix<Scalar>::Identity(P.rows(), P.rows());
  solveLowerInPlace<Scalar>(*L, S);
  return triangularFactor<Scalar>(S);
}

#define GVINS_SRI_INSTANTIATE(S)                                                              \
  template std::optional<DenseMatrix<S>> choleskyLower<S>(const DenseMatrix<S>&);             \
  template void solveLowerInPlace<S>(const DenseMatrix<S>&, DenseMatrix<S>&);                 \
  template DenseMatrix<S> triangularFactor<S>(const DenseMatrix<S>&);                         \
  template DenseMatrix<S> upperTriangularInverse<S>(                                          \
      const Eigen::Map<const RowMatrix<S>, Eigen::Unaligned, Eigen::OuterStride<>>&);          \
  template std::optional<DenseMatrix<S>> sqrtInformationFromCovariance<S>(const DenseMatrix<S>&);
GVINS_SRI_INSTANTIATE(float)
GVINS_SRI_INSTANTIATE(double)
#undef GVINS_SRI_INSTANTIATE

}  // namespace gvins::sri
