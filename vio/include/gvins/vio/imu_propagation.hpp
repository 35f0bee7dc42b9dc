// Inertial mean propagation on SO(3) x R^3 x R^3 and the error-state transition Phi with the
// discrete noise G Q G^T (paper Sec. II-A, after Trawny & Roumeliotis 2005; error state as in
// imu_state.hpp).
//
// Measurement assumption (the simulator generates data consistent with it):
//   A sample is the instantaneous angular rate / specific force at its time stamp. Between two
//   consecutive samples k and k+1 both signals follow the cubic polynomial through the samples
//   k-1, k, k+1, k+2 (Lagrange interpolation; time stamps need not be uniform). A neighbour
//   k-1 or k+2 is used only if it exists in the span passed in and its spacing is at most twice
//   that of [k, k+1] (so interpolation never reaches across a gap); with fewer neighbours the
//   quadratic through three samples or the straight line through k, k+1 is used. Pass samples up
//   to the second one after the end time for results independent of buffering.
//   Biases are constant during one propagate() call.
// One step over [t0, t0 + h] with w(t) = gyro(t) - bg and a(t) = accel(t) - ba:
//   rotation:  R(t0 + h) = R(t0) Exp(phi) with the 4th-order Magnus integrator on the two
//              Gauss-Legendre nodes tA,B = t0 + (1/2 -+ sqrt(3)/6) h (Blanes, Casas, Oteo & Ros,
//              "The Magnus expansion and some of its applications", Phys. Rep. 2009, sec. 5):
//              phi = h/2 (wA + wB) + sqrt(3)/12 h^2 (wA x wB); the midpoint rotation R(t0 + h/2)
//              uses the same formula on [t0, t0 + h/2];
//   velocity/position: classical RK4 of  v' = R(t) a(t) + g,  p' = v  with R(t) at t0, t0+h/2,
//              t0+h, i.e.  v1 = v0 + g h + h/6 (f0 + 4 fm + f1),
//                          p1 = p0 + v0 h + g h^2/2 + h^2/6 (f0 + 2 fm),  f = R(t) a(t).
// The scheme is 4th order: a smooth motion sampled at 200 Hz is reproduced to micrometres after
// 60 s (tests/vio/test_imu_propagation.cpp). A simulator that evaluates its continuous
// angular rate and specific force at the stamps is therefore consistent with it; one that needs
// agreement to rounding error defines its truth by integrating its noise-free samples with
// ImuPropagator.
//
// Noise: the white noise of the gyro/accel is held constant over one step with covariance
// sigma^2 / h (sigma the noise density, Kalibr convention); the bias random walks add
// sigma_b^2 h to the bias blocks per step. Phi is the exact Jacobian of the discrete scheme.
#pragma once

#include <cstdint>
#include <functional>
#include <span>

#include <Eigen/Core>

#include "gvins/vio/imu_noise.hpp"
#include "gvins/vio/imu_sample.hpp"
#include "gvins/vio/imu_state.hpp"

namespace gvins::vio {

/// The signal model over one step: 2 to 4 interpolation nodes (times in seconds relative to the
/// first node) and the step [t0, t0 + dt] in the same time axis.
struct ImuInterval {
  int nodes = 0;
  double tau[4] = {0, 0, 0, 0};
  Eigen::Vector3d gyro[4], accel[4];
  double t0 = 0.0;  ///< step start, seconds from the first node
  double dt = 0.0;  ///< step length, seconds

  /// Lagrange weights of the nodes at time t (same axis as tau).
  void weights(double t, double w[4]) const;
  Eigen::Vector3d gyroAt(double t) const;
  Eigen::Vector3d accelAt(double t) const;
};

/// Jacobians of one step w.r.t. the navigation error [dtheta, dp, dv] (order as ImuErr) and the
/// biases. Bg/Ba are also the inputs of the gyro/accel white noise held over the step (with
/// the measured-minus-bias sign they enter identically).
struct ImuStepJacobians {
  Eigen::Matrix<double, 9, 9> A;
  Eigen::Matrix<double, 9, 3> Bg;
  Eigen::Matrix<double, 9, 3> Ba;
};

/// One step of the navigation mean (R, p, v) in place; gravity is the gravity vector in W
/// (e.g. (0, 0, -9.81)). Pass gravity = 0 and R = I, p = v = 0 to integrate relative terms.
void integrateImuInterval(const ImuInterval& m, const Eigen::Vector3d& bg, const Eigen::Vector3d& ba,
                          const Eigen::Vector3d& gravity, Eigen::Matrix3d& R, Eigen::Vector3d& p,
                          Eigen::Vector3d& v, ImuStepJacobians* jacobians = nullptr);

/// The measurement model evaluated at time t (samples sorted and covering t): what the
/// propagator assumes the gyro and accelerometer read at t.
ImuSample interpolateImu(std::span<const ImuSample> samples, std::int64_t t_ns);

class ImuPropagator {
 public:
  /// `gravityMagnitude` in m/s^2; W is z-up, so the gravity vector is (0, 0, -g).
  explicit ImuPropagator(const ImuNoise& noise, double gravityMagnitude = 9.81);

  /// Propagates `state` from state.t_ns to t_end_ns (>= state.t_ns). `samples` must be sorted by
  /// strictly increasing time and cover the interval (first stamp <= state.t_ns, last stamp
  /// >= t_end_ns); measurements at the two ends are interpolated. Throws std::invalid_argument
  /// otherwise. Optionally returns the 15x15 transition Phi and discrete noise Qd = sum of
  /// Phi_j G_j Q_j G_j^T Phi_j^T over the steps (so that dx_end = Phi dx_start + w, Cov(w) = Qd).
  void propagate(ImuState& state, std::span<const ImuSample> samples, std::int64_t t_end_ns,
                 Matrix15d* Phi = nullptr, Matrix15d* Qd = nullptr) const;

  const ImuNoise& noise() const { return noise_; }
  const Eigen::Vector3d& gravity() const { return gravity_; }

 private:
  ImuNoise noise_;
  Eigen::Vector3d gravity_;
};

/// Calls fn(const ImuInterval&) for every step between t0_ns and t1_ns (t0 <= t1): the steps
/// end at the sample stamps strictly inside the interval and at t1. Validates coverage and
/// ordering as described for ImuPropagator::propagate() (std::invalid_argument).
void forEachImuInterval(std::span<const ImuSample> samples, std::int64_t t0_ns, std::int64_t t1_ns,
                        const std::function<void(const ImuInterval&)>& fn);

}  // namespace gvins::vio
