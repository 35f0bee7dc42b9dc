// Alignment of an estimated trajectory to a reference before computing errors:
//   - Sim(3)/SE(3): least-squares similarity (or rigid, scale fixed to 1) transform of the estimated
//     positions onto the reference positions, closed form of Umeyama (IEEE TPAMI 13(4), 1991,
//     "Least-squares estimation of transformation parameters between two point patterns").
//   - 4-DoF: rotation about the gravity axis (z) and translation only, the directions that VIO
//     cannot observe (Zhang & Scaramuzza, IROS 2018, "A Tutorial on Quantitative Trajectory
//     Evaluation for Visual(-Inertial) Odometry"). Closed form: after removing the centroids the
//     yaw ψ maximising Σ g_i·Rz(ψ) e_i is atan2(Σ (e_x g_y − e_y g_x), Σ (e_x g_x + e_y g_y)).
//   - first pose: the 4-DoF transform (yaw about z and translation) that puts the first estimated
//     pose on the first reference pose: the VIO's own gauge (its first pose is fixed by a tight
//     prior), the alignment under which the estimator's covariances describe its errors (NEES).
//     It needs orientations, so only evaluateTrajectory() (trajectory_metrics.hpp) applies it.
//   - none: identity, for results already in the reference frame (GNSS-fused global solutions).
// Convention: reference ≈ s R estimate + t.
#pragma once

#include <optional>
#include <span>
#include <string>
#include <string_view>

#include <Eigen/Core>

namespace gvins::vio {

enum class AlignmentKind { None, Yaw4Dof, SE3, Sim3, FirstPose4Dof };

/// "none", "4dof" (also "yaw", "posyaw"), "se3", "sim3", "first"; nullopt for anything else.
std::optional<AlignmentKind> parseAlignmentKind(std::string_view name);
std::string toString(AlignmentKind kind);

struct SimilarityTransform {
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
  Eigen::Vector3d t = Eigen::Vector3d::Zero();
  double scale = 1.0;
  Eigen::Vector3d apply(const Eigen::Vector3d& p) const { return scale * (R * p) + t; }
};

/// Best transform with ref_i ≈ s R est_i + t (least squares over all pairs). Needs at least 3
/// non-collinear points for SE3/Sim3 and 2 points distinct in x-y for 4-DoF; with fewer (or
/// degenerate) points the rotation that cannot be determined is left at identity. Throws
/// std::invalid_argument if the spans differ in length or are empty (except for None), and for
/// FirstPose4Dof (positions alone do not give it).
SimilarityTransform alignTrajectory(AlignmentKind kind, std::span<const Eigen::Vector3d> est,
                                    std::span<const Eigen::Vector3d> ref);

}  // namespace gvins::vio
