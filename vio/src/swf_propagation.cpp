// IMU propagation of the SRI-SWF estimator (swf_propagation.hpp) and the first-estimate
// transition (sri_swf_estimator.hpp: applyFirstEstimates).
#include "swf_propagation.hpp"

#include <vector>

#include "gvins/vio/so3.hpp"

namespace gvins::vio {

void applyFirstEstimates(Eigen::Matrix<double, 15, 15>& Phi, const Eigen::Matrix3d& R0, const Eigen::Vector3d& p0,
                         const Eigen::Vector3d& v0, const Eigen::Matrix3d& R1, const Eigen::Vector3d& p1,
                         const Eigen::Vector3d& v1, double dt, double gravity) {
  const Eigen::Vector3d g(0.0, 0.0, -gravity);
  // Attitude: Φ_θθ = ΔRᵀ maps the yaw direction R₀ᵀe_z to (R₀ΔR)ᵀe_z, not to R₁ᵀe_z when the
  // first estimate R₀ differs from the estimate R₁ was propagated from (a tilt correction since):
  // the smallest change that makes it so (rank one along w = R₀ᵀe_z, as the observability-
  // constrained transition of Hesch et al. 2014, eq. (35)); zero at Φ's own linearization point.
  const Eigen::Vector3d w = R0.transpose() * Eigen::Vector3d::UnitZ();
  const Eigen::Vector3d u = R1.transpose() * Eigen::Vector3d::UnitZ();
  Phi.block<3, 3>(ImuErr::kTheta, ImuErr::kTheta) += (u - Phi.block<3, 3>(ImuErr::kTheta, ImuErr::kTheta) * w) * w.transpose();
  Phi.block<3, 3>(ImuErr::kVel, ImuErr::kTheta) = -so3::skew(v1 - v0 - g * dt) * R0;
  Phi.block<3, 3>(ImuErr::kPos, ImuErr::kTheta) = -so3::skew(p1 - p0 - v0 * dt - 0.5 * dt * dt * g) * R0;
}

namespace detail {

using sri::BlockEstimate;
using sri::BlockId;
using sri::BlockSpec;
using sri::Placement;

template <typename Scalar>
void propagateToFrame(SwfState<Scalar>& S, std::int64_t t) {
  // 1. The IMU state at t, Φ and Q_d of the interval (first-estimate Φ: the previous state's
  // first estimates, applyFirstEstimates).
  ImuState s = S.newestState();
  Matrix15d Phi, Qd;
  S.prop.propagate(s, S.imuSpan(), t, &Phi, &Qd);
  const double dt = static_cast<double>(t - S.t_newest) * 1e-9;
  const SriSwfConfig& cfg = S.cfg;
  if (cfg.first_estimate_jacobians) {
    if (auto it = S.fe_pose.find(S.newest.pose.value); it != S.fe_pose.end()) {
      applyFirstEstimates(Phi, it->second.R_WI, it->second.p_WI, S.fe_v, s.R_WI, s.p_WI, s.v_WI, dt, cfg.gravity);
    }
  }
  // 2. Noise.
  Qd.diagonal().array() += 1e-14;  // keeps Q' positive definite for back-to-back frames
  // Position random walk (SriSwfConfig::position_random_walk): white velocity noise of q m²/s
  // on the position rows, q·Δt per step, so it does not depend on how the interval is split.
  Qd.diagonal().segment<3>(3).array() += cfg.position_random_walk * cfg.position_random_walk * dt;
  Qd.diagonal().segment<3>(0).array() += cfg.attitude_random_walk * cfg.attitude_random_walk * dt;
  // The bias block is renewed every imu_bias_renewal seconds (0: at every propagation) with the
  // random walk of the whole time since the last renewal; in between, the new pose and velocity
  // rows act on the kept block (SriSwfConfig::imu_bias_renewal).
  const double since = static_cast<double>(t - S.t_bias) * 1e-9;
  const bool renew = cfg.imu_bias_renewal <= 0.0 || since >= cfg.imu_bias_renewal - 1e-3;
  const int d = renew ? 15 : 9;
  if (renew && since > dt) {
    const ImuNoise& q = S.prop.noise();
    Qd.block<3, 3>(ImuErr::kBg, ImuErr::kBg).diagonal().array() += q.gyroscope_random_walk * q.gyroscope_random_walk * (since - dt);
    Qd.block<3, 3>(ImuErr::kBa, ImuErr::kBa).diagonal().array() +=
        q.accelerometer_random_walk * q.accelerometer_random_walk * (since - dt);
  }
  // 3. The block row: new pose (the clone, after the previous pose), velocity (and bias), the
  // replaced extra blocks marginalized.
  sri::Propagation<Scalar> step;
  step.addNewBlock(BlockSpec::pose("imu_pose"), poseEstimate<Scalar>(s.R_WI, s.p_WI), Placement::after(S.newest.pose));
  step.addNewBlock(BlockSpec::vector("imu_velocity", 3), BlockEstimate<Scalar>::fromVector(s.v_WI.cast<Scalar>()),
                   S.extraPlacement());
  const Eigen::Matrix<double, 6, 1> xb = SwfState<Scalar>::biasVector(s);
  if (renew) {
    // Placed like the velocity: at the back after it, or in front of it.
    step.addNewBlock(BlockSpec::vector("imu_bias", 6), BlockEstimate<Scalar>::fromVector(xb.cast<Scalar>()),
                     S.extraPlacement());
  }
  step.setTransition(S.newest.pose, Phi.topLeftCorner(d, 6).cast<Scalar>());
  step.setTransition(S.newest.velocity, Phi.block(0, 6, d, 3).cast<Scalar>());
  step.setTransition(S.newest.bias, Phi.topRightCorner(d, 6).cast<Scalar>());
  step.setNoiseCovariance(Qd.topLeftCorner(d, d).cast<Scalar>());
  step.marginalizeAfter(S.newest.velocity);
  if (renew) step.marginalizeAfter(S.newest.bias);
  const std::vector<BlockId> ids = S.f.propagate(step);
  // 4. Book-keeping: exact values (float), the newest blocks, the clone, first estimates.
  S.setExact(ids[0], poseEstimate<double>(s.R_WI, s.p_WI));
  S.setExact(ids[1], BlockEstimate<double>::fromVector(s.v_WI));
  if (renew) {
    S.setExact(ids[2], BlockEstimate<double>::fromVector(xb));
    S.newest.bias = ids[2];
    S.t_bias = t;
  }
  S.newest.pose = ids[0];
  S.newest.velocity = ids[1];
  S.t_newest = t;
  S.clones.push_back({ids[0], t});
  S.recordCloneMotion(ids[0], s, S.frame_td);
  // Clones get first estimates once the initialisation transient is over (first_estimate_delay).
  if (static_cast<double>(t - S.t_init) * 1e-9 >= cfg.first_estimate_delay) {
    S.fe_pose[ids[0].value] = poseOf(S.f.nominal(ids[0]));
  }
  S.fe_v = s.v_WI;
}

template void propagateToFrame(SwfState<float>&, std::int64_t);
template void propagateToFrame(SwfState<double>&, std::int64_t);

}  // namespace detail
}  // namespace gvins::vio
