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
#include "gnss_fusion_epoch.hpp"

namespace gvins::fusion {
namespace {

constexpr double kC = constants::kSpeedOfLight;

std::int64_t toNs(const GpsTime& t) {
  return t.wholeSeconds() * 1000000000LL + std::llround(t.fraction() * 1e9);
}

}  // namespace

template <typename Scalar>
GnssFusion<Scalar>::GnssFusion(GnssFusionConfig config) : config_(std::move(config)) {}

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
  return lever_.value(current(est) ? &est : nullptr);
}

template <typename Scalar>
std::optional<Eigen::Matrix<double, 6, 6>> GnssFusion<Scalar>::antennaCovariance(const vio::EstimatorBackend<Scalar>& est,
                                                                                 std::int64_t t_ns) const {
  if (!current(est) || !est.initialized() || (!frameBlock_.valid() && !worldChange_)) return std::nullopt;
  GnssStateValues s;
  if (!buildState(est, t_ns, s)) return std::nullopt;
  const AntennaKinematics k = antennaKinematics(s);
  // The kinematics' Jacobians of [p_N; v_N] over the blocks, in the order listed.
  const vio::ImuBlocks ib = est.newestImuBlocks();
  std::vector<sri::BlockId> blocks{ib.pose, ib.velocity, ib.bias};
  Eigen::Matrix<double, 6, Eigen::Dynamic> J(6, 22);
  J.leftCols<15>() = k.J_imu;
  Eigen::Index n = 15;
  if (frameBlock_.valid()) {
    blocks.push_back(frameBlock_);
    J.middleCols<4>(n) = k.J_frame;
    n += 4;
  }
  if (lever_.valid()) {
    blocks.push_back(lever_.block());
    J.middleCols<3>(n) = k.J_lever;
    n += 3;
  }
  const std::span<const sri::BlockId> ids(blocks);
  if (!est.informed(ids)) return std::nullopt;  // a block without information yet (sri_filter.hpp)
  const Eigen::MatrixXd P = est.covariance(ids).template cast<double>();
  const auto Jb = J.leftCols(n);
  const Eigen::Matrix<double, 6, 6> C_N = Jb * P * Jb.transpose() + k.J_earlier * k.integrationCovariance * k.J_earlier.transpose();
  Eigen::Matrix<double, 6, 6> R = Eigen::Matrix<double, 6, 6>::Zero();
  R.topLeftCorner<3, 3>() = k.R_EN;
  R.bottomRightCorner<3, 3>() = k.R_EN;
  return Eigen::Matrix<double, 6, 6>(R * C_N * R.transpose());
}

