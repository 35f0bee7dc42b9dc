// Zero-velocity update of the SRI-SWF estimator (zero_velocity_update.hpp).
#include "zero_velocity_update.hpp"

namespace gvins::vio::detail {

template <typename Scalar>
bool ZeroVelocityUpdater<Scalar>::update(SwfState<Scalar>& S, const FeatureFrame& frame, sri::BlockId previous_pose) {
  const SriSwfConfig& cfg = S.cfg;
  // 1. The frames of the standstill test's window.
  recent_.push_back(frame);
  while (!recent_.empty() && frame.t_ns - recent_.front().t_ns > static_cast<std::int64_t>(cfg.init_window * 1.5e9)) {
    recent_.pop_front();
  }
  if (!cfg.zero_velocity_update) return false;
  // 2. Standstill test. Without tracks (init_static_without_tracks) the IMU alone decides; the χ²
  // gate rejects the update when the state is known to move (a constant-velocity climb has a
  // quiet IMU too).
  Eigen::Vector3d ma, mg;
  int n = 0;
  const Standstill st = standstill(cfg, S.imuSpan(), frame, recent_, ma, mg, n);
  if (!(st == Standstill::kYes || (st == Standstill::kImuOnly && cfg.init_static_without_tracks))) return false;
  // 3. Rows: v = 0 and no displacement since the previous clone, whitened, gated, applied.
  const ImuState s = S.newestState();
  const PoseEstimate prev = poseOf(S.f.nominal(previous_pose));
  typename SwfState<Scalar>::Meas z(6);
  const double sv = cfg.zero_velocity_sigma;
  const double sp = sv * static_cast<double>(frame.t_ns - recent_[recent_.size() - 2].t_ns) * 1e-9;
  z.jacobian(S.newest.velocity, 3).setIdentity();
  z.jacobian(S.newest.pose, 6).block(3, 3, 3, 3).setIdentity();
  z.jacobian(previous_pose, 6).block(3, 3, 3, 3) = -Eigen::Matrix<Scalar, 3, 3>::Identity();
  z.residual().head(3) = (-s.v_WI).template cast<Scalar>();
  z.residual().tail(3) = (prev.p_WI - s.p_WI).template cast<Scalar>();
  Eigen::Matrix<Scalar, 6, 1> sd;
  sd << Eigen::Matrix<Scalar, 3, 1>::Constant(Scalar(sv)), Eigen::Matrix<Scalar, 3, 1>::Constant(Scalar(sp));
  z.whitenStdDevs(sd);
  if (!S.gate(z)) return false;
  S.f.update(z);
  S.notify("zupt");
  return true;
}

template class ZeroVelocityUpdater<float>;
template class ZeroVelocityUpdater<double>;

}  // namespace gvins::vio::detail
