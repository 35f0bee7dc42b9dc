// Pinhole projection with radial-tangential or equidistant distortion.
//
// Models (as documented for Kalibr's camera models and OpenCV's calib3d/fisheye modules):
//  radial-tangential (Brown-Conrady "plumb bob", k1 k2 p1 p2), normalised (x, y), r2 = x^2 + y^2:
//    xd = x (1 + k1 r2 + k2 r2^2) + 2 p1 x y + p2 (r2 + 2 x^2)
//    yd = y (1 + k1 r2 + k2 r2^2) + p1 (r2 + 2 y^2) + 2 p2 x y
//  equidistant (Kannala & Brandt 2006, k1..k4), r = |(x, y)|, theta = atan(r):
//    theta_d = theta (1 + k1 theta^2 + k2 theta^4 + k3 theta^6 + k4 theta^8)
//    (xd, yd) = theta_d / r (x, y)
//  pixel = (fx xd + cx, fy yd + cy).
// The inverse is solved by Gauss-Newton on the 2-D distortion (radtan) or Newton on the 1-D
// radial polynomial (equidistant).
#include "gvins/vio/camera_model.hpp"

#include <cmath>
#include <stdexcept>

#include <Eigen/LU>

namespace gvins::vio {
namespace {

// Distorted normalised coordinates and the 2x2 Jacobian d distorted / d undistorted.
Eigen::Vector2d distortRadTan(const std::array<double, 4>& d, const Eigen::Vector2d& p,
                              Eigen::Matrix2d* J) {
  const double k1 = d[0], k2 = d[1], p1 = d[2], p2 = d[3];
  const double x = p.x(), y = p.y();
  const double x2 = x * x, y2 = y * y, xy = x * y, r2 = x2 + y2;
  const double radial = 1.0 + k1 * r2 + k2 * r2 * r2;
  const Eigen::Vector2d out(x * radial + 2.0 * p1 * xy + p2 * (r2 + 2.0 * x2),
                            y * radial + p1 * (r2 + 2.0 * y2) + 2.0 * p2 * xy);
  if (J) {
    const double dradial_dr2 = k1 + 2.0 * k2 * r2;  // d radial / d r2; d r2/dx = 2x
    (*J)(0, 0) = radial + x * dradial_dr2 * 2.0 * x + 2.0 * p1 * y + p2 * 6.0 * x;
    (*J)(0, 1) = x * dradial_dr2 * 2.0 * y + 2.0 * p1 * x + p2 * 2.0 * y;
    (*J)(1, 0) = y * dradial_dr2 * 2.0 * x + p1 * 2.0 * x + 2.0 * p2 * y;
    (*J)(1, 1) = radial + y * dradial_dr2 * 2.0 * y + p1 * 6.0 * y + 2.0 * p2 * x;
  }
  return out;
}

Eigen::Vector2d distortEquidistant(const std::array<double, 4>& d, const Eigen::Vector2d& p,
                                   Eigen::Matrix2d* J) {
  const double r2 = p.squaredNorm();
  if (r2 < 1e-20) {
    // theta_d / r -> 1 and the Jacobian -> identity at the optical axis.
    if (J) J->setIdentity();
    return p;
  }
  const double r = std::sqrt(r2);
  const double th = std::atan(r);
  const double t2 = th * th;
  const double poly = 1.0 + t2 * (d[0] + t2 * (d[1] + t2 * (d[2] + t2 * d[3])));
  const double thd = th * poly;
  const double s = thd / r;  // scale applied to (x, y)
  if (J) {
    // d thd / d theta = 1 + 3 k1 t2 + 5 k2 t2^2 + 7 k3 t2^3 + 9 k4 t2^4; d theta / d r = 1/(1+r2)
    const double dthd_dth = 1.0 + t2 * (3.0 * d[0] + t2 * (5.0 * d[1] + t2 * (7.0 * d[2] + t2 * 9.0 * d[3])));
    const double ds_dr = (dthd_dth / (1.0 + r2) - s) / r;
    // d(s p)/dp = s I + p (ds/dr) (p/r)^T
    *J = s * Eigen::Matrix2d::Identity() + (ds_dr / r) * p * p.transpose();
  }
  return s * p;
}

}  // namespace

CameraModel::CameraModel(const CameraIntrinsics& intrinsics) : k_(intrinsics) {
  if (!(k_.fx > 0.0) || !(k_.fy > 0.0) || !std::isfinite(k_.cx) || !std::isfinite(k_.cy) ||
      !std::isfinite(k_.fx) || !std::isfinite(k_.fy)) {
    throw std::invalid_argument("CameraModel: focal lengths must be positive and finite");
  }
  for (double c : k_.distortion) {
    if (!std::isfinite(c)) throw std::invalid_argument("CameraModel: non-finite distortion coefficient");
  }
  if (k_.width < 0 || k_.height < 0) throw std::invalid_argument("CameraModel: negative image size");
}

Eigen::Vector2d CameraModel::distort(const Eigen::Vector2d& normalized, Eigen::Matrix2d* jacobian) const {
  switch (k_.model) {
    case DistortionModel::RadialTangential:
      return distortRadTan(k_.distortion, normalized, jacobian);
    case DistortionModel::Equidistant:
      return distortEquidistant(k_.distortion, normalized, jacobian);
    case DistortionModel::None:
      break;
  }
  if (jacobian) jacobian->setIdentity();
  return normalized;
}

Eigen::Vector2d CameraModel::distortAndProject(const Eigen::Vector2d& normalized,
                                               Eigen::Matrix2d* jacobian) const {
  const Eigen::Vector2d d = distort(normalized, jacobian);
  if (jacobian) {
    jacobian->row(0) *= k_.fx;
    jacobian->row(1) *= k_.fy;
  }
  return {k_.fx * d.x() + k_.cx, k_.fy * d.y() + k_.cy};
}

Eigen::Vector2d CameraModel::undistortNormalized(const Eigen::Vector2d& distorted) const {
  switch (k_.model) {
    case DistortionModel::None:
      return distorted;
    case DistortionModel::Equidistant: {
      // Solve theta_d(theta) = |distorted| by Newton, then r = tan(theta).
      const double thd = distorted.norm();
      if (thd < 1e-15) return distorted;
      const auto& d = k_.distortion;
      double th = std::min(thd, 1.5);
      for (int it = 0; it < 20; ++it) {
        const double t2 = th * th;
        const double f = th * (1.0 + t2 * (d[0] + t2 * (d[1] + t2 * (d[2] + t2 * d[3])))) - thd;
        const double df = 1.0 + t2 * (3.0 * d[0] + t2 * (5.0 * d[1] + t2 * (7.0 * d[2] + t2 * 9.0 * d[3])));
        if (!(std::abs(df) > 1e-12)) break;
        const double step = f / df;
        th = std::clamp(th - step, 0.0, 1.5707);
        if (std::abs(step) < 1e-15) break;
      }
      return distorted * (std::tan(th) / thd);
    }
    case DistortionModel::RadialTangential: {
      // Gauss-Newton on distort(u) = distorted, starting at u = distorted.
      Eigen::Vector2d u = distorted;
      Eigen::Matrix2d J;
      for (int it = 0; it < 30; ++it) {
        const Eigen::Vector2d e = distortRadTan(k_.distortion, u, &J) - distorted;
        if (e.squaredNorm() < 1e-30) break;
        const double det = J.determinant();
        if (!(std::abs(det) > 1e-12)) break;  // past the fold of the polynomial: give up
        const Eigen::Vector2d step = J.inverse() * e;
        u -= step;
        if (step.squaredNorm() < 1e-30) break;
      }
      return u;
    }
  }
  return distorted;
}

Eigen::Vector2d CameraModel::undistort(const Eigen::Vector2d& pixel) const {
  const Eigen::Vector2d d((pixel.x() - k_.cx) / k_.fx, (pixel.y() - k_.cy) / k_.fy);
  return undistortNormalized(d);
}

Eigen::Vector2d CameraModel::undistort(const Eigen::Vector2d& pixel, Eigen::Matrix2d* jacobian) const {
  const Eigen::Vector2d u = undistort(pixel);
  if (jacobian) {
    Eigen::Matrix2d J;
    distortAndProject(u, &J);
    *jacobian = J.inverse();
  }
  return u;
}

Eigen::Vector3d CameraModel::bearing(const Eigen::Vector2d& pixel) const {
  const Eigen::Vector2d u = undistort(pixel);
  return Eigen::Vector3d(u.x(), u.y(), 1.0).normalized();
}

std::optional<Eigen::Vector2d> CameraModel::project(const Eigen::Vector3d& pointCamera,
                                                    Eigen::Matrix<double, 2, 3>* jacobian) const {
  const double z = pointCamera.z();
  if (!(z > 1e-6)) return std::nullopt;
  const double iz = 1.0 / z;
  const Eigen::Vector2d n(pointCamera.x() * iz, pointCamera.y() * iz);
  if (!jacobian) return distortAndProject(n);
  Eigen::Matrix2d Jd;
  const Eigen::Vector2d px = distortAndProject(n, &Jd);
  Eigen::Matrix<double, 2, 3> Jn;
  Jn << iz, 0.0, -n.x() * iz, 0.0, iz, -n.y() * iz;
  *jacobian = Jd * Jn;
  return px;
}

bool CameraModel::inImage(const Eigen::Vector2d& pixel, double border) const {
  return pixel.x() >= border && pixel.y() >= border && pixel.x() <= k_.width - 1.0 - border &&
         pixel.y() <= k_.height - 1.0 - border;
}

}  // namespace gvins::vio