template <typename Scalar>
void GnssFusion<Scalar>::forgetState() {
  lever_.forget();
  frameBlock_ = {};
  worldChange_.reset();
  clocks_.forget();
  baseClock_.reset();
  zwd_.forget();
  lastUpdate_.reset();
  gateRecovery_.reset();
  ambiguities_.forget();
  stage_ = GnssFusionStage::kWaitingVio;
  frameRejections_ = 0;
  yawPending_ = false;
  startedAtRest_ = false;
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
  if (!clocks_.valid() || !current(est)) return std::nullopt;
  return clocks_.values(est);
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
bool GnssFusion<Scalar>::startFrame(vio::EstimatorBackend<Scalar>& est, const SppSolution& spp, std::int64_t t_ns) {
  if (!spp.valid() || !spp.velocity.valid) return false;
  anchor_ = GnssAnchor::at(spp.position);
  GnssStateValues s;
  if (!buildState(est, t_ns, s)) return false;
  const AntennaKinematics k = antennaKinematics(s);  // yaw 0, p_NW 0: p_N = p_W
  const Eigen::Vector3d vN = anchor_.R_EN.transpose() * spp.velocity.velocity;
  const double minV = config_.frameMinSpeed;
  const bool sppMoving = vN.head<2>().norm() >= minV, imuMoving = k.v_N.head<2>().norm() >= minV;
  const bool moving = sppMoving && imuMoving;
  // At rest (horizontally) only when both agree: one moving and the other not is an IMU velocity
  // far off (e.g. just after a visual initialisation in cruise), no start to make yet.
  if (!moving && (!config_.frameStartAtRest || sppMoving || imuMoving)) return false;
  const double yaw = moving ? velocityHeadingDifference(vN, k.v_N) : 0.0;
  const Eigen::Vector3d pN = anchor_.R_EN.transpose() * (spp.position - anchor_.ecef);
  Eigen::Matrix<Scalar, Eigen::Dynamic, 1> x(4);
  x[0] = static_cast<Scalar>(std::remainder(yaw, 2.0 * constants::kPi));
  x.template tail<3>() = (pN - yawRotation(yaw) * k.p_N).template cast<Scalar>();
  // Paper Sec. III-A: uninformative ("infinite covariance") prior. Without the headings the yaw
  // keeps the circle's σ as its prior instead, so that the block is informed (gated, with a
  // covariance) once the rows reach p_NW; the rows never inform the yaw (apply) until
  // headingFromMotion gives it a value.
  yawPending_ = !moving;
  startedAtRest_ = !moving;
  yawCentre_ = k.p_N;  // p_W,r (yaw 0, p_NW 0)
  auto prior = sri::Prior<Scalar>::uninformative();
  if (yawPending_) {
    typename sri::Prior<Scalar>::Matrix S = sri::Prior<Scalar>::Matrix::Zero(1, 4);
    S(0, 0) = static_cast<Scalar>(1.0 / kFrameYawPriorSigma);
    prior = sri::Prior<Scalar>::sqrtInformation(S);
  }
  frameBlock_ = est.addBlock(sri::BlockSpec::vector("gnss_frame", 4), sri::BlockEstimate<Scalar>::fromVector(x), prior);
  return true;
}

namespace {

/// Covariance of [heading, p_N] of the newest IMU state in local ENU while the frame block
/// [ψ, p_NW] is a state: heading = ψ + the yaw of R_WI (δθ is the right perturbation of R_WI, so
/// its world yaw is e_zᵀ R_WI δθ), p_N = p_NW + Rz(ψ) p_W. The frame's own ψ is not the quantity
/// the rows depend on: after a long stretch without GNSS (a cold start whose ephemerides come
/// late) the IMU's yaw in W has drifted with an uncertainty no GNSS row can reduce, and σ_ψ keeps
/// it, while the IMU's heading in ENU is what the GNSS rows determine. nullopt while not informed.
template <typename Scalar>
std::optional<Eigen::Matrix4d> enuHeadingPositionCovariance(const vio::EstimatorBackend<Scalar>& est,
                                                            sri::BlockId frame) {
  const vio::ImuBlocks ib = est.newestImuBlocks();
  const std::array<sri::BlockId, 2> ids{ib.pose, frame};
  if (!est.informed(ids)) return std::nullopt;
  const Eigen::MatrixXd P = est.covariance(ids).template cast<double>();
  const vio::ImuState x = est.newestImuState();
  const Eigen::Matrix3d Rz = yawRotation(static_cast<double>(est.estimate(frame).vector[0]));
  Eigen::Matrix<double, 4, 10> J = Eigen::Matrix<double, 4, 10>::Zero();  // ∂[heading; p_N]/∂[δθ δp | ψ p_NW]
  J.block<1, 3>(0, 0) = x.R_WI.row(2);
  J(0, 6) = 1.0;
  J.block<3, 3>(1, 3) = Rz;
  J.block<3, 1>(1, 6) = Eigen::Vector3d::UnitZ().cross(Rz * x.p_WI);
  J.block<3, 3>(1, 7).setIdentity();
  return Eigen::Matrix4d(J * P * J.transpose());
}

}  // namespace

template <typename Scalar>
bool GnssFusion<Scalar>::frameKnownInEnu(const vio::EstimatorBackend<Scalar>& est) const {
  const std::optional<Eigen::Matrix4d> C = enuHeadingPositionCovariance(est, frameBlock_);
  if (!C) return false;  // not informed (yet)
  const Eigen::Vector4d var = C->diagonal();
  // After a start at rest the position is known before the heading: the move then waits for the
  // heading to be known well (the local outputs keep the frame of the move, its error with them).
  const double sth = (startedAtRest_ ? config_.frameReanchorYawSigmaDeg : config_.frameYawSigmaDeg) * constants::kDegToRad;
  const double sp = config_.frameReanchorPositionSigma;
  return var[0] < sth * sth && var.tail<3>().maxCoeff() < sp * sp;
}

template <typename Scalar>
std::map<SatId, double> GnssFusion<Scalar>::ambiguities(const vio::EstimatorBackend<Scalar>& est) const {
  if (!current(est)) return {};
  return ambiguities_.values(est);
}

template <typename Scalar>
std::optional<double> GnssFusion<Scalar>::zenithWetDelay(const vio::EstimatorBackend<Scalar>& est) const {
  if (!zwd_.valid() || !current(est)) return std::nullopt;
  return zwd_.value(est);
}

namespace {

/// The blocks GNSS rows touch: newest pose, velocity and bias, frame, lever arm, clocks (all at
/// the back of the state), then the ambiguities; a row as a vector h over them, in this order.
struct RowLayout {
  std::vector<sri::BlockId> blocks;
  std::vector<int> dims;
  std::size_t nImu = 0;  // the client blocks follow
  int dim = 0;
  int frameAt = -1, leverAt = -1, clockAt = -1, isbAt = -1, zwdAt = -1, ambiguityAt = -1;

  /// Appends a block when valid; returns its column, -1 if not.
  int add(sri::BlockId id, int size) {
    if (!id.valid()) return -1;
    const int at = dim;
    blocks.push_back(id);
    dims.push_back(size);
    dim += size;
    return at;
  }
  /// h of row r (h.size() == dim).
  template <typename Row>
  void fill(const GnssRow& r, Row&& h) const {
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
  }
};

/// Whitens the rows of A (the kept rows `keep` of Σ_m = noise) by Σ_m^-½: Σ_m is block diagonal
/// (independent rows; the gpsvel triple and the DD phases correlated among themselves), each
/// block is whitened by its own Cholesky factor. False if a block is not positive definite.
bool whitenRows(Eigen::MatrixXd& A, const Eigen::MatrixXd& noise, const std::vector<int>& keep) {
  const auto nk = static_cast<Eigen::Index>(keep.size());
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
      if (!(s2 > 0.0)) return false;
      A.row(a) /= std::sqrt(s2);
      continue;
    }
    Eigen::MatrixXd S(b - a, b - a);
    for (Eigen::Index i = a; i < b; ++i)
      for (Eigen::Index k = a; k < b; ++k) S(i - a, k - a) = sigma(i, k);
    const Eigen::LLT<Eigen::MatrixXd> llt(S);
    if (llt.info() != Eigen::Success) return false;
    llt.matrixL().solveInPlace(A.middleRows(a, b - a));
  }
  return true;
}

