#include "gvins/fusion/gnss_measurement_models.hpp"

#include <cmath>

#include "gvins/base/constants.hpp"
#include "gvins/gnss/sagnac.hpp"
#include "gvins/gnss/zero_difference.hpp"
#include "gvins/vio/so3.hpp"

namespace gvins::fusion {

using Eigen::Matrix3d;
using Eigen::RowVector3d;
using Eigen::Vector3d;
using vio::so3::skew;

Matrix3d yawRotation(double yaw) {
  const double c = std::cos(yaw), s = std::sin(yaw);
  Matrix3d R;
  R << c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0;
  return R;
}

GnssAnchor GnssAnchor::at(const Vector3d& ecef) {
  GnssAnchor a;
  a.ecef = ecef;
  const Geodetic g = ecefToGeodetic(ecef);
  a.R_EN = ecefToEnuRotation(g.lat, g.lon).transpose();
  return a;
}

AntennaKinematics antennaKinematics(const GnssStateValues& s) {
  AntennaKinematics k;
  Matrix3d R;
  Vector3d p, v;
  Eigen::Matrix<double, 9, 15> H = Eigen::Matrix<double, 9, 15>::Zero();
  if (s.integration) {
    const vio::EarlierImuState e = vio::predictEarlierState(s.newest, *s.integration, s.gravity);
    R = e.R_WI;
    p = e.p_WI;
    v = e.v_WI;
    H = e.H;
    k.integrationCovariance = e.covariance;
  } else {
    R = s.newest.R_WI;
    p = s.newest.p_WI;
    v = s.newest.v_WI;
    H.block<9, 9>(0, 0).setIdentity();  // [δθ, δp, δv] are the first 9 entries of ImuErr
  }
  const Vector3d omega = s.omegaMeasured - s.newest.bg;
  const Vector3d wl = omega.cross(s.lever);
  const Matrix3d Rz = yawRotation(s.yaw);
  const Matrix3d dRz = skew(Vector3d::UnitZ()) * Rz;
  const Vector3d p_W = p + R * s.lever;
  const Vector3d v_W = v + R * wl;
  k.p_N = s.p_NW + Rz * p_W;
  k.v_N = Rz * v_W;
  k.x_E = s.anchor.ecef + s.anchor.R_EN * k.p_N;
  k.u_E = s.anchor.R_EN * k.v_N;
  k.R_EN = s.anchor.R_EN;

  // w.r.t. the state at t_k: R = R̂ Exp(δθ) ⇒ δ(R a) = −R [a]× δθ.
  k.J_earlier.block<3, 3>(0, 0) = -Rz * R * skew(s.lever);
  k.J_earlier.block<3, 3>(0, 3) = Rz;
  k.J_earlier.block<3, 3>(3, 0) = -Rz * R * skew(wl);
  k.J_earlier.block<3, 3>(3, 6) = Rz;
  k.J_imu = k.J_earlier * H;
  // ω = ω_m − b_g: ∂(ω × l)/∂b_g = [l]×.
  k.J_imu.block<3, 3>(3, vio::ImuErr::kBg) += Rz * R * skew(s.lever);

  k.J_frame.block<3, 1>(0, 0) = dRz * p_W;
  k.J_frame.block<3, 3>(0, 1).setIdentity();
  k.J_frame.block<3, 1>(3, 0) = dRz * v_W;
  k.J_lever.block<3, 3>(0, 0) = Rz * R;
  k.J_lever.block<3, 3>(3, 0) = Rz * R * skew(omega);
  return k;
}

GnssRow chainRow(const AntennaKinematics& k, const RowVector3d& dh_dpN, const RowVector3d& dh_dvN) {
  GnssRow r;
  Eigen::Matrix<double, 1, 6> d;
  d << dh_dpN, dh_dvN;
  r.H_imu = d * k.J_imu;
  r.H_frame = d * k.J_frame;
  r.H_lever = d * k.J_lever;
  r.H_earlier = d * k.J_earlier;
  r.dh_dpv = d;
  return r;
}

namespace {
constexpr double kC = constants::kSpeedOfLight;
constexpr double kOmegaE = constants::kWgs84OmegaE;
}  // namespace

GnssRow pseudorangeRow(const SatelliteModel& m, const AntennaKinematics& k, double clockBiasMeters) {
  Vector3d g;
  const double rho = geometricRange(m.position, k.x_E, &g);
  const double h =
      rho + clockBiasMeters - kC * (m.clockBias - m.groupDelay) + m.troposphere + m.ionosphere + m.shapiro;
  GnssRow r = chainRow(k, g.transpose() * k.R_EN, RowVector3d::Zero());
  r.residual = m.pseudorange - h;
  r.variance = m.codeVariance;
  r.clockBias = m.clock;
  r.H_tropo = m.mapWet;
  r.sat = m.sat;
  return r;
}

GnssRow carrierPhaseRow(const SatelliteModel& m, const AntennaKinematics& k, double clockBiasMeters,
                        double ambiguityMeters) {
  Vector3d g;
  const double rho = geometricRange(m.position, k.x_E, &g);
  const double h = rho + clockBiasMeters - kC * m.clockBias + m.troposphere + m.shapiro + ambiguityMeters;
  GnssRow r = chainRow(k, g.transpose() * k.R_EN, RowVector3d::Zero());
  r.residual = m.carrierRange - h;
  r.variance = m.phaseVariance;
  r.clockBias = m.clock;
  r.H_tropo = m.mapWet;
  r.sat = m.sat;
  return r;
}

GnssRow dopplerRow(const SatelliteModel& m, const AntennaKinematics& k, double clockDriftMps) {
  const Vector3d d = m.position - k.x_E;
  const double rho = d.norm();
  const Vector3d e = d / rho;
  const Vector3d w = m.velocity - k.u_E;
  const double h = e.dot(w) + sagnacRangeRateCorrection(m.position, m.velocity, k.x_E, k.u_E) + clockDriftMps -
                   kC * m.clockDrift;
  // ∂(e·w)/∂x = −wᵀ(I − e eᵀ)/ρ, ∂(e·w)/∂u = −eᵀ; Sagnac rate ω_e/c (vx_s y + x_s vy − vy_s x − y_s vx).
  const double f = kOmegaE / kC;
  const RowVector3d dh_dx =
      -(w.transpose() - w.dot(e) * e.transpose()) / rho + f * RowVector3d(-m.velocity.y(), m.velocity.x(), 0.0);
  const RowVector3d dh_du = -e.transpose() + f * RowVector3d(-m.position.y(), m.position.x(), 0.0);
  GnssRow r = chainRow(k, dh_dx * k.R_EN, dh_du * k.R_EN);
  r.residual = m.rangeRate - h;
  r.variance = m.dopplerVariance;
  r.H_drift = 1.0;
  r.sat = m.sat;
  return r;
}

GnssRow sdPseudorangeRow(const SingleDifference& sd, const AntennaKinematics& k, double roverClockMeters,
                         double baseClockMeters) {
  Vector3d g;
  // sdCodeResidual = P_r − OMC_b − model_r(x) = c(dt_r − dt_b) + noise.
  const double r0 = sdCodeResidual(sd, k.x_E, &g);
  GnssRow r = chainRow(k, g.transpose() * k.R_EN, RowVector3d::Zero());
  r.residual = r0 + baseClockMeters - roverClockMeters;
  r.variance = sd.codeVariance;
  r.sat = sd.sat;
  return r;
}

GnssRow ddPhaseRow(const DdEpoch& e, const DoubleDifference& dd, const AntennaKinematics& k) {
  const DdResidual d = ddPhaseResidual(e, dd, k.x_E);
  GnssRow r = chainRow(k, d.jacobian * k.R_EN, RowVector3d::Zero());
  r.residual = d.residual;
  r.variance = d.variance;
  r.sat = e.sd[static_cast<std::size_t>(dd.satellite)].sat;
  return r;
}

GnssRow velocityRow(const Vector3d& v_N_measured, int axis, const AntennaKinematics& k) {
  GnssRow r = chainRow(k, RowVector3d::Zero(), RowVector3d::Unit(axis));
  r.residual = v_N_measured[axis] - k.v_N[axis];
  return r;
}

GnssRow positionRow(const Vector3d& p_N_measured, int axis, const AntennaKinematics& k) {
  GnssRow r = chainRow(k, RowVector3d::Unit(axis), RowVector3d::Zero());
  r.residual = p_N_measured[axis] - k.p_N[axis];
  return r;
}

}  // namespace gvins::fusion
