// The paper's IMU integration terms gamma, beta, alpha between two times (Sec. III-C, after
// Forster et al., "On-Manifold Preintegration", IEEE T-RO 2017), their Jacobians w.r.t. the
// biases and their noise covariance Sigma_g, and the prediction of the navigation state at an
// earlier (delayed GNSS) time from the newest IMU state.
//
// Over [t_a, t_b] with bias linearisation points (bg, ba) and no gravity:
//   gamma = R_{I_a I_b}                          rotation of I_b in I_a
//   beta  = int R_{I_a I(t)} (a(t) - ba) dt      velocity change in I_a
//   alpha = int int R_{I_a I(s)} (a(s) - ba)     position change in I_a
// so that (g the gravity vector in W, dt = t_b - t_a)
//   R_b = R_a gamma,  v_b = v_a + g dt + R_a beta,  p_b = p_a + v_a dt + g dt^2/2 + R_a alpha,
// and, solved for the earlier time (paper eq. "integrate_meas", a = GNSS time k, b = state i):
//   R_a = R_b gamma^T,  v_a = v_b - g dt - R_a beta,  p_a = p_b - v_a dt - g dt^2/2 - R_a alpha.
// The terms are computed with exactly the step scheme of ImuPropagator (imu_propagation.hpp),
// so these identities hold to rounding error.
//
// Error convention of the terms (9-vector, order ImuIntegrationErr, mirrors ImuErr):
//   gamma_true = gamma Exp(d_gamma),  alpha_true = alpha + d_alpha,  beta_true = beta + d_beta.
// Sigma_g is the covariance of that vector due to the gyro/accel white noise (held over each
// step with covariance sigma^2/h as in the propagator). The biases are treated as constant over
// the window (their random walk over a GNSS delay of < 1 s is not included).
#pragma once

#include <cstdint>
#include <span>

#include <Eigen/Core>

#include "gvins/vio/imu_noise.hpp"
#include "gvins/vio/imu_sample.hpp"
#include "gvins/vio/imu_state.hpp"

namespace gvins::vio {

struct ImuIntegrationErr {
  static constexpr int kGamma = 0;
  static constexpr int kAlpha = 3;
  static constexpr int kBeta = 6;
  static constexpr int kDim = 9;
};

class ImuIntegration {
 public:
  ImuIntegration() = default;
  ImuIntegration(const ImuNoise& noise, const Eigen::Vector3d& bg, const Eigen::Vector3d& ba);

  /// Integrates the samples over [t_from, t_to] (t_from <= t_to), replacing any previous result.
  /// Sample coverage and ordering as for ImuPropagator::propagate(); throws std::invalid_argument.
  void integrate(std::span<const ImuSample> samples, std::int64_t t_from_ns, std::int64_t t_to_ns);
  /// Continues the integration from tTo() to t_to_ns (>= tTo()) with the same step scheme, so the
  /// terms from one time to each of a window's frames cost one pass over its samples. The sample
  /// interval holding the old tTo() is integrated in two parts, which differs from
  /// integrate(samples, tFrom(), t_to_ns) by the scheme's truncation error over that interval.
  /// Backwards in time or beyond the samples: std::invalid_argument, as integrate().
  void extend(std::span<const ImuSample> samples, std::int64_t t_to_ns);
  /// Sample intervals integrated since the last integrate() (a work count for the callers' tests).
  std::int64_t intervals() const { return intervals_; }

  std::int64_t tFrom() const { return t0_; }
  std::int64_t tTo() const { return t1_; }
  double dt() const { return static_cast<double>(t1_ - t0_) * 1e-9; }
  const Eigen::Matrix3d& gamma() const { return gamma_; }
  const Eigen::Vector3d& beta() const { return beta_; }
  const Eigen::Vector3d& alpha() const { return alpha_; }
  const Eigen::Vector3d& bg() const { return bg_; }
  const Eigen::Vector3d& ba() const { return ba_; }

  /// d [d_gamma, d_alpha, d_beta] / d [bg, ba]  (9x6), at the linearisation biases.
  const Eigen::Matrix<double, 9, 6>& biasJacobian() const { return jBias_; }
  /// Sigma_g: covariance of [d_gamma, d_alpha, d_beta] (9x9).
  const Eigen::Matrix<double, 9, 9>& covariance() const { return cov_; }

  /// First-order corrections of the terms for other biases (Forster et al. 2017, eq. 44).
  Eigen::Matrix3d gammaFor(const Eigen::Vector3d& bg) const;
  Eigen::Vector3d alphaFor(const Eigen::Vector3d& bg, const Eigen::Vector3d& ba) const;
  Eigen::Vector3d betaFor(const Eigen::Vector3d& bg, const Eigen::Vector3d& ba) const;

 private:
  ImuNoise noise_;
  Eigen::Vector3d bg_ = Eigen::Vector3d::Zero(), ba_ = Eigen::Vector3d::Zero();
  std::int64_t t0_ = 0, t1_ = 0;
  std::int64_t intervals_ = 0;
  Eigen::Matrix3d gamma_ = Eigen::Matrix3d::Identity();
  Eigen::Vector3d beta_ = Eigen::Vector3d::Zero(), alpha_ = Eigen::Vector3d::Zero();
  Eigen::Matrix<double, 9, 6> jBias_ = Eigen::Matrix<double, 9, 6>::Zero();
  Eigen::Matrix<double, 9, 9> cov_ = Eigen::Matrix<double, 9, 9>::Zero();
};

/// Navigation state at the earlier time t_a of an integration that ends at the newest state.
struct EarlierImuState {
  std::int64_t t_ns = 0;
  Eigen::Matrix3d R_WI = Eigen::Matrix3d::Identity();
  Eigen::Vector3d p_WI = Eigen::Vector3d::Zero();
  Eigen::Vector3d v_WI = Eigen::Vector3d::Zero();
  /// d [dtheta_a, dp_a, dv_a] / d (newest 15-dim error state, ImuErr order). Same error
  /// convention at both times (imu_state.hpp).
  Eigen::Matrix<double, 9, 15> H = Eigen::Matrix<double, 9, 15>::Zero();
  /// d [dtheta_a, dp_a, dv_a] / d [d_gamma, d_alpha, d_beta].
  Eigen::Matrix<double, 9, 9> G = Eigen::Matrix<double, 9, 9>::Zero();
  /// G Sigma_g G^T: covariance of the earlier state's error due to integration noise (to be
  /// added to the GNSS measurement covariance through the measurement Jacobian, paper Sec. III-C).
  Eigen::Matrix<double, 9, 9> covariance = Eigen::Matrix<double, 9, 9>::Zero();
};

/// Predicts pose and velocity at integ.tFrom() from `newest` (whose t_ns must equal integ.tTo(),
/// else std::invalid_argument). The newest state's biases are used through the first-order bias
/// correction of the terms; re-integrate when they moved far from integ.bg()/ba().
EarlierImuState predictEarlierState(const ImuState& newest, const ImuIntegration& integ,
                                    const Eigen::Vector3d& gravity);

}  // namespace gvins::vio
