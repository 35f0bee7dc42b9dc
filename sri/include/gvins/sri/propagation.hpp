// Description of a propagation step for SriFilter::propagate (paper, Sec. II-A, eq. (8); eq. (21) for the receiver clocks).
//
// New blocks x_new (e.g. the next IMU pose clone and IMU extra state) follow the linearized
// process model in error state
//     δx_new = Σ_b Φ_b δx_b + e + G w,   w ~ N(0, Q),   Q' = G Q Gᵀ,
// where the sum runs over existing blocks b and e = f(x̂_old) ⊟ x̂_new is the prediction residual
// (zero when x̂_new = f(x̂_old), the usual case). With S = Q'^(−½) (SᵀS = Q'⁻¹) the filter appends
// the block row
//     [ S Φ_b1 … S Φ_bk   −S ]  with right-hand side  −S e
// below [R r] (the paper's V₁ and −Q'^(−½)), re-triangularizes only the columns from the first
// one touched, and then marginalizes the blocks listed in `marginalize` (e.g. the old IMU extra
// state).
#pragma once

#include <utility>
#include <vector>

#include <Eigen/Core>

#include "gvins/sri/block.hpp"
#include "gvins/sri/block_estimate.hpp"
#include "gvins/sri/state_layout.hpp"

namespace gvins::sri {

template <typename Scalar>
class Propagation {
 public:
  using Matrix = Eigen::Matrix<Scalar, Eigen::Dynamic, Eigen::Dynamic>;
  using Vector = Eigen::Matrix<Scalar, Eigen::Dynamic, 1>;

  struct NewBlock {
    BlockSpec spec;
    BlockEstimate<Scalar> estimate;  ///< Predicted value x̂_new.
    Placement placement;
  };

  /// Adds a new block; x_new stacks the new blocks in the order they are added. Returns the
  /// block's first row in x_new.
  int addNewBlock(const BlockSpec& spec, const BlockEstimate<Scalar>& predicted,
                  Placement placement = Placement::back()) {
    const int row = dim_;
    blocks_.push_back({spec, predicted, placement});
    dim_ += spec.dim;
    return row;
  }
  /// Φ_b: columns of the transition w.r.t. an existing block (dim() × dim of the block).
  void setTransition(BlockId existing, const Matrix& phi) { phis_.emplace_back(existing, phi); }
  /// Noise covariance Q' (dim() × dim(), positive definite).
  void setNoiseCovariance(const Matrix& q) {
    noise_ = q;
    noise_is_sqrt_info_ = false;
  }
  /// Noise square-root information S with SᵀS = Q'⁻¹ (dim() × dim()).
  void setNoiseSqrtInformation(const Matrix& s) {
    noise_ = s;
    noise_is_sqrt_info_ = true;
  }
  /// e = f(x̂_old) ⊟ x̂_new (dim() entries); zero if not set.
  void setResidual(const Vector& e) { residual_ = e; }
  /// Blocks to marginalize once the new rows are absorbed (e.g. the previous IMU extra state).
  void marginalizeAfter(BlockId id) { marginalize_.push_back(id); }

  int dim() const { return dim_; }
  const std::vector<NewBlock>& newBlocks() const { return blocks_; }
  const std::vector<std::pair<BlockId, Matrix>>& transitions() const { return phis_; }
  const Matrix& noise() const { return noise_; }
  bool noiseIsSqrtInformation() const { return noise_is_sqrt_info_; }
  const Vector& residual() const { return residual_; }
  const std::vector<BlockId>& marginalized() const { return marginalize_; }

 private:
  std::vector<NewBlock> blocks_;
  std::vector<std::pair<BlockId, Matrix>> phis_;
  Matrix noise_;
  bool noise_is_sqrt_info_ = false;
  Vector residual_;
  std::vector<BlockId> marginalize_;
  int dim_ = 0;
};

}  // namespace gvins::sri
