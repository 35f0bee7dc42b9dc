// The zenith wet delay state of the GNSS fusion (vio+dopp+ppp, or estimate_zwd): the residual of
// the wet delay about the troposphere model, m, as one client block of size 1 with the prior
// N(0, σ²) at its creation and a random walk stepped at every GNSS epoch (docs/gnss_fusion.md,
// "Float PPP"). GnssZwdState owns that block: creation, prior, propagation, value and removal.
#pragma once

#include "gvins/base/gnss_time.hpp"
#include "gvins/sri/block.hpp"
#include "gvins/vio/estimator_backend.hpp"

namespace gvins::fusion {

template <typename Scalar>
class GnssZwdState {
 public:
  /// Whether the block exists.
  bool valid() const { return block_.valid(); }
  sri::BlockId block() const { return block_; }
  /// The time the block refers to (its creation or its last random-walk step).
  const GpsTime& time() const { return time_; }

  /// Adds the block at time t: estimate 0 (the model's wet delay), prior σ `sigma` (m).
  void create(vio::EstimatorBackend<Scalar>& est, const GpsTime& t, double sigma);
  /// The block at time t (no step backwards): one random-walk step of variance q²·Δt with q
  /// `randomWalk` (m/√s) and Δt the time since time(); the estimate stays.
  void propagate(vio::EstimatorBackend<Scalar>& est, const GpsTime& t, double randomWalk);
  /// The estimate (m; valid() only).
  double value(const vio::EstimatorBackend<Scalar>& est) const;
  /// Marginalizes the block (an outage).
  void marginalize(vio::EstimatorBackend<Scalar>& est);
  /// Forgets the block (the estimator's state is gone).
  void forget() { block_ = {}; }

 private:
  sri::BlockId block_;
  GpsTime time_;
};

extern template class GnssZwdState<float>;
extern template class GnssZwdState<double>;

}  // namespace gvins::fusion
