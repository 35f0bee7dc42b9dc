// The inertial navigation state and its error-state convention.
//
// Frames: W is a gravity-aligned local world frame (z up, gravity = (0, 0, -g)); I is the IMU
// frame (EuRoC's sensor frame S of imu0). R_WI rotates IMU-frame vectors into W, p_WI and v_WI are
// the IMU position and velocity in W.
//
// Error state (15-dimensional, in this order; see ImuErr for indices):
//   R_WI = R_WI_est * Exp(dtheta)   (local, IMU-frame rotation error; Forster et al. 2017)
//   p_WI = p_est + dp,  v_WI = v_est + dv,  bg = bg_est + dbg,  ba = ba_est + dba.
#pragma once

#include <cstdint>

#include <Eigen/Core>

namespace gvins::vio {

struct ImuState {
  std::int64_t t_ns = 0;
  Eigen::Matrix3d R_WI = Eigen::Matrix3d::Identity();
  Eigen::Vector3d p_WI = Eigen::Vector3d::Zero();
  Eigen::Vector3d v_WI = Eigen::Vector3d::Zero();
  Eigen::Vector3d bg = Eigen::Vector3d::Zero();  ///< gyroscope bias, rad/s
  Eigen::Vector3d ba = Eigen::Vector3d::Zero();  ///< accelerometer bias, m/s^2
};

/// Offsets of the error-state blocks (each 3-dimensional).
struct ImuErr {
  static constexpr int kTheta = 0;
  static constexpr int kPos = 3;
  static constexpr int kVel = 6;
  static constexpr int kBg = 9;
  static constexpr int kBa = 12;
  static constexpr int kDim = 15;
};

using Matrix15d = Eigen::Matrix<double, 15, 15>;
using Vector15d = Eigen::Matrix<double, 15, 1>;

/// Applies an error-state correction with the convention above.
void boxPlus(ImuState& state, const Vector15d& delta);
/// Error state d such that boxPlus(estimate, d) == truth (orientation via SO(3) Log).
Vector15d boxMinus(const ImuState& truth, const ImuState& estimate);

}  // namespace gvins::vio
