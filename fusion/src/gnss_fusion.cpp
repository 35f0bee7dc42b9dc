#include "gvins/fusion/gnss_fusion.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>

#include <Eigen/Cholesky>

#include "gvins/base/constants.hpp"
#include "gvins/base/local_frame.hpp"
#include "gvins/gnss/phase_windup.hpp"
#include "gvins/sri/chi_square.hpp"

namespace gvins::fusion {
namespace {

constexpr double kC = constants::kSpeedOfLight;

std::int64_t toNs(const GpsTime& t) {
  return t.wholeSeconds() * 1000000000LL + std::llround(t.fraction() * 1e9);
}

/// Marginalizes a client block that is in the state and forgets its id.
template <typename Scalar>
void marginalizeBlock(vio::EstimatorBackend<Scalar>& est, sri::BlockId& id) {
  if (id.valid() && est.contains(id)) est.marginalize(std::span<const sri::BlockId>(&id, 1));
  id = {};
}

enum RowType : int { kPsr, kDopp, kDpsr, kDdcp, kVel, kFrame, kPhase };

GnssTypeCount& countOf(GnssEpochReport& r, int type) {
  switch (type) {
    case kPsr: return r.psr;
    case kDopp: return r.dopp;
    case kDpsr: return r.dpsr;
    case kDdcp: return r.ddcp;
    case kVel: return r.vel;
    case kPhase: return r.phase;
    default: return r.frame;
  }
}

}  // namespace

const char* toString(GnssFusionStage s) {
  switch (s) {
    case GnssFusionStage::kWaitingVio: return "waiting-vio";
    case GnssFusionStage::kWaitingFix: return "waiting-fix";
    case GnssFusionStage::kFrameInit: return "frame-init";
    case GnssFusionStage::kTight: return "tight";
  }
  return "?";
}

template <typename Scalar>
GnssFusion<Scalar>::GnssFusion(GnssFusionConfig config) : config_(std::move(config)), leverStart_(config_.leverArm) {}

template <typename Scalar>
GnssFusion<Scalar>::~GnssFusion() = default;

template <typename Scalar>
void GnssFusion<Scalar>::setBasePosition(const Eigen::Vector3d& ecef) {
  config_.basePosition = ecef;
  if (rtk_) rtk_->setBasePosition(ecef);
}

template <typename Scalar>
bool GnssFusion<Scalar>::buildState(const vio::EstimatorBackend<Scalar>& est, std::int64_t t_ns,
                                    GnssStateValues& s) const {
  s.newest = est.newestImuState();
  s.gravity = est.gravity();
  s.integration.reset();
  if (config_.integration() && t_ns < s.newest.t_ns) {
    s.integration = est.integrateToNewest(t_ns);
    if (!s.integration) return false;
  }
  const auto w = est.angularRateAt(config_.integration() ? t_ns : s.newest.t_ns);
  s.omegaMeasured = (w ? *w : Eigen::Vector3d::Zero()) + s.newest.bg;
  s.anchor = anchor_;
  if (frameBlock_.valid()) {
    const auto v = est.estimate(frameBlock_).vector.template cast<double>();
    s.yaw = v[0];
    s.p_NW = v.template segment<3>(1);
  } else {
    s.yaw = 0.0;
    s.p_NW.setZero();
  }
  s.lever = leverArm(est);
  return true;
}

template <typename Scalar>
Eigen::Vector3d GnssFusion<Scalar>::leverArm(const vio::EstimatorBackend<Scalar>& est) const {
  if (leverBlock_.valid() && current(est)) return est.estimate(leverBlock_).vector.template cast<double>();
  return carriedLever();  // no block yet, or the state is gone (its last estimate, if plausible)
}

template <typename Scalar>
std::optional<Eigen::Matrix3d> GnssFusion<Scalar>::antennaCovariance(const vio::EstimatorBackend<Scalar>& est,
                                                                     std::int64_t t_ns) const {
  if (!current(est) || !est.initialized() || (!frameBlock_.valid() && !worldChange_)) return std::nullopt;
  GnssStateValues s;
  if (!buildState(est, t_ns, s)) return std::nullopt;
  const AntennaKinematics k = antennaKinematics(s);
  // Rows 0..2 of the kinematics' Jacobians (p_N) over the blocks, in the order listed.
  const vio::ImuBlocks ib = est.newestImuBlocks();
  std::vector<sri::BlockId> blocks{ib.pose, ib.velocity, ib.bias};
  Eigen::Matrix<double, 3, Eigen::Dynamic> J(3, 22);
  J.leftCols<15>() = k.J_imu.template topRows<3>();
  Eigen::Index n = 15;
  if (frameBlock_.valid()) {
    blocks.push_back(frameBlock_);
    J.middleCols<4>(n) = k.J_frame.template topRows<3>();
    n += 4;
  }
  if (leverBlock_.valid()) {
    blocks.push_back(leverBlock_);
    J.middleCols<3>(n) = k.J_lever.template topRows<3>();
    n += 3;
  }
  Eigen::MatrixXd P;
  try {
    P = est.covariance(std::span<const sri::BlockId>(blocks)).template cast<double>();
  } catch (const std::exception&) {
    return std::nullopt;  // a block without information yet (sri_filter.hpp)
  }
  const auto Jb = J.leftCols(n);
  const Eigen::Matrix<double, 3, 9> Je = k.J_earlier.template topRows<3>();
  const Eigen::Matrix3d C_N = Jb * P * Jb.transpose() + Je * k.integrationCovariance * Je.transpose();
  return Eigen::Matrix3d(k.R_EN * C_N * k.R_EN.transpose());
}

template <typename Scalar>
Eigen::Vector3d GnssFusion<Scalar>::carriedLever() const {
  if (leverLast_ && ((*leverLast_ - config_.leverArm).cwiseAbs().array() <= 3.0 * config_.leverArmSigma).all()) {
    return *leverLast_;
  }
  return leverStart_;
}

template <typename Scalar>
void GnssFusion<Scalar>::forgetState() {
  leverStart_ = carriedLever();
  leverLast_.reset();
  frameBlock_ = {};
  worldChange_.reset();
  leverBlock_ = {};
  clockBlock_ = {};
  isbBlock_ = {};
  zwdBlock_ = {};
  clockSystems_.clear();
  lastUpdate_.reset();
  gateRecovery_.reset();
  ambiguities_.clear();
  ambiguityTime_.reset();
  stage_ = GnssFusionStage::kWaitingVio;
  if (insAlign_) insAlign_->clear();
}

template <typename Scalar>
std::optional<Eigen::Vector4d> GnssFusion<Scalar>::frame(const vio::EstimatorBackend<Scalar>& est) const {
  if (!current(est)) return std::nullopt;
  if (worldChange_) return Eigen::Vector4d::Zero();  // the estimator's world is ENU now
  if (!frameBlock_.valid()) return std::nullopt;
  return Eigen::Vector4d(est.estimate(frameBlock_).vector.template cast<double>());
}

template <typename Scalar>
std::optional<Eigen::VectorXd> GnssFusion<Scalar>::clocks(const vio::EstimatorBackend<Scalar>& est) const {
  if (!clockBlock_.valid() || !current(est)) return std::nullopt;
  return systemClocks(est);
}

template <typename Scalar>
Eigen::VectorXd GnssFusion<Scalar>::systemClocks(const vio::EstimatorBackend<Scalar>& est) const {
  const int n = static_cast<int>(clockSystems_.size());
  const Eigen::VectorXd c = est.estimate(clockBlock_).vector.template cast<double>();
  Eigen::VectorXd out = Eigen::VectorXd::Constant(n + 1, c[0]);
  out[n] = c[1];
  if (isbBlock_.valid()) out.segment(1, n - 1) += est.estimate(isbBlock_).vector.template cast<double>();
  return out;
}

template <typename Scalar>
std::optional<AntennaKinematics> GnssFusion<Scalar>::antennaAt(const vio::EstimatorBackend<Scalar>& est,
                                                               std::int64_t t_ns) const {
  if ((!frameBlock_.valid() && !worldChange_) || !current(est)) return std::nullopt;
  GnssStateValues s;
  if (!buildState(est, t_ns, s)) return std::nullopt;
  return antennaKinematics(s);
}

template <typename Scalar>
void GnssFusion<Scalar>::ensureLever(vio::EstimatorBackend<Scalar>& est) {
  if (!config_.calibrateLeverArm || leverBlock_.valid()) return;
  leverBlock_ = est.addBlock(sri::BlockSpec::vector("gnss_lever_arm", 3),
                             sri::BlockEstimate<Scalar>::fromVector(leverStart_.template cast<Scalar>()),
                             sri::Prior<Scalar>::stdDev(3, static_cast<Scalar>(config_.leverArmSigma)));
}

template <typename Scalar>
bool GnssFusion<Scalar>::startFrame(vio::EstimatorBackend<Scalar>& est, const SppSolution& spp, std::int64_t t_ns) {
  if (!spp.valid() || !spp.velocity.valid) return false;
  anchor_ = GnssAnchor::at(spp.position);
  GnssStateValues s;
  if (!buildState(est, t_ns, s)) return false;
  const AntennaKinematics k = antennaKinematics(s);  // yaw 0, p_NW 0: p_N = p_W
  const Eigen::Vector3d vN = anchor_.R_EN.transpose() * spp.velocity.velocity;
  const double minV = config_.frameMinSpeed;
  if (vN.head<2>().norm() < minV || k.v_N.head<2>().norm() < minV) return false;
  const double yaw = std::atan2(vN.y(), vN.x()) - std::atan2(k.v_N.y(), k.v_N.x());
  const Eigen::Vector3d pN = anchor_.R_EN.transpose() * (spp.position - anchor_.ecef);
  Eigen::Matrix<Scalar, Eigen::Dynamic, 1> x(4);
  x[0] = static_cast<Scalar>(std::remainder(yaw, 2.0 * constants::kPi));
  x.template tail<3>() = (pN - yawRotation(yaw) * k.p_N).template cast<Scalar>();
  // Paper Sec. III-A: uninformative ("infinite covariance") prior.
  frameBlock_ = est.addBlock(sri::BlockSpec::vector("gnss_frame", 4), sri::BlockEstimate<Scalar>::fromVector(x),
                             sri::Prior<Scalar>::uninformative());
  return true;
}

template <typename Scalar>
bool GnssFusion<Scalar>::frameKnownInEnu(const vio::EstimatorBackend<Scalar>& est) const {
  const vio::ImuBlocks ib = est.newestImuBlocks();
  const std::array<sri::BlockId, 2> ids{ib.pose, frameBlock_};
  Eigen::MatrixXd P;
  try {
    P = est.covariance(std::span<const sri::BlockId>(ids)).template cast<double>();
  } catch (const std::exception&) {
    return false;  // not informed (yet)
  }
  const Eigen::Matrix3d Rz = yawRotation(static_cast<double>(est.estimate(frameBlock_).vector[0]));
  Eigen::Matrix<double, 3, 10> J = Eigen::Matrix<double, 3, 10>::Zero();  // ∂p_N/∂[δθ δp | ψ p_NW]
  J.block<3, 3>(0, 3) = Rz;
  J.col(6) = Eigen::Vector3d::UnitZ().cross(Rz * est.newestImuState().p_WI);
  J.block<3, 3>(0, 7).setIdentity();
  const Eigen::Matrix3d Pn = J * P * J.transpose();
  const double sth = config_.frameYawSigmaDeg * constants::kDegToRad;
  const double sp = config_.frameReanchorPositionSigma;
  return P(6, 6) < sth * sth && Pn.diagonal().maxCoeff() < sp * sp;
}

template <typename Scalar>
void GnssFusion<Scalar>::propagateClocks(vio::EstimatorBackend<Scalar>& est, const GpsTime& t) {
  const double dt = t - clockTime_;
  if (!clockBlock_.valid() || dt <= 0.0) return;
  using Mat = typename sri::Propagation<Scalar>::Matrix;
  Mat phi = Mat::Identity(2, 2);
  phi(0, 1) = static_cast<Scalar>(dt);
  // Bias b' = b + d·dt, drift d' = d: white-noise drift q_d and bias random walk q_b over dt
  // (two-state clock model, e.g. Brown & Hwang, "Introduction to Random Signals and Applied
  // Kalman Filtering", 4th ed., sec. 9.3). The inter-system biases are constant: only these two
  // columns are replaced (and swept past the state) per epoch.
  const double qb = std::pow(config_.clockBiasRandomWalk, 2), qd = std::pow(config_.clockDriftRandomWalk, 2);
  Eigen::Matrix2d Q;
  Q << qb * dt + qd * dt * dt * dt / 3.0, qd * dt * dt / 2.0, qd * dt * dt / 2.0, qd * dt;
  const Eigen::VectorXd x = est.estimate(clockBlock_).vector.template cast<double>();
  const Eigen::VectorXd xp = phi.template cast<double>() * x;
  sri::Propagation<Scalar> step;
  step.addNewBlock(sri::BlockSpec::vector("gnss_clock", 2),
                   sri::BlockEstimate<Scalar>::fromVector(xp.template cast<Scalar>()));
  step.setTransition(clockBlock_, phi);
  step.setNoiseCovariance(Q.template cast<Scalar>());
  step.marginalizeAfter(clockBlock_);
  clockBlock_ = est.propagate(step, vio::ClientBlockRegion::kParameters).at(0);
  clockTime_ = t;
  // The inter-system biases: a random walk stepped every isbRenewalInterval seconds with the
  // variance accumulated since the last step (Brown & Hwang, sec. 9.3: a Wiener process sampled
  // at those instants; no columns swept in between).
  const double di = t - isbTime_;
  if (!isbBlock_.valid() || !(config_.isbRandomWalk > 0.0) || di < config_.isbRenewalInterval) return;
  isbBlock_ = randomWalkStep(est, isbBlock_, "gnss_isb", static_cast<int>(clockSystems_.size()) - 1,
                             config_.isbRandomWalk * config_.isbRandomWalk * di);
  isbTime_ = t;
}

template <typename Scalar>
sri::BlockId GnssFusion<Scalar>::randomWalkStep(vio::EstimatorBackend<Scalar>& est, sri::BlockId id, const char* name,
                                                int size, double variance) {
  using Mat = typename sri::Propagation<Scalar>::Matrix;
  sri::Propagation<Scalar> step;
  step.addNewBlock(sri::BlockSpec::vector(name, size), est.estimate(id));
  step.setTransition(id, Mat::Identity(size, size));
  step.setNoiseCovariance(Mat::Identity(size, size) * static_cast<Scalar>(variance));
  step.marginalizeAfter(id);
  return est.propagate(step, vio::ClientBlockRegion::kParameters).at(0);
}

template <typename Scalar>
std::map<SatId, double> GnssFusion<Scalar>::ambiguities(const vio::EstimatorBackend<Scalar>& est) const {
  std::map<SatId, double> out;
  if (!current(est)) return out;
  for (const auto& [sat, a] : ambiguities_) out[sat] = static_cast<double>(est.estimate(a.id).vector[0]);
  return out;
}

template <typename Scalar>
std::optional<double> GnssFusion<Scalar>::zenithWetDelay(const vio::EstimatorBackend<Scalar>& est) const {
  if (!zwdBlock_.valid() || !current(est)) return std::nullopt;
  return static_cast<double>(est.estimate(zwdBlock_).vector[0]);
}

template <typename Scalar>
void GnssFusion<Scalar>::propagateZwd(vio::EstimatorBackend<Scalar>& est, const GpsTime& t) {
  const double dt = t - zwdTime_;
  if (!zwdBlock_.valid() || dt <= 0.0) return;
  zwdBlock_ = randomWalkStep(est, zwdBlock_, "gnss_zwd", 1, config_.zwdRandomWalk * config_.zwdRandomWalk * dt);
  zwdTime_ = t;
}

template <typename Scalar>
void GnssFusion<Scalar>::propagateAmbiguities(vio::EstimatorBackend<Scalar>& est, const std::vector<SatId>& broadcast,
                                              const GpsTime& t) {
  const double dt = ambiguityTime_ ? t - *ambiguityTime_ : 0.0;
  ambiguityTime_ = t;
  const double q = config_.broadcastAmbiguityRandomWalk;
  if (!(dt > 0.0) || !(q > 0.0)) return;
  std::vector<SatId> sats;
  for (const SatId& s : broadcast)
    if (ambiguities_.count(s)) sats.push_back(s);
  if (sats.empty()) return;
  using Mat = typename sri::Propagation<Scalar>::Matrix;
  const auto n = static_cast<Eigen::Index>(sats.size());
  sri::Propagation<Scalar> step;
  for (Eigen::Index i = 0; i < n; ++i) {
    const sri::BlockId old = ambiguities_.at(sats[static_cast<std::size_t>(i)]).id;
    step.addNewBlock(sri::BlockSpec::vector("gnss_ambiguity", 1), est.estimate(old));
    Mat phi = Mat::Zero(n, 1);
    phi(i, 0) = Scalar(1);
    step.setTransition(old, phi);
    step.marginalizeAfter(old);
  }
  step.setNoiseCovariance(Mat::Identity(n, n) * static_cast<Scalar>(q * q * dt));
  const std::vector<sri::BlockId> ids = est.propagate(step, vio::ClientBlockRegion::kFront);
  for (Eigen::Index i = 0; i < n; ++i)
    ambiguities_.at(sats[static_cast<std::size_t>(i)]).id = ids.at(static_cast<std::size_t>(i));
}

template <typename Scalar>
void GnssFusion<Scalar>::dropAmbiguity(vio::EstimatorBackend<Scalar>& est, SatId sat) {
  const auto it = ambiguities_.find(sat);
  if (it == ambiguities_.end()) return;
  marginalizeBlock(est, it->second.id);
  ambiguities_.erase(it);
}

template <typename Scalar>
vio::BackendUpdate<Scalar> GnssFusion<Scalar>::apply(vio::EstimatorBackend<Scalar>& est, std::vector<GnssRow>& rows,
                                                     const Eigen::MatrixXd& noise,
                                                     const Eigen::Matrix<double, 9, 9>& intCov,
                                                     std::vector<bool>& accepted, bool gate,
                                                     const std::vector<sri::BlockId>& ambiguities) {
  const vio::ImuBlocks ib = est.newestImuBlocks();
  accepted.assign(rows.size(), false);
  // The blocks GNSS rows touch: newest pose, velocity and bias, frame, lever arm, clocks (all at
  // the back of the state); a row as a vector h over them, in this order.
  std::vector<sri::BlockId> blocks{ib.pose, ib.velocity, ib.bias};
  std::vector<int> dims{6, 3, 6};
  const std::size_t nImu = blocks.size();  // the client blocks follow
  int dim = 15;
  auto addBlock = [&](sri::BlockId id, int size) {
    blocks.push_back(id);
    dims.push_back(size);
    dim += size;
  };
  const int frameAt = frameBlock_.valid() ? dim : -1;
  if (frameBlock_.valid()) addBlock(frameBlock_, 4);
  const int leverAt = leverBlock_.valid() ? dim : -1;
  if (leverBlock_.valid()) addBlock(leverBlock_, 3);
  const int clockAt = clockBlock_.valid() ? dim : -1;
  if (clockBlock_.valid()) addBlock(clockBlock_, 2);
  const int isbAt = isbBlock_.valid() ? dim : -1;  // with the clock, one per system after the first
  if (isbBlock_.valid()) addBlock(isbBlock_, static_cast<int>(clockSystems_.size()) - 1);
  const int zwdAt = zwdBlock_.valid() ? dim : -1;
  if (zwdBlock_.valid()) addBlock(zwdBlock_, 1);
  const int ambiguityAt = dim;
  for (const sri::BlockId& id : ambiguities) addBlock(id, 1);
  auto rowVector = [&](const GnssRow& r, auto&& h) {
    h.setZero();
    h.template head<15>() = r.H_imu;
    if (frameAt >= 0) h.template segment<4>(frameAt) = r.H_frame;
    if (leverAt >= 0) h.template segment<3>(leverAt) = r.H_lever;
    if (clockAt >= 0) {
      if (r.clockBias >= 0) h[clockAt] = 1.0;                           // b_s = c + i_s
      if (r.clockBias > 0 && isbAt >= 0) h[isbAt + r.clockBias - 1] = 1.0;
      h[clockAt + 1] = r.H_drift;
    }
    if (zwdAt >= 0) h[zwdAt] = r.H_tropo;
    if (r.ambiguity >= 0) h[ambiguityAt + r.ambiguity] = 1.0;
  };

  // Row gate: each row alone against the joint marginal covariance P of those blocks (cheap at
  // the back of the state): χ² = r² / (σ² + J Σ_k Jᵀ + h P hᵀ), the innovation test of the row.
  const bool rowGate = gate && config_.rowGate < 1.0;
  Eigen::MatrixXd P;
  bool haveP = false;
  if (rowGate) {
    try {
      P = est.covariance(std::span<const sri::BlockId>(blocks)).template cast<double>();
      haveP = true;
    } catch (const std::exception&) {
      // A block without information (e.g. a new frame block): rows pass the row gate.
    }
  }
  const double q1 = rowGate ? rowGateQuantile_(config_.rowGate, 1) : 0.0;
  // All rows as [h | J] at once; the gate's h P hᵀ and J Σ_k Jᵀ of every row from two products.
  const auto nr = static_cast<Eigen::Index>(rows.size());
  Eigen::MatrixXd HJ(nr, dim + 9);
  for (Eigen::Index i = 0; i < nr; ++i) {
    const GnssRow& r = rows[static_cast<std::size_t>(i)];
    rowVector(r, HJ.row(i).head(dim));
    HJ.row(i).tail<9>() = r.H_earlier;
  }
  Eigen::VectorXd gateVar(nr);  // σ² + J Σ_k Jᵀ + h P hᵀ per row
  if (haveP) {
    // The products as matrices first: nested in the coefficient-wise expression Eigen would
    // evaluate them lazily, one scalar dot product per coefficient.
    const Eigen::MatrixXd HP = HJ.leftCols(dim) * P;
    const Eigen::Matrix<double, Eigen::Dynamic, 9> JS = HJ.rightCols<9>() * intCov;
    gateVar = HP.cwiseProduct(HJ.leftCols(dim)).rowwise().sum() + JS.cwiseProduct(HJ.rightCols<9>()).rowwise().sum() +
              noise.diagonal();
  }
  std::vector<int> keep;
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const GnssRow& r = rows[i];
    if (!std::isfinite(r.residual)) continue;
    if (haveP) {
      const double v = gateVar[static_cast<Eigen::Index>(i)];
      if (!(v > 0.0) || r.residual * r.residual > q1 * v) continue;
    }
    keep.push_back(static_cast<int>(i));
  }
  vio::BackendUpdate<Scalar> u;
  if (keep.empty()) return u;

