// SLAM features of the SRI-SWF estimator (slam_update.hpp).
#include "slam_update.hpp"

#include <algorithm>
#include <span>

#include "gvins/sri/qr_update.hpp"

namespace gvins::vio::detail {
namespace {

using sri::BlockEstimate;
using sri::BlockId;
using sri::BlockSpec;
using sri::Placement;

/// Rotates the rows of m (Givens, orthogonal: same information and χ²) so that its columns of
/// block `id` are upper triangular: rows ≥ d then have exact zeros there and start at a later
/// column of R. For a stereo SLAM re-observation (4 rows, 3 feature columns) one of the four
/// rows no longer starts at the feature, i.e. it skips the columns of all SLAM features in
/// the update (docs/vio_estimator.md, speed).
template <typename Scalar>
void triangularizeBlock(sri::Measurement<Scalar>& m, BlockId id, int d) {
  const int rows = m.rows();
  if (rows <= d) return;
  int b = -1;
  for (int i = 0; i < m.numBlocks(); ++i) {
    if (m.blockId(i) == id) b = i;
  }
  if (b < 0) return;
  for (int j = 0; j < d; ++j) {
    for (int i = rows - 1; i > j; --i) {
      auto F = m.jacobianAt(b);
      const Scalar y = F(i, j);
      if (y == Scalar(0)) continue;
      Scalar c, sn;
      sri::makeGivens(F(i - 1, j), y, c, sn);
      m.rotateRows(i - 1, i, c, sn);
      F(i, j) = Scalar(0);
    }
  }
}

}  // namespace

template <typename Scalar>
bool SlamUpdater<Scalar>::rows(SwfState<Scalar>& S, const typename SwfState<Scalar>::Slam& s,
                               const std::vector<typename SwfState<Scalar>::Obs>& obs, Meas& m) {
  m.reset(2 * static_cast<int>(obs.size()));
  S.declareBlocks(m, s.block, s.anchor, obs);
  const Eigen::Vector3d fx = S.f.nominal(s.block).vector.template cast<double>();
  const AnchoredPoint ap = anchoredPoint(fx, S.pose(s.anchor), S.ext(0));
  // Jacobians at the first estimates of anchor and clone (the residual at the current ones).
  const bool fej = S.cfg.first_estimate_jacobians;
  const AnchoredPoint apj = fej ? anchoredPoint(fx, S.poseJ(s.anchor), S.ext(0)) : ap;
  for (std::size_t k = 0; k < obs.size(); ++k) {
    const auto& o = obs[k];
    const int r = 2 * static_cast<int>(k);
    const Eigen::Vector3d p_C = pointInCamera(S.obsPose(o.clone), S.ext(o.cam), ap.p_W);
    if (!(p_C.z() > S.cfg.min_depth)) return false;
    const CameraPoint cj = cameraPoint(fej ? S.poseJ(o.clone) : S.obsPose(o.clone), S.ext(o.cam), apj.p_W);
    const double is = S.inverseSigma(o.cam, p_C.z());
    const Eigen::Matrix<double, 2, 3> Jp = is * projectionJacobian(cj.p_C);
    const Eigen::Matrix<double, 2, 3> A = Jp * cj.J_point;
    m.jacobian(s.block, 3).middleRows(r, 2) += (A * apj.J_feature).template cast<Scalar>();
    m.jacobian(s.anchor, 6).middleRows(r, 2) += (A * apj.J_anchor).template cast<Scalar>();
    m.jacobian(o.clone, 6).middleRows(r, 2) += (Jp * cj.J_pose).template cast<Scalar>();
    if (!S.ext_ids.empty()) {
      m.jacobian(S.ext_ids[0], 6).middleRows(r, 2) += (A * apj.J_ext).template cast<Scalar>();
      m.jacobian(S.ext_ids[static_cast<std::size_t>(o.cam)], 6).middleRows(r, 2) +=
          (Jp * cj.J_ext).template cast<Scalar>();
    }
    if (S.td_id.valid()) {
      m.jacobian(S.td_id, 1).middleRows(r, 2) += (Jp * S.timeOffsetColumn(o.clone, cj)).template cast<Scalar>();
    }
    m.residual().segment(r, 2) = (is * (o.z - p_C.head<2>() / p_C.z())).template cast<Scalar>();
  }
  m.setWhitened();
  triangularizeBlock(m, s.block, 3);
  return true;
}

// The update's post-fit residual ‖e‖² equals the innovation χ² (docs/sri_core.md §5), so all
// rows are applied at once (R and r saved before) and kept if the joint χ² passes; only
// otherwise is every feature tested on its own (SriFilter::chiSquare, a triangular solve from
// the feature's column each).
template <typename Scalar>
std::vector<BlockId> SlamUpdater<Scalar>::updateReobserved(SwfState<Scalar>& S, const FeatureFrame& frame,
                                                           FrameResult& res) {
  using Obs = typename SwfState<Scalar>::Obs;
  // 1. Rows of every re-observed SLAM feature (behind the camera: treated as lost).
  std::vector<Meas> parts;
  std::vector<std::uint64_t> part_ids;
  for (const FeatureObservation& o : frame.features) {
    auto it = S.slam.find(o.id);
    if (it == S.slam.end()) continue;
    std::vector<Obs> obs{{S.newest.pose, 0, o.normalized0}};
    if (S.stereo() && o.stereo) obs.push_back({S.newest.pose, 1, o.normalized1});
    parts.emplace_back();
    if (rows(S, it->second, obs, parts.back())) {
      part_ids.push_back(o.id);
    } else {
      parts.pop_back();
      it->second.seen = false;
    }
  }
  // 2. Joint update, undone when its χ² fails; then feature by feature.
  if (!parts.empty()) {
    backup_R_ = S.f.rawR();
    backup_r_ = S.f.rawResidual();
    const sri::UpdateResult<Scalar> u = S.f.update(std::span<const Meas>(parts));
    res.gated_features += static_cast<int>(parts.size());
    if (static_cast<double>(u.chi2) <= S.chi2Threshold(u.dof)) {
      res.updated = true;
    } else {
      S.f.rawR() = backup_R_;
      S.f.rawResidual() = backup_r_;
      std::vector<Meas> kept;
      for (std::size_t k = 0; k < parts.size(); ++k) {
        if (S.gate(parts[k])) {
          kept.push_back(std::move(parts[k]));
        } else {
          S.slam[part_ids[k]].seen = false;
          ++res.rejected_features;
        }
      }
      if (!kept.empty()) {
        S.f.update(std::span<const Meas>(kept));
        res.updated = true;
      }
    }
    S.notify("slam_update");
  }
  // 3. Features not seen leave the SLAM set (in id order).
  std::vector<BlockId> lost;
  std::vector<std::uint64_t> sids;
  for (auto& [id, s] : S.slam) sids.push_back(id);
  std::sort(sids.begin(), sids.end());
  for (std::uint64_t id : sids) {
    if (!S.slam[id].seen) {
      lost.push_back(S.slam[id].block);
      S.slam.erase(id);
    }
  }
  return lost;
}

template <typename Scalar>
void SlamUpdater<Scalar>::initialize(SwfState<Scalar>& S, const std::vector<NewSlamFeature<Scalar>>& fresh,
                                     FrameResult& res) {
  Meas m;
  for (const NewSlamFeature<Scalar>& ns : fresh) {
    const Eigen::Vector3d& f0 = ns.f0;
    const AnchoredPoint& apj = ns.apj;
    typename SwfState<Scalar>::Slam s;
    s.block = S.f.addBlock(BlockSpec::vector("slam", 3), BlockEstimate<Scalar>::fromVector(f0.cast<Scalar>()),
                           sri::Prior<Scalar>::uninformative(), Placement::before(S.clones.front().id));
    S.setExact(s.block, BlockEstimate<double>::fromVector(f0));
    s.anchor = S.newest.pose;
    s.seen = true;
    const Meas& top = ns.top;
    const Eigen::Matrix3d Rf = top.nuisanceJacobian().template cast<double>();
    m.reset(3);
    S.declareBlocks(m, s.block, s.anchor, S.tracks[ns.id].obs);  // top's blocks and the feature
    for (int b = 0; b < top.numBlocks(); ++b) m.jacobian(top.blockId(b), top.blockDim(b)) = top.jacobianAt(b);
    m.jacobian(s.block, 3) = (Rf * apj.J_feature).template cast<Scalar>();
    m.jacobian(s.anchor, 6) += (Rf * apj.J_anchor).template cast<Scalar>();
    if (!S.ext_ids.empty()) m.jacobian(S.ext_ids[0], 6) += (Rf * apj.J_ext).template cast<Scalar>();
    m.residual() = top.residual();
    m.setWhitened();
    S.f.update(m);
    S.slam.emplace(ns.id, s);
    res.updated = true;
  }
}

template class SlamUpdater<float>;
template class SlamUpdater<double>;

}  // namespace gvins::vio::detail
