// Square-root inverse (SRI) filter over named state blocks — the estimation core of SRI-GVINS.
//
// The filter keeps an upper-triangular square-root information matrix R and a residual r: the
// (error-state) information is Λ = RᵀR and the cost of an error δx about the current estimate x̂
// is ‖R δx − r‖². It never forms a covariance (Wu et al. 2015, "A Square Root Inverse Filter for
// Efficient Vision-aided Inertial Navigation on Mobile Devices"; Bierman 1977, "Factorization
// Methods for Discrete Sequential Estimation"). The columns of R follow the order of the state
// blocks (StateLayout); that order is also the elimination order:
//   - marginalizing blocks that sit first costs nothing (their rows and columns are dropped);
//   - measurement rows whose first non-zero column is c₀ only touch the columns ≥ c₀;
//   - the covariance of the trailing blocks comes from the trailing block of R alone.
// So put what will be marginalized soon first and what measurements touch most last. For the
// SRI-SWF (paper eq. (1)) [SLAM features | clones, oldest first | parameters | IMU extra] keeps
// VIO updates cheap (rows start at the recent clones) while marginalizing the oldest clone
// costs a sweep over the feature rows; docs/sri_core.md has the measured trade-offs.
//
// Error-state conventions (block.hpp): vectors x = x̂ + δx; rotations R = R̂·Exp(δθ) (kRight,
// default) or Exp(δθ)·R̂ (kLeft), chosen per block; poses [δθ; δp] with p = p̂ + δp.
//
// Minimal example (a 3-D position with a velocity, a GNSS-like position fix):
//
//   using namespace gvins::sri;
//   SriFilter<double> f;
//   BlockId p = f.addBlock(BlockSpec::vector("pos", 3),
//                          BlockEstimate<double>::fromVector(Eigen::Vector3d(10, 0, 0)),
//                          Prior<double>::stdDev(3, 30.0));
//   BlockId v = f.addBlock(BlockSpec::vector("vel", 3), BlockEstimate<double>::zero(BlockKind::kVector, 3),
//                          Prior<double>::uninformative());
//   Measurement<double> z(3);
//   z.jacobian(p, 3).setIdentity();
//   z.residual() = fix - f.estimate(p).vector;   // z − h(x̂)
//   z.whitenStdDev(0.02);
//   if (auto c = f.chiSquare(z); c && c->value < chiSquareQuantile(0.99, c->dof)) {
//     f.update(z);
//     f.correct();                                // x̂ ← x̂ ⊞ R⁻¹r, r ← 0
//   }
//   Eigen::MatrixXd P = f.covariance(std::vector{p});  // 3×3 marginal covariance
//
// Propagation (paper eq. (8)) is described by a Propagation object (propagation.hpp);
// measurement rows by a Measurement (measurement.hpp), which also does null-space projection
// of nuisance columns and QR compression. docs/sri_core.md has the derivations.
//
// Scalar is float or double (both compiled into gvins_sri). Mixed precision: R, r, the rows and
// the solve are in Scalar, the nominal values (estimates) are always kept in double — a float
// filter stores a double copy, applies every correction to it in double and hands out its
// rounded value through estimate(). Nominal values can be far from zero (positions kilometres
// from the origin, clock biases) where float's resolution (1e-4 m at 1.5 km) would add a
// rounding error to every correction; the error state is small and float suffices for it.
// nominal() gives the double value, setNominal() sets it without moving r (measurements in
// docs/vio_estimator.md, "Float").
#pragma once

#include <limits>
#include <optional>
#include <span>
#include <vector>

#include <Eigen/Core>

#include "gvins/sri/block.hpp"
#include "gvins/sri/block_estimate.hpp"
#include "gvins/sri/chi_square.hpp"
#include "gvins/sri/measurement.hpp"
#include "gvins/sri/prior.hpp"
#include "gvins/sri/propagation.hpp"
#include "gvins/sri/qr_update.hpp"
#include "gvins/sri/state_layout.hpp"

