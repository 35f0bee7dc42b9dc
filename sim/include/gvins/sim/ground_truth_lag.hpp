// Clock lag between a recording's ground truth and its IMU: the τ for which the real gyro (ground-
// truth bias removed) best matches the truth's angular rate, ω_gyro(t) ≈ ω_truth(t + τ), by least
// squares over the whole recording. A positive τ means the truth lags the IMU. Ground truth that
// is fused from motion capture and an IMU (EuRoC's state_groundtruth_estimate0) can carry such a
// lag of a millisecond or so; a camera simulated from that truth with offset t_d is then offset by
// t_d − τ on the IMU's clock.
#pragma once

#include <vector>

#include "gvins/sim/recorded_trajectory.hpp"

namespace gvins::sim {

/// Mean squared residual |ω_gyro(t) − b_g(t) − ω_truth(t + τ)|² [(rad/s)²], both averaged over
/// blocks of 10 samples (the airframe's vibration averages out), for τ = from, from +
/// step, ..., to (s), over the IMU samples at least 1 s inside the recording. Throws
/// std::invalid_argument for an empty or unordered grid or a recording shorter than 2 s + |τ|.
std::vector<double> gyroLagCost(const RecordedTrajectory& trajectory, double from, double to, double step);

/// The lag τ (s) that minimises gyroLagCost on a 0.25 ms grid within ±maxLag, refined by a parabola
/// through the grid minimum and its neighbours. Throws std::runtime_error when the minimum lies on
/// the edge of the grid (no lag within ±maxLag explains the data).
double gyroLag(const RecordedTrajectory& trajectory, double maxLag = 3e-3);

}  // namespace gvins::sim
