// Measurement models of the tightly-coupled GNSS fusion (paper Sec. III, eqs. pos_w_r, vel_w_r,
// N_p_rk, zp, zd, z_dp, z_ddcp, integrate_meas): residuals and Jacobians on the estimator's
// blocks. docs/gnss_fusion.md has the derivations; tests/fusion/test_gnss_models.cpp checks every
// Jacobian against finite differences.
//
// Frames and states (all evaluated in double, whatever Scalar the filter runs in):
//   W   VIO world frame (z up), I IMU frame; newest IMU state (ImuState, error vio::ImuErr order).
//   N   local East-North-Up frame at the GNSS anchor (the first SPP fix), E = ECEF.
//   Frame block (kVector 4): [ψ, p_NW] with R_NW = Rz(ψ), so p_N = p_NW + Rz(ψ) p_W.
//   Lever arm l = ^I p_r (kVector 3).
// Antenna at the GNSS measurement time t_k (earlier than the newest IMU state t_i, paper
// Sec. III-C): the IMU state at t_k is predicted from the newest state with the integration
// terms γ, β, α (vio::predictEarlierState), whose noise Σ_g enters the measurement covariance as
// J Σ_g Jᵀ; the "no integration" ablation uses the newest state as if it were at t_k.
//   p_W,r = p_WI + R_WI l,   v_W,r = v_WI + R_WI (ω × l),   ω = ω_m − b_g (bias-corrected rate)
//   p_N = p_NW + Rz p_W,r,   v_N = Rz v_W,r,   x_E = a_E + R_EN p_N,   u_E = R_EN v_N.
#pragma once

#include <optional>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "gvins/base/local_frame.hpp"
#include "gvins/base/satellite.hpp"
#include "gvins/base/signal.hpp"
#include "gvins/gnss/double_difference.hpp"
#include "gvins/vio/imu_integration.hpp"
#include "gvins/vio/imu_state.hpp"

