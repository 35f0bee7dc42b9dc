#include "gvins/vio/stereo_matcher.hpp"

#include <algorithm>
#include <cmath>

#include <Eigen/LU>

#include "gvins/vio/so3.hpp"

namespace gvins::vio {

StereoMatcher::StereoMatcher(const CameraModel& cam0, const CameraModel& cam1, const Eigen::Matrix4d& T_C1C0,
                             const StereoConfig& config)
    : cam0_(cam0), cam1_(cam1), R_(T_C1C0.topLeftCorner<3, 3>()), t_(T_C1C0.topRightCorner<3, 1>()), cfg_(config) {
  E_ = so3::skew(t_) * R_;
}

std::optional<Eigen::Vector2d> StereoMatcher::predict(const Eigen::Vector2d& pixel0, double depth) const {
  const Eigen::Vector2d n = cam0_.undistort(pixel0);
  return cam1_.project(R_ * (Eigen::Vector3d(n.x(), n.y(), 1.0) * depth) + t_);
}

double StereoMatcher::epipolarError(const Eigen::Vector2d& n0, const Eigen::Vector2d& n1) const {
  const Eigen::Vector3d l = E_ * Eigen::Vector3d(n0.x(), n0.y(), 1.0);
  const double d = std::abs(l.x() * n1.x() + l.y() * n1.y() + l.z()) / std::hypot(l.x(), l.y());
  return d * cam1_.intrinsics().fx;
}

std::optional<double> StereoMatcher::depth(const Eigen::Vector2d& n0, const Eigen::Vector2d& n1) const {
  // lambda0 R x0 - lambda1 x1 = -t  (x0, x1 homogeneous normalised); normal equations.
  const Eigen::Vector3d a = R_ * Eigen::Vector3d(n0.x(), n0.y(), 1.0);
  const Eigen::Vector3d b(n1.x(), n1.y(), 1.0);
  Eigen::Matrix2d A;
  A << a.dot(a), -a.dot(b), -a.dot(b), b.dot(b);
  const Eigen::Vector2d rhs(-a.dot(t_), b.dot(t_));
  const double det = A.determinant();
  if (!(std::abs(det) > 1e-12 * a.squaredNorm() * b.squaredNorm())) return std::nullopt;
  const Eigen::Vector2d lam = A.inverse() * rhs;
  if (!(lam.x() > 0.0) || !(lam.y() > 0.0)) return std::nullopt;
  return lam.x();
}

void StereoMatcher::match(const ImagePyramid& leftImage, const ImagePyramid& rightImage,
                          const std::vector<cv::Point2f>& left, std::vector<cv::Point2f>& right,
                          std::vector<unsigned char>& status, double predictionDepth) const {
  right.resize(left.size(), cv::Point2f(std::nanf(""), 0.f));
  status.assign(left.size(), 0);
  // Features with a prior (last frame's match moved by the left motion) are off by a fraction
  // of a pixel: cfg_.priorLevels (default: the image only). The others start from the depth
  // prediction and use the whole pyramid.
  std::vector<std::size_t> idx[2];
  std::vector<cv::Point2f> from[2], to[2];
  for (std::size_t i = 0; i < left.size(); ++i) {
    const bool prior = !std::isnan(right[i].x);
    cv::Point2f guess = right[i];
    if (!prior) {
      const auto p = predict({left[i].x, left[i].y}, predictionDepth);
      guess = p ? cv::Point2f(static_cast<float>(p->x()), static_cast<float>(p->y())) : left[i];
    }
    idx[prior].push_back(i);
    from[prior].push_back(left[i]);
    to[prior].push_back(guess);
  }
  for (int prior = 0; prior < 2; ++prior) {
    if (idx[prior].empty()) continue;
    KltParams p = cfg_.klt;
    if (prior) p.levels = std::clamp(cfg_.priorLevels, 0, p.levels);
    std::vector<unsigned char> st;
    trackKlt(leftImage, rightImage, from[prior], to[prior], st, p, true);
    for (std::size_t k = 0; k < idx[prior].size(); ++k) {
      right[idx[prior][k]] = to[prior][k];
      status[idx[prior][k]] = st[k];
    }
  }
  for (std::size_t i = 0; i < left.size(); ++i) {
    if (!status[i]) continue;
    const Eigen::Vector2d n0 = cam0_.undistort({left[i].x, left[i].y});
    const Eigen::Vector2d n1 = cam1_.undistort({right[i].x, right[i].y});
    if (epipolarError(n0, n1) > cfg_.maxEpipolarError) {
      status[i] = 0;
      continue;
    }
    const auto z = depth(n0, n1);
    if (!z || *z < cfg_.minDepth) status[i] = 0;
  }
}

}  // namespace gvins::vio
