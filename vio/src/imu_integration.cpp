#include "gvins/vio/imu_integration.hpp"

#include <stdexcept>
#include <string>

#include "gvins/vio/imu_propagation.hpp"
#include "gvins/vio/so3.hpp"

namespace gvins::vio {

using Eigen::Matrix3d;
using Eigen::Vector3d;

ImuIntegration::ImuIntegration(const ImuNoise& noise, const Vector3d& bg, const Vector3d& ba)
    : noise_(noise), bg_(bg), ba_(ba) {}

void ImuIntegration::integrate(std::span<const ImuSample> samples, std::int64_t t_from_ns,
                               std::int64_t t_to_ns) {
  gamma_.setIdentity();
  beta_.setZero();
  alpha_.setZero();
  jBias_.setZero();
  cov_.setZero();
  t0_ = t_from_ns;
  t1_ = t_from_ns;
  intervals_ = 0;
  extend(samples, t_to_ns);
}

void ImuIntegration::extend(std::span<const ImuSample> samples, std::int64_t t_to_ns) {
  const double sg2 = noise_.gyroscope_noise_density * noise_.gyroscope_noise_density;
  const double sa2 = noise_.accelerometer_noise_density * noise_.accelerometer_noise_density;
  const Vector3d zero = Vector3d::Zero();
  ImuStepJacobians J;
  forEachImuInterval(samples, t1_, t_to_ns, [&](const ImuInterval& m) {
    ++intervals_;
    // gamma, alpha, beta play the roles of R, p, v of the propagator with zero gravity; the
    // propagator's [theta, p, v] Jacobians are therefore those of [gamma, alpha, beta].
    integrateImuInterval(m, bg_, ba_, zero, gamma_, alpha_, beta_, &J);
    Eigen::Matrix<double, 9, 6> B;
    B << J.Bg, J.Ba;
    jBias_ = (J.A * jBias_ + B).eval();
    const double h = m.dt;
    cov_ = (J.A * cov_ * J.A.transpose() + (sg2 / h) * J.Bg * J.Bg.transpose() +
            (sa2 / h) * J.Ba * J.Ba.transpose()).eval();
  });
  t1_ = t_to_ns;
  cov_ = (0.5 * (cov_ + cov_.transpose())).eval();
}

Matrix3d ImuIntegration::gammaFor(const Vector3d& bg) const {
  return gamma_ * so3::exp(jBias_.block<3, 3>(ImuIntegrationErr::kGamma, 0) * (bg - bg_));
}

Vector3d ImuIntegration::alphaFor(const Vector3d& bg, const Vector3d& ba) const {
  return alpha_ + jBias_.block<3, 3>(ImuIntegrationErr::kAlpha, 0) * (bg - bg_) +
         jBias_.block<3, 3>(ImuIntegrationErr::kAlpha, 3) * (ba - ba_);
}

Vector3d ImuIntegration::betaFor(const Vector3d& bg, const Vector3d& ba) const {
  return beta_ + jBias_.block<3, 3>(ImuIntegrationErr::kBeta, 0) * (bg - bg_) +
         jBias_.block<3, 3>(ImuIntegrationErr::kBeta, 3) * (ba - ba_);
}

EarlierImuState predictEarlierState(const ImuState& newest, const ImuIntegration& integ,
                                    const Vector3d& gravity) {
  if (newest.t_ns != integ.tTo()) {
    throw std::invalid_argument("predictEarlierState: integration ends at " + std::to_string(integ.tTo()) +
                                ", state is at " + std::to_string(newest.t_ns));
  }
  const double dt = integ.dt();
  const Matrix3d gamma = integ.gammaFor(newest.bg);
  const Vector3d beta = integ.betaFor(newest.bg, newest.ba);
  const Vector3d alpha = integ.alphaFor(newest.bg, newest.ba);

  EarlierImuState out;
  out.t_ns = integ.tFrom();
  out.R_WI = newest.R_WI * gamma.transpose();
  out.v_WI = newest.v_WI - gravity * dt - out.R_WI * beta;
  out.p_WI = newest.p_WI - out.v_WI * dt - 0.5 * gravity * dt * dt - out.R_WI * alpha;

  // Linearisation (derivation in docs/vio_frontend.md):
  //   dtheta_a = gamma dtheta_b - gamma (J_gamma,bg dbg + d_gamma)
  //   dv_a     = dv_b + R_a [beta]x dtheta_a - R_a (J_beta,b db + d_beta)
  //   dp_a     = dp_b - dt dv_a + R_a [alpha]x dtheta_a - R_a (J_alpha,b db + d_alpha)
  constexpr int T = 0, P = 3, V = 6;
  constexpr int gT = ImuIntegrationErr::kGamma, gA = ImuIntegrationErr::kAlpha, gB = ImuIntegrationErr::kBeta;
  const auto& Jb = integ.biasJacobian();
  auto& H = out.H;
  auto& G = out.G;
  H.setZero();
  G.setZero();
  // rotation; gammaFor(bg + d) = gamma Exp(Jr(J (bg - bg_lin)) J d) to first order in d.
  const Vector3d dPhi = Jb.block<3, 3>(gT, 0) * (newest.bg - integ.bg());
  H.block<3, 3>(T, ImuErr::kTheta) = gamma;
  H.block<3, 3>(T, ImuErr::kBg) = -gamma * so3::rightJacobian(dPhi) * Jb.block<3, 3>(gT, 0);
  G.block<3, 3>(T, gT) = -gamma;
  // velocity
  const Matrix3d Rb = out.R_WI * so3::skew(beta);
  H.block<3, 15>(V, 0) = Rb * H.block<3, 15>(T, 0);
  H.block<3, 3>(V, ImuErr::kVel) += Matrix3d::Identity();
  H.block<3, 6>(V, ImuErr::kBg) -= out.R_WI * Jb.block<3, 6>(gB, 0);
  G.block<3, 9>(V, 0) = Rb * G.block<3, 9>(T, 0);
  G.block<3, 3>(V, gB) -= out.R_WI;
  // position
  const Matrix3d Ra = out.R_WI * so3::skew(alpha);
  H.block<3, 15>(P, 0) = Ra * H.block<3, 15>(T, 0) - dt * H.block<3, 15>(V, 0);
  H.block<3, 3>(P, ImuErr::kPos) += Matrix3d::Identity();
  H.block<3, 6>(P, ImuErr::kBg) -= out.R_WI * Jb.block<3, 6>(gA, 0);
  G.block<3, 9>(P, 0) = Ra * G.block<3, 9>(T, 0) - dt * G.block<3, 9>(V, 0);
  G.block<3, 3>(P, gA) -= out.R_WI;
  out.covariance = G * integ.covariance() * G.transpose();
  out.covariance = (0.5 * (out.covariance + out.covariance.transpose())).eval();
  return out;
}

}  // namespace gvins::vio