  // Whitening with Σ = Σ_m + J Σ_k Jᵀ (paper Sec. III-C). Σ_m is block diagonal (independent
  // rows; the gpsvel triple and the DD phases correlated among themselves): each block is
  // whitened by its own Cholesky factor. The integration error e ~ N(0, Σ_k) of the state at the
  // measurement time, common to all rows, enters as a 9-column nuisance J L_k (Σ_k = L_k L_kᵀ)
  // with prior rows I and is projected out: exactly the rows that the full Σ would give, without
  // the n³ Cholesky of Σ.
  const auto nk = static_cast<Eigen::Index>(keep.size());
  Eigen::MatrixXd A(nk, dim + 9 + 1);  // [h | J | r]
  for (Eigen::Index j = 0; j < nk; ++j) {
    const auto i = static_cast<std::size_t>(keep[static_cast<std::size_t>(j)]);
    A.row(j).head(dim + 9) = HJ.row(static_cast<Eigen::Index>(i));
    A(j, dim + 9) = rows[i].residual;
  }
  auto sigma = [&](Eigen::Index a, Eigen::Index b) { return noise(keep[static_cast<std::size_t>(a)], keep[static_cast<std::size_t>(b)]); };
  std::vector<std::pair<Eigen::Index, Eigen::Index>> groups;  // [begin, end) of coupled rows
  for (Eigen::Index a = 0; a < nk;) {
    Eigen::Index b = a + 1;
    for (bool coupled = true; coupled && b < nk;) {
      coupled = false;
      for (Eigen::Index c = a; c < b && !coupled; ++c) coupled = sigma(b, c) != 0.0;
      if (coupled) ++b;
    }
    groups.emplace_back(a, b);
    a = b;
  }
  bool blockDiagonal = true;
  for (const auto& g : groups) {
    for (Eigen::Index a = g.first; a < g.second && blockDiagonal; ++a)
      for (Eigen::Index c = g.second; c < nk && blockDiagonal; ++c) blockDiagonal = sigma(a, c) == 0.0;
  }
  if (!blockDiagonal) groups.assign(1, {0, nk});  // not expected: whiten with the whole Σ_m
  for (const auto& [a, b] : groups) {
    if (b - a == 1) {
      const double s2 = sigma(a, a);
      if (!(s2 > 0.0)) return u;
      A.row(a) /= std::sqrt(s2);
      continue;
    }
    Eigen::MatrixXd S(b - a, b - a);
    for (Eigen::Index i = a; i < b; ++i)
      for (Eigen::Index k = a; k < b; ++k) S(i - a, k - a) = sigma(i, k);
    const Eigen::LLT<Eigen::MatrixXd> llt(S);
    if (llt.info() != Eigen::Success) return u;
    llt.matrixL().solveInPlace(A.middleRows(a, b - a));
  }
  // L_k of the (positive semi-definite) integration covariance.
  // (Pivoted LDLᵀ: Σ_k = Pᵀ L D Lᵀ P, L_k = Pᵀ L D^½; it may be singular. Any L_k with
  // L_k L_kᵀ = Σ_k gives the same projected rows.)
  const Eigen::LDLT<Eigen::Matrix<double, 9, 9>> ldlt(intCov);
  const Eigen::Matrix<double, 9, 9> L = ldlt.matrixL();
  const Eigen::Matrix<double, 9, 9> Lk =
      ldlt.transpositionsP().transpose() * (L * ldlt.vectorD().cwiseMax(0.0).cwiseSqrt().asDiagonal());
  const bool nuisance = Lk.norm() > 0.0;
  sri::Measurement<Scalar> m(static_cast<int>(nk) + (nuisance ? 9 : 0));
  for (std::size_t bi = 0, col = 0; bi < blocks.size(); col += static_cast<std::size_t>(dims[bi]), ++bi) {
    const auto c = static_cast<Eigen::Index>(col);
    if (bi >= nImu && A.middleCols(c, dims[bi]).isZero(0.0)) continue;  // e.g. the lever arm without excitation
    m.jacobian(blocks[bi], dims[bi]).topRows(nk) = A.middleCols(c, dims[bi]).template cast<Scalar>();
  }
  m.residual().head(nk) = A.col(dim + 9).template cast<Scalar>();
  if (nuisance) {
    auto N = m.nuisance(9);
    N.topRows(nk) = (A.middleCols(dim, 9) * Lk).template cast<Scalar>();
    N.bottomRows(9).setIdentity();
  }
  m.setWhitened();
  if (nuisance) m.projectNuisance(nullptr, sri::Measurement<Scalar>::NuisanceProjection::kHouseholder);
  u = est.update(m, gate ? config_.epochGate : 1.0);
  if (u.applied) {
    for (int i : keep) accepted[static_cast<std::size_t>(i)] = true;
  }
  return u;
}

