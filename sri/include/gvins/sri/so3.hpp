// SO(3) exponential and logarithm on unit quaternions (Hamilton convention, Eigen::Quaternion),
// used for the boxplus/boxminus of rotation blocks.
//
// Exp(φ) is the rotation by |φ| about φ/|φ| (Rodrigues); as a unit quaternion
// q = [cos(|φ|/2), sin(|φ|/2) φ/|φ|] (e.g. Solà 2017, "Quaternion kinematics for the error-state
// Kalman filter", eq. 101). Log is its inverse on the principal branch |φ| ≤ π.
#pragma once

#include <cmath>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace gvins::sri::so3 {

template <typename Scalar>
using Vector3 = Eigen::Matrix<Scalar, 3, 1>;
template <typename Scalar>
using Matrix3 = Eigen::Matrix<Scalar, 3, 3>;

/// Skew-symmetric matrix [φ]× with [φ]× a = φ × a.
template <typename Scalar>
Matrix3<Scalar> hat(const Vector3<Scalar>& phi) {
  Matrix3<Scalar> m;
  m << Scalar(0), -phi.z(), phi.y(), phi.z(), Scalar(0), -phi.x(), -phi.y(), phi.x(), Scalar(0);
  return m;
}

/// Unit quaternion of Exp(φ).
template <typename Scalar>
Eigen::Quaternion<Scalar> expQuaternion(const Vector3<Scalar>& phi) {
  const Scalar theta2 = phi.squaredNorm();
  Scalar w;
  Scalar k;  // sin(θ/2)/θ
  // Below θ² ~ eps the Taylor series sin(θ/2)/θ = 1/2 - θ²/48 + ... is exact in working precision.
  if (theta2 < Scalar(16) * Eigen::NumTraits<Scalar>::epsilon()) {
    k = Scalar(0.5) - theta2 / Scalar(48);
    w = Scalar(1) - theta2 / Scalar(8);
  } else {
    const Scalar theta = std::sqrt(theta2);
    k = std::sin(Scalar(0.5) * theta) / theta;
    w = std::cos(Scalar(0.5) * theta);
  }
  Eigen::Quaternion<Scalar> q(w, k * phi.x(), k * phi.y(), k * phi.z());
  q.normalize();
  return q;
}

/// Rotation matrix of Exp(φ).
template <typename Scalar>
Matrix3<Scalar> exp(const Vector3<Scalar>& phi) {
  return expQuaternion(phi).toRotationMatrix();
}

/// Log of a unit quaternion, |φ| ≤ π.
template <typename Scalar>
Vector3<Scalar> log(const Eigen::Quaternion<Scalar>& q_in) {
  Eigen::Quaternion<Scalar> q = q_in.normalized();
  if (q.w() < Scalar(0)) q.coeffs() = -q.coeffs();  // same rotation, w ≥ 0: angle in [0, π]
  const Vector3<Scalar> v = q.vec();
  const Scalar s = v.norm();
  if (s < Scalar(4) * std::sqrt(Eigen::NumTraits<Scalar>::epsilon())) {
    // θ = 2 atan2(s, w) ≈ 2 s / w (1 - s²/(3 w²)); the relative error of the first term is below
    // s², i.e. below working precision here.
    return (Scalar(2) / q.w()) * v;
  }
  const Scalar theta = Scalar(2) * std::atan2(s, q.w());
  return (theta / s) * v;
}

/// Log of a rotation matrix, |φ| ≤ π.
template <typename Scalar>
Vector3<Scalar> log(const Matrix3<Scalar>& R) {
  return log(Eigen::Quaternion<Scalar>(R));
}

}  // namespace gvins::sri::so3
