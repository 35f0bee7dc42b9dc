// The GNSS antenna lever arm ^I p_r (m, the antenna in the IMU frame) of the GNSS fusion: with
// calibrate_lever_arm one client block of size 3, the prior N(start, σ² I) at its creation and
// constant (no propagation, no marginalization while the estimator's state lives); without it
// the configured value. GnssLeverArmState owns that block: creation, prior, value, and what
// carries over when the estimator starts a new state (its blocks are gone): the last estimate
// when it is within 3 prior σ (per axis) of the configured value, else the value the block
// started from (a state that ran away does not pass its lever arm on).
#pragma once

#include <optional>

#include <Eigen/Core>

#include "gvins/sri/block.hpp"
#include "gvins/vio/estimator_backend.hpp"

namespace gvins::fusion {

template <typename Scalar>
class GnssLeverArmState {
 public:
  /// `configured`: the lever arm of the configuration (the first block's start value and the
  /// centre of the carry-over test); `sigma`: the block's prior σ per axis (m).
  GnssLeverArmState(const Eigen::Vector3d& configured, double sigma)
      : configured_(configured), sigma_(sigma), start_(configured) {}

  /// Whether the block exists.
  bool valid() const { return block_.valid(); }
  sri::BlockId block() const { return block_; }
  /// The value the next block starts from (also the lever arm of a start without the block).
  const Eigen::Vector3d& start() const { return start_; }

  /// Adds the block unless it exists: estimate start(), prior σ per axis.
  void create(vio::EstimatorBackend<Scalar>& est);
  /// The lever arm: the block's estimate when the block exists and `est` (the state it belongs
  /// to) is given, else carried().
  Eigen::Vector3d value(const vio::EstimatorBackend<Scalar>* est) const;
  /// Keeps the block's estimate (after each epoch) for the carry-over; nothing without a block.
  void record(const vio::EstimatorBackend<Scalar>& est);
  /// The last recorded estimate when within 3 prior σ per axis of the configured value, else start().
  Eigen::Vector3d carried() const;
  /// Forgets the block (the estimator's state is gone): the next one starts from carried().
  void forget();

 private:
  Eigen::Vector3d configured_;
  double sigma_;
  Eigen::Vector3d start_;                 // before/at the block's creation
  std::optional<Eigen::Vector3d> last_;   // the block's estimate after the last epoch
  sri::BlockId block_;
};

extern template class GnssLeverArmState<float>;
extern template class GnssLeverArmState<double>;

}  // namespace gvins::fusion