/// The rows as the re-acquisition tests see them (gnss_gate_recovery.hpp). G: the columns of the
/// newest pose's δp and of the receiver clock (range rows), of the velocity and the clock drift
/// (rate rows). The band variance: the measurement noise plus the states G leaves out (the
/// inter-system biases, the wet delay, the ambiguities; attitude, biases, frame and lever arm act
/// on an epoch's rows through the antenna position and velocity, which the correction takes).
ReacquisitionRows reacquisitionRows(const RowLayout& lay, const Eigen::MatrixXd& HJ, const Eigen::MatrixXd& P,
                                    const Eigen::Matrix<double, 9, 9>& intCov, const Eigen::MatrixXd& noise,
                                    const std::vector<GnssRow>& rows, const std::vector<int>& groups) {
  const Eigen::Index n = HJ.rows(), dim = lay.dim;
  const auto H = HJ.leftCols(dim);
  const auto J = HJ.rightCols<9>();
  ReacquisitionRows out;
  out.group = groups;
  out.residual.resize(n);
  out.G = Eigen::MatrixXd::Zero(n, 4);
  out.S = H * P * H.transpose() + J * intCov * J.transpose() + noise;
  // The layout's blocks after the clock: inter-system biases, wet delay, ambiguities.
  const Eigen::Index other = lay.isbAt >= 0 ? lay.isbAt : lay.zwdAt >= 0 ? lay.zwdAt : lay.ambiguityAt;
  Eigen::MatrixXd Ho = Eigen::MatrixXd::Zero(n, dim);
  Ho.rightCols(dim - other) = H.rightCols(dim - other);
  out.bandVariance = (Ho * P).cwiseProduct(Ho).rowwise().sum() + noise.diagonal();
  for (Eigen::Index i = 0; i < n; ++i) {
    const GnssRow& r = rows[static_cast<std::size_t>(i)];
    out.residual[i] = r.residual;
    out.sats.push_back(r.sat);
    const bool rate = groups[static_cast<std::size_t>(i)] == kReacquireRate;
    out.G.row(i).head<3>() = H.row(i).segment<3>(rate ? 6 : 3);  // δv or the pose's δp
    if (lay.clockAt >= 0) out.G(i, 3) = H(i, lay.clockAt + (rate ? 1 : 0));
  }
  return out;
}

}  // namespace

