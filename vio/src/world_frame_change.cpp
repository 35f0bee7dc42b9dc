#include "gvins/vio/world_frame_change.hpp"

#include <stdexcept>
#include <utility>
#include <vector>

#include <Eigen/Geometry>

#include "gvins/vio/so3.hpp"

namespace gvins::vio {

WorldFrameChange WorldFrameChange::fromVector(const Eigen::Vector4d& v) {
  WorldFrameChange c;
  c.yaw = v[0];
  c.t = v.tail<3>();
  return c;
}

Eigen::Matrix3d WorldFrameChange::rotation() const {
  return Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
}

WorldFrameChange WorldFrameChange::inverse() const {
  WorldFrameChange c;
  c.yaw = -yaw;
  c.t = -(rotation().transpose() * t);
  return c;
}

template <typename Scalar>
WorldFrameChange reanchorWorld(sri::SriFilter<Scalar>& f, sri::BlockId frame, std::span<const ReanchoredPose> poses,
                               std::span<const ReanchoredVelocity> velocities) {
  using Matrix = Eigen::Matrix<Scalar, Eigen::Dynamic, Eigen::Dynamic>;
  const sri::BlockInfo& fb = f.layout().block(frame);
  if (fb.kind != sri::BlockKind::kVector || fb.dim != 4) {
    throw std::invalid_argument("vio::reanchorWorld: block '" + fb.name + "' is not a 4-vector [yaw; t]");
  }
  const WorldFrameChange c = WorldFrameChange::fromVector(f.nominal(frame).vector);
  const Eigen::Matrix3d Rz = c.rotation();
  const Eigen::Matrix3d dRz = so3::skew(Eigen::Vector3d::UnitZ()) * Rz;  // ∂Rz/∂ψ
  // substitute() needs the frame after every block it enters: put it last.
  if (f.layout().blocks().back().id != frame) {
    std::vector<sri::BlockId> order;
    for (const sri::BlockInfo& b : f.layout().blocks()) {
      if (b.id != frame) order.push_back(b.id);
    }
    order.push_back(frame);
    f.reorder(order);
  }
  for (const ReanchoredPose& rp : poses) {
    const sri::BlockId id = rp.id;
    const sri::BlockInfo& b = f.layout().block(id);
    if (b.kind != sri::BlockKind::kPose) {
      throw std::invalid_argument("vio::reanchorWorld: block '" + b.name + "' is not a pose");
    }
    const sri::BlockEstimate<double> x = f.nominal(id);
    const Eigen::Matrix3d R = x.rotation.toRotationMatrix();
    const Eigen::Vector3d p = x.vector;
    // R' = Rz(ψ) R, p' = Rz(ψ) p + t. Right perturbation R = R̂ Exp(δθ):
    // Rz(ψ + δψ) R̂ Exp(δθ) = R̂' Exp(δθ + R̂ᵀ e_z δψ); left, Exp(δθ) R̂: Exp(Rz δθ + e_z δψ) R̂'.
    // δp' = Rz δp + (∂Rz/∂ψ) p̂ δψ + δt. R̂, p̂ in B: the linearization values.
    const Eigen::Matrix3d& Rl = rp.R_lin ? *rp.R_lin : R;
    const Eigen::Vector3d& pl = rp.p_lin ? *rp.p_lin : p;
    Eigen::Matrix<double, 6, 6> A = Eigen::Matrix<double, 6, 6>::Identity();
    Eigen::Matrix<double, 6, 4> B = Eigen::Matrix<double, 6, 4>::Zero();
    if (b.perturbation == sri::RotationPerturbation::kRight) {
      B.block<3, 1>(0, 0) = Rl.transpose() * Eigen::Vector3d::UnitZ();
    } else {
      A.topLeftCorner<3, 3>() = Rz;
      B.block<3, 1>(0, 0) = Eigen::Vector3d::UnitZ();
    }
    A.bottomRightCorner<3, 3>() = Rz;
    B.block<3, 1>(3, 0) = dRz * pl;
    B.block<3, 3>(3, 1).setIdentity();
    const sri::BlockEstimate<double> next =
        sri::BlockEstimate<double>::fromPose(Eigen::Quaterniond(Rz * R).normalized(), Rz * p + c.t);
    const std::vector<std::pair<sri::BlockId, Matrix>> Bs = {{frame, B.cast<Scalar>()}};
    f.substitute(id, A.cast<Scalar>(), Bs, next);
  }
  for (const ReanchoredVelocity& rv : velocities) {
    const sri::BlockId id = rv.id;
    const sri::BlockInfo& b = f.layout().block(id);
    if (b.kind != sri::BlockKind::kVector || b.dim < 3) {
      throw std::invalid_argument("vio::reanchorWorld: block '" + b.name + "' is not a vector starting with a velocity");
    }
    sri::BlockEstimate<double> next = f.nominal(id);
    const Eigen::Vector3d v = next.vector.head<3>();
    next.vector.head<3>() = Rz * v;
    // v' = Rz(ψ) v: δv' = Rz δv + (∂Rz/∂ψ) v̂ δψ.
    Matrix A = Matrix::Identity(b.dim, b.dim);
    A.template topLeftCorner<3, 3>() = Rz.cast<Scalar>();
    Matrix B = Matrix::Zero(b.dim, 4);
    B.template block<3, 1>(0, 0) = (dRz * (rv.v_lin ? *rv.v_lin : v)).cast<Scalar>();
    const std::vector<std::pair<sri::BlockId, Matrix>> Bs = {{frame, B}};
    f.substitute(id, A, Bs, next);
  }
  f.marginalize(frame);
  return c;
}

template WorldFrameChange reanchorWorld<float>(sri::SriFilter<float>&, sri::BlockId, std::span<const ReanchoredPose>,
                                               std::span<const ReanchoredVelocity>);
template WorldFrameChange reanchorWorld<double>(sri::SriFilter<double>&, sri::BlockId, std::span<const ReanchoredPose>,
                                                std::span<const ReanchoredVelocity>);

}  // namespace gvins::vio
