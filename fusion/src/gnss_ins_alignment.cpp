#include "gvins/fusion/gnss_ins_alignment.hpp"

#include <cmath>
#include <limits>
#include <stdexcept>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
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
  pending_.clear();
  status_ = GnssInsStatus::kCollecting;
  yawSigmaDeg_ = tiltSigmaDeg_ = varianceFactor_ = std::numeric_limits<double>::quiet_NaN();
}

void GnssInsAlignment::dropOldest() {
  epochs_.pop_front();
  if (epochs_.empty()) return;
  // Re-base the IMU terms on the new first epoch j: R_jk = R_0jᵀ R_0k, β_jk = R_0jᵀ (β_0k − β_0j).
  const Eigen::Matrix3d Rj = epochs_.front().R_0k;
  const Eigen::Vector3d bj = epochs_.front().beta_0k;
  const Eigen::Matrix3d Jtj = epochs_.front().Jth_g, Jgj = epochs_.front().Jb_g, Jaj = epochs_.front().Jb_a;
  for (Epoch& e : epochs_) {
    // R_jk = R_0jᵀ R_0k: θ_jk = θ_0k − R_0kᵀ R_0j θ_0j to first order; β_jk = R_0jᵀ (β_0k − β_0j).
    const Eigen::Vector3d db = e.beta_0k - bj;
    e.Jb_g = Rj.transpose() * (e.Jb_g - Jgj) + vio::so3::skew(Rj.transpose() * db) * Jtj;
    e.Jb_a = Rj.transpose() * (e.Jb_a - Jaj);
    e.Jth_g = e.Jth_g - e.R_0k.transpose() * Rj * Jtj;
    // Kept a rotation: a product of products from every earlier slide compounds its rounding
    // (the orthogonality error grew about 1.4× per slide: NaN after some 60 slides of 10 Hz).
    e.R_0k = Eigen::Quaterniond(Rj.transpose() * e.R_0k).normalized().toRotationMatrix();
    e.beta_0k = Rj.transpose() * db;
  }
  Epoch& f = epochs_.front();  // exactly the window's origin
  f.R_0k.setIdentity();
  f.beta_0k.setZero();
  f.Jth_g.setZero();
  f.Jb_g.setZero();
  f.Jb_a.setZero();
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
  const std::int64_t lastT = !pending_.empty() ? pending_.back().t_ns : !epochs_.empty() ? epochs_.back().t_ns : 0;
  if (t_ns <= lastT) return std::nullopt;
  Epoch e;
  e.t_ns = t_ns;
  e.p_N = spp.position;  // ECEF here; converted at the fit (ENU at the window's first epoch)
  e.v_N = spp.velocity.velocity;
  e.Cp = spp.positionCovariance;
  e.Cv = spp.velocity.covariance;
  pending_.push_back(e);
  // Epochs enter the window once the IMU covers them (an epoch's time may lie a little past the
  // newest sample: its receiver clock).
  bool added = false;
  while (!pending_.empty() && !imu.empty() && pending_.front().t_ns <= imu.back().t_ns) {
    added = true;
    if (!integrateInto(pending_.front(), imu)) status_ = GnssInsStatus::kNoImu;
    pending_.pop_front();
  }
  if (!added || status_ == GnssInsStatus::kNoImu) return std::nullopt;
  while (epochs_.size() > 2 &&
         static_cast<double>(epochs_.back().t_ns - epochs_.front().t_ns) * 1e-9 > cfg_.window) dropOldest();
  if (epochs_.size() < 2) {
    status_ = GnssInsStatus::kCollecting;
    return std::nullopt;
  }
  return fit(imu, lever);
}

