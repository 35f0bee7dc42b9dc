// The simulated truth: a rigid-body motion of the body (= IMU) frame B in the local world frame
// W, evaluated at any time of the flight.
//
// Conventions (shared by every part of gvins-sim; see docs/dataset_format.md):
//   * t is in seconds from the flight start (t = 0 is LocalFrame::startTime), 0 <= t <= duration().
//   * W is East-North-Up at the geodetic origin of the LocalFrame (local_frame.hpp): an
//     Earth-fixed frame, z along the ellipsoid normal of the origin.
//   * B is the IMU frame (x forward, y left, z up for the vehicles built here). R_WB rotates
//     B-vectors into W; p_WB, v_WB, a_WB are the position of the IMU and its first two time
//     derivatives in W (derivatives taken in W).
//   * omega_B is the angular velocity of B relative to W expressed in B, i.e.
//     dR_WB/dt = R_WB [omega_B]x; alpha_B = d(omega_B)/dt.
// A trajectory is at least C^2 in position and C^1 in orientation (the implementations in this
// module are C^6 / C^4), so that the IMU signals derived from it are continuous.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace gvins::sim {

/// The full kinematic truth at one instant.
struct TrajectoryState {
  double t = 0.0;                                       ///< s from the flight start
  Eigen::Vector3d p_WB = Eigen::Vector3d::Zero();       ///< m, position of B in W
  Eigen::Vector3d v_WB = Eigen::Vector3d::Zero();       ///< m/s
  Eigen::Vector3d a_WB = Eigen::Vector3d::Zero();       ///< m/s^2 (kinematic, without gravity)
  Eigen::Matrix3d R_WB = Eigen::Matrix3d::Identity();   ///< B -> W
  Eigen::Vector3d omega_B = Eigen::Vector3d::Zero();    ///< rad/s, in B
  Eigen::Vector3d alpha_B = Eigen::Vector3d::Zero();    ///< rad/s^2, in B

  /// Position in W of a point fixed in B (e.g. the GNSS antenna at lever arm l_B):
  /// p_WB + R_WB l_B.
  Eigen::Vector3d pointPosition(const Eigen::Vector3d& l_B) const { return p_WB + R_WB * l_B; }
  /// Velocity in W of a point fixed in B: v_WB + R_WB (omega_B x l_B).
  Eigen::Vector3d pointVelocity(const Eigen::Vector3d& l_B) const {
    return v_WB + R_WB * omega_B.cross(l_B);
  }
  /// Acceleration in W of a point fixed in B:
  /// a_WB + R_WB (alpha_B x l_B + omega_B x (omega_B x l_B)).
  Eigen::Vector3d pointAcceleration(const Eigen::Vector3d& l_B) const {
    return a_WB + R_WB * (alpha_B.cross(l_B) + omega_B.cross(omega_B.cross(l_B)));
  }
};

/// A trajectory: truth at any time of the flight. Implementations are immutable after
/// construction and evaluate() is thread-safe.
class Trajectory {
 public:
  virtual ~Trajectory() = default;

  /// Length of the flight in seconds (the motion is defined on [0, duration()]).
  virtual double duration() const = 0;
  /// The truth at time t (s from the flight start). Times outside [0, duration()] are clamped
  /// to the interval.
  virtual TrajectoryState evaluate(double t) const = 0;

  // Shorthands (each calls evaluate()).
  Eigen::Vector3d position(double t) const { return evaluate(t).p_WB; }
  Eigen::Vector3d velocity(double t) const { return evaluate(t).v_WB; }
  Eigen::Vector3d acceleration(double t) const { return evaluate(t).a_WB; }
  Eigen::Matrix3d orientation(double t) const { return evaluate(t).R_WB; }
  Eigen::Vector3d angularVelocity(double t) const { return evaluate(t).omega_B; }
  Eigen::Vector3d angularAcceleration(double t) const { return evaluate(t).alpha_B; }
};

}  // namespace gvins::sim
