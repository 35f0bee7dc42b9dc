// Square-root factors of small dense covariance / information matrices (priors, process and
// measurement noise). Kept in one translation unit so that the heavy Eigen templates are
// instantiated once per scalar.
#pragma once

#include <optional>

#include <Eigen/Core>

#include "gvins/sri/qr_update.hpp"

namespace gvins::sri {

template <typename Scalar>
using DenseMatrix = Eigen::Matrix<Scalar, Eigen::Dynamic, Eigen::Dynamic>;

/// Lower Cholesky factor L (A = L Lᵀ) of a symmetric matrix (lower triangle read);
/// nullopt if A is not positive definite (Golub & Van Loan, Algorithm 4.2.1).
template <typename Scalar>
std::optional<DenseMatrix<Scalar>> choleskyLower(const DenseMatrix<Scalar>& A);

/// M ← L⁻¹ M for lower-triangular L.
template <typename Scalar>
void solveLowerInPlace(const DenseMatrix<Scalar>& L, DenseMatrix<Scalar>& M);

/// Upper-triangular U (cols × cols) with UᵀU = SᵀS, i.e. the R factor of the QR of S (any number
/// of rows; zero rows are added when S has fewer rows than columns).
template <typename Scalar>
DenseMatrix<Scalar> triangularFactor(const DenseMatrix<Scalar>& S);

/// Upper-triangular U with UᵀU = P⁻¹ for a covariance P; nullopt if P is not positive definite.
template <typename Scalar>
std::optional<DenseMatrix<Scalar>> sqrtInformationFromCovariance(const DenseMatrix<Scalar>& P);

/// U⁻¹ of an upper-triangular U (k × k, non-zero diagonal; only the upper triangle is read),
/// blocked: U = [A B; 0 C] gives U⁻¹ = [A⁻¹, −A⁻¹ B C⁻¹; 0, C⁻¹] (Higham, "Accuracy and
/// Stability of Numerical Algorithms", 2nd ed., sec. 14.2), the off-diagonal blocks as
/// triangular matrix products, so that most of the k³/3 flops run in Eigen's blocked kernels
/// instead of k triangular vector solves.
template <typename Scalar>
DenseMatrix<Scalar> upperTriangularInverse(
    const Eigen::Map<const RowMatrix<Scalar>, Eigen::Unaligned, Eigen::OuterStride<>>& U);

extern template std::optional<DenseMatrix<float>> choleskyLower<float>(const DenseMatrix<float>&);
extern template std::optional<DenseMatrix<double>> choleskyLower<double>(
    const DenseMatrix<double>&);
extern template void solveLowerInPlace<float>(const DenseMatrix<float>&, DenseMatrix<float>&);
extern template void solveLowerInPlace<double>(const DenseMatrix<double>&, DenseMatrix<double>&);
extern template DenseMatrix<float> upperTriangularInverse<float>(
    const Eigen::Map<const RowMatrix<float>, Eigen::Unaligned, Eigen::OuterStride<>>&);
extern template DenseMatrix<double> upperTriangularInverse<double>(
    const Eigen::Map<const RowMatrix<double>, Eigen::Unaligned, Eigen::OuterStride<>>&);
extern template DenseMatrix<float> triangularFactor<float>(const DenseMatrix<float>&);
extern template DenseMatrix<double> triangularFactor<double>(const DenseMatrix<double>&);
extern template std::optional<DenseMatrix<float>> sqrtInformationFromCovariance<float>(
    const DenseMatrix<float>&);
extern template std::optional<DenseMatrix<double>> sqrtInformationFromCovariance<double>(
    const DenseMatrix<double>&);

}  // namespace gvins::sri
