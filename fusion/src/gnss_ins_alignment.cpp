#include "gvins/fusion/gnss_ins_alignment.hpp"

#include <cmath>
#include <limits>
#include <stdexcept>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/SVD>

#include "gvins/sri/chi_square.hpp"
#include "gvins/vio/imu_integration.hpp"
#include "gvins/vio/imu_propagation.hpp"
#include "gvins/vio/so3.hpp"

namespace gvins::fusion {

namespace {
constexpr double kRadToDeg = 57.29577951308232;
}

std::string_view gnssInsStatusText(GnssInsStatus s) {
  switch (s) {
    case GnssInsStatus::kNoFix: return "no GNSS fix";
    case GnssInsStatus::kNoDoppler: return "no Doppler velocity";
    case GnssInsStatus::kNoImu: return "IMU gap";
    case GnssInsStatus::kCollecting: return "collecting GNSS epochs";
    case GnssInsStatus::kNoAcceleration: return "yaw unobservable: too little horizontal acceleration";
    case GnssInsStatus::kInconsistent: return "GNSS/INS fit rejected";
    case GnssInsStatus::kAligned: return "aligned";
  }
  return "?";
}

GnssInsAlignment::GnssInsAlignment(const GnssInsAlignmentConfig& cfg, const vio::ImuNoise& noise, double gravity)
    : cfg_(cfg), noise_(noise), gravity_(gravity) {
  clear();
}

void GnssInsAlignment::clear() {
  epochs_.clear();
  status_ = GnssInsStatus::kCollecting;
  yawSigmaDeg_ = tiltSigmaDeg_ = std::numeric_limits<double>::quiet_NaN();
}

void GnssInsAlignment::dropOldest() {
  epochs_.pop_front();
  if (epochs_.empty()) return;
  // Re-base the IMU terms on the new first epoch j: R_jk = R_0jᵀ R_0k, β_jk = R_0jᵀ (β_0k − β_0j).
  const Eigen::Matrix3d Rj = epochs_.front().R_0k;
  const Eigen::Vector3d bj = epochs_.front().beta_0k;
  for (Epoch& e : epochs_) {
    e.R_0k = Rj.transpose() * e.R_0k;
    e.beta_0k = Rj.transpose() * (e.beta_0k - bj);
  }
}

std::optional<vio::ExternalInitialState> GnssInsAlignment::add(std::int64_t t_ns, const SppSolution& spp,
                                                               std::span<const vio::ImuSample> imu,
                                                               const Eigen::Vector3d& lever) {
  if (!spp.valid()) {
    status_ = GnssInsStatus::kNoFix;
    return std::nullopt;
  }
  if (!spp.velocity.valid) {
    status_ = GnssInsStatus::kNoDoppler;
    return std::nullopt;
  }
  if (!epochs_.empty() && t_ns <= epochs_.back().t_ns) return std::nullopt;
  Epoch e;
  e.t_ns = t_ns;
  e.p_N = spp.position;  // ECEF here; converted at the fit (ENU at the window's first epoch)
  e.v_N = spp.velocity.velocity;
  e.Cp = spp.positionCovariance;
  e.Cv = spp.velocity.covariance;
  e.R_0k.setIdentity();
  e.beta_0k.setZero();
  if (!epochs_.empty()) {
    const Epoch& last = epochs_.back();
    vio::ImuIntegration integ(noise_, Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero());
    try {
      integ.integrate(imu, last.t_ns, t_ns);
    } catch (const std::invalid_argument&) {
      clear();
      epochs_.push_back(e);
      status_ = GnssInsStatus::kNoImu;
      return std::nullopt;
    }
    e.R_0k = last.R_0k * integ.gamma();
    e.beta_0k = last.beta_0k + last.R_0k * integ.beta();
  }
  epochs_.push_back(e);
  while (epochs_.size() > 2 && static_cast<double>(t_ns - epochs_.front().t_ns) * 1e-9 > cfg_.window) dropOldest();
  if (epochs_.size() < 2) {
    status_ = GnssInsStatus::kCollecting;
    return std::nullopt;
  }
  return fit(imu, lever);
}

std::optional<vio::ExternalInitialState> GnssInsAlignment::fit(std::span<const vio::ImuSample> imu,
                                                               const Eigen::Vector3d& lever) {
  anchor_ = GnssAnchor::at(epochs_.front().p_N);
  const Eigen::Matrix3d R_NE = anchor_.R_EN.transpose();
  const Eigen::Vector3d g_N(0.0, 0.0, -gravity_);
  const Epoch& e0 = epochs_.front();
  const Eigen::Vector3d v0 = R_NE * e0.v_N;
  const auto velVar = [&](const Epoch& e) {
    return (R_NE * e.Cv * R_NE.transpose()).trace() / 3.0 + cfg_.velocityFloor * cfg_.velocityFloor;
  };
  const double var0 = velVar(e0);
  // Pairs b_k (N) = R_NI0 a_k (I0) with scalar weights.
  const std::size_t n = epochs_.size() - 1;
  std::vector<Eigen::Vector3d> b(n), a(n);
  std::vector<double> w(n);
  Eigen::Matrix3d B = Eigen::Matrix3d::Zero();
  for (std::size_t k = 0; k < n; ++k) {
    const Epoch& e = epochs_[k + 1];
    const double dt = static_cast<double>(e.t_ns - e0.t_ns) * 1e-9;
    b[k] = R_NE * e.v_N - v0 - g_N * dt;
    a[k] = e.beta_0k;
    // Velocity noise of both epochs, accelerometer white noise and bias over dt, and the
    // rotation the gyro bias leaves in R_0k (about half the window's on average).
    const double na = noise_.accelerometer_noise_density;
    const double rot = cfg_.gyroBiasSigma * dt * 0.5 * a[k].norm();
    const double var = var0 + velVar(e) + na * na * dt + std::pow(cfg_.accelBiasSigma * dt, 2) + rot * rot;
    w[k] = 1.0 / var;
    B += w[k] * b[k] * a[k].transpose();
  }
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(B, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d D = Eigen::Matrix3d::Identity();
  D(2, 2) = (svd.matrixU() * svd.matrixV().transpose()).determinant() < 0.0 ? -1.0 : 1.0;
  const Eigen::Matrix3d R_NI0 = svd.matrixU() * D * svd.matrixV().transpose();
  // Information of a world-frame rotation error and the residual test.
  Eigen::Matrix3d info = Eigen::Matrix3d::Zero();
  double chi2 = 0.0;
  for (std::size_t k = 0; k < n; ++k) {
    const Eigen::Matrix3d J = vio::so3::skew(R_NI0 * a[k]);
    info += w[k] * J.transpose() * J;
    chi2 += w[k] * (b[k] - R_NI0 * a[k]).squaredNorm();
  }
  // The attitude covariance (world frame). Every pair shares the first epoch's velocity, whose
  // error the scalar weights count as independent per pair: the information is halved for it.
  info *= 0.5;
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(info);
  const double inf = std::numeric_limits<double>::infinity();
  Eigen::Matrix3d P = Eigen::Matrix3d::Constant(inf);
  if (eig.eigenvalues().minCoeff() > 1e-12 * std::max(1.0, eig.eigenvalues().maxCoeff())) {
    P = eig.eigenvectors() * eig.eigenvalues().cwiseInverse().asDiagonal() * eig.eigenvectors().transpose();
  }
  yawSigmaDeg_ = std::sqrt(P(2, 2)) * kRadToDeg;
  tiltSigmaDeg_ = std::sqrt(std::max(P(0, 0), P(1, 1))) * kRadToDeg;
  const int dof = static_cast<int>(3 * n) - 3;
  if (dof > 0 && chi2 > sri::chiSquareQuantile(cfg_.gate, dof)) {
    status_ = GnssInsStatus::kInconsistent;
    return std::nullopt;
  }
  if (!(yawSigmaDeg_ < cfg_.maxYawSigmaDeg) || !(tiltSigmaDeg_ < cfg_.maxTiltSigmaDeg)) {
    status_ = GnssInsStatus::kNoAcceleration;
    return std::nullopt;
  }
  // The IMU state at the newest epoch K.
  const Epoch& eK = epochs_.back();
  const double T = static_cast<double>(eK.t_ns - e0.t_ns) * 1e-9;
  vio::ExternalInitialState out;
  vio::ImuState& s = out.state;
  s.t_ns = eK.t_ns;
  s.R_WI = R_NI0 * eK.R_0k;
  const Eigen::Vector3d omega = vio::interpolateImu(imu, eK.t_ns).gyro;
  s.p_WI = R_NE * (eK.p_N - anchor_.ecef) - s.R_WI * lever;
  s.v_WI = R_NE * eK.v_N - s.R_WI * omega.cross(lever);
  vio::Matrix15d& C = out.covariance;
  C.setZero();
  const Eigen::Matrix3d Pw = P + Eigen::Matrix3d::Identity() * std::pow(cfg_.gyroBiasSigma * T, 2);
  C.block<3, 3>(vio::ImuErr::kTheta, vio::ImuErr::kTheta) = s.R_WI.transpose() * Pw * s.R_WI;  // body frame
  C.block<3, 3>(vio::ImuErr::kPos, vio::ImuErr::kPos) =
      R_NE * eK.Cp * R_NE.transpose() + Eigen::Matrix3d::Identity() * cfg_.positionFloor * cfg_.positionFloor;
  C.block<3, 3>(vio::ImuErr::kVel, vio::ImuErr::kVel) =
      R_NE * eK.Cv * R_NE.transpose() + Eigen::Matrix3d::Identity() * cfg_.velocityFloor * cfg_.velocityFloor;
  C.block<3, 3>(vio::ImuErr::kBg, vio::ImuErr::kBg).diagonal().setConstant(cfg_.gyroBiasSigma * cfg_.gyroBiasSigma);
  C.block<3, 3>(vio::ImuErr::kBa, vio::ImuErr::kBa).diagonal().setConstant(cfg_.accelBiasSigma * cfg_.accelBiasSigma);
  C = 0.5 * (C + C.transpose()).eval();
  status_ = GnssInsStatus::kAligned;
  epochs_.clear();
  return out;
}

}  // namespace gvins::fusion
