#include "gvins/vio/trajectory_alignment.hpp"

#include <cmath>
#include <stdexcept>

#include <Eigen/LU>
#include <Eigen/SVD>

namespace gvins::vio {

std::optional<AlignmentKind> parseAlignmentKind(std::string_view name) {
  if (name == "none") return AlignmentKind::None;
  if (name == "4dof" || name == "yaw" || name == "posyaw") return AlignmentKind::Yaw4Dof;
  if (name == "se3") return AlignmentKind::SE3;
  if (name == "sim3") return AlignmentKind::Sim3;
  if (name == "first" || name == "first-pose") return AlignmentKind::FirstPose4Dof;
  return std::nullopt;
}

std::string toString(AlignmentKind kind) {
  switch (kind) {
    case AlignmentKind::None: return "none";
    case AlignmentKind::Yaw4Dof: return "4dof";
    case AlignmentKind::SE3: return "se3";
    case AlignmentKind::Sim3: return "sim3";
    case AlignmentKind::FirstPose4Dof: return "first";
  }
  return "?";
}

namespace {

SimilarityTransform umeyama(std::span<const Eigen::Vector3d> est, std::span<const Eigen::Vector3d> ref,
                            bool withScale) {
  const double n = static_cast<double>(est.size());
  Eigen::Vector3d me = Eigen::Vector3d::Zero(), mr = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < est.size(); ++i) {
    me += est[i];
    mr += ref[i];
  }
  me /= n;
  mr /= n;
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();  // Σ_xy of the paper: (1/n) Σ (ref − mr)(est − me)^T
  double varE = 0.0;
  for (std::size_t i = 0; i < est.size(); ++i) {
    const Eigen::Vector3d de = est[i] - me;
    cov += (ref[i] - mr) * de.transpose();
    varE += de.squaredNorm();
  }
  cov /= n;
  varE /= n;
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(cov, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d S = Eigen::Matrix3d::Identity();
  if (svd.matrixU().determinant() * svd.matrixV().determinant() < 0.0) S(2, 2) = -1.0;
  SimilarityTransform T;
  T.R = svd.matrixU() * S * svd.matrixV().transpose();
  if (withScale && varE > 0.0) T.scale = (svd.singularValues().asDiagonal() * S).trace() / varE;
  T.t = mr - T.scale * T.R * me;
  return T;
}

SimilarityTransform yawAlign(std::span<const Eigen::Vector3d> est, std::span<const Eigen::Vector3d> ref) {
  const double n = static_cast<double>(est.size());
  Eigen::Vector3d me = Eigen::Vector3d::Zero(), mr = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < est.size(); ++i) {
    me += est[i];
    mr += ref[i];
  }
  me /= n;
  mr /= n;
  double sinSum = 0.0, cosSum = 0.0;
  for (std::size_t i = 0; i < est.size(); ++i) {
    const Eigen::Vector3d e = est[i] - me, g = ref[i] - mr;
    sinSum += e.x() * g.y() - e.y() * g.x();
    cosSum += e.x() * g.x() + e.y() * g.y();
  }
  const double yaw = (sinSum == 0.0 && cosSum == 0.0) ? 0.0 : std::atan2(sinSum, cosSum);
  SimilarityTransform T;
  const double c = std::cos(yaw), s = std::sin(yaw);
  T.R << c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0;
  T.t = mr - T.R * me;
  return T;
}

}  // namespace

SimilarityTransform alignTrajectory(AlignmentKind kind, std::span<const Eigen::Vector3d> est,
                                    std::span<const Eigen::Vector3d> ref) {
  if (kind == AlignmentKind::None) return {};
  if (est.size() != ref.size()) throw std::invalid_argument("alignTrajectory: point counts differ");
  if (est.empty()) throw std::invalid_argument("alignTrajectory: no points");
  switch (kind) {
    case AlignmentKind::Yaw4Dof: return yawAlign(est, ref);
    case AlignmentKind::SE3: return umeyama(est, ref, false);
    case AlignmentKind::Sim3: return umeyama(est, ref, true);
    case AlignmentKind::FirstPose4Dof:
      throw std::invalid_argument("alignTrajectory: the first-pose alignment needs orientations (evaluateTrajectory)");
    case AlignmentKind::None: break;
  }
  return {};
}

}  // namespace gvins::vio
