// Prior of a new state block, centred at the block's initial estimate.
#pragma once

#include <Eigen/Core>

namespace gvins::sri {

template <typename Scalar>
struct Prior {
  using Matrix = Eigen::Matrix<Scalar, Eigen::Dynamic, Eigen::Dynamic>;
  using Vector = Eigen::Matrix<Scalar, Eigen::Dynamic, 1>;

  enum class Type : unsigned char {
    kUninformative,    ///< Zero information ("infinite covariance"): R gets zero rows.
    kSqrtInformation,  ///< `matrix` = S with SᵀS = Λ (any number of rows, dim columns).
    kCovariance,       ///< `matrix` = P (dim × dim, positive definite).
  };
  Type type = Type::kUninformative;
  Matrix matrix;

  static Prior uninformative() { return {Type::kUninformative, Matrix()}; }
  static Prior sqrtInformation(const Matrix& S) { return {Type::kSqrtInformation, S}; }
  static Prior covariance(const Matrix& P) { return {Type::kCovariance, P}; }
  /// Independent errors with standard deviations σᵢ.
  static Prior stdDevs(const Vector& sigma) {
    return {Type::kSqrtInformation, Matrix(sigma.cwiseInverse().asDiagonal())};
  }
  /// Isotropic standard deviation σ for a block of `dim` entries.
  static Prior stdDev(int dim, Scalar sigma) {
    return {Type::kSqrtInformation, Matrix(Matrix::Identity(dim, dim) / sigma)};
  }
};

}  // namespace gvins::sri
