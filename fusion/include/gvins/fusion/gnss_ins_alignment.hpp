// GNSS/INS alignment: the IMU state from SPP positions and Doppler velocities over a few epochs
// and the IMU between them, so that the estimator can start in the GNSS modes when the visual
// initialisation has not (a cruise start, a camera that sees nothing yet). Vision joins once it
// tracks (the estimator's visual updates need no initialisation of their own).
//
// Model (W = local ENU at the first fix of the window, z up, gravity g_N = (0, 0, −g)): with
// β_0k the IMU's velocity change over [t_0, t_k] in the IMU frame at t_0 (vio::ImuIntegration,
// zero biases),
//   v_N(t_k) − v_N(t_0) − g_N (t_k − t_0) = R_NI0 β_0k.
// Every epoch pairs a known vector in N with one in I0: R_NI0 solves Wahba's problem (weighted
// SVD; Markley, "Attitude determination using vector observations and the singular value
// decomposition", J. Astronaut. Sci. 36(3), 1988), the start of a Gauss-Newton fit of R_NI0, v_N(t_0) and
// the gyro and accelerometer biases (β_0k first order in them, priors σ_bg, σ_ba): a gyro bias
// tilts the integrated terms by bg Δt, which the Doppler velocities see as g bg Δt²/2. The
// gravity term makes the tilt observable at once; the yaw needs a horizontal velocity change
// (acceleration, a turn). Weights from each epoch's Doppler velocity covariance (full, ENU) and
// the accelerometer noise over Δt_k, scaled by the window's variance factor f = max(1, χ²/dof)
// (a posteriori variance of unit weight; e.g. Teunissen, "Adjustment theory", 2000): a
// receiver's velocity covariance can be optimistic by several times, and the attitude σ must be
// that of the scatter the window shows.
// Observability test: the window is accepted when the yaw and tilt σ (with f) are below the
// configured limits, f below maxVarianceFactor and no epoch an outlier against the scaled
// covariance; otherwise status() says what is missing.
#pragma once

#include <cstdint>
#include <deque>
#include <optional>
#include <span>
#include <string_view>

#include <Eigen/Core>

#include "gvins/fusion/gnss_measurement_models.hpp"
#include "gvins/gnss/spp.hpp"
#include "gvins/vio/external_initial_state.hpp"
#include "gvins/vio/imu_noise.hpp"
#include "gvins/vio/imu_sample.hpp"

namespace gvins::fusion {

enum class GnssInsStatus : std::uint8_t {
  kNoFix,             ///< no valid SPP position this epoch
  kNoDoppler,         ///< SPP without a Doppler velocity
  kNoImu,             ///< the IMU does not cover the interval since the previous epoch (window restarted)
  kCollecting,        ///< fewer than three epochs in the window (two leave the yaw about their velocity change open)
  kNoAcceleration,    ///< the yaw is not observable yet: too little horizontal velocity change
  kInconsistent,      ///< the fit's residuals fail the χ² test (bad Doppler, a jump)
  kAligned,           ///< a state was produced
};
std::string_view gnssInsStatusText(GnssInsStatus s);

struct GnssInsAlignmentConfig {
  double window = 5.0;           ///< s of epochs used at most
  double maxYawSigmaDeg = 10.0;  ///< accepted when the yaw σ is below this ...
  double maxTiltSigmaDeg = 1.0;  ///< ... and the roll/pitch σ below this
  double velocityFloor = 0.05;   ///< m/s added (in quadrature) to the Doppler velocity σ per axis
  double positionFloor = 1.0;    ///< m added to the SPP position σ per axis
  double gyroBiasSigma = 0.005;  ///< rad/s, prior of the (unestimated) gyro bias
  double accelBiasSigma = 0.1;   ///< m/s², prior of the (unestimated) accelerometer bias
  double gate = 0.9999;          ///< χ² probability of the per-epoch outlier test (over the window)
  /// Largest variance factor accepted: the Doppler velocities may scatter about the IMU by this
  /// many times their reported variance (σ 4×); more is a window that does not fit (a wrong IMU
  /// time or rig, a jump).
  double maxVarianceFactor = 16.0;
};

class GnssInsAlignment {
 public:
  GnssInsAlignment(const GnssInsAlignmentConfig& cfg, const vio::ImuNoise& noise, double gravity);

  /// Adds the SPP solution of the epoch at sensor time t_ns; `imu` the buffered samples (must
  /// cover the time since the previous epoch), `lever` the antenna in the IMU frame. Returns the
  /// IMU state at t_ns in ENU at anchor() once the window passes the test.
  std::optional<vio::ExternalInitialState> add(std::int64_t t_ns, const SppSolution& spp,
                                               std::span<const vio::ImuSample> imu, const Eigen::Vector3d& lever);
  GnssInsStatus status() const { return status_; }
  const GnssAnchor& anchor() const { return anchor_; }
  /// Attitude σ of the last fit (deg; NaN before one): yaw and the larger of roll/pitch.
  double yawSigmaDeg() const { return yawSigmaDeg_; }
  double tiltSigmaDeg() const { return tiltSigmaDeg_; }
  /// Variance factor of the last fit's velocities, max(1, χ²/dof) (NaN before one).
  double varianceFactor() const { return varianceFactor_; }
  void clear();

 private:
  struct Epoch {
    std::int64_t t_ns = 0;
    Eigen::Vector3d p_N, v_N;
    Eigen::Matrix3d Cp, Cv;      // ENU covariances
    Eigen::Matrix3d R_0k;        // IMU rotation since the window's first epoch (I_k in I_0)
    Eigen::Vector3d beta_0k;     // IMU velocity change since the first epoch, in I_0
    Eigen::Matrix3d Jth_g;       // ∂θ_0k/∂bg (right perturbation of R_0k)
    Eigen::Matrix3d Jb_g, Jb_a;  // ∂β_0k/∂bg, ∂β_0k/∂ba
  };
  std::optional<vio::ExternalInitialState> fit(std::span<const vio::ImuSample> imu, const Eigen::Vector3d& lever);
  void dropOldest();
  /// Appends `e` with its IMU terms since the last epoch; false (window restarted at e) on a gap.
  bool integrateInto(Epoch e, std::span<const vio::ImuSample> imu);

  GnssInsAlignmentConfig cfg_;
  vio::ImuNoise noise_;
  double gravity_;
  GnssAnchor anchor_;
  std::deque<Epoch> epochs_;
  std::deque<Epoch> pending_;  // not yet covered by the IMU
  GnssInsStatus status_ = GnssInsStatus::kCollecting;
  double yawSigmaDeg_, tiltSigmaDeg_, varianceFactor_;
};

}  // namespace gvins::fusion