bool GnssInsAlignment::integrateInto(Epoch e, std::span<const vio::ImuSample> imu) {
  e.R_0k.setIdentity();
  e.beta_0k.setZero();
  e.Jth_g.setZero();
  e.Jb_g.setZero();
  e.Jb_a.setZero();
  if (epochs_.empty()) {
    epochs_.push_back(e);
    return true;
  }
  const Epoch& last = epochs_.back();
  vio::ImuIntegration integ(noise_, Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero());
  try {
    integ.integrate(imu, last.t_ns, e.t_ns);
  } catch (const std::invalid_argument&) {
    epochs_.clear();  // a gap: the window starts again here
    epochs_.push_back(e);
    return false;
  }
  const Eigen::Matrix<double, 9, 6>& J = integ.biasJacobian();  // rows [γ α β], columns [bg ba]
  e.R_0k = last.R_0k * integ.gamma();
  e.beta_0k = last.beta_0k + last.R_0k * integ.beta();
  e.Jth_g = integ.gamma().transpose() * last.Jth_g + J.block<3, 3>(0, 0);
  e.Jb_g = last.Jb_g - last.R_0k * vio::so3::skew(integ.beta()) * last.Jth_g + last.R_0k * J.block<3, 3>(6, 0);
  e.Jb_a = last.Jb_a + last.R_0k * J.block<3, 3>(6, 3);
  epochs_.push_back(e);
  return true;
}

namespace {

/// One epoch of the fit: u_k = v_N(t_k) − g_N Δt_k (N) = v_N(t_0) + R_NI0 (β_0k + Jg_k bg + Ja_k ba),
/// weight matrix W_k (independent per epoch; the first epoch's velocity is an unknown like the others).
struct Pair {
  Eigen::Vector3d u, beta;
  Eigen::Matrix3d Jg, Ja;
  Eigen::Matrix3d W;
};

Eigen::Vector3d residual(const Pair& p, const Eigen::Matrix3d& R, const Eigen::Vector3d& bg, const Eigen::Vector3d& ba,
                         const Eigen::Vector3d& v0) {
  return p.u - v0 - R * (p.beta + p.Jg * bg + p.Ja * ba);
}

/// Gauss-Newton on [δθ (world), bg, ba, v_0] from R (Wahba), zero biases and v0, with the bias
/// priors and a step halved until the cost does not grow (a yaw the window barely observes, a
/// straight line, otherwise takes steps that leave the residuals larger); returns the 12×12
/// covariance and the weighted residual sum, both at the returned state.
Eigen::Matrix<double, 12, 12> refine(const std::vector<Pair>& pairs, double sbg, double sba, Eigen::Matrix3d& R,
                                     Eigen::Vector3d& bg, Eigen::Vector3d& ba, Eigen::Vector3d& v0, double& chi2) {
  using M = Eigen::Matrix<double, 12, 12>;
  using V = Eigen::Matrix<double, 12, 1>;
  const auto priorCost = [&](const Eigen::Vector3d& g, const Eigen::Vector3d& a) {
    return g.squaredNorm() / (sbg * sbg) + a.squaredNorm() / (sba * sba);
  };
  const auto dataCost = [&](const Eigen::Matrix3d& R1, const Eigen::Vector3d& g, const Eigen::Vector3d& a,
                            const Eigen::Vector3d& v) {
    double c = 0.0;
    for (const Pair& p : pairs) {
      const Eigen::Vector3d r = residual(p, R1, g, a, v);
      c += r.dot(p.W * r);
    }
    return c;
  };
  M H;
  V g;
  const auto linearize = [&]() {
    H.setZero();
    g.setZero();
    for (const Pair& p : pairs) {
      const Eigen::Vector3d bt = p.beta + p.Jg * bg + p.Ja * ba;
      const Eigen::Vector3d r = p.u - v0 - R * bt;  // residual() with its bias-corrected term at hand
      Eigen::Matrix<double, 3, 12> A;  // r(x ⊞ d) ≈ r + A d
      A << vio::so3::skew(R * bt), -R * p.Jg, -R * p.Ja, -Eigen::Matrix3d::Identity();
      H += A.transpose() * p.W * A;
      g -= A.transpose() * p.W * r;
    }
    H.block<3, 3>(3, 3).diagonal().array() += 1.0 / (sbg * sbg);
    H.block<3, 3>(6, 6).diagonal().array() += 1.0 / (sba * sba);
    g.segment<3>(3) -= bg / (sbg * sbg);
    g.segment<3>(6) -= ba / (sba * sba);
  };
  chi2 = dataCost(R, bg, ba, v0);
  double cost = chi2 + priorCost(bg, ba);
  linearize();
  for (int it = 0; it < 8; ++it) {
    const V d = H.ldlt().solve(g);
    bool stepped = false;
    for (double s = 1.0; s > 1e-3 && !stepped; s *= 0.5) {
      const Eigen::Matrix3d R1 = vio::so3::exp(s * d.head<3>()) * R;
      const Eigen::Vector3d bg1 = bg + s * d.segment<3>(3), ba1 = ba + s * d.segment<3>(6), v1 = v0 + s * d.segment<3>(9);
      const double c1 = dataCost(R1, bg1, ba1, v1);
      if (!(c1 + priorCost(bg1, ba1) <= cost)) continue;
      R = R1;
      bg = bg1;
      ba = ba1;
      v0 = v1;
      chi2 = c1;
      cost = c1 + priorCost(bg1, ba1);
      stepped = true;
    }
    if (!stepped) break;
    linearize();
    if (d.norm() < 1e-10) break;
  }
  return H.ldlt().solve(M::Identity());
}

}  // namespace