template <typename Scalar>
vio::BackendUpdate<Scalar> GnssFusion<Scalar>::apply(vio::EstimatorBackend<Scalar>& est, std::vector<GnssRow>& rows,
                                                     const Eigen::MatrixXd& noise,
                                                     const Eigen::Matrix<double, 9, 9>& intCov,
                                                     std::vector<bool>& accepted, bool gate,
                                                     const std::vector<sri::BlockId>& ambiguities,
                                                     ReacquisitionEpoch* reacquisition) {
  const vio::ImuBlocks ib = est.newestImuBlocks();
  accepted.assign(rows.size(), false);
  RowLayout lay;
  lay.blocks = {ib.pose, ib.velocity, ib.bias};
  lay.dims = {6, 3, 6};
  lay.nImu = lay.blocks.size();
  lay.dim = 15;
  lay.frameAt = lay.add(frameBlock_, 4);
  lay.leverAt = lay.add(lever_.block(), 3);
  lay.clockAt = lay.add(clocks_.clockBlock(), 2);
  // With the clock, one per system after the first.
  lay.isbAt = lay.add(clocks_.isbBlock(), static_cast<int>(clocks_.systems().size()) - 1);
  lay.zwdAt = lay.add(zwd_.block(), 1);
  lay.ambiguityAt = lay.dim;
  for (const sri::BlockId& id : ambiguities) lay.add(id, 1);
  const int dim = lay.dim;

  // Row gate: each row alone against the joint marginal covariance P of those blocks (cheap at
  // the back of the state): χ² = r² / (σ² + J Σ_k Jᵀ + h P hᵀ), the innovation test of the row.
  const bool rowGate = gate && config_.rowGate < 1.0;
  // A block without information (e.g. a new frame block): rows pass the row gate.
  const bool haveP = rowGate && est.informed(lay.blocks);
  Eigen::MatrixXd P;
  if (haveP) P = est.covariance(lay.blocks).template cast<double>();
  const double q1 = rowGate ? rowGateQuantile_(config_.rowGate, 1) : 0.0;
  // All rows as [h | J] at once; the gate's h P hᵀ and J Σ_k Jᵀ of every row from two products.
  const auto nr = static_cast<Eigen::Index>(rows.size());
  Eigen::MatrixXd HJ(nr, dim + 9);
  for (Eigen::Index i = 0; i < nr; ++i) {
    const GnssRow& r = rows[static_cast<std::size_t>(i)];
    lay.fill(r, HJ.row(i).head(dim));
    HJ.row(i).tail<9>() = r.H_earlier;
  }
  // The frame's yaw while it is a nuisance (yawPending_): uniform on the circle about its guess
  // ψ̂, it turns the antenna's horizontal ENU position and velocity about the W origin,
  // Rz(ψ) x_h = Rz(ψ̂) x_h + n with E n = 0, E n nᵀ = |x_h|² I₂ (x_h: p_W,r or v_W,r). Its column
  // leaves the rows and n joins the nuisance (4 columns, σ |p_h| and |v_h|, yawSpread_: p_h the
  // displacement since the frame's start, the constant offset before it being p_NW's), projected
  // out like the integration error: the rows do not inform a yaw whose value is a guess, and
  // carry what it may move, also far from linear (half a turn).
  const bool yawNuisance = yawPending_ && lay.frameAt >= 0;
  const int ny = yawNuisance ? 4 : 0;
  Eigen::MatrixXd Ny(nr, ny);
  if (yawNuisance) {
    HJ.col(lay.frameAt).setZero();
    Ny = yawNuisanceColumns(rows);
  }
  Eigen::VectorXd gateVar(nr);  // σ² + J Σ_k Jᵀ + h P hᵀ per row
  if (haveP) {
    // The products as matrices first: nested in the coefficient-wise expression Eigen would
    // evaluate them lazily, one scalar dot product per coefficient.
    const Eigen::MatrixXd HP = HJ.leftCols(dim) * P;
    const Eigen::Matrix<double, Eigen::Dynamic, 9> JS = HJ.rightCols<9>() * intCov;
    gateVar = HP.cwiseProduct(HJ.leftCols(dim)).rowwise().sum() + JS.cwiseProduct(HJ.rightCols<9>()).rowwise().sum() +
              noise.diagonal();
    if (yawNuisance) gateVar += Ny.rowwise().squaredNorm();
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
  // Re-acquisition (gnss_gate_recovery.hpp): the widened gate and the consensus choose the rows
  // of their groups; the other rows keep the row gate above.
  bool readmitted = false;
  if (reacquisition && haveP) {
    ReacquisitionEpoch& re = *reacquisition;
    re.rows = reacquisitionRows(lay, HJ, P, intCov, noise, rows, re.groups);
    re.selection = selectReacquisitionRows(re.rows, re.tau, gateRecovery_.acceleration(), q1, config_.epochGate);
    std::vector<int> chosen;
    for (std::size_t i = 0; i < rows.size(); ++i) {
      const bool normal = std::find(keep.begin(), keep.end(), static_cast<int>(i)) != keep.end();
      const bool admitted = re.selection.admitted[i];
      if (re.groups[i] == kReacquireNone ? normal : admitted) chosen.push_back(static_cast<int>(i));
      if (admitted && !normal) re.normal = false;
      readmitted = readmitted || admitted;
    }
    for (const ReacquisitionGroupResult& g : re.selection.groups) re.normal = re.normal && (g.offered == 0 || g.admitted);
    keep = std::move(chosen);
  }
  vio::BackendUpdate<Scalar> u;
  if (keep.empty()) return u;

  // Whitening with Σ = Σ_m + J Σ_k Jᵀ (paper Sec. III-C), Σ_m block by block (whitenRows). The
  // integration error e ~ N(0, Σ_k) of the state at the measurement time, common to all rows,
  // enters as a 9-column nuisance J L_k (Σ_k = L_k L_kᵀ) with prior rows I and is projected out:
  // exactly the rows that the full Σ would give, without the n³ Cholesky of Σ.
  const auto nk = static_cast<Eigen::Index>(keep.size());
  const Eigen::Index rc = dim + 9 + ny;  // the residual's column
  Eigen::MatrixXd A(nk, rc + 1);        // [h | J | yaw nuisance | r]
  for (Eigen::Index j = 0; j < nk; ++j) {
    const auto i = static_cast<std::size_t>(keep[static_cast<std::size_t>(j)]);
    A.row(j).head(dim + 9) = HJ.row(static_cast<Eigen::Index>(i));
    if (yawNuisance) A.row(j).segment(dim + 9, ny) = Ny.row(static_cast<Eigen::Index>(i));
    A(j, rc) = rows[i].residual;
  }
  if (!whitenRows(A, noise, keep)) return u;
  // L_k of the (positive semi-definite) integration covariance.
  // (Pivoted LDLᵀ: Σ_k = Pᵀ L D Lᵀ P, L_k = Pᵀ L D^½; it may be singular. Any L_k with
  // L_k L_kᵀ = Σ_k gives the same projected rows.)
  const Eigen::LDLT<Eigen::Matrix<double, 9, 9>> ldlt(intCov);
  const Eigen::Matrix<double, 9, 9> L = ldlt.matrixL();
  const Eigen::Matrix<double, 9, 9> Lk =
      ldlt.transpositionsP().transpose() * (L * ldlt.vectorD().cwiseMax(0.0).cwiseSqrt().asDiagonal());
  const bool nuisance = Lk.norm() > 0.0;
  const int ni = nuisance ? 9 : 0;
  const int nn = ni + ny;
  sri::Measurement<Scalar> m(static_cast<int>(nk) + nn);
  for (std::size_t bi = 0, col = 0; bi < lay.blocks.size(); col += static_cast<std::size_t>(lay.dims[bi]), ++bi) {
    const auto c = static_cast<Eigen::Index>(col);
    const int d = lay.dims[bi];
    if (bi >= lay.nImu && A.middleCols(c, d).isZero(0.0)) continue;  // e.g. the lever arm without excitation
    m.jacobian(lay.blocks[bi], d).topRows(nk) = A.middleCols(c, d).template cast<Scalar>();
  }
  m.residual().head(nk) = A.col(rc).template cast<Scalar>();
  if (nn > 0) {
    auto N = m.nuisance(nn);
    if (nuisance) N.topLeftCorner(nk, 9) = (A.middleCols(dim, 9) * Lk).template cast<Scalar>();
    if (yawNuisance) N.block(0, ni, nk, ny) = A.middleCols(dim + 9, ny).template cast<Scalar>();
    N.bottomRows(nn).setIdentity();  // their priors: N(0, I) in these units
  }
  m.setWhitened();
  if (nn > 0) m.projectNuisance(nullptr, sri::Measurement<Scalar>::NuisanceProjection::kHouseholder);
  u = est.update(m, gate ? config_.epochGate : 1.0);
  if (readmitted) {
    // Rejected by the normal epoch gate: the widened joint χ² of the consensus stands for it.
    reacquisition->normal = reacquisition->normal && u.applied;
    if (!u.applied) u = est.update(m, 1.0);
  }
  if (u.applied) {
    for (int i : keep) accepted[static_cast<std::size_t>(i)] = true;
  }
  return u;
}

template <typename Scalar>
const ObsEpoch& GnssFusion<Scalar>::prepareRover(const ObsEpoch& roverInput, const EphemerisStore& nav,
                                                 GnssEpochReport& rep) {
  // Doppler sanity of the rover stream before any user (doppler_consistency.hpp): flipped signs
  // corrected, bad Dopplers dropped; the base's is checked inside the RTK module.
  checkedRover_ = roverInput;
  clockJumps_.apply(checkedRover_, nav.glonassChannels());  // whole-ms receiver clock jumps (clock_jump_repair.hpp)
  const std::size_t warned = roverDoppler_.warnings().size();
  roverDoppler_.apply(checkedRover_, nav.glonassChannels());
  rep.warnings.assign(roverDoppler_.warnings().begin() + static_cast<std::ptrdiff_t>(warned), roverDoppler_.warnings().end());
  const ObsEpoch& roverRaw = checkedRover_;
  // Carrier-smoothed codes for the psr rows, and for the SD code rows of dpsr and ddcp on both
  // receivers (every epoch, also before the VIO is ready, so that the arcs are long when the rows
  // start). Ddcp's RTK module takes the raw codes (Epoch::roverRaw, the raw base): its filter
  // estimates the ambiguities from phase minus code, which smoothing would correlate in time.
  const bool smoothDifferences = config_.usesDifferences();
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
  return smoother_ ? smoothed_ : roverRaw;
}

template <typename Scalar>
void GnssFusion<Scalar>::useNavigation(const EphemerisStore& nav) {
  if (nav_ == &nav) return;
  nav_ = &nav;
  // The SPP covariance of the frame updates and the alignment as before the correlated-error
  // model of the reported covariance (spp_config.hpp ReportedErrorModel), until it is tuned here.
  SppConfig sppConfig;
  sppConfig.reportedError.enabled = false;
  spp_ = std::make_unique<SppSolver>(nav, sppConfig);
  if (config_.usesDifferences()) {
    // The SD code variances with the fusion's code weighting (double_difference.cpp).
    RtkConfig rtkConfig;
    if (config_.codeWeighting == GnssCodeWeighting::kElevationCn0) rtkConfig.codeWeighting = WeightingScheme::ElevationSnr;
    rtk_ = std::make_unique<RtkSolver>(nav, rtkConfig);
    // Ddcp with smoothing: the SD code rows from the smoothed codes of both receivers, formed as
    // dpsr forms them (RtkSolver::differences), beside the RTK module on the raw ones.
    codeRtk_.reset();
    if (config_.mode == GnssFusionMode::kDoppDdcp && baseSmoother_) codeRtk_ = std::make_unique<RtkSolver>(nav, rtkConfig);
    for (RtkSolver* r : {rtk_.get(), codeRtk_.get()}) {
      if (!r) continue;
      r->setRoverDopplerCheckedByCaller();  // checked at the input (prepareRover), once
      if (config_.basePosition) r->setBasePosition(*config_.basePosition);
    }
    baseWarned_ = 0;
  }
}

template <typename Scalar>
const SppSolution& GnssFusion<Scalar>::sppOf(Epoch& e) {
  // SPP only where it is used (frame initialisation, the clock before the clock block exists,
  // vio+gpsvel): in the tight stage with clocks it is not needed.
  if (!e.spp) e.spp = spp_->solve(e.rover);
  return *e.spp;
}

template <typename Scalar>
void GnssFusion<Scalar>::runRtk(Epoch& e) {
  // (The epoch counts as fixed only where tightUpdate applies the DD phases of a validated fix.)
  const RtkSolution rtk = rtk_->process(e.roverRaw, &e.states);
  e.baseAge = rtk.age;
  e.rtkProcessed = true;
}

template <typename Scalar>
void GnssFusion<Scalar>::feedRtk(Epoch& e, const ObsEpoch* base) {
  // Ddcp runs the whole RTK module at every epoch until it fixes, then at the base epochs only
  // (no extrapolated base there) and holds the fix in between (RtkSolver::differencesWithHeldFix,
  // in the tight stage): the ambiguities are constant along the arcs.
  const bool newBase = base && (!lastBase_ || base->time > *lastBase_);
  if (newBase) {
    // The RTK module takes the raw base epochs unless they are smoothed for it (dpsr).
    const bool rawBase = !baseSmoother_ || codeRtk_;
    if (baseSmoother_) {
      // The smoothed base codes from Doppler-checked epochs (the smoother's slip detector tests
      // the Doppler), as the rover's are checked at the input; Ddcp's RTK module keeps the raw
      // base epoch and its own check.
      ObsEpoch b = *base;
      baseDoppler_.apply(b, e.nav.glonassChannels());
      baseSmoother_->apply(b, e.nav.glonassChannels());
      (codeRtk_ ? codeRtk_ : rtk_)->addBaseEpoch(b);
    }
    if (rawBase) rtk_->addBaseEpoch(*base);
    lastBase_ = base->time;
    // The base's Doppler check: the RTK module's on the raw base epochs, else the fusion's.
    if (rawBase) {
      const std::vector<std::string>& w = rtk_->base().doppler().warnings();
      for (; baseWarned_ < w.size(); ++baseWarned_) e.rep.warnings.push_back(w[baseWarned_]);
    } else {
      const std::vector<std::string>& w = baseDoppler_.warnings();
      for (; baseCheckWarned_ < w.size(); ++baseCheckWarned_) e.rep.warnings.push_back(w[baseCheckWarned_]);
    }
  }
  const std::optional<GpsTime> lastRun = rtk_->lastProcessTime();
  e.rtkDeferred = e.fullRtk && newBase && config_.rtkHoldFix && rtk_->hasHeldFix() && lastRun &&
                  e.rover.time - *lastRun < config_.rtkRevalidateInterval;
  if (e.fullRtk && !e.rtkDeferred && (newBase || !rtk_->hasHeldFix() || !config_.rtkHoldFix)) runRtk(e);
}

template <typename Scalar>
void GnssFusion<Scalar>::resetAfterOutage(vio::EstimatorBackend<Scalar>& est, GnssEpochReport& rep) {
  clocks_.marginalize(est);
  baseClock_.reset();
  zwd_.marginalize(est);
  if (rtk_) rtk_->reset();
  if (codeRtk_) codeRtk_->reset();
  ambiguities_.dropAll(est);
  rep.reset = true;
  lastUpdate_.reset();
}

template <typename Scalar>
bool GnssFusion<Scalar>::measurementTime(const vio::EstimatorBackend<Scalar>& est, Epoch& e) {
  // Measurement time: the tag minus the receiver clock (GPS, or the first system estimated).
  double dtr = 0.0;
  if (clocks_.valid()) {
    const Eigen::VectorXd c = est.estimate(clocks_.clockBlock()).vector.template cast<double>();
    dtr = (c[0] + c[1] * (e.rover.time - clocks_.time())) / kC;  // [c·dt, c·ḋt]
  } else if (sppOf(e).valid()) {
    for (const auto& b : sppOf(e).clockBias) {
      if (b) {
        dtr = *b / kC;
        break;
      }
    }
  }
  if (!(std::abs(dtr) < 0.01)) dtr = 0.0;
  e.tMeas = e.rover.time - dtr;
  e.t_ns = toNs(e.tMeas);
  const std::int64_t newest = est.newestTime();
  if (e.t_ns > newest) {
    if (e.t_ns - newest > 10000000) return false;  // the driver sends epochs up to newestTime()
    e.t_ns = newest;
  }
  return true;
}

template <typename Scalar>
bool GnssFusion<Scalar>::frameUpdate(vio::EstimatorBackend<Scalar>& est, Epoch& e, const AntennaKinematics& k) {
  const SppSolution& spp = sppOf(e);
  if (!spp.valid()) return false;
  GnssEpochReport& rep = e.rep;
  GnssRowSet rows;
  addPositionRows(anchor_, spp.position, spp.positionCovariance, k, rows);
  if (spp.velocity.valid) addVelocityRows(anchor_, spp.velocity, k, kFrame, true, rows);
  const std::span<const sri::BlockId> frameIds(&frameBlock_, 1);
  // The rows are gated once the frame block has information.
  const bool first = !est.informed(frameIds);
  std::vector<bool> acc;
  const auto u = apply(est, rows.rows, rows.noise(), k.integrationCovariance, acc, !first);
  rep.chi2 = static_cast<double>(u.chi2);
  rep.dof = u.dof;
  for (std::size_t i = 0; i < rows.size(); ++i) (acc[i] ? rep.frame.used : rep.frame.rejected)++;
  rep.updated = u.applied;
  if (first && u.applied && !linearStart(est, e, rows)) return false;
  // Frame rows gated out at two epochs in a row after the first update: the state predicted from
  // the start disagrees with the fixes beyond its covariance (a start that was not linear, whose
  // later updates would collapse the heading σ about a wrong estimate). One epoch is an outlier.
  frameRejections_ = !first && !u.applied && !rows.rows.empty() ? frameRejections_ + 1 : 0;
  if (frameRejections_ >= 2) {
    char buf[300];
    std::snprintf(buf, sizeof buf,
                  "GNSS frame initialisation at %d %.3f: the SPP rows were gated out at %d epochs in a row after the "
                  "start (χ² %.1f on %d rows): the state does not follow the fixes",
                  e.rover.time.week(), e.rover.time.tow(), frameRejections_, rep.chi2, rep.dof);
    frameRejections_ = 0;
    if (restartFrame(est, e, buf)) return false;
  }
  // Converged when the IMU's heading in ENU is known to σ_θ (enuHeadingPositionCovariance).
  const std::optional<Eigen::Matrix4d> C = enuHeadingPositionCovariance(est, frameBlock_);
  const double sth = config_.frameYawSigmaDeg * constants::kDegToRad;
  if (C && (*C)(0, 0) < sth * sth) stage_ = GnssFusionStage::kTight;
  // Yaw a nuisance: the modes with range rows go tight once the frame's position is informed (the
  // rows keep projecting the yaw out); the others keep the SPP rows until the yaw converged.
  const bool ranges = config_.usesPseudorange() || config_.usesDifferences();
  if (yawPending_ && ranges && C) stage_ = GnssFusionStage::kTight;
  return true;
}

template <typename Scalar>
Eigen::MatrixXd GnssFusion<Scalar>::yawNuisanceColumns(const std::vector<GnssRow>& rows) const {
  Eigen::MatrixXd N(static_cast<Eigen::Index>(rows.size()), 4);
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const auto& d = rows[i].dh_dpv;
    N.row(static_cast<Eigen::Index>(i)) << d[0] * yawSpread_[0], d[1] * yawSpread_[0], d[3] * yawSpread_[1],
        d[4] * yawSpread_[1];
  }
  return N;
}

