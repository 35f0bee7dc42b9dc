// Window management of the SRI-SWF estimator: SLAM re-anchoring and marginalization
// (window_marginalization.hpp).
#include "window_marginalization.hpp"

#include <algorithm>
#include <utility>

namespace gvins::vio::detail {
namespace {

using sri::BlockEstimate;
using sri::BlockId;
using sri::BlockSpec;
using sri::Placement;

/// A re-anchored feature: its new inverse depth and the Jacobians of the change of variables
/// with respect to the old feature block, the old anchor, the new anchor and extrinsic 0.
struct Reanchored {
  std::uint64_t id;
  Eigen::Vector3d fnew;
  Eigen::Matrix3d Jf;
  Eigen::Matrix<double, 3, 6> Ja, Jb, Je;
};

/// The re-anchoring with reanchor_sigma > 0: one Propagation of all features into new blocks
/// (after the old ones, which are marginalized) with that noise.
template <typename Scalar>
void reanchorWithNoise(SwfState<Scalar>& S, BlockId old_anchor, const std::vector<Reanchored>& items) {
  using MatrixS = typename SwfState<Scalar>::MatrixS;
  using VectorS = typename SwfState<Scalar>::VectorS;
  const int K = static_cast<int>(items.size());
  sri::Propagation<Scalar> step;
  MatrixS Pa_phi = MatrixS::Zero(3 * K, 6), Pb_phi = MatrixS::Zero(3 * K, 6), Pe_phi = MatrixS::Zero(3 * K, 6);
  VectorS q(3 * K);
  for (int k = 0; k < K; ++k) {
    const Reanchored& it = items[static_cast<std::size_t>(k)];
    const auto& s = S.slam[it.id];
    step.addNewBlock(BlockSpec::vector("slam", 3), BlockEstimate<Scalar>::fromVector(it.fnew.template cast<Scalar>()),
                     Placement::after(s.block));
    MatrixS Pf = MatrixS::Zero(3 * K, 3);
    Pf.middleRows(3 * k, 3) = it.Jf.template cast<Scalar>();
    step.setTransition(s.block, Pf);
    Pa_phi.middleRows(3 * k, 3) = it.Ja.template cast<Scalar>();
    Pb_phi.middleRows(3 * k, 3) = it.Jb.template cast<Scalar>();
    Pe_phi.middleRows(3 * k, 3) = it.Je.template cast<Scalar>();
    const double sg = S.cfg.reanchor_sigma;
    q.segment(3 * k, 3) << Scalar(sg * sg), Scalar(sg * sg), Scalar(sg * sg * it.fnew.z() * it.fnew.z());
    step.marginalizeAfter(s.block);
  }
  step.setTransition(old_anchor, Pa_phi);
  step.setTransition(S.newest.pose, Pb_phi);
  if (!S.ext_ids.empty()) step.setTransition(S.ext_ids[0], Pe_phi);
  step.setNoiseCovariance(MatrixS(q.asDiagonal()));
  const std::vector<BlockId> nids = S.f.propagate(step);
  for (int k = 0; k < K; ++k) {
    auto& s = S.slam[items[static_cast<std::size_t>(k)].id];
    s.block = nids[static_cast<std::size_t>(k)];
    s.anchor = S.newest.pose;
    S.setExact(s.block, BlockEstimate<double>::fromVector(items[static_cast<std::size_t>(k)].fnew));
  }
}

}  // namespace

template <typename Scalar>
std::vector<BlockId> reanchorSlamFeatures(SwfState<Scalar>& S, BlockId old_anchor) {
  using MatrixS = typename SwfState<Scalar>::MatrixS;
  // 1. The features anchored there, in id order.
  std::vector<std::uint64_t> ids;
  std::vector<BlockId> drop;
  for (auto& [id, s] : S.slam) {
    if (s.anchor == old_anchor) ids.push_back(id);
  }
  if (ids.empty()) return drop;
  std::sort(ids.begin(), ids.end());
  // 2. New inverse depths at the current estimates, Jacobians at the first estimates of both
  // anchors (first_estimate_jacobians).
  const PoseEstimate& Pa = S.pose(old_anchor);
  const PoseEstimate& Pb = S.pose(S.newest.pose);
  const PoseEstimate& PaJ = S.poseJ(old_anchor);
  const PoseEstimate& PbJ = S.poseJ(S.newest.pose);
  const CameraExtrinsic e0 = S.ext(0);
  std::vector<Reanchored> items;
  for (std::uint64_t id : ids) {
    auto& s = S.slam[id];
    const Eigen::Vector3d fx = S.f.nominal(s.block).vector.template cast<double>();
    const AnchoredPoint ap0 = anchoredPoint(fx, Pa, e0);
    CameraPoint cp0;
    const Eigen::Vector3d fn = inverseDepthOf(ap0.p_W, Pb, e0, nullptr, &cp0);
    if (!(cp0.p_C.z() > S.cfg.min_depth)) {
      drop.push_back(s.block);
      S.slam.erase(id);
      continue;
    }
    const AnchoredPoint ap = anchoredPoint(fx, PaJ, e0);
    Eigen::Matrix3d D;
    CameraPoint cp;
    inverseDepthOf(ap.p_W, PbJ, e0, &D, &cp);
    Reanchored it;
    it.id = id;
    it.fnew = fn;
    it.Jf = D * cp.J_point * ap.J_feature;
    it.Ja = D * cp.J_point * ap.J_anchor;
    it.Jb = D * cp.J_pose;
    it.Je = D * (cp.J_point * ap.J_ext + cp.J_ext);
    items.push_back(it);
  }
  if (items.empty()) return drop;
  if (S.cfg.reanchor_sigma > 0.0) {
    reanchorWithNoise(S, old_anchor, items);
    return drop;
  }
  // 3. Without noise the re-anchoring is an exact change of variables of each feature block in
  // place (SriFilter::substitute: its columns and own rows only, no new block, no sweep).
  for (const Reanchored& it : items) {
    auto& s = S.slam[it.id];
    std::vector<std::pair<BlockId, MatrixS>> B;
    B.emplace_back(old_anchor, it.Ja.template cast<Scalar>());
    B.emplace_back(S.newest.pose, it.Jb.template cast<Scalar>());
    if (!S.ext_ids.empty()) B.emplace_back(S.ext_ids[0], it.Je.template cast<Scalar>());
    S.f.substitute(s.block, MatrixS(it.Jf.template cast<Scalar>()), B, BlockEstimate<double>::fromVector(it.fnew));
    s.anchor = S.newest.pose;
  }
  return drop;
}

template <typename Scalar>
void marginalizeWindow(SwfState<Scalar>& S, std::vector<BlockId> lost_slam, bool dropping) {
  std::vector<BlockId> marg = std::move(lost_slam);
  if (dropping) {
    const BlockId oldest = S.clones.front().id;
    const std::vector<BlockId> d = reanchorSlamFeatures(S, oldest);
    S.notify("reanchor");
    marg.insert(marg.end(), d.begin(), d.end());
    marg.push_back(oldest);
    S.clones.pop_front();
    S.fe_pose.erase(oldest.value);
    S.clone_motion.erase(oldest.value);
    for (auto& [id, tr] : S.tracks) {
      auto& o = tr.obs;
      const auto n0 = o.size();
      o.erase(std::remove_if(o.begin(), o.end(), [&](const auto& x) { return x.clone == oldest; }), o.end());
      if (o.size() != n0) --tr.frames;
    }
  }
  if (!marg.empty()) {
    S.f.marginalize(marg);
    S.notify("marginalize");
  }
}

template std::vector<BlockId> reanchorSlamFeatures(SwfState<float>&, BlockId);
template std::vector<BlockId> reanchorSlamFeatures(SwfState<double>&, BlockId);
template void marginalizeWindow(SwfState<float>&, std::vector<BlockId>, bool);
template void marginalizeWindow(SwfState<double>&, std::vector<BlockId>, bool);

}  // namespace gvins::vio::detail
