#include "gvins/vio/external_initial_state.hpp"

#include <cmath>

#include <Eigen/Cholesky>

#include "gvins/vio/sri_swf_estimator.hpp"
#include "gvins/vio/visual_inertial_initializer.hpp"

namespace gvins::vio {

std::string externalInitialStateError(const ExternalInitialState& s) {
  const ImuState& x = s.state;
  if (!x.R_WI.allFinite() || !x.p_WI.allFinite() || !x.v_WI.allFinite() || !x.bg.allFinite() || !x.ba.allFinite())
    return "state: not finite";
  if (!(x.R_WI.transpose() * x.R_WI - Eigen::Matrix3d::Identity()).isZero(1e-6) || !(x.R_WI.determinant() > 0.0))
    return "R_WI: not a rotation";
  const Matrix15d& P = s.covariance;
  if (!P.allFinite()) return "covariance: not finite";
  if (!(P - P.transpose()).isZero(1e-9 * (1.0 + P.cwiseAbs().maxCoeff()))) return "covariance: not symmetric";
  const Eigen::LLT<Matrix15d> llt(P);
  if (llt.info() != Eigen::Success) return "covariance: not positive definite";
  return {};
}

Matrix15d initialStateCovariance(const InitialState& s, const SriSwfConfig& cfg) {
  Matrix15d P = Matrix15d::Zero();
  const Eigen::Matrix3d& R = s.state.R_WI;
  P.block<3, 3>(ImuErr::kTheta, ImuErr::kTheta) = R.transpose() * s.P_theta_world * R;  // body-frame δθ
  const auto diag = [&P](int at, double sigma) { P.block<3, 3>(at, at).diagonal().setConstant(sigma * sigma); };
  diag(ImuErr::kPos, cfg.init_position_sigma);
  diag(ImuErr::kVel, s.sigma_v);
  diag(ImuErr::kBg, s.sigma_bg);
  diag(ImuErr::kBa, cfg.init_accel_bias_sigma);
  return P;
}

}  // namespace gvins::vio