std::optional<vio::ExternalInitialState> GnssInsAlignment::fit(std::span<const vio::ImuSample> imu,
                                                               const Eigen::Vector3d& lever) {
  anchor_ = GnssAnchor::at(epochs_.front().p_N);
  const Eigen::Matrix3d R_NE = anchor_.R_EN.transpose();
  const Eigen::Vector3d g_N(0.0, 0.0, -gravity_);
  const Epoch& e0 = epochs_.front();
  const Eigen::Vector3d v0 = R_NE * e0.v_N;
  const double na = noise_.accelerometer_noise_density;
  // Each epoch's Doppler velocity with its full ENU covariance (the vertical is typically three
  // times the horizontal σ) and the accelerometer white noise over dt.
  const auto velCov = [&](const Epoch& e, double dt) -> Eigen::Matrix3d {
    return R_NE * e.Cv * R_NE.transpose() +
           Eigen::Matrix3d::Identity() * (cfg_.velocityFloor * cfg_.velocityFloor + na * na * dt);
  };
  const double var0 = velCov(e0, 0.0).trace() / 3.0;
  std::vector<Pair> pairs;
  Eigen::Matrix3d B = Eigen::Matrix3d::Zero();  // Wahba's start: velocity changes since epoch 0
  for (const Epoch& e : epochs_) {
    const double dt = static_cast<double>(e.t_ns - e0.t_ns) * 1e-9;
    const Eigen::Matrix3d C = velCov(e, dt);
    pairs.push_back({R_NE * e.v_N - g_N * dt, e.beta_0k, e.Jb_g, e.Jb_a, C.inverse()});
    B += (pairs.back().u - v0) * e.beta_0k.transpose() / (var0 + C.trace() / 3.0);
  }
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(B, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d D = Eigen::Matrix3d::Identity();
  D(2, 2) = (svd.matrixU() * svd.matrixV().transpose()).determinant() < 0.0 ? -1.0 : 1.0;
  Eigen::Matrix3d R_NI0 = svd.matrixU() * D * svd.matrixV().transpose();
  Eigen::Vector3d bg = Eigen::Vector3d::Zero(), ba = Eigen::Vector3d::Zero(), v0fit = v0;
  double chi2 = 0.0;
  Eigen::Matrix<double, 12, 12> P = refine(pairs, cfg_.gyroBiasSigma, cfg_.accelBiasSigma, R_NI0, bg, ba, v0fit, chi2);
  const int dof = static_cast<int>(3 * pairs.size()) - 6;  // attitude and v_0 free; biases have priors
  // Two epochs determine v_0 and only two attitude angles (one velocity change): the yaw about
  // it has no information, and the inverse of the near-singular normal matrix can report any σ
  // for it (0° was seen on the simulated walk). Nor can the residuals be tested.
  if (dof <= 0 || !P.allFinite() || !(P.diagonal().minCoeff() > 0.0)) {
    yawSigmaDeg_ = tiltSigmaDeg_ = varianceFactor_ = std::numeric_limits<double>::quiet_NaN();
    status_ = dof <= 0 ? GnssInsStatus::kCollecting : GnssInsStatus::kNoAcceleration;
    return std::nullopt;
  }
  // The variance factor of the velocities (a posteriori variance of unit weight): a receiver's
  // Doppler velocity covariance can be optimistic by several times (the real hand-held u-blox
  // walk: χ²/dof 3-6 against it). The fit is repeated with the covariances scaled by it, so that
  // the attitude and bias σ are those of the scatter the window shows; never scaled down.
  varianceFactor_ = std::max(1.0, chi2 / dof);
  if (varianceFactor_ > 1.0) {
    for (Pair& p : pairs) p.W /= varianceFactor_;
    P = refine(pairs, cfg_.gyroBiasSigma, cfg_.accelBiasSigma, R_NI0, bg, ba, v0fit, chi2);
  }
  // Consistency: the scatter within what a Doppler velocity can be off by (maxVarianceFactor),
  // and no epoch an outlier against the scaled covariance (χ²(3) at the gate, Bonferroni over
  // the window's epochs): a jump or a bad Doppler velocity rejects the window.
  double worst = 0.0;
  for (const Pair& p : pairs) {
    const Eigen::Vector3d r = residual(p, R_NI0, bg, ba, v0fit);
    worst = std::max(worst, r.dot(p.W * r));
  }
  const double epochBound =
      sri::chiSquareQuantile(1.0 - (1.0 - cfg_.gate) / static_cast<double>(pairs.size()), 3);
  yawSigmaDeg_ = std::sqrt(P(2, 2)) * kRadToDeg;
  tiltSigmaDeg_ = std::sqrt(std::max(P(0, 0), P(1, 1))) * kRadToDeg;
  if (!P.allFinite() || !(varianceFactor_ <= cfg_.maxVarianceFactor) || !(worst <= epochBound)) {
    status_ = GnssInsStatus::kInconsistent;
    return std::nullopt;
  }
  if (!(yawSigmaDeg_ < cfg_.maxYawSigmaDeg) || !(tiltSigmaDeg_ < cfg_.maxTiltSigmaDeg)) {
    status_ = GnssInsStatus::kNoAcceleration;
    return std::nullopt;
  }
  // The IMU state at the newest epoch K: R_NIK = R_NI0 R_0K(bg).
  const Epoch& eK = epochs_.back();
  vio::ExternalInitialState out;
  vio::ImuState& s = out.state;
  s.t_ns = eK.t_ns;
  s.R_WI = R_NI0 * eK.R_0k * vio::so3::exp(eK.Jth_g * bg);
  s.bg = bg;
  s.ba = ba;
  const Eigen::Vector3d omega = vio::interpolateImu(imu, eK.t_ns).gyro - bg;
  s.p_WI = R_NE * (eK.p_N - anchor_.ecef) - s.R_WI * lever;
  s.v_WI = R_NE * eK.v_N - s.R_WI * omega.cross(lever);
  vio::Matrix15d& C = out.covariance;
  C.setZero();
  // Attitude at K: the fit's at t_0 carried by R_0K (world frame; its bias part is in P's bg).
  const Eigen::Matrix3d Jk = R_NI0 * eK.R_0k * eK.Jth_g;  // world-frame rotation per bg
  Eigen::Matrix<double, 3, 9> T;
  T << Eigen::Matrix3d::Identity(), Jk, Eigen::Matrix3d::Zero();  // [δθ bg ba] of P
  const Eigen::Matrix3d Pw = T * P.topLeftCorner<9, 9>() * T.transpose();
  C.block<3, 3>(vio::ImuErr::kTheta, vio::ImuErr::kTheta) = s.R_WI.transpose() * Pw * s.R_WI;  // body frame
  C.block<3, 3>(vio::ImuErr::kPos, vio::ImuErr::kPos) =
      R_NE * eK.Cp * R_NE.transpose() + Eigen::Matrix3d::Identity() * cfg_.positionFloor * cfg_.positionFloor;
  C.block<3, 3>(vio::ImuErr::kVel, vio::ImuErr::kVel) =
      varianceFactor_ * R_NE * eK.Cv * R_NE.transpose() +
      Eigen::Matrix3d::Identity() * cfg_.velocityFloor * cfg_.velocityFloor;
  C.block<6, 6>(vio::ImuErr::kBg, vio::ImuErr::kBg) = P.block<6, 6>(3, 3);
  C = 0.5 * (C + C.transpose()).eval();
  status_ = GnssInsStatus::kAligned;
  epochs_.clear();
  return out;
}

}  // namespace gvins::fusion
