// The evaluations at the end of the replay (replay_stages.hpp): the local trajectory against the
// dataset's ground truth, the GNSS antenna solutions against the true antenna track.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <stdexcept>

#include "gvins/base/geodetic.hpp"
#include "gvins/base/local_frame.hpp"
#include "replay_stages.hpp"

namespace gvins::fusion::detail {

namespace fs = std::filesystem;

namespace {

/// Horizontal and vertical RMS of the aligned estimate against the reference (z is up).
Eigen::Vector2d horizontalVerticalRmse(const vio::EvaluationResult& r) {
  double h = 0.0, v = 0.0;
  for (std::size_t i = 0; i < r.reference.size(); ++i) {
    const Eigen::Vector3d e = r.estimateAligned[i] - r.reference[i];
    h += e.head<2>().squaredNorm();
    v += e.z() * e.z();
  }
  const double m = static_cast<double>(std::max<std::size_t>(r.reference.size(), 1));
  return {std::sqrt(h / m), std::sqrt(v / m)};
}

}  // namespace

ReplaySummary::Accuracy accuracyOf(const vio::EvaluationResult& r) {
  ReplaySummary::Accuracy a;
  a.poses = r.matched;
  a.positionRmse = r.translation.rmse;
  a.rotationRmseDeg = r.rotation.rmse;
  if (r.velocity.count > 0) a.velocityRmse = r.velocity.rmse;
  if (r.bodyVelocity.count > 0) a.bodyVelocityRmse = r.bodyVelocity.rmse;
  a.pathLength = r.pathLength;
  for (const auto& seg : r.segments)
    if (seg.count > 0) a.driftPercent = seg.driftPercent;
  if (r.neesCount > 0) {
    a.positionNees = r.positionNees;
    a.orientationNees = r.orientationNees;
  }
  const Eigen::Vector2d hv = horizontalVerticalRmse(r);
  a.horizontalRmse = hv[0];
  a.verticalRmse = hv[1];
  return a;
}

void evaluateLocal(const vio::EurocDataset& ds, const std::vector<vio::TrajectorySample>& localTrack,
                   const std::vector<vio::PoseCovariance>& covs, const fs::path& out, ReplaySummary& sum) {
  vio::EvaluationOptions eo2;
  eo2.alignment = vio::AlignmentKind::Yaw4Dof;
  try {
    const auto r = vio::evaluateTrajectory(localTrack, vio::toTrajectorySamples(ds.groundTruth()), covs, eo2);
    std::ostringstream os;
    if (sum.estimatorResets > 0) {
      os << "(the VIO state after the last of " << sum.estimatorResets
         << " resets only: the poses before it are in other VIO frames)\n";
    }
    vio::printEvaluation(os, r);
    sum.evaluationTable = os.str();
    sum.local = accuracyOf(r);
    // Aligned on the poses of the first 10 % of the horizontal path (estimated): the yaw of a
    // 4-DoF alignment is undetermined on a vertical segment, e.g. a take-off climb, which
    // made the first 10 % of the 3-D path of the 60m-400m-8 flight (52 m, nearly all climb)
    // give 134 m.
    vio::EvaluationOptions eo4 = eo2;
    auto horizontal = [&](std::size_t i) { return (localTrack[i].p - localTrack[i - 1].p).head<2>().norm(); };
    double path = 0.0;
    for (std::size_t i = 1; i < localTrack.size(); ++i) path += horizontal(i);
    double walked = 0.0;
    eo4.alignFirst = localTrack.size();
    for (std::size_t i = 1; i < localTrack.size(); ++i) {
      walked += horizontal(i);
      if (walked >= 0.1 * path) {
        eo4.alignFirst = std::max<std::size_t>(i + 1, 2);
        break;
      }
    }
    sum.local.startAlignedPositionRmse =
        vio::evaluateTrajectory(localTrack, vio::toTrajectorySamples(ds.groundTruth()), covs, eo4).translation.rmse;
    vio::EvaluationOptions eo5 = eo2;
    eo5.alignment = vio::AlignmentKind::FirstPose4Dof;
    const auto rf = vio::evaluateTrajectory(localTrack, vio::toTrajectorySamples(ds.groundTruth()), covs, eo5);
    if (rf.neesCount > 0) {
      sum.local.positionNeesFirstPose = rf.positionNees;
      sum.local.orientationNeesFirstPose = rf.orientationNees;
      char b[160];
      std::snprintf(b, sizeof b, "NEES with the first-pose alignment (the estimator's gauge): position %.3f, orientation %.3f\n",
                    rf.positionNees, rf.orientationNees);
      sum.evaluationTable += b;
    }
    for (const auto& f : vio::writeEvaluationPlots(r, (out / "eval_").string())) sum.files.push_back(f);
  } catch (const std::invalid_argument& e) {
    sum.evaluationTable = std::string("not evaluated: ") + e.what() + "\n";
  }
}

void evaluateGlobal(const std::string& dataset, const ReplayOptions& opt, const std::vector<EcefTruthSample>& evalTrack,
                    bool fromTight, const fs::path& out, ReplaySummary& sum) {
  const fs::path ecefTruth = fs::path(dataset) / "truth" / "groundtruth_ecef.csv";
  if (evalTrack.size() < 2 || (opt.truthPos.empty() && !fs::exists(ecefTruth))) return;
  const auto truth = opt.truthPos.empty()
                         ? readEcefTruthCsv(ecefTruth.string())
                         : ecefTruthFromPos(readPosFile(opt.truthPos), opt.truthPosMaxQuality, opt.sensorToGpst_ns);
  if (truth.empty()) return;
  const Eigen::Vector3d origin = truth.front().antenna;
  const Geodetic og = ecefToGeodetic(origin);
  const Eigen::Matrix3d R_NE = ecefToEnuRotation(og.lat, og.lon);
  auto enu = [&](const EcefTruthSample& x) {
    std::optional<Eigen::Vector3d> v;
    if (x.antennaVelocity) v = R_NE * *x.antennaVelocity;
    return vio::TrajectorySample{x.t_ns, Eigen::Matrix3d::Identity(), ecefToEnu(x.antenna, origin), v};
  };
  std::vector<vio::TrajectorySample> ref, track;
  for (const auto& x : truth) ref.push_back(enu(x));
  for (const auto& x : evalTrack) track.push_back(enu(x));
  vio::EvaluationOptions eo3;
  eo3.alignment = vio::AlignmentKind::None;
  try {
    const auto r = vio::evaluateTrajectory(track, ref, {}, eo3);
    std::ostringstream os;
    vio::printEvaluation(os, r);
    const Eigen::Vector2d hv = horizontalVerticalRmse(r);
    char b[200];
    std::snprintf(b, sizeof b, "horizontal RMS %.4f m, vertical RMS %.4f m over %zu epochs%s\n", hv[0], hv[1],
                  r.reference.size(), fromTight ? " (from the first tightly coupled update)" : "");
    sum.globalEvaluationTable = os.str() + b;
    sum.global = accuracyOf(r);  // its horizontal/vertical RMS are those printed above
    for (const auto& f : vio::writeEvaluationPlots(r, (out / "eval_global_").string())) sum.files.push_back(f);
  } catch (const std::invalid_argument& e) {
    sum.globalEvaluationTable = std::string("not evaluated: ") + e.what() + "\n";
  }
}

}  // namespace gvins::fusion::detail
