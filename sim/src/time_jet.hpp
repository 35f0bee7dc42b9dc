// Second-order forward-mode differentiation in time: a quantity with its first and second
// time derivatives, propagated exactly through the arithmetic of attitude construction
// (normalisation, cross products, trigonometry). Private to gvins_sim.
#pragma once

#include <cmath>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace gvins::sim::detail {

/// f, f', f''.
struct Jet {
  double v = 0.0, d1 = 0.0, d2 = 0.0;
  Jet() = default;
  Jet(double value, double first = 0.0, double second = 0.0) : v(value), d1(first), d2(second) {}
};
inline Jet operator+(Jet a, Jet b) { return {a.v + b.v, a.d1 + b.d1, a.d2 + b.d2}; }
inline Jet operator-(Jet a, Jet b) { return {a.v - b.v, a.d1 - b.d1, a.d2 - b.d2}; }
inline Jet operator-(Jet a) { return {-a.v, -a.d1, -a.d2}; }
inline Jet operator*(Jet a, Jet b) { return {a.v * b.v, a.d1 * b.v + a.v * b.d1, a.d2 * b.v + 2.0 * a.d1 * b.d1 + a.v * b.d2}; }
inline Jet operator*(double s, Jet a) { return {s * a.v, s * a.d1, s * a.d2}; }
/// 1/a: (1/a)' = -a'/a^2, (1/a)'' = 2 a'^2/a^3 - a''/a^2.
inline Jet inverse(Jet a) {
  const double i = 1.0 / a.v;
  return {i, -a.d1 * i * i, (2.0 * a.d1 * a.d1 * i - a.d2) * i * i};
}
inline Jet sqrt(Jet a) {
  const double s = std::sqrt(a.v);
  const double d1 = 0.5 * a.d1 / s;
  return {s, d1, (0.5 * a.d2 - d1 * d1) / s};
}
inline Jet sin(Jet a) {
  const double s = std::sin(a.v), c = std::cos(a.v);
  return {s, c * a.d1, c * a.d2 - s * a.d1 * a.d1};
}
inline Jet cos(Jet a) {
  const double s = std::sin(a.v), c = std::cos(a.v);
  return {c, -s * a.d1, -s * a.d2 - c * a.d1 * a.d1};
}

/// A 3-vector with its first and second time derivatives.
struct Jet3 {
  Eigen::Vector3d v = Eigen::Vector3d::Zero(), d1 = Eigen::Vector3d::Zero(), d2 = Eigen::Vector3d::Zero();
  Jet operator[](int i) const { return {v[i], d1[i], d2[i]}; }
  static Jet3 from(Jet x, Jet y, Jet z) {
    Jet3 r;
    r.v << x.v, y.v, z.v;
    r.d1 << x.d1, y.d1, z.d1;
    r.d2 << x.d2, y.d2, z.d2;
    return r;
  }
};
inline Jet3 operator+(const Jet3& a, const Jet3& b) { return {a.v + b.v, a.d1 + b.d1, a.d2 + b.d2}; }
inline Jet3 operator*(Jet s, const Jet3& a) {
  return {s.v * a.v, s.d1 * a.v + s.v * a.d1, s.d2 * a.v + 2.0 * s.d1 * a.d1 + s.v * a.d2};
}
inline Jet dot(const Jet3& a, const Jet3& b) {
  return {a.v.dot(b.v), a.d1.dot(b.v) + a.v.dot(b.d1), a.d2.dot(b.v) + 2.0 * a.d1.dot(b.d1) + a.v.dot(b.d2)};
}
inline Jet3 cross(const Jet3& a, const Jet3& b) {
  return {a.v.cross(b.v), a.d1.cross(b.v) + a.v.cross(b.d1),
          a.d2.cross(b.v) + 2.0 * a.d1.cross(b.d1) + a.v.cross(b.d2)};
}
inline Jet3 normalized(const Jet3& a) { return inverse(sqrt(dot(a, a))) * a; }

/// A 3x3 matrix with its first and second time derivatives.
struct JetMat3 {
  Eigen::Matrix3d v = Eigen::Matrix3d::Identity(), d1 = Eigen::Matrix3d::Zero(), d2 = Eigen::Matrix3d::Zero();
  static JetMat3 fromColumns(const Jet3& x, const Jet3& y, const Jet3& z) {
    JetMat3 m;
    m.v << x.v, y.v, z.v;
    m.d1 << x.d1, y.d1, z.d1;
    m.d2 << x.d2, y.d2, z.d2;
    return m;
  }
};
inline JetMat3 operator*(const JetMat3& a, const JetMat3& b) {
  return {a.v * b.v, a.d1 * b.v + a.v * b.d1, a.d2 * b.v + 2.0 * a.d1 * b.d1 + a.v * b.d2};
}
/// Elementary rotations about x, y, z by an angle jet.
inline JetMat3 rotX(Jet a) {
  const Jet c = cos(a), s = sin(a);
  JetMat3 m;
  m.v << 1, 0, 0, 0, c.v, -s.v, 0, s.v, c.v;
  m.d1 << 0, 0, 0, 0, c.d1, -s.d1, 0, s.d1, c.d1;
  m.d2 << 0, 0, 0, 0, c.d2, -s.d2, 0, s.d2, c.d2;
  return m;
}
inline JetMat3 rotY(Jet a) {
  const Jet c = cos(a), s = sin(a);
  JetMat3 m;
  m.v << c.v, 0, s.v, 0, 1, 0, -s.v, 0, c.v;
  m.d1 << c.d1, 0, s.d1, 0, 0, 0, -s.d1, 0, c.d1;
  m.d2 << c.d2, 0, s.d2, 0, 0, 0, -s.d2, 0, c.d2;
  return m;
}
inline JetMat3 rotZ(Jet a) {
  const Jet c = cos(a), s = sin(a);
  JetMat3 m;
  m.v << c.v, -s.v, 0, s.v, c.v, 0, 0, 0, 1;
  m.d1 << c.d1, -s.d1, 0, s.d1, c.d1, 0, 0, 0, 0;
  m.d2 << c.d2, -s.d2, 0, s.d2, c.d2, 0, 0, 0, 0;
  return m;
}

/// Body angular velocity and acceleration of a rotation jet R(t) (R orthonormal):
/// omega = vee(R^T R'), alpha = d/dt omega = vee(R'^T R' + R^T R''), of which only the
/// antisymmetric part R^T R'' contributes (R'^T R' is symmetric).
inline void angularRates(const JetMat3& R, Eigen::Vector3d& omega, Eigen::Vector3d& alpha) {
  const Eigen::Matrix3d W = R.v.transpose() * R.d1;
  const Eigen::Matrix3d A = R.v.transpose() * R.d2;
  omega << 0.5 * (W(2, 1) - W(1, 2)), 0.5 * (W(0, 2) - W(2, 0)), 0.5 * (W(1, 0) - W(0, 1));
  alpha << 0.5 * (A(2, 1) - A(1, 2)), 0.5 * (A(0, 2) - A(2, 0)), 0.5 * (A(1, 0) - A(0, 1));
}

}  // namespace gvins::sim::detail
