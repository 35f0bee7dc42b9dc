// Private: IMU propagation of the SRI-SWF estimator to a new frame (paper eq. (8)).
#pragma once

#include <cstdint>

#include "swf_state.hpp"

namespace gvins::vio::detail {

/// Propagates the newest IMU state to `t` (the frame's IMU time): appends the block row of the
/// transition Φ and noise G Q Gᵀ (ImuPropagator; first-estimate Φ, applyFirstEstimates); the
/// new pose block is the frame's clone, the previous velocity block (and, every
/// imu_bias_renewal seconds, the bias block) is marginalized.
template <typename Scalar>
void propagateToFrame(SwfState<Scalar>& s, std::int64_t t);

}  // namespace gvins::vio::detail
