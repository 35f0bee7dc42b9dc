// GnssFusion: the first value of the frame's yaw after a start without horizontal motion
// (GnssFusionConfig::frameStartAtRest, docs/gnss_fusion.md "Stages").
#include <cmath>

#include "gvins/base/constants.hpp"
#include "gvins/fusion/gnss_fusion.hpp"
#include "gnss_fusion_epoch.hpp"

namespace gvins::fusion {

template <typename Scalar>
void GnssFusion<Scalar>::headingFromMotion(vio::EstimatorBackend<Scalar>& est, Epoch& e) {
  const SppSolution& spp = sppOf(e);
  if (!spp.valid() || !spp.velocity.valid) return;
  GnssStateValues s;
  if (!buildState(est, e.t_ns, s)) return;
  const AntennaKinematics k = antennaKinematics(s);  // at the yaw's current value ψ̂
  const Eigen::Vector3d vN = anchor_.R_EN.transpose() * spp.velocity.velocity;
  const double minV = config_.frameMinSpeed;
  if (vN.head<2>().norm() < minV || k.v_N.head<2>().norm() < minV) return;
  // The same guess as startFrame's, about the current value (k.v_N = Rz(ψ̂) v_W).
  const double yaw0 = s.yaw;
  const double yaw = std::remainder(yaw0 + velocityHeadingDifference(vN, k.v_N), 2.0 * constants::kPi);
  // p_NW so that the ENU position the rows determined stays: that of the antenna at the frame's
  // start, c (in W), p_NW + Rz(ψ) c; its displacement since (vertical at first, then the start
  // of the horizontal motion, predicted with the yaw's guess) turns with the new yaw.
  const Eigen::Vector3d& pW = yawCentre_;
  const Eigen::Vector3d pNW = s.p_NW + yawRotation(yaw0) * pW - yawRotation(yaw) * pW;
  // The new block: ψ' = the guess + w, w of the prior's σ (the rows never informed ψ: it had its
  // prior alone), and p_NW' = p_NW + Rz(ψ̂) c − Rz(ψ') c, whose error δp_NW − J δψ'
  // (J = ∂Rz(ψ) c/∂ψ at the guess) keeps p_NW' + Rz(ψ') c with the information the rows gave it.

  using Mat = typename sri::Propagation<Scalar>::Matrix;
  Eigen::Matrix<Scalar, Eigen::Dynamic, 1> x(4);
  x[0] = static_cast<Scalar>(yaw);
  x.template tail<3>() = pNW.template cast<Scalar>();
  sri::Propagation<Scalar> step;
  step.addNewBlock(sri::BlockSpec::vector("gnss_frame", 4), sri::BlockEstimate<Scalar>::fromVector(x));
  Mat phi = Mat::Zero(4, 4);
  phi.template bottomRightCorner<3, 3>().setIdentity();
  step.setTransition(frameBlock_, phi);
  // Noise [w; −J w + e], e ~ N(0, ε² I) on p_NW' (ε 1 mm keeps it positive definite): Q' = L Lᵀ
  // with L = [σ 0; −J σ ε I], given as its square-root information L⁻¹ = [1/σ 0; J/ε I/ε] (the
  // covariance form is too ill-conditioned for float filters).
  constexpr double eps = 1e-3;
  const Eigen::Vector3d J = Eigen::Vector3d::UnitZ().cross(yawRotation(yaw) * pW);
  Mat S = Mat::Zero(4, 4);
  S(0, 0) = static_cast<Scalar>(1.0 / kFrameYawPriorSigma);
  S.template block<3, 1>(1, 0) = (J / eps).cast<Scalar>();
  S.template bottomRightCorner<3, 3>() = Mat::Identity(3, 3) * static_cast<Scalar>(1.0 / eps);
  step.setNoiseSqrtInformation(S);
  step.marginalizeAfter(frameBlock_);
  frameBlock_ = est.propagate(step, vio::ClientBlockRegion::kParameters).at(0);
  yawPending_ = false;
}

template void GnssFusion<float>::headingFromMotion(vio::EstimatorBackend<float>&, Epoch&);
template void GnssFusion<double>::headingFromMotion(vio::EstimatorBackend<double>&, Epoch&);

}  // namespace gvins::fusion