namespace gvins::sri {

struct SriOptions {
  /// kAuto switches an update to Givens rotations when (largest entry of the new whitened rows)
  /// / (smallest non-zero row of R that the rows meet) exceeds auto_givens_ratio_float (float) or
  /// auto_givens_ratio_double (double). See docs/sri_core.md for the measurement behind these.
  double auto_givens_ratio_float = 1e3;
  double auto_givens_ratio_double = 1e10;
  /// A diagonal entry |R_jj| ≤ zero_pivot × max|R_ii| counts as no information in solve()
  /// (that error-state component is left at zero). 0: only exact zeros.
  double zero_pivot = 0.0;
  /// Id of the first block (then counting up, never reused). A filter that replaces another one
  /// whose ids may still be held somewhere (e.g. an estimator that starts again after a failure)
  /// starts at the old filter's nextBlockId(), so that a stale id never names a new block.
  std::uint64_t first_block_id = 1;
};

struct UpdateOptions {
  RotationScheme scheme = RotationScheme::kAuto;
  /// Innovation gate: when the rows' χ² (the post-fit ‖e‖² of the update, = the χ² of
  /// chiSquare()) exceeds this, the update is undone (the touched trailing block of [R r] is
  /// restored) and UpdateResult::applied is false. Not applied when a column from the first one
  /// the rows touch onwards has no information (zero pivot; chiSquare() has no value when such a
  /// column is touched or coupled). Costs one copy of the trailing block instead of
  /// chiSquare()'s solves.
  double max_chi2 = std::numeric_limits<double>::infinity();
};

template <typename Scalar>
struct UpdateResult {
  Scalar chi2 = 0;  ///< Post-fit residual ‖e‖² of the rows, = innovation Mahalanobis distance.
  int dof = 0;      ///< Rows (including rows removed by Measurement::compress).
  RotationScheme scheme = RotationScheme::kBlockedHouseholder;  ///< Scheme used.
  bool applied = true;  ///< False if UpdateOptions::max_chi2 rejected the rows.
};

template <typename Scalar>
struct ChiSquare {
  Scalar value = 0;  ///< rᵀ (H P Hᵀ + Σ)⁻¹ r for the predicted residual r.
  int dof = 0;
};

template <typename Scalar>
class SriFilter {
 public:
  using Matrix = Eigen::Matrix<Scalar, Eigen::Dynamic, Eigen::Dynamic>;
  using Vector = Eigen::Matrix<Scalar, Eigen::Dynamic, 1>;

  explicit SriFilter(SriOptions options = {});

  const SriOptions& options() const { return options_; }
  const StateLayout& layout() const { return layout_; }
  /// The id the next added block gets (SriOptions::first_block_id).
  std::uint64_t nextBlockId() const { return layout_.nextId(); }
  /// Error-state dimension.
  int dim() const { return n_; }
  /// Pre-allocates storage for a state of `dim` (the filter grows as needed otherwise).
  void reserve(int dim);

  // ---------------------------------------------------------------- state blocks
  /// Adds a block with the given estimate and a prior centred at it. Throws
  /// std::invalid_argument for an inconsistent spec, estimate or prior (e.g. covariance not
  /// positive definite), std::out_of_range for an unknown placement anchor.
  BlockId addBlock(const BlockSpec& spec, const BlockEstimate<Scalar>& estimate,
                   const Prior<Scalar>& prior, Placement where = Placement::back());
  /// Marginalizes blocks (Schur complement, exact in the linear-Gaussian case). Blocks at the
  /// front are dropped for free; others are first moved to the front by re-triangularizing
  /// (sweepColumnsToFront). Throws std::out_of_range for an unknown id.
  void marginalize(std::span<const BlockId> ids);
  void marginalize(BlockId id) { marginalize(std::span<const BlockId>(&id, 1)); }
  /// Exact change of variables of one block, without noise: its error state becomes
  /// δx' = A δx + Σ_j B_j δx_j over blocks j that all come after it in the order (e.g. a SLAM
  /// feature re-anchored to a later clone, or a pose re-expressed in another world frame whose
  /// offset is block j). R's columns are substituted (R_x A⁻¹, and R_j −= R_x A⁻¹ B_j) on the
  /// rows that see the block, its own dim rows are re-triangularized (Givens, O(dim²·n)), r is
  /// unchanged, and `estimate` becomes the block's value: no new block, no marginalization sweep.
  /// Any kind of block: for rotations and poses A and B_j are the caller's first-order maps of the
  /// error state (δθ, [δθ; δp]) at the new `estimate`. Throws std::invalid_argument for a
  /// singular or misshaped A or B_j, a B_j on a block at or before this one, or an estimate of
  /// another kind or size.
  void substitute(BlockId id, const Matrix& A, std::span<const std::pair<BlockId, Matrix>> B,
                  const BlockEstimate<double>& estimate);
  /// Changes the order of the blocks (`order` lists every block once) and re-triangularizes
  /// the columns after the unchanged prefix.
  void reorder(std::span<const BlockId> order);

