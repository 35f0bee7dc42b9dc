// Private: the zero-velocity update of the SRI-SWF estimator at a detected standstill.
#pragma once

#include <deque>

#include "swf_state.hpp"

namespace gvins::vio::detail {

/// At a standstill (the static test of the initialisation over the last init_window: IMU
/// spread and median parallax; the IMU alone when too few features are tracked and
/// init_static_without_tracks) adds the rows v = 0 (σ = zero_velocity_sigma) and p_k − p_{k−1}
/// = 0 (σ · frame interval) on the newest velocity and the two newest clones, gated by χ².
/// Without it a mono rig at rest has no triangulable features and drifts with the IMU.
template <typename Scalar>
class ZeroVelocityUpdater {
 public:
  /// Adds `frame` (its IMU time; the newest clone is its pose, `previous_pose` the one before)
  /// to the recent frames and, when zero_velocity_update is on and the rig stands still,
  /// applies the update. Returns whether it was applied.
  bool update(SwfState<Scalar>& s, const FeatureFrame& frame, sri::BlockId previous_pose);

 private:
  std::deque<FeatureFrame> recent_;  // frames of the last 1.5 init_window
};

extern template class ZeroVelocityUpdater<float>;
extern template class ZeroVelocityUpdater<double>;

}  // namespace gvins::vio::detail
