// A state to start the estimator from that comes from outside the visual-inertial
// initialisation (e.g. a GNSS/INS alignment in fusion/): the IMU state at a time within the
// buffered IMU samples and its covariance. vio/ does not know where it comes from; the client
// picks the world frame W (z up, gravity (0, 0, −g), so that the estimator's IMU model holds).
// EstimatorBackend::initializeFrom (estimator_backend.hpp) starts a state from it; the visual
// features join with the next frames (docs/vio_estimator.md "Initialisation").
#pragma once

#include <string>

#include <Eigen/Core>

#include "gvins/vio/imu_state.hpp"

namespace gvins::vio {

struct ExternalInitialState {
  /// IMU state at state.t_ns (R_WI, p_WI, v_WI, biases) in the client's world frame.
  ImuState state;
  /// Covariance in ImuErr order [δθ δp δv δbg δba] (δθ the right perturbation of R_WI, in the
  /// IMU frame). The estimator keeps its pose, velocity and bias blocks and drops the
  /// correlations between them (its prior is per block).
  Matrix15d covariance = Matrix15d::Zero();
};

/// Empty when `s` can start a state; otherwise what is wrong with it ("covariance: not positive
/// definite", "R_WI: not a rotation", ...).
std::string externalInitialStateError(const ExternalInitialState& s);

struct InitialState;
struct SriSwfConfig;
/// The covariance in ImuErr order that an initialisation's InitialState stands for under `cfg`
/// (attitude from P_theta_world, the gauge position σ, σ_v, σ_bg and the accelerometer-bias σ).
Matrix15d initialStateCovariance(const InitialState& s, const SriSwfConfig& cfg);

}  // namespace gvins::vio