  // ---------------------------------------------------------------- estimates
  /// The estimate in Scalar (for a float filter: the nominal() value rounded to float).
  const BlockEstimate<Scalar>& estimate(BlockId id) const;
  /// The estimate in double (the value the filter corrects; equal to estimate() for double).
  const BlockEstimate<double>& nominal(BlockId id) const;
  /// Replaces the double value of a block by one that rounds to the same Scalar value up to
  /// rounding (the exact value of an estimate that was passed in Scalar to addBlock or in a
  /// Propagation): R and r are not changed, i.e. the difference is not treated as a move of the
  /// linearization point. Throws std::invalid_argument for a wrong shape, or if `value` differs
  /// from the current value by more than `tolerance` (absolute per entry: vector entries, rotation
  /// angle in rad).
  void setNominal(BlockId id, const BlockEstimate<double>& value, double tolerance = 1e-2);
  /// Moves the linearization point of a block, keeping the estimated distribution: r is adjusted
  /// by −R δ with δ = value ⊟ old (first order for rotations).
  void setEstimate(BlockId id, const BlockEstimate<Scalar>& value);

  // ---------------------------------------------------------------- filter steps
  /// Appends the propagation block row of the paper's eq. (8) for new blocks, re-triangularizes
  /// and marginalizes the listed blocks. Returns the ids of the new blocks (in order added).
  std::vector<BlockId> propagate(const Propagation<Scalar>& step);
  /// Stacks the whitened rows [H r] under [R r] and re-triangularizes the columns from the first
  /// one they touch (the paper's eq. (12)). The estimate is not moved; call correct() (or keep
  /// stacking measurements first). Throws std::logic_error if the rows are not whitened or still
  /// have nuisance columns, std::out_of_range for an unknown block.
  UpdateResult<Scalar> update(const Measurement<Scalar>& m, const UpdateOptions& options = {});
  /// The rows of several measurements at once, as if stacked into one (the same result as
  /// update() of their stack, without forming it): parts may share blocks; dof and χ² are
  /// those of all rows.
  UpdateResult<Scalar> update(std::span<const Measurement<Scalar>> parts, const UpdateOptions& options = {});
  /// Mahalanobis distance of a candidate measurement without forming a covariance (triangular
  /// solve with the trailing block of R from the first touched column). nullopt if it touches
  /// state without information, or if the trailing block has a coupled zero pivot (see
  /// covariance()).
  std::optional<ChiSquare<Scalar>> chiSquare(const Measurement<Scalar>& m) const;
  /// Δx = R⁻¹ r by back-substitution. Components without information (zero pivots) get 0.
  Vector solve() const;
  /// x̂ ← x̂ ⊞ Δx with Δx = solve(), then r ← r − R Δx (= 0 when R is non-singular).
  void correct();

  // ---------------------------------------------------------------- covariance
  /// Joint marginal covariance of the listed blocks, in the listed order: Y = R⁻ᵀ E on the
  /// trailing part of R from the first listed block (forward substitution), P = YᵀY. Cheap for
  /// blocks at the back. Later blocks that carry no information and are not coupled (e.g. new,
  /// not yet observed) are ignored. Throws std::domain_error if a listed block has no
  /// information, or if a later column without information (zero pivot) is coupled to the rest:
  /// R alone then does not give the covariance (it would need a pseudo-inverse); give such
  /// blocks a weak prior instead of none, or marginalize them.
  Matrix covariance(std::span<const BlockId> ids) const;
  /// Whether covariance() and covarianceFactor() of the listed blocks are defined (do not
  /// throw): every listed block carries information and no later column without information is
  /// coupled to the rest. The query for callers that branch on it, e.g. on a new block with an
  /// uninformative prior that no row has reached yet.
  bool informed(std::span<const BlockId> ids) const;
  /// A factor F of the same marginal covariance, P = F Fᵀ, without forming P: the rows of
  /// R_t⁻¹ (R_t the informed trailing part of R from the first listed block, inverted column by
  /// column with forward substitutions, about k³/6 operations for k trailing columns) that belong
  /// to the listed blocks, in the listed order; F has one column per informed trailing column.
  /// When the listed blocks are consecutive in the state, in the listed order, from the first
  /// trailing column, the leading square part of F is upper triangular (rows of a block see only
  /// its own and later columns), so rows H that are zero on the first s columns need only
  /// F.bottomRightCorner(rows − s, cols − s). Same errors as covariance().
  Matrix covarianceFactor(std::span<const BlockId> ids) const;
  /// Full covariance R⁻¹R⁻ᵀ (for tests and debugging; O(n³)).
  Matrix fullCovariance() const;

