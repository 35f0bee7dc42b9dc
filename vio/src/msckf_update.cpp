// MSCKF update of the SRI-SWF estimator (msckf_update.hpp).
#include "msckf_update.hpp"

#include <algorithm>
#include <limits>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>

namespace gvins::vio::detail {
namespace {

using sri::BlockId;

bool isObserved(const std::vector<std::uint64_t>& observed, std::uint64_t id) {
  return std::binary_search(observed.begin(), observed.end(), id);
}

/// Stacks whitened measurements without nuisance columns into one (single allocation).
template <typename Scalar>
void stackAll(const std::vector<sri::Measurement<Scalar>>& ms, sri::Measurement<Scalar>& out) {
  int rows = 0;
  std::vector<BlockId> ids;
  std::vector<int> dims;
  for (const auto& m : ms) {
    rows += m.rows();
    for (int i = 0; i < m.numBlocks(); ++i) {
      if (std::find(ids.begin(), ids.end(), m.blockId(i)) != ids.end()) continue;
      ids.push_back(m.blockId(i));
      dims.push_back(m.blockDim(i));
    }
  }
  out.reset(rows);
  out.addBlocks(ids, dims);  // one allocation
  int r0 = 0;
  for (const auto& m : ms) {
    for (int i = 0; i < m.numBlocks(); ++i) {
      out.jacobian(m.blockId(i), m.blockDim(i)).middleRows(r0, m.rows()) = m.jacobianAt(i);
    }
    out.residual().segment(r0, m.rows()) = m.residual();
    r0 += m.rows();
  }
  out.setWhitened();
}

}  // namespace

// ------------------------------------------------------------------ which tracks
template <typename Scalar>
FeatureSelection selectFeatures(const SwfState<Scalar>& S, const std::vector<std::uint64_t>& observed, bool dropping,
                                BlockId oldest) {
  struct Cand {
    std::uint64_t id;
    int frames;
    bool alive;
  };
  std::vector<Cand> cands;
  for (auto& [id, tr] : S.tracks) {
    const bool alive = isObserved(observed, id);
    if (!alive) {
      if (tr.frames >= S.cfg.min_track_msckf) cands.push_back({id, tr.frames, false});
    } else if (dropping && !tr.obs.empty() && tr.obs.front().clone == oldest) {
      cands.push_back({id, tr.frames, true});
    }
  }
  std::sort(cands.begin(), cands.end(), [](const Cand& a, const Cand& b) {
    return a.frames != b.frames ? a.frames > b.frames : a.id < b.id;
  });
  // Window-long tracks become SLAM features while there are free slots; the rest are MSCKF
  // features.
  FeatureSelection sel;
  int slots = S.cfg.max_slam_features - static_cast<int>(S.slam.size());
  for (const Cand& c : cands) {
    sel.used.push_back(c.id);
    if (c.alive && slots > 0) {
      sel.slam_new.push_back(c.id);
      --slots;
    } else if (static_cast<int>(sel.msckf.size()) < S.cfg.max_msckf_per_frame && c.frames >= S.cfg.min_track_msckf) {
      sel.msckf.push_back(c.id);
    }
  }
  return sel;
}

template <typename Scalar>
void retireTracks(SwfState<Scalar>& S, const FeatureSelection& sel, const std::vector<std::uint64_t>& observed) {
  for (std::uint64_t id : sel.used) S.tracks.erase(id);  // used (or unusable): restart alive ones
  for (auto it = S.tracks.begin(); it != S.tracks.end();) {
    it = isObserved(observed, it->first) ? std::next(it) : S.tracks.erase(it);
  }
}

// ------------------------------------------------------------------ triangulation
template <typename Scalar>
bool MsckfUpdater<Scalar>::triangulate(SwfState<Scalar>& S, const std::vector<Obs>& obs, Eigen::Vector3d& p_W) {
  if (obs.size() < 2) return false;
  // 1. The rays once (p_C = R_CW (p_W − c), as cameraPoint's p_C), then a linear initial guess:
  // the point closest to all rays.
  rays_.resize(obs.size());
  Eigen::Matrix3d A = Eigen::Matrix3d::Zero();
  Eigen::Vector3d rhs = Eigen::Vector3d::Zero();
  for (std::size_t k = 0; k < obs.size(); ++k) {
    const PoseEstimate& P = S.obsPose(obs[k].clone);
    const CameraExtrinsic e = S.ext(obs[k].cam);
    Ray& ray = rays_[k];
    ray.R_CW = e.R_IC.transpose() * P.R_WI.transpose();
    ray.c = P.p_WI + P.R_WI * e.p_IC;
    ray.z = obs[k].z;
    const Eigen::Vector3d b = (ray.R_CW.transpose() * Eigen::Vector3d(ray.z.x(), ray.z.y(), 1.0)).normalized();
    const Eigen::Matrix3d M = Eigen::Matrix3d::Identity() - b * b.transpose();
    A += M;
    rhs += M * ray.c;
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(A);
  if (es.eigenvalues()(0) < 1e-9 * es.eigenvalues()(2)) return false;
  p_W = A.ldlt().solve(rhs);
  // 2. Gauss-Newton on the inverse depth in the first observing camera.
  const PoseEstimate& P0 = S.obsPose(obs[0].clone);
  const CameraExtrinsic e0 = S.ext(obs[0].cam);
  const Eigen::Vector3d c0 = rays_[0].R_CW * (p_W - rays_[0].c);
  if (!(c0.z() > S.cfg.min_depth)) return false;
  Eigen::Vector3d fpar(c0.x() / c0.z(), c0.y() / c0.z(), 1.0 / c0.z());
  for (int it = 0; it < 8; ++it) {
    const AnchoredPoint ap = anchoredPoint(fpar, P0, e0);
    Eigen::Matrix3d H = Eigen::Matrix3d::Zero();
    Eigen::Vector3d g = Eigen::Vector3d::Zero();
    for (const Ray& ray : rays_) {
      const Eigen::Vector3d p_C = ray.R_CW * (ap.p_W - ray.c);
      if (!(p_C.z() > 1e-6)) return false;
      const Eigen::Vector2d r = ray.z - p_C.head<2>() / p_C.z();
      const Eigen::Matrix<double, 2, 3> J = projectionJacobian(p_C) * ray.R_CW * ap.J_feature;
      H += J.transpose() * J;
      g += J.transpose() * r;
    }
    const Eigen::Vector3d d = H.ldlt().solve(g);
    if (!d.allFinite()) return false;
    fpar += d;
    if (!(fpar.z() > 0.0)) return false;
    if (d.norm() < 1e-10 * (1.0 + fpar.norm())) break;
  }
  // 3. Depth bounds in every observing camera, baseline against the first depth.
  p_W = anchoredPoint(fpar, P0, e0).p_W;
  double depth0 = 0.0, base = 0.0;
  for (std::size_t k = 0; k < rays_.size(); ++k) {
    const double z = (rays_[k].R_CW * (p_W - rays_[k].c)).z();
    if (!(z >= S.cfg.min_depth && z <= S.cfg.max_depth)) return false;
    if (k == 0) depth0 = z;
    base = std::max(base, (rays_[k].c - rays_[0].c).norm());
  }
  return base >= S.cfg.min_baseline_ratio * depth0;
}

// ------------------------------------------------------------------ rows
template <typename Scalar>
void MsckfUpdater<Scalar>::featureRows(SwfState<Scalar>& S, const std::vector<Obs>& obs, const Eigen::Vector3d& p_W,
                                       Meas& m, const Eigen::Vector3d* p_J) {
  m.reset(2 * static_cast<int>(obs.size()));
  S.declareBlocks(m, BlockId{}, BlockId{}, obs);
  auto N = m.nuisance(3);
  for (std::size_t k = 0; k < obs.size(); ++k) {
    const Obs& o = obs[k];
    const int r = 2 * static_cast<int>(k);
    // Jacobians at the first estimates, the residual at the current poses (p_C only).
    const bool fej = S.cfg.first_estimate_jacobians;
    const CameraPoint cj = cameraPoint(fej ? S.poseJ(o.clone) : S.obsPose(o.clone), S.ext(o.cam), p_J ? *p_J : p_W);
    const Eigen::Vector3d p_C = fej || p_J ? pointInCamera(S.obsPose(o.clone), S.ext(o.cam), p_W) : cj.p_C;
    const double is = S.inverseSigma(o.cam, p_C.z());
    const Eigen::Matrix<double, 2, 3> Jp = is * projectionJacobian(cj.p_C);
    m.jacobian(o.clone, 6).middleRows(r, 2) += (Jp * cj.J_pose).template cast<Scalar>();
    if (!S.ext_ids.empty()) {
      m.jacobian(S.ext_ids[static_cast<std::size_t>(o.cam)], 6).middleRows(r, 2) +=
          (Jp * cj.J_ext).template cast<Scalar>();
    }
    if (S.td_id.valid()) {
      m.jacobian(S.td_id, 1).middleRows(r, 2) += (Jp * S.timeOffsetColumn(o.clone, cj)).template cast<Scalar>();
    }
    N.middleRows(r, 2) = (Jp * cj.J_point).template cast<Scalar>();
    m.residual().segment(r, 2) = (is * (o.z - p_C.head<2>() / p_C.z())).template cast<Scalar>();
  }
  m.setWhitened();
}

// ------------------------------------------------------------------ window gate
// Window covariance for gating MSCKF-type rows (clones, extrinsics, time offset): once per
// frame a factor Pw = F Fᵀ (SriFilter::covarianceFactor: the window's rows of the inverse of
// the trailing block of R, which starts at the oldest clone; no covariance is formed), then
// χ² = zᵀ(I + G Gᵀ)⁻¹z with G = H F per feature. H is zero before the first block it touches
// (s), and the window blocks lead the trailing block in this order, so F[s:, :s] = 0 and
// G = H[:, s:] F[s:, s:] (fewer flops for short tracks on the newest clones); I + G Gᵀ is a
// rank update. Cheaper than SriFilter::chiSquare's per-feature triangular solve and QR. Valid
// when r = 0 (right after correct()). Two exact bounds decide most features without G:
// I ≤ I + G Gᵀ ≤ (1 + ‖H‖²_F tr(Pw)) I, so χ² ≤ ‖z‖² (accept when ‖z‖² is below the
// threshold) and χ² ≥ ‖z‖² / (1 + ‖H‖²_F tr(Pw)) (reject when that is above it).
template <typename Scalar>
void MsckfUpdater<Scalar>::windowCovariance(const SwfState<Scalar>& S) {
  std::vector<BlockId> ids;
  pw_off_.clear();
  int off = 0;
  for (const auto& c : S.clones) {
    ids.push_back(c.id);
    pw_off_[c.id.value] = off;
    off += 6;
  }
  for (BlockId e : S.ext_ids) {
    ids.push_back(e);
    pw_off_[e.value] = off;
    off += 6;
  }
  if (S.td_id.valid()) {
    ids.push_back(S.td_id);
    pw_off_[S.td_id.value] = off;
    off += 1;
  }
  Fw_ = S.f.covarianceFactor(ids).template cast<double>();
  pw_trace_ = Fw_.squaredNorm();
  // The structure the gate uses (checked, not assumed: client blocks could sit in between).
  const int d = static_cast<int>(Fw_.rows());
  fw_leading_triangular_ = Fw_.cols() >= d;
  for (int j = 0; j < d && fw_leading_triangular_; ++j) {
    fw_leading_triangular_ = Fw_.col(j).tail(d - j - 1).isZero(0.0);
  }
}

template <typename Scalar>
bool MsckfUpdater<Scalar>::gateWindow(const SwfState<Scalar>& S, const Meas& m) {
  if (S.cfg.chi2_probability >= 1.0) return true;
  const int rows = m.rows();
  const double thr = S.chi2Threshold(rows);
  const double zz = static_cast<double>(m.residual().squaredNorm());
  if (zz <= thr) return true;
  double hh = 0.0;
  for (int i = 0; i < m.numBlocks(); ++i) hh += static_cast<double>(m.jacobianAt(i).squaredNorm());
  if (zz > thr * (1.0 + hh * pw_trace_)) return false;
  const int d = static_cast<int>(Fw_.rows());
  int s0 = d;
  for (int i = 0; i < m.numBlocks(); ++i) s0 = std::min(s0, pw_off_.at(m.blockId(i).value));
  const int k = d - s0;
  gate_H_.setZero(rows, k);
  for (int i = 0; i < m.numBlocks(); ++i) {
    gate_H_.middleCols(pw_off_.at(m.blockId(i).value) - s0, m.blockDim(i)) = m.jacobianAt(i).template cast<double>();
  }
  const int cols = static_cast<int>(Fw_.cols());
  if (fw_leading_triangular_) {
    gate_G_.noalias() = gate_H_ * Fw_.bottomRightCorner(k, cols - s0);
  } else {
    gate_G_.noalias() = gate_H_ * Fw_.bottomRows(k);
  }
  gate_S_.setIdentity(rows, rows);
  gate_S_.template selfadjointView<Eigen::Lower>().rankUpdate(gate_G_);
  const Eigen::LLT<Eigen::MatrixXd> llt(gate_S_);
  if (llt.info() != Eigen::Success) return false;
  gate_z_ = m.residual().template cast<double>();
  llt.matrixL().solveInPlace(gate_z_);
  return gate_z_.squaredNorm() <= thr;
}

// ------------------------------------------------------------------ update
// A new SLAM feature's projected rows are exactly those of its full rows [H_f H_x] after they
// have been triangularized in the feature columns (all Jacobians with respect to the point, its
// inverse depth and its anchor pose lie in the span of H_f), so they join the stack; its state
// block is then initialised by the three rows Q₁ᵀ[H_f H_x r] alone (SlamUpdater::initialize).
template <typename Scalar>
std::vector<NewSlamFeature<Scalar>> MsckfUpdater<Scalar>::update(SwfState<Scalar>& S, const FeatureSelection& sel,
                                                                FrameResult& res) {
  windowCovariance(S);
  // 1. MSCKF features: triangulate, rows, null-space projection, gate.
  std::vector<Meas> parts;
  Meas m;
  for (std::uint64_t id : sel.msckf) {
    const auto& tr = S.tracks[id];
    Eigen::Vector3d p;
    if (!triangulate(S, tr.obs, p)) continue;
    featureRows(S, tr.obs, p, m);
    m.projectNuisance();
    ++res.gated_features;
    if (!gateWindow(S, m)) {
      ++res.rejected_features;
      continue;
    }
    parts.push_back(std::move(m));
    ++res.msckf_features;
  }
  // 2. New SLAM features: the same, keeping the three point rows. Linearised where the SLAM rows
  // of the feature will be (SlamUpdater::rows): at the point that the inverse depth gives with
  // the anchor's first estimate, so that the rows keep the unobservable directions of the
  // first-estimate Jacobians.
  std::vector<NewSlamFeature<Scalar>> fresh;
  for (std::uint64_t id : sel.slam_new) {
    const auto& tr = S.tracks[id];
    Eigen::Vector3d p;
    if (!triangulate(S, tr.obs, p)) continue;
    NewSlamFeature<Scalar> ns{id, inverseDepthOf(p, S.pose(S.newest.pose), S.ext(0)), AnchoredPoint{}, Meas{}};
    ns.apj = anchoredPoint(ns.f0, S.cfg.first_estimate_jacobians ? S.poseJ(S.newest.pose) : S.pose(S.newest.pose),
                           S.ext(0));
    featureRows(S, tr.obs, p, m, &ns.apj.p_W);
    m.projectNuisance(&ns.top);
    ++res.gated_features;
    if (!gateWindow(S, m)) {
      ++res.rejected_features;
      continue;
    }
    if (ns.top.rows() != 3) continue;  // too few observations to fix the point
    if (m.rows() > 0) parts.push_back(std::move(m));
    fresh.push_back(std::move(ns));
  }
  // 3. One stacked, compressed update.
  if (!parts.empty()) {
    Meas total;
    stackAll(parts, total);
    total.compress();
    S.f.update(total);
    res.updated = true;
    S.notify("msckf_update");
  }
  return fresh;
}

template FeatureSelection selectFeatures(const SwfState<float>&, const std::vector<std::uint64_t>&, bool, BlockId);
template FeatureSelection selectFeatures(const SwfState<double>&, const std::vector<std::uint64_t>&, bool, BlockId);
template void retireTracks(SwfState<float>&, const FeatureSelection&, const std::vector<std::uint64_t>&);
template void retireTracks(SwfState<double>&, const FeatureSelection&, const std::vector<std::uint64_t>&);
template class MsckfUpdater<float>;
template class MsckfUpdater<double>;

}  // namespace gvins::vio::detail