template <typename Scalar>
bool GnssFusion<Scalar>::linearStart(vio::EstimatorBackend<Scalar>& est, Epoch& e, const GnssRowSet& rows) {
  // The first rows meet a block without information: linearly they are fitted exactly, so what
  // is left of them at the corrected state is the error of the linearisation.
  GnssStateValues s;
  if (!buildState(est, e.t_ns, s)) return true;
  const AntennaKinematics k = antennaKinematics(s);
  const SppSolution& spp = sppOf(e);
  GnssRowSet after;
  addPositionRows(anchor_, spp.position, spp.positionCovariance, k, after);
  if (spp.velocity.valid) addVelocityRows(anchor_, spp.velocity, k, kFrame, true, after);
  if (after.size() != rows.size()) return true;
  Eigen::VectorXd r(static_cast<Eigen::Index>(after.size()));
  for (std::size_t i = 0; i < after.size(); ++i) r[static_cast<Eigen::Index>(i)] = after.rows[i].residual;
  Eigen::MatrixXd noise = rows.noise();
  if (yawPending_) {  // the yaw's nuisance (apply) moves the rows too
    const Eigen::MatrixXd N = yawNuisanceColumns(after.rows);
    noise += N * N.transpose();
  }
  const Eigen::LLT<Eigen::MatrixXd> llt(noise);
  if (llt.info() != Eigen::Success || !r.allFinite()) return true;
  const double chi2 = r.dot(llt.solve(r));
  const double bound = sri::chiSquareQuantile(config_.epochGate, static_cast<int>(r.size()));
  if (chi2 <= bound) return true;
  const std::array<sri::BlockId, 1> vel{est.newestImuBlocks().velocity};
  const double sv = est.informed(vel) ? std::sqrt(static_cast<double>(est.covariance(vel).trace())) : 0.0;
  char buf[420];
  std::snprintf(buf, sizeof buf,
                "GNSS frame initialisation at %d %.3f: after the first SPP update the antenna is still %.1f m and "
                "%.2f m/s from the fix (χ² %.1f > %.1f on %d rows; IMU velocity σ %.1f m/s): the IMU state is too far "
                "off for a linear start",
                e.rover.time.week(), e.rover.time.tow(), r.head<3>().norm(),
                r.size() >= 6 ? r.segment<3>(3).norm() : 0.0, chi2, bound, static_cast<int>(r.size()), sv);
  return !restartFrame(est, e, buf);
}