  // ---------------------------------------------------------------- raw access
  /// R (n×n, zeros below the diagonal) and r, copied.
  Matrix squareRootInformation() const;
  Vector residual() const;
  /// Views of the internal storage; entries below the diagonal of R are unspecified.
  RowMatrixView<Scalar> rawR();
  VectorView<Scalar> rawResidual();

 private:
  int position(BlockId id) const { return layout_.index(id); }
  /// The block at `pos` takes `value` (the double value of a float filter, rounded for
  /// estimates_); R and r are not touched.
  void storeNominal(int pos, const BlockEstimate<double>& value);
  Scalar* rowPtr(int i) { return buf_.data() + static_cast<std::ptrdiff_t>(off_ + i) * ld_ + off_; }
  const Scalar* rowPtr(int i) const {
    return buf_.data() + static_cast<std::ptrdiff_t>(off_ + i) * ld_ + off_;
  }
  RowMatrixView<Scalar> view(int row, int col, int rows, int cols);
  Eigen::Map<const RowMatrix<Scalar>, Eigen::Unaligned, Eigen::OuterStride<>> cview(int row, int col,
                                                                                  int rows,
                                                                                  int cols) const;
  VectorView<Scalar> rview(int row, int rows) { return VectorView<Scalar>(rbuf_.data() + off_ + row, rows); }

  /// Opens d zero rows/columns at column c (storage only).
  void openColumns(int c, int d);
  /// Storage is recentred/grown so that `need` columns fit with headroom.
  void relocate(int need);
  /// Drops rows [0, d) and columns [c, c+d) after sweepColumnsToFront(c, d, 0).
  void dropFrontAfterSweep(int c, int d);
  bool hasZeroPivot(int from) const;
  using ConstView = Eigen::Map<const RowMatrix<Scalar>, Eigen::Unaligned, Eigen::OuterStride<>>;
  /// The trailing factor R[c:, c:] without the columns that carry no information and are not
  /// coupled to any other (e.g. a new block with an uninformative prior): those do not change
  /// any covariance or chi-square of the others. `keep` lists the kept columns (relative to c);
  /// `copy` holds the reduced factor when one was needed. nullopt if a column without
  /// information is coupled to the others (see covariance()).
  std::optional<ConstView> informedTrailing(int c, std::vector<int>& keep, RowMatrix<Scalar>& copy) const;
  // The informed trailing factor from the first listed block (nullopt: no columns listed) and
  // the position in it of every listed column, in order; the errors of covariance() (`who`).
  std::optional<ConstView> listedTrailing(std::span<const BlockId> ids, const char* who, std::vector<int>& columns,
                                          RowMatrix<Scalar>& copy) const;

  SriOptions options_;
  StateLayout layout_;
  std::vector<BlockEstimate<Scalar>> estimates_;  // parallel to layout_.blocks()
  std::vector<BlockEstimate<double>> nominal_;    // float filters only: double values, parallel
  RowMatrix<Scalar> buf_;                         // cap_ × ld_, R at (off_, off_)
  Vector rbuf_;                                   // cap_, r at off_
  int cap_ = 0;
  // Row stride: cap_ rounded up to an odd number of 64-byte cache lines. With a power-of-two
  // stride (e.g. 512 doubles, 4 KiB) the rows that a sweep or an update rotates together all map
  // to the same L1 cache set and evict each other.
  int ld_ = 0;
  int off_ = 0;
  int n_ = 0;
  // Update workspace.
  RowMatrix<Scalar> work_;
  RowMatrix<Scalar> gate_backup_;  // update(): trailing [R r] while max_chi2 is tested
  Vector work_z_;
  std::vector<int> lead_;
};

extern template class SriFilter<float>;
extern template class SriFilter<double>;

}  // namespace gvins::sri
