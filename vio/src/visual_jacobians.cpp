#include "gvins/vio/visual_jacobians.hpp"

#include "gvins/vio/so3.hpp"

namespace gvins::vio {

Eigen::Vector3d pointInCamera(const PoseEstimate& pose, const CameraExtrinsic& ext, const Eigen::Vector3d& p_W) {
  const Eigen::Vector3d p_I = pose.R_WI.transpose() * (p_W - pose.p_WI);
  return ext.R_IC.transpose() * (p_I - ext.p_IC);
}

CameraPoint cameraPoint(const PoseEstimate& pose, const CameraExtrinsic& ext, const Eigen::Vector3d& p_W) {
  CameraPoint c;
  const Eigen::Vector3d p_I = pose.R_WI.transpose() * (p_W - pose.p_WI);
  c.p_C = ext.R_IC.transpose() * (p_I - ext.p_IC);
  c.J_point = ext.R_IC.transpose() * pose.R_WI.transpose();
  c.J_pose.leftCols<3>() = ext.R_IC.transpose() * so3::skew(p_I);
  c.J_pose.rightCols<3>() = -c.J_point;
  c.J_ext.leftCols<3>() = so3::skew(c.p_C);
  c.J_ext.rightCols<3>() = -ext.R_IC.transpose();
  return c;
}

Eigen::Matrix<double, 2, 3> projectionJacobian(const Eigen::Vector3d& p) {
  const double iz = 1.0 / p.z();
  Eigen::Matrix<double, 2, 3> J;
  J << iz, 0.0, -p.x() * iz * iz, 0.0, iz, -p.y() * iz * iz;
  return J;
}

AnchoredPoint anchoredPoint(const Eigen::Vector3d& f, const PoseEstimate& anchor, const CameraExtrinsic& ext0) {
  AnchoredPoint a;
  const double rho = f.z();
  const Eigen::Vector3d p_Ca(f.x() / rho, f.y() / rho, 1.0 / rho);
  const Eigen::Vector3d p_I = ext0.R_IC * p_Ca + ext0.p_IC;
  a.p_W = anchor.R_WI * p_I + anchor.p_WI;
  Eigen::Matrix3d D;
  D << 1.0 / rho, 0.0, -f.x() / (rho * rho), 0.0, 1.0 / rho, -f.y() / (rho * rho), 0.0, 0.0, -1.0 / (rho * rho);
  const Eigen::Matrix3d RR = anchor.R_WI * ext0.R_IC;
  a.J_feature = RR * D;
  a.J_anchor.leftCols<3>() = -anchor.R_WI * so3::skew(p_I);
  a.J_anchor.rightCols<3>().setIdentity();
  a.J_ext.leftCols<3>() = -RR * so3::skew(p_Ca);
  a.J_ext.rightCols<3>() = anchor.R_WI;
  return a;
}

Eigen::Vector3d inverseDepthOf(const Eigen::Vector3d& p_W, const PoseEstimate& anchor, const CameraExtrinsic& ext0,
                               Eigen::Matrix3d* J_pC, CameraPoint* cp) {
  const CameraPoint c = cameraPoint(anchor, ext0, p_W);
  const Eigen::Vector3d& p = c.p_C;
  const double iz = 1.0 / p.z();
  if (J_pC) {
    *J_pC << iz, 0.0, -p.x() * iz * iz, 0.0, iz, -p.y() * iz * iz, 0.0, 0.0, -iz * iz;
  }
  if (cp) *cp = c;
  return {p.x() * iz, p.y() * iz, iz};
}

PoseEstimate poseAfter(const PoseEstimate& pose, const Eigen::Vector3d& w, const Eigen::Vector3d& v, double dt) {
  PoseEstimate p;
  p.R_WI = pose.R_WI * so3::exp(w * dt);
  p.p_WI = pose.p_WI + v * dt;
  return p;
}

Eigen::Vector3d timeOffsetJacobian(const CameraPoint& cp, const Eigen::Vector3d& w, const Eigen::Vector3d& v) {
  return cp.J_pose.leftCols<3>() * w + cp.J_pose.rightCols<3>() * v;
}

}  // namespace gvins::vio