template <typename Scalar>
GnssEpochReport GnssFusion<Scalar>::processEpoch(vio::EstimatorBackend<Scalar>& est, const ObsEpoch& roverInput,
                                                 const ObsEpoch* base, const EphemerisStore& nav) {
  const auto wall0 = std::chrono::steady_clock::now();
  GnssEpochReport rep;
  rep.time = roverInput.time;
  auto finish = [&]() {
    if (leverBlock_.valid() && current(est)) leverLast_ = est.estimate(leverBlock_).vector.template cast<double>();
    rep.stage = stage_;
    for (; signalWarned_ < signalNotices_.messages().size(); ++signalWarned_)
      rep.warnings.push_back(signalNotices_.messages()[signalWarned_]);
    for (; jumpWarned_ < clockJumps_.warnings().size(); ++jumpWarned_) rep.warnings.push_back(clockJumps_.warnings()[jumpWarned_]);
    for (; clockWarned_ < clockNotices_.size(); ++clockWarned_) rep.warnings.push_back(clockNotices_[clockWarned_]);
    for (; gateWarned_ < gateRecovery_.warnings().size(); ++gateWarned_) rep.warnings.push_back(gateRecovery_.warnings()[gateWarned_]);
    rep.elapsedMicroseconds =
        std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - wall0).count();
    return rep;
  };
  if (config_.mode == GnssFusionMode::kVio) return finish();
  // Doppler sanity of the rover stream before any user (doppler_consistency.hpp): flipped signs
  // corrected, bad Dopplers dropped; the base's is checked inside the RTK module.
  checkedRover_ = roverInput;
  clockJumps_.apply(checkedRover_, nav.glonassChannels());  // whole-ms receiver clock jumps (clock_jump_repair.hpp)
  const std::size_t warned = roverDoppler_.warnings().size();
  roverDoppler_.apply(checkedRover_, nav.glonassChannels());
  rep.warnings.assign(roverDoppler_.warnings().begin() + static_cast<std::ptrdiff_t>(warned), roverDoppler_.warnings().end());
  const ObsEpoch& roverRaw = checkedRover_;
  // Carrier-smoothed codes for the psr rows, and for the dpsr rows on both receivers (every epoch,
  // also before the VIO is ready, so that the arcs are long when the rows start). Ddcp keeps the
  // raw codes: its RTK filter estimates the ambiguities from phase minus code, which smoothing
  // would correlate in time.
  const bool smoothDifferences = config_.mode == GnssFusionMode::kDoppDpsr;
  const bool ppp = config_.mode == GnssFusionMode::kDoppPpp;
  if (ppp) {
    // Arcs of the float ambiguities (every epoch, also before the VIO is ready); raw codes.
    if (!arcs_) arcs_ = std::make_unique<CarrierSmoother>();
    arcSmoothed_ = roverRaw;
    arcs_->apply(arcSmoothed_, nav.glonassChannels());
  }
  if (!ppp && config_.carrierSmoothing > 0.0 && (config_.usesPseudorange() || smoothDifferences)) {
    if (!smoother_) {
      CarrierSmoothingOptions o;
      o.window = config_.carrierSmoothing;
      smoother_ = std::make_unique<CarrierSmoother>(o);
      if (smoothDifferences) baseSmoother_ = std::make_unique<CarrierSmoother>(o);
    }
    smoothed_ = roverRaw;
    smoother_->apply(smoothed_, nav.glonassChannels());
  }
  const ObsEpoch& rover = smoother_ ? smoothed_ : roverRaw;
  if (nav_ != &nav) {
    nav_ = &nav;
    spp_ = std::make_unique<SppSolver>(nav);
    if (config_.usesDifferences()) {
      rtk_ = std::make_unique<RtkSolver>(nav);
      rtk_->setRoverDopplerCheckedByCaller();  // checked at the input below, once
      baseWarned_ = 0;
      if (config_.basePosition) rtk_->setBasePosition(*config_.basePosition);
    }
  }
  // SPP only where it is used (frame initialisation, the clock before the clock block exists,
  // vio+gpsvel): in the tight stage with clocks it is not needed.
  std::optional<SppSolution> sppCache;
  auto sppNow = [&]() -> const SppSolution& {
    if (!sppCache) sppCache = spp_->solve(rover);
    return *sppCache;
  };
  // Dpsr needs only the single differences, formed in the tight stage about the antenna
  // estimate (RtkSolver::differences: no float filter, no ambiguity resolution); Ddcp runs the
  // whole RTK module for its fixed ambiguities.
  const bool fullRtk = rtk_ && config_.mode == GnssFusionMode::kDoppDdcp;
  // Satellite states of this epoch, computed once for the RTK module's differences and the
  // fusion's satellite models.
  TransmitStates states(nav, rover.time);
  std::optional<double> baseAge;
  // Ddcp runs the whole RTK module at every epoch until it fixes, then at the base epochs only
  // (no extrapolated base there) and holds the fix in between (RtkSolver::differencesWithHeldFix,
  // in the tight stage below): the ambiguities are constant along the arcs.
  bool rtkProcessed = false;
  // Held and nothing new: a new base epoch within rtk_revalidate_interval of the last run takes
  // the held fix too (in the tight stage below), unless its DD phases differ from that run's
  // (a new satellite, a slip, another reference): then the module runs there.
  bool rtkDeferred = false;
  auto runRtk = [&] {
    const RtkSolution rtk = rtk_->process(roverRaw, &states);
    rep.rtkFixed = rtk.quality == SolutionQuality::Fix;
    baseAge = rtk.age;
    rtkProcessed = true;
  };
  if (rtk_) {
    const bool newBase = base && (!lastBase_ || base->time > *lastBase_);
    if (newBase) {
      if (baseSmoother_) {
        ObsEpoch b = *base;
        baseSmoother_->apply(b, nav.glonassChannels());
        rtk_->addBaseEpoch(b);
      } else {
        rtk_->addBaseEpoch(*base);
      }
      lastBase_ = base->time;
      const std::vector<std::string>& w = rtk_->base().doppler().warnings();  // the base's Doppler check
      for (; baseWarned_ < w.size(); ++baseWarned_) rep.warnings.push_back(w[baseWarned_]);
    }
    const std::optional<GpsTime> lastRun = rtk_->lastProcessTime();
    rtkDeferred = fullRtk && newBase && config_.rtkHoldFix && rtk_->hasHeldFix() && lastRun &&
                  rover.time - *lastRun < config_.rtkRevalidateInterval;
    if (fullRtk && !rtkDeferred && (newBase || !rtk_->hasHeldFix() || !config_.rtkHoldFix)) runRtk();
  }
  // A new estimator state (the VIO started again, EstimatorBackend::generation): the client
  // blocks are gone; frame, clocks, lever arm and ambiguities start again.
  if (!current(est)) {
    if (stage_ != GnssFusionStage::kWaitingVio && stage_ != GnssFusionStage::kWaitingFix) rep.reset = true;
    forgetState();
    generation_ = est.generation();
  }
  if (!est.initialized()) {
    stage_ = GnssFusionStage::kWaitingVio;
    if (config_.insStart) startFromGnss(est, rover, rep);
    return finish();
  }
  if (stage_ == GnssFusionStage::kWaitingVio) stage_ = GnssFusionStage::kWaitingFix;

  // Outage: clocks and ambiguities start again.
  if (lastUpdate_ && rover.time - *lastUpdate_ > config_.outageReset && stage_ == GnssFusionStage::kTight) {
    marginalizeBlock(est, clockBlock_);
    marginalizeBlock(est, isbBlock_);
    marginalizeBlock(est, zwdBlock_);
    if (rtk_) rtk_->reset();
    while (!ambiguities_.empty()) dropAmbiguity(est, ambiguities_.begin()->first);
    ambiguityTime_.reset();
    rep.reset = true;
    lastUpdate_.reset();
  }

  // Measurement time: the tag minus the receiver clock (GPS, or the first system estimated).
  double dtr = 0.0;
  if (clockBlock_.valid()) {
    const Eigen::VectorXd c = est.estimate(clockBlock_).vector.template cast<double>();
    dtr = (c[0] + c[1] * (rover.time - clockTime_)) / kC;  // [c·dt, c·ḋt]
  } else if (sppNow().valid()) {
    for (const auto& b : sppNow().clockBias) {
      if (b) {
        dtr = *b / kC;
        break;
      }
    }
  }
  if (!(std::abs(dtr) < 0.01)) dtr = 0.0;
  const GpsTime tMeas = rover.time - dtr;
  std::int64_t t_ns = toNs(tMeas);
  const std::int64_t newest = est.newestTime();
  if (t_ns > newest) {
    if (t_ns - newest > 10000000) return finish();  // the driver sends epochs up to newestTime()
    t_ns = newest;
  }
  rep.t_ns = t_ns;
  ensureLever(est);

  if (stage_ == GnssFusionStage::kWaitingFix) {
    if (!startFrame(est, sppNow(), t_ns)) return finish();
    stage_ = GnssFusionStage::kFrameInit;
  }

  // The paper marginalizes the converged frame and keeps the VIO frame; here the estimator moves
  // into ENU with it (an exact change of variables, world_frame_change.hpp), so the GNSS
  // information on the yaw stays in the poses and the rows lose the frame's columns. Not at the
  // convergence itself: the SPP rows of the initialisation leave the frame's position metres off
  // (height σ ~12 m on demo_short), which the first raw rows correct at once; moved with them,
  // the local outputs (fixed to the frame of the move) would jump by that much. So the move waits
  // until the IMU's position in N, p_N = p_NW + Rz(ψ) p_W, is known to
  // frame_reanchor_position_sigma (p_NW alone is not: far from the VIO origin its σ is the yaw's
  // times the distance).
  if (stage_ == GnssFusionStage::kTight && frameBlock_.valid() && config_.frameReanchor && frameKnownInEnu(est)) {
    worldChange_ = est.reanchorWorld(frameBlock_);
    frameBlock_ = {};
  }
  GnssStateValues s;
  if (!buildState(est, t_ns, s)) return finish();
  AntennaKinematics k = antennaKinematics(s);
  std::vector<GnssRow> rows;
  std::vector<int> types;
  std::vector<double> diag;
  Eigen::MatrixXd noise;

  if (stage_ == GnssFusionStage::kFrameInit) {
    const SppSolution& spp = sppNow();
    if (!spp.valid()) return finish();
    const Eigen::Matrix3d R_NE = anchor_.R_EN.transpose();
    const Eigen::Vector3d pN = R_NE * (spp.position - anchor_.ecef);
    const int nv = spp.velocity.valid ? 3 : 0;
    noise = Eigen::MatrixXd::Zero(3 + nv, 3 + nv);
    for (int a = 0; a < 3; ++a) {
      rows.push_back(positionRow(pN, a, k));
      types.push_back(kFrame);
    }
    noise.block<3, 3>(0, 0) = R_NE * spp.positionCovariance * R_NE.transpose() + 0.25 * Eigen::Matrix3d::Identity();
    if (nv) {
      const Eigen::Vector3d vN = R_NE * spp.velocity.velocity;
      for (int a = 0; a < 3; ++a) {
        rows.push_back(velocityRow(vN, a, k));
        types.push_back(kFrame);
      }
      noise.block<3, 3>(3, 3) = R_NE * spp.velocity.covariance * R_NE.transpose() + 0.0025 * Eigen::Matrix3d::Identity();
    }
    bool informed = true;
    try {
      const sri::BlockId id = frameBlock_;
      (void)est.covariance(std::span<const sri::BlockId>(&id, 1));
    } catch (const std::exception&) {
      informed = false;
    }
    std::vector<bool> acc;
    const auto u = apply(est, rows, noise, k.integrationCovariance, acc, informed);
    rep.chi2 = static_cast<double>(u.chi2);
    rep.dof = u.dof;
    for (std::size_t i = 0; i < rows.size(); ++i) (acc[i] ? rep.frame.used : rep.frame.rejected)++;
    rep.updated = u.applied;
    try {
      const sri::BlockId id = frameBlock_;
      const auto P = est.covariance(std::span<const sri::BlockId>(&id, 1));
      const double sth = config_.frameYawSigmaDeg * constants::kDegToRad;
      if (static_cast<double>(P(0, 0)) < sth * sth) stage_ = GnssFusionStage::kTight;
    } catch (const std::exception&) {
    }
  } else {
    // Tight stage.
    const SppSolution* sppVel = config_.mode == GnssFusionMode::kGpsVel ? &sppNow() : nullptr;
    const bool needClocks = config_.usesDoppler();
    std::vector<SatelliteModel> models = satelliteModels(rover, nav, k.x_E, &states);
    if (needClocks && !clockBlock_.valid()) {
      if (!initClocks(est, models, k, tMeas)) return finish();
      rep.clocksInitialized = true;
      for (SatelliteModel& m : models) m.clock = clockIndex(m.sat);
    }
    if (clockBlock_.valid()) propagateClocks(est, tMeas);
    if (clockBlock_.valid() && !rep.clocksInitialized) {  // systems whose ephemerides came later
      addLateClockSystems(est, models, k, tMeas);
      for (SatelliteModel& m : models) m.clock = clockIndex(m.sat);
    }
    if (clockBlock_.valid() && config_.zwdState()) {
      if (!zwdBlock_.valid()) {
        Eigen::Matrix<Scalar, Eigen::Dynamic, 1> z = Eigen::Matrix<Scalar, Eigen::Dynamic, 1>::Zero(1);
        zwdBlock_ = est.addBlock(sri::BlockSpec::vector("gnss_zwd", 1), sri::BlockEstimate<Scalar>::fromVector(z),
                                 sri::Prior<Scalar>::stdDev(1, static_cast<Scalar>(config_.zwdSigma)));
        zwdTime_ = tMeas;
      }
      propagateZwd(est, tMeas);
      const double zwd = static_cast<double>(est.estimate(zwdBlock_).vector[0]);
      for (SatelliteModel& m : models) m.troposphere += m.mapWet * zwd;
    }
    Eigen::VectorXd clk;
    if (clockBlock_.valid()) clk = systemClocks(est);
    const int n = static_cast<int>(clockSystems_.size());
    const bool excited = config_.calibrateLeverArm &&
                         (s.omegaMeasured - s.newest.bg).norm() >= config_.minRotationRate;
    if (config_.usesDoppler()) {
      for (const SatelliteModel& m : models) {
        if (!m.hasDoppler) continue;
        GnssRow r = dopplerRow(m, k, clk[n]);
        if (!excited) r.H_lever.setZero();
        rows.push_back(r);
        types.push_back(kDopp);
        diag.push_back(r.variance);
      }
    }
    if (config_.usesPseudorange()) {
      for (const SatelliteModel& m : models) {
        if (m.clock < 0) continue;
        GnssRow r = pseudorangeRow(m, k, clk[m.clock]);
        r.H_lever.setZero();
        rows.push_back(r);
        types.push_back(kPsr);
        diag.push_back(r.variance);
      }
    }
    if (sppVel && sppVel->velocity.valid) {
      const Eigen::Matrix3d R_NE = anchor_.R_EN.transpose();
      const Eigen::Vector3d vN = R_NE * sppVel->velocity.velocity;
      for (int a = 0; a < 3; ++a) {
        GnssRow r = velocityRow(vN, a, k);
        r.H_lever.setZero();
        rows.push_back(r);
        types.push_back(kVel);
        diag.push_back(0.0);
      }
    }
    // vio+dopp+ppp: ionosphere-free phase rows, one float ambiguity state per satellite arc.
    std::vector<sri::BlockId> ambBlocks;
    std::vector<SatId> ambSats;
    if (ppp && clockBlock_.valid()) {
      // Ambiguities of satellites on broadcast orbits and clocks follow their drifting errors.
      std::vector<SatId> broadcast;
      for (const SatelliteModel& m : models)
        if (!m.precise && !m.ssr) broadcast.push_back(m.sat);
      propagateAmbiguities(est, broadcast, tMeas);
      // Satellites with a state first, then the others highest first (max_ambiguities).
      std::vector<const SatelliteModel*> order;
      for (const SatelliteModel& m : models) order.push_back(&m);
      std::stable_sort(order.begin(), order.end(), [&](const SatelliteModel* a, const SatelliteModel* b) {
        const bool ha = ambiguities_.count(a->sat) > 0, hb = ambiguities_.count(b->sat) > 0;
        if (ha != hb) return ha;
        return a->azel.elevation > b->azel.elevation;
      });
      for (const SatelliteModel* mp : order) {
        const SatelliteModel& m = *mp;
        if (!m.hasCarrier || m.clock < 0 || arcs_->samples(m.sat) == 0) continue;
        const GpsTime start = rover.time - arcs_->arcLength(m.sat);
        auto it = ambiguities_.find(m.sat);
        if (it != ambiguities_.end() && std::abs(it->second.arcStart - start) > 1e-3) {
          dropAmbiguity(est, m.sat);  // new arc: cycle slip, gap or signal change
          it = ambiguities_.end();
        }
        if (it == ambiguities_.end()) {
          if (config_.maxAmbiguities > 0 && static_cast<int>(ambiguities_.size()) >= config_.maxAmbiguities) continue;
          // Centred on phase minus code (code model: + c·group delay), which differ by the
          // ambiguity plus the code error. The arc may be older than the state (epochs before
          // the VIO or the clocks were ready, a restart after rejections): its carrier-smoothed
          // code carries those epochs' codes, weighted as the code rows are (each epoch as one
          // measurement: σ/sqrt(n)) except for the orbit/clock error, a bias per satellite that no
          // averaging reduces; a new arc starts from the raw code with a loose prior.
          Eigen::Matrix<Scalar, Eigen::Dynamic, 1> x(1);
          double code = m.pseudorange, sigma = config_.ambiguitySigma;
          const SatObs* so = arcSmoothed_.find(m.sat);
          const SignalObs* s1 = so ? so->find(m.code) : nullptr;
          const SignalObs* s2 = so ? so->find(m.code2) : nullptr;
          if (arcs_->samples(m.sat) > 1 && s1 && s2 && s1->hasCode() && s2->hasCode()) {
            code = m.ifA1 * s1->pseudorange + m.ifA2 * s2->pseudorange;
            const double nf = arcs_->noiseFactor(m.sat);
            sigma = std::sqrt((m.codeVariance - m.ephemerisVariance) * nf * nf + m.ephemerisVariance);
          }
          x[0] = static_cast<Scalar>(m.carrierRange - (code - kC * m.groupDelay));
          Ambiguity a;
          // In front of the state: visual rows never reach those columns, and a state that ends
          // with its arc is cheap to marginalize there.
          a.id = est.addBlock(sri::BlockSpec::vector("gnss_ambiguity", 1), sri::BlockEstimate<Scalar>::fromVector(x),
                              sri::Prior<Scalar>::stdDev(1, static_cast<Scalar>(sigma)), vio::ClientBlockRegion::kFront);
          a.arcStart = start;
          it = ambiguities_.emplace(m.sat, a).first;
        }
        it->second.lastRow = rover.time;
        const double nAmb = static_cast<double>(est.estimate(it->second.id).vector[0]);
        SatelliteModel mc = m;
        if (config_.broadcastRecordChanges && !m.precise && !m.ssr) {
          BroadcastRecordContinuity& r = it->second.records;
          if (r.update(nav, m.sat, rover.time - m.pseudorange / kC, m.transmitTime, k.x_E).changed) ++rep.recordChanges;
          mc.carrierRange += r.shift();
        }
        if (config_.phaseWindup) {
          const double w = continueWindup(m.windup, it->second.windup);
          it->second.windup = w;
          mc.carrierRange -= m.windupWavelength * w;
        }
        GnssRow r = carrierPhaseRow(mc, k, clk[m.clock], nAmb);
        r.H_lever.setZero();
        r.ambiguity = static_cast<int>(ambBlocks.size());
        ambBlocks.push_back(it->second.id);
        ambSats.push_back(m.sat);
        rows.push_back(r);
        types.push_back(kPhase);
        diag.push_back(r.variance);
      }
    }
    const std::size_t nIndependent = rows.size();
    std::vector<DoubleDifference> phase;
    if (rtk_ && !fullRtk) baseAge = rtk_->differences(rover, k.x_E, &states);
    if (fullRtk && !rtkProcessed) {
      int heldFixed = 0;
      baseAge = rtk_->differencesWithHeldFix(roverRaw, k.x_E, heldFixed, &states);
      rep.rtkFixed = heldFixed > 0;
      if (rtkDeferred && !rtk_->phasePairsAsProcessed()) runRtk();
    }
    if (baseAge && config_.usesDifferences() && *baseAge <= config_.maxBaseAge) {
      const DdEpoch& e = rtk_->measurements();
      // Base clock per system: mean base code OMC (clock + errors common to the base).
      std::vector<double> sum(static_cast<std::size_t>(n), 0.0);
      std::vector<int> cnt(static_cast<std::size_t>(n), 0);
      for (const SingleDifference& sd : e.sd) {
        const int c = clockIndex(sd.sat);
        if (c < 0 || !sd.hasCode) continue;
        sum[static_cast<std::size_t>(c)] += sd.baseCodeOmc;
        cnt[static_cast<std::size_t>(c)]++;
      }
      for (const SingleDifference& sd : e.sd) {
        const int c = clockIndex(sd.sat);
        if (c < 0 || !sd.hasCode || sd.elevation < config_.elevationMaskDeg * constants::kDegToRad) continue;
        const double cb = sum[static_cast<std::size_t>(c)] / cnt[static_cast<std::size_t>(c)];
        GnssRow r = sdPseudorangeRow(sd, k, clk[c], cb);
        r.clockBias = c;
        rows.push_back(r);
        types.push_back(kDpsr);
        diag.push_back(r.variance);
      }
      if (config_.mode == GnssFusionMode::kDoppDdcp && rep.rtkFixed) {
        for (const DoubleDifference& dd : e.phase) {
          if (dd.ambiguityMeters) phase.push_back(dd);
        }
        for (const DoubleDifference& dd : phase) {
          rows.push_back(ddPhaseRow(e, dd, k));
          types.push_back(kDdcp);
        }
      }
    }
    noise = Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(rows.size()), static_cast<Eigen::Index>(rows.size()));
    for (std::size_t i = 0; i < diag.size(); ++i) noise(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(i)) = diag[i];
    if (sppVel && sppVel->velocity.valid) {
      const Eigen::Matrix3d R_NE = anchor_.R_EN.transpose();
      const Eigen::Index o = static_cast<Eigen::Index>(nIndependent) - 3;
      noise.block<3, 3>(o, o) = R_NE * sppVel->velocity.covariance * R_NE.transpose() + 0.0025 * Eigen::Matrix3d::Identity();
    }
    if (!phase.empty()) {
      const Eigen::Index o = static_cast<Eigen::Index>(diag.size());
      const Eigen::Index np = static_cast<Eigen::Index>(phase.size());
      noise.block(o, o, np, np) = ddCovariance(rtk_->measurements(), phase, true);
    }
    if (!rows.empty()) {
      std::vector<bool> acc;
      const auto u = apply(est, rows, noise, k.integrationCovariance, acc, gateRecovery_.gated(rover.time), ambBlocks);
      gateRecovery_.outcome(rover.time, u.applied, rows.size());  // re-acquisition (gnss_gate_recovery.hpp)
      rep.chi2 = static_cast<double>(u.chi2);
      rep.dof = u.dof;
      rep.updated = u.applied;
      for (std::size_t i = 0; i < rows.size(); ++i) {
        GnssTypeCount& c = countOf(rep, types[i]);
        (acc[i] ? c.used : c.rejected)++;
        if (types[i] != kPhase) continue;
        // A phase row gated out again and again: the ambiguity no longer fits (undetected slip,
        // broadcast orbit/clock change); it restarts from phase minus code.
        const SatId sat = ambSats[static_cast<std::size_t>(rows[i].ambiguity)];
        Ambiguity& a = ambiguities_.at(sat);
        a.rejections = acc[i] ? 0 : a.rejections + 1;
        if (a.rejections >= config_.ambiguityResetRejections) dropAmbiguity(est, sat);
      }
    }
    // Ambiguities of satellites without a phase row for a while (set, masked, lost).
    for (auto it = ambiguities_.begin(); it != ambiguities_.end();) {
      const SatId sat = it->first;
      const bool stale = rover.time - it->second.lastRow > 10.0;
      ++it;
      if (stale) dropAmbiguity(est, sat);
    }
    rep.ambiguities = static_cast<int>(ambiguities_.size());
  }
  if (rep.updated) lastUpdate_ = rover.time;
  if (buildState(est, t_ns, s)) {
    k = antennaKinematics(s);
    rep.antennaEcef = k.x_E;
    rep.antennaVelocityEcef = k.u_E;
    rep.antennaGeodetic = ecefToGeodetic(k.x_E);
  }
  return finish();
}

template class GnssFusion<float>;
template class GnssFusion<double>;

}  // namespace gvins::fusion
