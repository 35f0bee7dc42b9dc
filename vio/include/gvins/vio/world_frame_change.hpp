// A change of the VIO world frame along the VIO's four unobservable directions: a rotation ψ about
// gravity (z) and a translation t, x_W' = Rz(ψ) x_W + t. Gravity stays (0, 0, −g) in W'.
//
// A client that estimated where the VIO world frame W lies in a frame of its own (fusion/: the VIO
// frame's yaw and origin in local ENU, paper Sec. III-A) holds [ψ; t] as a client block; once it
// has converged, reanchorWorld() re-expresses the estimator's state in W' and marginalizes the
// block (EstimatorBackend::reanchorWorld). This is an exact change of variables (at the
// linearization values given, below), so the information the block carried (e.g. the GNSS yaw)
// moves into the poses:
// unlike fixing the block (the paper's marginalization of the converged frame in the VIO frame),
// the VIO's own gauge prior on its first pose does not keep pinning the global yaw afterwards.
#pragma once

#include <optional>
#include <span>

#include <Eigen/Core>

#include "gvins/sri/block.hpp"
#include "gvins/sri/sri_filter.hpp"

namespace gvins::vio {

struct WorldFrameChange {
  double yaw = 0.0;                              ///< ψ, rad, about W's z axis (gravity).
  Eigen::Vector3d t = Eigen::Vector3d::Zero();  ///< Origin of W in W'.

  /// From a client block's estimate [ψ; t_x; t_y; t_z].
  static WorldFrameChange fromVector(const Eigen::Vector4d& v);
  Eigen::Matrix3d rotation() const;  ///< Rz(ψ)
  Eigen::Vector3d point(const Eigen::Vector3d& p_W) const { return rotation() * p_W + t; }
  Eigen::Vector3d direction(const Eigen::Vector3d& v_W) const { return rotation() * v_W; }
  Eigen::Matrix3d attitude(const Eigen::Matrix3d& R_WI) const { return rotation() * R_WI; }
  /// W' → W.
  WorldFrameChange inverse() const;
};

/// A pose block (kPose of R_WI, p_WI, either perturbation convention) to re-express, and where
/// the frame's Jacobian B is evaluated: at the block's estimate, or at given values — an
/// estimator with first-estimate Jacobians passes its first estimates, so that the yaw/position
/// uncertainty the frame hands over lies along its own unobservable directions N (built from
/// them); at the current estimates it would leak into what the visual rows observe (H N ≠ 0).
struct ReanchoredPose {
  sri::BlockId id;
  std::optional<Eigen::Matrix3d> R_lin;
  std::optional<Eigen::Vector3d> p_lin;
};
/// A kVector block whose first three entries are a velocity in W (the rest, e.g. IMU biases, does
/// not change), and where B is evaluated (see ReanchoredPose).
struct ReanchoredVelocity {
  sri::BlockId id;
  std::optional<Eigen::Vector3d> v_lin;
};

/// Re-expresses an SRI state in W' = the frame held by the client block `frame` (kVector(4),
/// [ψ; t]) and marginalizes that block. Everything not listed (body-frame parameters, features
/// anchored in a camera, receiver clocks) does not depend on W. Per block a change of variables
/// of the error state δx' = A δx + B δframe (sri::SriFilter::substitute; exact at the
/// linearization values), after moving `frame` to the back of the order; the filter's
/// information about x' is that about x and the frame together. The estimates become
/// (Rz R, Rz p + t) and Rz v. Returns the change applied (the block's estimate). Throws
/// std::invalid_argument for a frame block that is not a 4-vector, or a pose/velocity block of
/// the wrong kind.
template <typename Scalar>
WorldFrameChange reanchorWorld(sri::SriFilter<Scalar>& f, sri::BlockId frame, std::span<const ReanchoredPose> poses,
                               std::span<const ReanchoredVelocity> velocities);

}  // namespace gvins::vio
