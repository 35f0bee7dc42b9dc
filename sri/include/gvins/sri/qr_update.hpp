// Structured QR updates of an upper-triangular square-root information factor.
//
// These are the numerical kernels of the SRI filter (sri_filter.hpp); they are public so that
// they can be tested and benchmarked on their own. All matrices are row-major views with an
// arbitrary row stride (the filter keeps R in a larger buffer).
//
// Kernels:
// - householderRowUpdate: QR of [R r; W z] where R (k×k) is upper triangular and the rows of W
//   are sorted by their first non-zero column ("lead"). Householder reflectors in the compact WY
//   form Q = I − V T Vᵀ (Schreiber & Van Loan 1989) specialised to the triangular-over-
//   pentagonal structure (V = [I; V_W], as in LAPACK's xTPQRT): a reflector for column j only
//   involves row j of R and the rows of W whose lead is ≤ j. Panels of 4 reflectors are applied
//   to the trailing columns by a register-blocked SIMD kernel (one pass over W per panel for
//   Z = X + V_Wᵀ W, one for W −= V_W TᵀZ).
// - givensRowUpdate: the same factorization with Givens rotations between row j of R and each
//   active row of W. About 1.5× the flops of Householder and no level-3 operations, but each
//   rotation only combines two rows with coefficients c, s ∈ [−1, 1]; light rows are never
//   formed as the difference of heavy ones, which keeps it accurate in float when rows of very
//   different weight meet (row-wise stability, cf. Cox & Higham 1998; Householder QR needs row
//   sorting/pivoting for that, Powell & Reid 1969). See docs/sri_core.md for the measurement.
// - sweepColumnsToFront: re-triangularization after moving a block of d columns to an earlier
//   position, with one chain of d adjacent-row Givens rotations per row passed over
//   (Golub & Van Loan, Matrix Computations, 4th ed., §6.5 on updating QR after column
//   permutations). This is how blocks that are not in front get marginalized. The chains of
//   two consecutive rows are applied in one pass over the columns (each row loaded and stored
//   once per pair).
#pragma once

#include <cmath>
#include <span>

#include <Eigen/Core>

namespace gvins::sri {

template <typename Scalar>
using RowMatrix = Eigen::Matrix<Scalar, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
template <typename Scalar>
using RowMatrixView = Eigen::Map<RowMatrix<Scalar>, Eigen::Unaligned, Eigen::OuterStride<>>;
template <typename Scalar>
using VectorView = Eigen::Map<Eigen::Matrix<Scalar, Eigen::Dynamic, 1>>;

/// Givens rotation [c s; −s c] with −s·a + c·b = 0 and c·a + s·b = ρ = hypot(a, b) ≥ 0 for
/// b ≠ 0 (Golub & Van Loan, Algorithm 5.1.3, scaled against overflow); for b = 0 the identity
/// (ρ = a keeps its sign; the sign of a row of R is free). Returns ρ.
template <typename Scalar>
inline Scalar makeGivens(Scalar a, Scalar b, Scalar& c, Scalar& s) {
  if (b == Scalar(0)) {
    c = Scalar(1);
    s = Scalar(0);
    return a;
  }
  const Scalar aa = std::abs(a);
  const Scalar ab = std::abs(b);
  Scalar rho;
  if (ab > aa) {
    const Scalar t = a / b;
    rho = ab * std::sqrt(Scalar(1) + t * t);
  } else {
    const Scalar t = b / a;
    rho = aa * std::sqrt(Scalar(1) + t * t);
  }
  c = a / rho;
  s = b / rho;
  return rho;
}

/// Which orthogonal transformations an update uses.
enum class RotationScheme : unsigned char {
  kAuto,                ///< Householder unless the row scales are far apart (SriOptions).
  kBlockedHouseholder,  ///< Fastest.
  kGivens,              ///< Row-wise stable for stiff weightings.
};

/// QR of [R r; W z] → [R' r'; 0 e] by blocked Householder reflections.
/// - R: k×k upper triangular (entries below the diagonal must be zero), r: k.
/// - W: m×k, z: m. Rows sorted so that lead[i] (first column that may be non-zero in row i;
///   k for an all-zero row) is non-decreasing.
/// On return R, r hold R', r'; the contents of W are unspecified and z holds the post-update
/// residuals: ‖z‖² is the rows' contribution to the least-squares cost,
/// i.e. the chi-square of the update (see sri_filter.hpp).
template <typename Scalar>
void householderRowUpdate(RowMatrixView<Scalar> R, VectorView<Scalar> r, RowMatrixView<Scalar> W,
                          VectorView<Scalar> z, std::span<const int> lead);

/// Same factorization as householderRowUpdate with Givens rotations (panels of 4 columns whose
/// rotations are applied to the trailing columns in one register-blocked pass).
template <typename Scalar>
void givensRowUpdate(RowMatrixView<Scalar> R, VectorView<Scalar> r, RowMatrixView<Scalar> W,
                     VectorView<Scalar> z, std::span<const int> lead);

/// R (n×n upper triangular), r (n). Moves the d columns [c, c+d) to position t ≤ c in the
/// elimination order and re-triangularizes, keeping the physical column order: on return
/// - rows < t and rows ≥ c+d are unchanged;
/// - rows t..t+d−1 are the rows of the moved block in the new order: upper triangular within the
///   physical columns [c, c+d), and dense in the later columns of the new order ([t, c), ≥ c+d);
/// - row t+d+q (0 ≤ q < c−t) starts at physical column t+q and is zero in [c, c+d).
/// Cost ≈ 6·d·Σᵢ (n − i) flops over the c − t rows passed over.
template <typename Scalar>
void sweepColumnsToFront(RowMatrixView<Scalar> R, VectorView<Scalar> r, int c, int d, int t);

extern template void householderRowUpdate<float>(RowMatrixView<float>, VectorView<float>,
                                                 RowMatrixView<float>, VectorView<float>,
                                                 std::span<const int>);
extern template void householderRowUpdate<double>(RowMatrixView<double>, VectorView<double>,
                                                  RowMatrixView<double>, VectorView<double>,
                                                  std::span<const int>);
extern template void givensRowUpdate<float>(RowMatrixView<float>, VectorView<float>,
                                            RowMatrixView<float>, VectorView<float>,
                                            std::span<const int>);
extern template void givensRowUpdate<double>(RowMatrixView<double>, VectorView<double>,
                                             RowMatrixView<double>, VectorView<double>,
                                             std::span<const int>);
extern template void sweepColumnsToFront<float>(RowMatrixView<float>, VectorView<float>, int, int,
                                                int);
extern template void sweepColumnsToFront<double>(RowMatrixView<double>, VectorView<double>, int,
                                                 int, int);

}  // namespace gvins::sri
