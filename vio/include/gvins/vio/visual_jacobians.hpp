// Visual measurement model of the SRI-SWF and its Jacobians (public for the finite-difference
// tests).
//
// A camera C is mounted on the IMU with the extrinsic pose T_IC (R_IC, p_IC: camera in the IMU
// frame). A world point p_W seen from the IMU pose (R_WI, p_WI) is at
//   p_I = R_WIᵀ (p_W − p_WI),   p_C = R_ICᵀ (p_I − p_IC),
// and measured as undistorted normalised coordinates z = (x/z, y/z) of p_C.
// Error states (block.hpp, kRight): R_WI = R̂_WI Exp(δθ), p_WI = p̂_WI + δp for the IMU pose,
// R_IC = R̂_IC Exp(δφ), p_IC = p̂_IC + δt for the extrinsic. Hence
//   ∂p_C/∂δθ = R_ICᵀ [p_I]×,  ∂p_C/∂δp = −R_ICᵀ R_WIᵀ,  ∂p_C/∂δφ = [p_C]×,  ∂p_C/∂δt = −R_ICᵀ,
//   ∂p_C/∂p_W = R_ICᵀ R_WIᵀ.
// SLAM features use the anchored inverse depth of Civera et al. (2008): f = (α, β, ρ) with the
// point p_Ca = (α, β, 1)/ρ in camera 0 of an anchor IMU pose a:
//   p_W = R_WIa (R_IC0 p_Ca + p_IC0) + p_WIa.
#pragma once

#include <Eigen/Core>

namespace gvins::vio {

/// Camera pose in the IMU frame.
struct CameraExtrinsic {
  Eigen::Matrix3d R_IC = Eigen::Matrix3d::Identity();
  Eigen::Vector3d p_IC = Eigen::Vector3d::Zero();
};

/// An IMU pose (clone).
struct PoseEstimate {
  Eigen::Matrix3d R_WI = Eigen::Matrix3d::Identity();
  Eigen::Vector3d p_WI = Eigen::Vector3d::Zero();
};

/// p_C of a world point with its Jacobians.
struct CameraPoint {
  Eigen::Vector3d p_C = Eigen::Vector3d::Zero();
  Eigen::Matrix<double, 3, 6> J_pose;  ///< ∂p_C/∂[δθ; δp] of the IMU pose
  Eigen::Matrix<double, 3, 6> J_ext;   ///< ∂p_C/∂[δφ; δt] of the extrinsic
  Eigen::Matrix3d J_point;             ///< ∂p_C/∂p_W
};

CameraPoint cameraPoint(const PoseEstimate& pose, const CameraExtrinsic& ext, const Eigen::Vector3d& p_W);
/// cameraPoint's p_C alone (no Jacobians): for residuals whose Jacobians are evaluated elsewhere
/// (first estimates).
Eigen::Vector3d pointInCamera(const PoseEstimate& pose, const CameraExtrinsic& ext, const Eigen::Vector3d& p_W);

/// ∂(x/z, y/z)/∂p_C.
Eigen::Matrix<double, 2, 3> projectionJacobian(const Eigen::Vector3d& p_C);

/// World point of an anchored inverse-depth feature with its Jacobians.
struct AnchoredPoint {
  Eigen::Vector3d p_W = Eigen::Vector3d::Zero();
  Eigen::Matrix3d J_feature;              ///< ∂p_W/∂(α, β, ρ)
  Eigen::Matrix<double, 3, 6> J_anchor;   ///< ∂p_W/∂[δθ; δp] of the anchor pose
  Eigen::Matrix<double, 3, 6> J_ext;      ///< ∂p_W/∂[δφ; δt] of camera 0's extrinsic
};

AnchoredPoint anchoredPoint(const Eigen::Vector3d& f, const PoseEstimate& anchor, const CameraExtrinsic& ext0);

/// Camera-IMU time offset (Li & Mourikis 2014): the pose dt seconds after `pose` with the body
/// angular rate w (rad/s, IMU frame) and the world velocity v held constant,
///   R_WI Exp(w dt),  p_WI + v dt.
PoseEstimate poseAfter(const PoseEstimate& pose, const Eigen::Vector3d& w, const Eigen::Vector3d& v, double dt);
/// d p_C / d dt of cameraPoint(poseAfter(pose, w, v, dt), ext, p_W), given that CameraPoint:
/// J_pose [w; v] (exact: d/d dt of R Exp(w dt) is the right perturbation w).
Eigen::Vector3d timeOffsetJacobian(const CameraPoint& cp, const Eigen::Vector3d& w, const Eigen::Vector3d& v);

/// Inverse-depth parameters (α, β, ρ) of a world point in camera 0 of `anchor`, and
/// ∂f/∂p_C (3×3) for the chain rule (p_C the point in that camera).
Eigen::Vector3d inverseDepthOf(const Eigen::Vector3d& p_W, const PoseEstimate& anchor, const CameraExtrinsic& ext0,
                               Eigen::Matrix3d* J_pC = nullptr, CameraPoint* cp = nullptr);

}  // namespace gvins::vio