namespace gvins::fusion {

/// Rz(ψ): rotation about the up axis.
Eigen::Matrix3d yawRotation(double yaw);

/// The local ENU frame N at an ECEF anchor point.
struct GnssAnchor {
  Eigen::Vector3d ecef = Eigen::Vector3d::Zero();
  Eigen::Matrix3d R_EN = Eigen::Matrix3d::Identity();  ///< v_E = R_EN v_N
  static GnssAnchor at(const Eigen::Vector3d& ecef);
};

/// Everything the antenna position/velocity at a GNSS time depends on.
struct GnssStateValues {
  vio::ImuState newest;  ///< newest IMU state (time t_i)
  /// Integration terms over [t_k, t_i]; nullopt: "no integration" (newest state used at t_k).
  std::optional<vio::ImuIntegration> integration;
  Eigen::Vector3d gravity = Eigen::Vector3d(0.0, 0.0, -9.81);  ///< in W
  /// Raw gyro reading at t_k (rad/s, I frame); ω = ω_m − newest.bg.
  Eigen::Vector3d omegaMeasured = Eigen::Vector3d::Zero();
  double yaw = 0.0;                                 ///< ψ of R_NW
  Eigen::Vector3d p_NW = Eigen::Vector3d::Zero();   ///< origin of W in N
  Eigen::Vector3d lever = Eigen::Vector3d::Zero();  ///< ^I p_r
  GnssAnchor anchor;
};

/// Antenna position/velocity at t_k in N and E with their Jacobians. Rows 0..2: p_N, 3..5: v_N.
struct AntennaKinematics {
  Eigen::Vector3d p_N = Eigen::Vector3d::Zero(), v_N = Eigen::Vector3d::Zero();
  Eigen::Vector3d x_E = Eigen::Vector3d::Zero(), u_E = Eigen::Vector3d::Zero();
  Eigen::Matrix3d R_EN = Eigen::Matrix3d::Identity();  ///< of the anchor
  Eigen::Matrix<double, 6, 15> J_imu = Eigen::Matrix<double, 6, 15>::Zero();  ///< newest error (ImuErr)
  Eigen::Matrix<double, 6, 4> J_frame = Eigen::Matrix<double, 6, 4>::Zero();  ///< [ψ, p_NW]
  Eigen::Matrix<double, 6, 3> J_lever = Eigen::Matrix<double, 6, 3>::Zero();
  /// w.r.t. the error of the state at t_k, [δθ, δp, δv] (for J Σ_g Jᵀ).
  Eigen::Matrix<double, 6, 9> J_earlier = Eigen::Matrix<double, 6, 9>::Zero();
  /// Covariance of [δθ, δp, δv] at t_k due to the integration noise (zero without integration).
  Eigen::Matrix<double, 9, 9> integrationCovariance = Eigen::Matrix<double, 9, 9>::Zero();
};

AntennaKinematics antennaKinematics(const GnssStateValues& s);

/// One linearized scalar measurement: residual r = z − h(x̂) and ∂h/∂(blocks).
struct GnssRow {
  double residual = 0.0;
  double variance = 0.0;  ///< measurement noise (without the integration noise)
  Eigen::Matrix<double, 1, 15> H_imu = Eigen::Matrix<double, 1, 15>::Zero();
  Eigen::Matrix<double, 1, 4> H_frame = Eigen::Matrix<double, 1, 4>::Zero();
  Eigen::Matrix<double, 1, 3> H_lever = Eigen::Matrix<double, 1, 3>::Zero();
  Eigen::Matrix<double, 1, 9> H_earlier = Eigen::Matrix<double, 1, 9>::Zero();
  /// ∂h/∂[p_N, v_N] of the antenna (chainRow): the yaw's nuisance before the frame has a yaw.
  Eigen::Matrix<double, 1, 6> dh_dpv = Eigen::Matrix<double, 1, 6>::Zero();
  int clockBias = -1;       ///< index of the clock-bias entry touched (coefficient +1), -1: none
  int ambiguity = -1;       ///< index of the float-ambiguity block touched (coefficient +1), -1: none
  double H_tropo = 0.0;     ///< coefficient of the zenith wet delay residual (wet mapping function)
  double H_drift = 0.0;     ///< coefficient of the clock drift entry
  SatId sat;
};

/// Chains ∂h/∂p_N and ∂h/∂v_N through the kinematics.
GnssRow chainRow(const AntennaKinematics& k, const Eigen::RowVector3d& dh_dpN, const Eigen::RowVector3d& dh_dvN);

/// Per-satellite model terms at the rover transmit time (from the gnss layer).
struct SatelliteModel {
  SatId sat;
  ObsCode code;
  int clock = -1;  ///< index of the receiver clock (system) this satellite uses
  GpsTime transmitTime;  ///< GPST of transmission
  Eigen::Vector3d position = Eigen::Vector3d::Zero();  ///< ECEF of the transmit time
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();
  double clockBias = 0.0;   ///< s, with relativity, without group delay
  double clockDrift = 0.0;  ///< s/s
  double groupDelay = 0.0;  ///< s, broadcast for this code
  double troposphere = 0.0; ///< m, modelled slant delay at the rover (plus m_w · the ZWD state, if any)
  double mapWet = 0.0;      ///< wet mapping function at the satellite's elevation (∂T/∂ZWD)
  double shapiro = 0.0;     ///< m, relativistic (Shapiro) delay, gnss::shapiroDelay
  double ionosphere = 0.0;  ///< m, modelled code delay (Klobuchar) on this frequency; 0 if ionosphere-free
  bool ionosphereFree = false;  ///< pseudorange and group delay are a dual-frequency ionosphere-free pair:
  ObsCode code2;                ///< its second signal, and the combination
  double ifA1 = 1.0, ifA2 = 0.0;  ///< P = a1·P(code) + a2·P(code2)
  double wavelength = 0.0;  ///< m
  bool precise = false;     ///< orbit and clock from precise products (SP3/RINEX clock)
  bool ssr = false;         ///< orbit and clock corrected by SSR
  AzEl azel;
  double pseudorange = 0.0; ///< m
  double cn0 = 0.0;         ///< C/N0 of the code, dB-Hz (an ionosphere-free pair: the lower one; 0 unknown)
  bool hasDoppler = false;
  double rangeRate = 0.0;   ///< m/s, −λ·D
  /// Ionosphere-free carrier phase a1·λ1·φ1 + a2·λ2·φ2 (m) of the pair's bands, when both phases
  /// exist (vio+dopp+ppp); it equals the code's model minus group delays plus an ambiguity.
  bool hasCarrier = false;
  double carrierRange = 0.0;
  double phaseVariance = 0.0;  ///< m²
  /// Phase wind-up (gvins/gnss/phase_windup.hpp) in cycles, in [−0.5, 0.5] (the caller continues it
  /// over the arc), and the metres per cycle of the combination, a1 λ1 + a2 λ2; the observed
  /// phase contains + windupWavelength · windup.
  double windup = 0.0;
  double windupWavelength = 0.0;
  double codeVariance = 0.0;     ///< m²
  double ephemerisVariance = 0.0;  ///< m², the orbit/clock part of codeVariance (a bias per satellite)
  double dopplerVariance = 0.0;  ///< (m/s)²
};

/// Pseudorange (paper eq. zp): h = ρ(x_E) + Sagnac + c·dt_r,sys − c(dt_s − gd) + T + I + Shapiro.
GnssRow pseudorangeRow(const SatelliteModel& m, const AntennaKinematics& k, double clockBiasMeters);
/// Undifferenced ionosphere-free carrier phase with a float ambiguity N (m; it absorbs the
/// integer ambiguities, phase biases and any constant part of the orbit/clock error):
/// h = ρ(x_E) + Sagnac + c·dt_r,sys − c·dt_s + T + Shapiro + N (no group delay, no ionosphere).
/// The row's `ambiguity` is left −1 for the caller to set.
GnssRow carrierPhaseRow(const SatelliteModel& m, const AntennaKinematics& k, double clockBiasMeters,
                        double ambiguityMeters);
/// Doppler as a range rate (paper eq. zd, times −λ): h = e·(v_s − u_E) + Sagnac rate + c·ḋt_r − c·ḋt_s.
GnssRow dopplerRow(const SatelliteModel& m, const AntennaKinematics& k, double clockDriftMps);
/// Single-differenced pseudorange vs the base (paper eq. z_dp). `sd` from the gnss layer's
/// DdEpoch carries the base OMC; the base clock (per system) is removed with `baseClockMeters`,
/// the mean base code OMC of the system, so the rover clock state keeps its meaning:
/// r = [P_r − (OMC_b − ĉdt_b)] − [ρ_r − c dt_s + T_r + c·dt_r].
GnssRow sdPseudorangeRow(const SingleDifference& sd, const AntennaKinematics& k, double roverClockMeters,
                         double baseClockMeters);
/// Double-differenced carrier phase (paper eq. z_ddcp) with the ambiguity of `dd` (fixed by the
/// gnss RTK/LAMBDA): clocks cancel.
GnssRow ddPhaseRow(const DdEpoch& e, const DoubleDifference& dd, const AntennaKinematics& k);
/// Loosely-coupled receiver velocity (`vio+gpsvel`): row `axis` of v_N.
GnssRow velocityRow(const Eigen::Vector3d& v_N_measured, int axis, const AntennaKinematics& k);
/// Frame initialisation (paper eq. N_p_rk): row `axis` of p_N.
GnssRow positionRow(const Eigen::Vector3d& p_N_measured, int axis, const AntennaKinematics& k);

}  // namespace gvins::fusion