template <typename Scalar>
bool GnssFusion<Scalar>::restartFrame(vio::EstimatorBackend<Scalar>& est, Epoch& e, const std::string& why) {
  if (!est.restart()) {  // the backend cannot: the start goes on, and the gates judge it
    e.rep.warnings.push_back(why + "; the estimator cannot restart, the start goes on");
    return false;
  }
  e.rep.warnings.push_back(why + "; the estimator's state is dropped and " +
                           (config_.insStart ? "starts again from the GNSS/INS alignment" : "initialises again"));
  e.rep.reset = true;
  e.rep.frameRestart = true;
  e.rep.updated = false;
  forgetState();
  generation_ = est.generation();
  return true;
}

template <typename Scalar>
void GnssFusion<Scalar>::reportNotices(GnssEpochReport& rep) {
  for (; signalWarned_ < signalNotices_.messages().size(); ++signalWarned_) rep.warnings.push_back(signalNotices_.messages()[signalWarned_]);
  for (; jumpWarned_ < clockJumps_.warnings().size(); ++jumpWarned_) rep.warnings.push_back(clockJumps_.warnings()[jumpWarned_]);
  for (; clockWarned_ < clockNotices_.size(); ++clockWarned_) rep.warnings.push_back(clockNotices_[clockWarned_]);
  for (; gateWarned_ < gateRecovery_.warnings().size(); ++gateWarned_) rep.warnings.push_back(gateRecovery_.warnings()[gateWarned_]);
}

