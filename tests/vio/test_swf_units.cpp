// The units behind SriSwfEstimator on their own (vio/src, private): MsckfUpdater's triangulation
// against simulated points and its rejection of weak geometry, and selectFeatures' choice of
// MSCKF and SLAM features against its specification.
#include <algorithm>
#include <cstdint>
#include <vector>

#include <gtest/gtest.h>

#include "gvins/vio/so3.hpp"
#include "msckf_update.hpp"
#include "swf_state.hpp"

namespace gvins::vio {
namespace {

using detail::SwfState;
using Eigen::Matrix3d;
using Eigen::Vector3d;

SriSwfConfig monoConfig() {
  SriSwfConfig cfg;
  CameraCalibration cam;
  cam.name = "cam0";
  cam.intrinsics.width = 752;
  cam.intrinsics.height = 480;
  cam.intrinsics.fx = cam.intrinsics.fy = 460.0;
  cam.intrinsics.cx = 376.0;
  cam.intrinsics.cy = 240.0;
  // Camera 5 cm beside the IMU, turned a little about its optical axis.
  cam.T_BS.topLeftCorner<3, 3>() = so3::exp(Vector3d(0.0, 0.0, 0.1));
  cam.T_BS.topRightCorner<3, 1>() = Vector3d(0.05, 0.0, 0.0);
  cfg.cameras.push_back(cam);
  return cfg;
}

/// A clone block at pose (R, p) in the state's filter.
sri::BlockId addClone(SwfState<double>& S, const Matrix3d& R, const Vector3d& p) {
  const sri::BlockId id = S.f.addBlock(sri::BlockSpec::pose("clone"), detail::poseEstimate<double>(R, p),
                                       sri::Prior<double>::stdDev(6, 0.1));
  S.clones.push_back({id, 0});
  return id;
}

/// The noise-free observation of world point p_W from the clone (camera 0).
SwfState<double>::Obs observe(SwfState<double>& S, sri::BlockId clone, const Vector3d& p_W) {
  const PoseEstimate& P = S.pose(clone);
  const CameraExtrinsic e = S.ext(0);
  const Vector3d p_C = e.R_IC.transpose() * (P.R_WI.transpose() * (p_W - P.p_WI) - e.p_IC);
  return {clone, 0, p_C.head<2>() / p_C.z()};
}

TEST(SwfUnits, TriangulationRecoversSimulatedPointsAndRejectsWeakGeometry) {
  const SriSwfConfig cfg = monoConfig();
  SwfState<double> S(cfg, 1);
  // Five clones along a 2 m path looking up (+z), with small attitude changes.
  std::vector<sri::BlockId> ids;
  for (int k = 0; k < 5; ++k) {
    ids.push_back(addClone(S, so3::exp(Vector3d(0.02 * k, -0.01 * k, 0.05 * k)), Vector3d(0.5 * k, 0.1 * k, 0.02 * k)));
  }
  detail::MsckfUpdater<double> msckf;
  const std::vector<Vector3d> points{{1.0, 2.0, 10.0}, {-3.0, 0.5, 25.0}, {2.0, -1.0, 4.0}, {0.3, 0.2, 60.0}};
  for (const Vector3d& p_W : points) {
    std::vector<SwfState<double>::Obs> obs;
    for (sri::BlockId id : ids) obs.push_back(observe(S, id, p_W));
    Vector3d p;
    ASSERT_TRUE(msckf.triangulate(S, obs, p)) << p_W.transpose();
    EXPECT_LT((p - p_W).norm(), 1e-9 * p_W.norm()) << p_W.transpose();
  }
  // Too close (0.3 m < min_depth 0.5 m).
  {
    std::vector<SwfState<double>::Obs> obs;
    for (sri::BlockId id : ids) obs.push_back(observe(S, id, Vector3d(0.2, 0.1, 0.3)));
    Vector3d p;
    EXPECT_FALSE(msckf.triangulate(S, obs, p));
  }
  // Baseline 4 mm at 10 m depth: below min_baseline_ratio 0.005 (the same point seen over the
  // 2 m path passes, above); without the ratio the same rays triangulate.
  for (const double ratio : {cfg.min_baseline_ratio, 0.0}) {
    SriSwfConfig c = cfg;
    c.min_baseline_ratio = ratio;
    SwfState<double> T(c, 1);
    std::vector<SwfState<double>::Obs> obs;
    for (int k = 0; k < 5; ++k) {
      const sri::BlockId id = addClone(T, Matrix3d::Identity(), Vector3d(0.001 * k, 0.0, 0.0));
      obs.push_back(observe(T, id, points[0]));
    }
    Vector3d p;
    EXPECT_EQ(msckf.triangulate(T, obs, p), ratio == 0.0) << ratio;
  }
  // One observation only.
  {
    Vector3d p;
    EXPECT_FALSE(msckf.triangulate(S, {observe(S, ids[0], points[0])}, p));
  }
}

TEST(SwfUnits, FeatureSelectionFollowsTrackLengthSlotsAndLimits) {
  SriSwfConfig cfg = monoConfig();
  cfg.min_track_msckf = 3;
  cfg.max_msckf_per_frame = 2;
  cfg.max_slam_features = 3;
  SwfState<double> S(cfg, 1);
  std::vector<sri::BlockId> ids;
  for (int k = 0; k < 4; ++k) ids.push_back(addClone(S, Matrix3d::Identity(), Vector3d(k, 0, 0)));
  // A track observed in the clones [first, 4) (frames = its length).
  auto track = [&](std::uint64_t id, int first) {
    auto& tr = S.tracks[id];
    for (int k = first; k < 4; ++k) tr.obs.push_back({ids[static_cast<std::size_t>(k)], 0, Eigen::Vector2d::Zero()});
    tr.frames = 4 - first;
  };
  track(10, 0);  // alive, from the oldest clone: SLAM when dropping
  track(11, 0);  // alive, from the oldest clone: SLAM when dropping
  track(12, 1);  // alive, not from the oldest: kept
  track(20, 0);  // lost, 4 frames
  track(21, 1);  // lost, 3 frames
  track(22, 1);  // lost, 3 frames (longer id: after 21)
  track(23, 2);  // lost, 2 frames: too short
  S.slam[99] = {};  // one SLAM feature in the state: 2 free slots
  const std::vector<std::uint64_t> observed{10, 11, 12};
  const detail::FeatureSelection sel = detail::selectFeatures(S, observed, true, ids[0]);
  // Candidates longest first, ties by id: 10, 11, 20 (4 frames), 21, 22 (3).
  EXPECT_EQ(sel.used, (std::vector<std::uint64_t>{10, 11, 20, 21, 22}));
  EXPECT_EQ(sel.slam_new, (std::vector<std::uint64_t>{10, 11}));
  EXPECT_EQ(sel.msckf, (std::vector<std::uint64_t>{20, 21}));  // max_msckf_per_frame 2
  // Not dropping: the alive tracks are no candidates.
  const detail::FeatureSelection keep = detail::selectFeatures(S, observed, false, ids[0]);
  EXPECT_TRUE(keep.slam_new.empty());
  EXPECT_EQ(keep.used, (std::vector<std::uint64_t>{20, 21, 22}));
  // After the frame: used and unobserved tracks end, the alive unused one stays.
  detail::retireTracks(S, sel, observed);
  std::vector<std::uint64_t> left;
  for (const auto& [id, tr] : S.tracks) left.push_back(id);
  std::sort(left.begin(), left.end());
  EXPECT_EQ(left, (std::vector<std::uint64_t>{12}));
}

}  // namespace
}  // namespace gvins::vio
