// Accuracy of an estimated trajectory against a reference (ground truth):
//   - time association: every estimated pose is matched to the reference interpolated at its
//     time (linear position/velocity, slerp orientation) when reference samples within
//     `tolerance` lie on both sides, else to the nearest reference sample within `tolerance`,
//     else it is counted as unmatched;
//   - alignment (trajectory_alignment.hpp) of the matched positions;
//   - absolute errors after alignment: position (m), orientation (angle of R_ref^T·R·R_est, deg),
//     velocity (m/s; the estimate's own velocity, rotated and scaled by the alignment, where it
//     has one, else central differences of the aligned positions of neighbouring matched
//     poses; reference velocity from the file or likewise differenced);
//   - body-frame velocity error |R_estᵀ v_est − R_refᵀ v_ref| where both carry velocities
//     (independent of the alignment; the velocity RMSE of the SRI-GVINS paper's tables);
//   - relative errors over travelled distance (KITTI odometry style, Geiger et al., CVPR 2012):
//     for each segment length L and every start pose, the pose at which the reference path has
//     grown by L; translation error |trans(ΔT_ref⁻¹ ΔT_est)| with ΔT = T_i⁻¹ T_j (independent of
//     the alignment except for its scale), reported as drift % of L and rotation deg/m;
//   - NEES with pose covariances (pose_covariance_csv.hpp): position e_pᵀ P_pp⁻¹ e_p with
//     e_p = p_ref − p_aligned and P_pp rotated into the reference frame (R P_pp Rᵀ), orientation
//     δθᵀ P_θθ⁻¹ δθ with R_ref = R_aligned·Exp(δθ). Expected value 3 for a consistent estimator.
#pragma once

#include <cstdint>
#include <iosfwd>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "gvins/vio/euroc_csv.hpp"
#include "gvins/vio/pose_covariance_csv.hpp"
#include "gvins/vio/trajectory_alignment.hpp"
#include "gvins/vio/tum_trajectory.hpp"

namespace gvins::vio {

/// A pose with optional velocity (the reference or the estimate).
struct TrajectorySample {
  std::int64_t t_ns = 0;
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();  ///< body-to-world
  Eigen::Vector3d p = Eigen::Vector3d::Zero();
  std::optional<Eigen::Vector3d> v;
};

std::vector<TrajectorySample> toTrajectorySamples(const std::vector<TumPose>& poses);
std::vector<TrajectorySample> toTrajectorySamples(const std::vector<GroundTruthSample>& gt);

struct EvaluationOptions {
  AlignmentKind alignment = AlignmentKind::SE3;
  std::int64_t tolerance_ns = 20'000'000;
  std::vector<double> segmentLengths = {10.0, 50.0, 100.0};
  /// Only this many first matched poses are used for the alignment (0: all).
  std::size_t alignFirst = 0;
};

struct SegmentError {
  double length = 0.0;   ///< m
  std::size_t count = 0; ///< segments found (0 if the path is shorter)
  double meanTranslation = 0.0, rmseTranslation = 0.0;  ///< m
  double driftPercent = 0.0;       ///< mean translation error / length * 100
  double rotationDegPerM = 0.0;    ///< mean rotation error / length
};

struct ErrorStats {
  std::size_t count = 0;
  double rmse = 0.0, mean = 0.0, median = 0.0, max = 0.0;
};

struct EvaluationResult {
  std::size_t estimatePoses = 0, referencePoses = 0, matched = 0, unmatched = 0;
  AlignmentKind alignmentKind = AlignmentKind::SE3;
  SimilarityTransform alignment;
  double duration = 0.0;      ///< s, first to last matched pose
  double pathLength = 0.0;    ///< m, of the reference over the matched poses
  ErrorStats translation;     ///< m
  ErrorStats rotation;        ///< deg
  ErrorStats velocity;        ///< m/s (count 0 if not computable)
  ErrorStats bodyVelocity;    ///< m/s, |R_estᵀ v_est − R_refᵀ v_ref| where both have a velocity
  std::vector<SegmentError> segments;
  std::size_t neesCount = 0;  ///< matched poses with a covariance
  double positionNees = 0.0, orientationNees = 0.0;  ///< averages (expected 3 each)
  // Per matched pose, for plots.
  std::vector<double> time;  ///< s since the first matched pose
  std::vector<Eigen::Vector3d> estimateAligned, reference;
  std::vector<double> translationError, rotationErrorDeg;
  std::vector<double> positionSigma3;  ///< 3·sqrt(trace P_pp) where a covariance exists, else NaN
};

/// Throws std::invalid_argument when fewer than 2 poses match.
EvaluationResult evaluateTrajectory(const std::vector<TrajectorySample>& estimate,
                                    const std::vector<TrajectorySample>& reference,
                                    const std::vector<PoseCovariance>& covariances,
                                    const EvaluationOptions& options);

/// The accuracy table (plain text).
void printEvaluation(std::ostream& os, const EvaluationResult& r);

/// `<prefix>trajectory_top.svg` (x-y of estimate and reference), `<prefix>position_error.svg`
/// (with the 3σ bound 3·sqrt(trace P_pp) when covariances were given) and
/// `<prefix>rotation_error.svg` over time. Returns the files written; throws std::runtime_error if one cannot be written.
std::vector<std::string> writeEvaluationPlots(const EvaluationResult& r, const std::string& prefix);

}  // namespace gvins::vio