template <typename Scalar>
GnssEpochReport GnssFusion<Scalar>::processEpoch(vio::EstimatorBackend<Scalar>& est, const ObsEpoch& roverInput,
                                                 const ObsEpoch* base, const EphemerisStore& nav) {
  const auto wall0 = std::chrono::steady_clock::now();
  GnssEpochReport rep;
  rep.time = roverInput.time;
  auto finish = [&]() {
    if (current(est)) lever_.record(est);
    rep.stage = stage_;
    reportNotices(rep);
    rep.elapsedMicroseconds =
        std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - wall0).count();
    return rep;
  };
  if (config_.mode == GnssFusionMode::kVio) return finish();
  const ObsEpoch& rover = prepareRover(roverInput, nav, rep);
  useNavigation(nav);
  Epoch e(checkedRover_, rover, nav, rep);
  e.fullRtk = rtk_ && config_.mode == GnssFusionMode::kDoppDdcp;
  if (rtk_) feedRtk(e, base);
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
    resetAfterOutage(est, rep);
  }
  if (!measurementTime(est, e)) return finish();
  rep.t_ns = e.t_ns;
  if (config_.calibrateLeverArm) lever_.create(est);

  if (stage_ == GnssFusionStage::kWaitingFix) {
    if (!startFrame(est, sppOf(e), e.t_ns)) return finish();
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
  if (yawPending_ && frameBlock_.valid()) headingFromMotion(est, e);
  GnssStateValues s;
  if (!buildState(est, e.t_ns, s)) return finish();
  AntennaKinematics k = antennaKinematics(s);
  if (yawPending_) {
    // The antenna's horizontal displacement in W since the frame's start (its offset from the W
    // origin then is a constant that p_NW absorbs) and its horizontal velocity.
    const Eigen::Vector3d pW = yawRotation(s.yaw).transpose() * (k.p_N - s.p_NW);
    yawSpread_ << (pW - yawCentre_).head<2>().norm(), k.v_N.head<2>().norm();
  }
  if (stage_ == GnssFusionStage::kFrameInit) {
    if (!frameUpdate(est, e, k)) return finish();
  } else if (!tightUpdate(est, e, s, k)) {
    return finish();
  }
  if (rep.updated) lastUpdate_ = rover.time;
  if (buildState(est, e.t_ns, s)) {
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
