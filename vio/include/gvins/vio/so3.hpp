// Rotation group SO(3) helpers on Eigen 3x3 matrices: skew matrix, exponential and logarithm
// maps, and the right Jacobian with its inverse.
//
// Formulas: Rodrigues' rotation formula; right Jacobian Jr(phi) and its inverse as given in
// Forster et al., "On-Manifold Preintegration for Real-Time Visual-Inertial Odometry",
// IEEE T-RO 2017, eqs. (8)-(9) (after Chirikjian 2011). Convention used throughout gvins::vio:
//   Exp(phi + dphi) ~= Exp(phi) Exp(Jr(phi) dphi)
//   Log(Exp(phi) Exp(dphi)) ~= phi + Jr^-1(phi) dphi
#pragma once

#include <algorithm>
#include <cmath>

#include <Eigen/Core>

namespace gvins::vio::so3 {

/// [v]x such that [v]x w = v x w.
inline Eigen::Matrix3d skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d m;
  m << 0.0, -v.z(), v.y(), v.z(), 0.0, -v.x(), -v.y(), v.x(), 0.0;
  return m;
}

/// Rotation matrix of the rotation vector phi (axis * angle).
inline Eigen::Matrix3d exp(const Eigen::Vector3d& phi) {
  const double t2 = phi.squaredNorm();
  const Eigen::Matrix3d k = skew(phi);
  double a, b;  // sin(t)/t and (1-cos t)/t^2, with Taylor series near 0
  if (t2 < 1e-8) {
    a = 1.0 - t2 / 6.0;
    b = 0.5 - t2 / 24.0;
  } else {
    const double t = std::sqrt(t2);
    a = std::sin(t) / t;
    b = (1.0 - std::cos(t)) / t2;
  }
  return Eigen::Matrix3d::Identity() + a * k + b * k * k;
}

/// Rotation vector of R, angle in [0, pi].
inline Eigen::Vector3d log(const Eigen::Matrix3d& R) {
  const Eigen::Vector3d w(R(2, 1) - R(1, 2), R(0, 2) - R(2, 0), R(1, 0) - R(0, 1));
  const double c = std::clamp(0.5 * (R.trace() - 1.0), -1.0, 1.0);
  if (c > 1.0 - 1e-10) return 0.5 * (1.0 + (1.0 - c) / 3.0) * w;  // t/(2 sin t) ~ (1 + t^2/6)/2
  const double t = std::acos(c);
  if (c < -1.0 + 1e-6) {
    // Near pi: the axis is the column of R + I with the largest norm (R + I = 2 n n^T at pi).
    const Eigen::Matrix3d S = R + Eigen::Matrix3d::Identity();
    int k = 0;
    S.colwise().squaredNorm().maxCoeff(&k);
    Eigen::Vector3d n = S.col(k).normalized();
    if (n.dot(w) < 0.0) n = -n;  // keep the sign consistent with the antisymmetric part
    return t * n;
  }
  return t / (2.0 * std::sin(t)) * w;
}

/// Right Jacobian Jr(phi).
inline Eigen::Matrix3d rightJacobian(const Eigen::Vector3d& phi) {
  const double t2 = phi.squaredNorm();
  const Eigen::Matrix3d k = skew(phi);
  double a, b;  // (1-cos t)/t^2, (t - sin t)/t^3
  if (t2 < 1e-8) {
    a = 0.5 - t2 / 24.0;
    b = 1.0 / 6.0 - t2 / 120.0;
  } else {
    const double t = std::sqrt(t2);
    a = (1.0 - std::cos(t)) / t2;
    b = (t - std::sin(t)) / (t2 * t);
  }
  return Eigen::Matrix3d::Identity() - a * k + b * k * k;
}

/// Inverse of the right Jacobian.
inline Eigen::Matrix3d rightJacobianInverse(const Eigen::Vector3d& phi) {
  const double t2 = phi.squaredNorm();
  const Eigen::Matrix3d k = skew(phi);
  double b;  // 1/t^2 - (1+cos t)/(2 t sin t)
  if (t2 < 1e-8) {
    b = 1.0 / 12.0 + t2 / 720.0;
  } else {
    const double t = std::sqrt(t2);
    b = 1.0 / t2 - (1.0 + std::cos(t)) / (2.0 * t * std::sin(t));
  }
  return Eigen::Matrix3d::Identity() + 0.5 * k + b * k * k;
}

}  // namespace gvins::vio::so3
