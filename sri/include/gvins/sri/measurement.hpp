// A linearized measurement for the SRI filter: Jacobian blocks w.r.t. named state blocks, the
// residual r = z − h(x̂), optional nuisance columns (not in the state, e.g. an MSCKF feature
// position), noise whitening, null-space projection of the nuisance and QR compression.
//
//   Measurement<double> m(2);                  // two rows
//   m.jacobian(clone_id, 6) = H_clone;        // 2×6, error-state columns of the block
//   m.jacobian(extrinsic_id, 6) = H_ext;
//   m.residual() = z - h;                     // 2 entries
//   m.whitenStdDev(1.5);                      // pixel noise σ: rows ← rows / σ
//   filter.update(m);
#pragma once

#include <span>
#include <vector>

#include <Eigen/Core>

#include "gvins/sri/block.hpp"

namespace gvins::sri {

template <typename Scalar>
class Measurement {
 public:
  using Matrix = Eigen::Matrix<Scalar, Eigen::Dynamic, Eigen::Dynamic>;
  /// The stacked Jacobian's storage: row-major, so that the row operations of the null-space
  /// projection, the compression and the filter update (which copies rows into its row-major
  /// work matrix) run on contiguous memory.
  using JacobianMatrix = Eigen::Matrix<Scalar, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
  using Vector = Eigen::Matrix<Scalar, Eigen::Dynamic, 1>;

  explicit Measurement(int rows = 0) { reset(rows); }

  /// Forgets everything and sets the number of rows.
  void reset(int rows);
  int rows() const { return static_cast<int>(residual_.size()); }

  /// Jacobian w.r.t. a state block, rows() × dim (error-state columns with the block's
  /// convention, block.hpp). Zero on first access; later calls return the same columns and
  /// throw std::invalid_argument if `dim` differs.
  Eigen::Block<JacobianMatrix> jacobian(BlockId id, int dim);
  /// Declares block columns at once (one allocation, zero-initialised), appended in this order;
  /// blocks already present are kept (their dimension must match). Saves the reallocation that
  /// every new block costs in jacobian() when many blocks are stacked.
  void addBlocks(std::span<const BlockId> ids, std::span<const int> dims);
  /// Residual r = z − h(x̂) (rows() entries).
  Vector& residual() { return residual_; }
  const Vector& residual() const { return residual_; }
  /// Nuisance Jacobian (rows() × dim) of parameters that are not state blocks, e.g. the 3-D
  /// position of an MSCKF feature. Zero on first access; must be removed with
  /// projectNuisance() before the update.
  Eigen::Block<Matrix> nuisance(int dim);
  int nuisanceDim() const { return static_cast<int>(nuisance_.cols()); }
  const Matrix& nuisanceJacobian() const { return nuisance_; }

  /// Block columns, in insertion order.
  int numBlocks() const { return static_cast<int>(blocks_.size()); }
  BlockId blockId(int i) const { return blocks_[static_cast<std::size_t>(i)].id; }
  int blockDim(int i) const { return blocks_[static_cast<std::size_t>(i)].dim; }
  Eigen::Block<const JacobianMatrix> jacobianAt(int i) const {
    const Entry& e = blocks_[static_cast<std::size_t>(i)];
    return H_.block(0, e.col, rows(), e.dim);
  }
  Eigen::Block<JacobianMatrix> jacobianAt(int i) {
    const Entry& e = blocks_[static_cast<std::size_t>(i)];
    return H_.block(0, e.col, rows(), e.dim);
  }
  /// Rotates rows a and b (Jacobians, nuisance and residual) by the Givens rotation
  /// [row a; row b] ← [c s; −s c] [row a; row b]; whitened rows stay whitened.
  void rotateRows(int a, int b, Scalar c, Scalar s);
  /// All block columns side by side (rows() × Σ dims), in insertion order.
  const JacobianMatrix& stackedJacobian() const { return H_; }

  // --- Noise. The filter needs unit-covariance rows; one of these must be called once.
  /// Rows already have unit noise covariance.
  void setWhitened() { whitened_ = true; }
  /// Noise covariance σ² I: rows ← rows / σ.
  void whitenStdDev(Scalar sigma);
  /// Independent noise with standard deviations σᵢ: row i ← row i / σᵢ.
  void whitenStdDevs(const Vector& sigmas);
  /// Full noise covariance Σ = L Lᵀ (Cholesky): rows ← L⁻¹ rows. Throws std::invalid_argument if Σ
  /// is not positive definite.
  void whitenCovariance(const Matrix& covariance);
  /// Square-root information S (SᵀS = Σ⁻¹, rows() × rows()): rows ← S rows.
  void whitenSqrtInformation(const Matrix& sqrtInformation);
  bool isWhitened() const { return whitened_; }

  // --- Compression (rows must be whitened first; orthogonal transforms keep them white).
  /// Projects the rows onto the left null space of the nuisance Jacobian with Givens rotations
  /// (MSCKF, Mourikis & Roumeliotis 2007): the nuisance columns are triangularized from the
  /// bottom up and the top nuisanceDim() rows, which carry all the information about the
  /// nuisance, are dropped. The nuisance Jacobian must have full column rank. Returns the number
  /// of rows removed. Throws std::logic_error if not whitened.
  ///
  /// `nuisanceRows` (optional) receives the removed rows Q₁ᵀ[N H r]: the nuisance columns as an
  /// upper-triangular q × q factor, the same block columns and the residual, whitened (all rows
  /// when rows() ≤ q). With them the information about the nuisance is kept: a new state block
  /// for it is initialised by these q rows alone (chain rule onto its parameters), since the
  /// projected rows are orthogonal to every Jacobian in the nuisance's column space.
  ///
  /// `how`: kGivens (default) rotates adjacent rows and skips the leading zeros of each row, which
  /// suits sparse rows (MSCKF: each observation on its own clone); kHouseholder reflects all rows
  /// at once per nuisance column (q reflections instead of about q·m rotations, each a square root
  /// and divisions that wait for the previous one), for dense rows such as the GNSS rows with the
  /// IMU integration noise as nuisance. Same information either way (an orthogonal transform).
  enum class NuisanceProjection { kGivens, kHouseholder };
  int projectNuisance(Measurement* nuisanceRows = nullptr, NuisanceProjection how = NuisanceProjection::kGivens);
  /// If rows() exceeds the number of state columns p, replaces [H r] by the first p rows of its
  /// QR factorization (Householder): the update is unchanged; the residual of the dropped rows,
  /// which no state can explain, is kept in discardedChiSquare(). Throws std::logic_error if not
  /// whitened or nuisance columns remain. Returns the number of rows removed.
  int compress();
  /// Appends the rows of another measurement (same whitening state; blocks are matched by id,
  /// nuisance columns are not allowed in either).
  void stack(const Measurement& other);

  /// Chi-square contribution and number of rows removed by compress().
  Scalar discardedChiSquare() const { return discarded_chi2_; }
  int discardedRows() const { return discarded_rows_; }

 private:
  struct Entry {
    BlockId id;
    int col = 0;
    int dim = 0;
  };
  template <typename Op>
  void transformRows(Op&& op);

  JacobianMatrix H_;  // rows × Σ block dims
  Matrix nuisance_;  // rows × nuisance dim
  Vector residual_;
  std::vector<Entry> blocks_;
  bool whitened_ = false;
  Scalar discarded_chi2_ = 0;
  int discarded_rows_ = 0;
};

extern template class Measurement<float>;
extern template class Measurement<double>;

}  // namespace gvins::sri
