#include "gvins/sri/block_estimate.hpp"

#include <stdexcept>

#include "gvins/sri/so3.hpp"

namespace gvins::sri {

template <typename Scalar>
BlockEstimate<Scalar> BlockEstimate<Scalar>::zero(BlockKind kind, int dim) {
  switch (kind) {
    case BlockKind::kVector:
      return {Quaternion::Identity(), Vector::Zero(dim)};
    case BlockKind::kRotation:
      return {Quaternion::Identity(), Vector()};
    case BlockKind::kPose:
      return {Quaternion::Identity(), Vector::Zero(3)};
  }
  return {};
}

template <typename Scalar>
bool hasShape(const BlockEstimate<Scalar>& value, BlockKind kind, int dim) {
  switch (kind) {
    case BlockKind::kVector:
      return dim > 0 && value.vector.size() == dim;
    case BlockKind::kRotation:
      return dim == 3 && value.vector.size() == 0;
    case BlockKind::kPose:
      return dim == 6 && value.vector.size() == 3;
  }
  return false;
}

namespace {

template <typename Scalar>
void perturbRotation(RotationPerturbation p, Eigen::Quaternion<Scalar>& q,
                     const Eigen::Matrix<Scalar, 3, 1>& dtheta) {
  const Eigen::Quaternion<Scalar> dq = so3::expQuaternion<Scalar>(dtheta);
  q = (p == RotationPerturbation::kRight) ? (q * dq) : (dq * q);
  q.normalize();
}

template <typename Scalar>
Eigen::Matrix<Scalar, 3, 1> rotationDifference(RotationPerturbation p,
                                               const Eigen::Quaternion<Scalar>& a,
                                               const Eigen::Quaternion<Scalar>& b) {
  // a = b·Exp(δ) → δ = Log(b⁻¹ a);  a = Exp(δ)·b → δ = Log(a b⁻¹).
  return (p == RotationPerturbation::kRight) ? so3::log<Scalar>(b.conjugate() * a)
                                             : so3::log<Scalar>(a * b.conjugate());
}

}  // namespace

template <typename Scalar>
void boxplus(const BlockInfo& info, BlockEstimate<Scalar>& x,
             const Eigen::Ref<const Eigen::Matrix<Scalar, Eigen::Dynamic, 1>>& delta) {
  if (delta.size() != info.dim || !hasShape(x, info.kind, info.dim)) {
    throw std::invalid_argument("sri::boxplus: size mismatch for block '" + info.name + "'");
  }
  switch (info.kind) {
    case BlockKind::kVector:
      x.vector += delta;
      break;
    case BlockKind::kRotation:
      perturbRotation<Scalar>(info.perturbation, x.rotation, delta.template head<3>());
      break;
    case BlockKind::kPose:
      perturbRotation<Scalar>(info.perturbation, x.rotation, delta.template head<3>());
      x.vector += delta.template tail<3>();
      break;
  }
}

template <typename Scalar>
Eigen::Matrix<Scalar, Eigen::Dynamic, 1> boxminus(const BlockInfo& info,
                                                  const BlockEstimate<Scalar>& a,
                                                  const BlockEstimate<Scalar>& b) {
  if (!hasShape(a, info.kind, info.dim) || !hasShape(b, info.kind, info.dim)) {
    throw std::invalid_argument("sri::boxminus: size mismatch for block '" + info.name + "'");
  }
  Eigen::Matrix<Scalar, Eigen::Dynamic, 1> d(info.dim);
  switch (info.kind) {
    case BlockKind::kVector:
      d = a.vector - b.vector;
      break;
    case BlockKind::kRotation:
      d.template head<3>() = rotationDifference<Scalar>(info.perturbation, a.rotation, b.rotation);
      break;
    case BlockKind::kPose:
      d.template head<3>() = rotationDifference<Scalar>(info.perturbation, a.rotation, b.rotation);
      d.template tail<3>() = a.vector - b.vector;
      break;
  }
  return d;
}

#define GVINS_SRI_INSTANTIATE(S)                                                              \
  template struct BlockEstimate<S>;                                                           \
  template bool hasShape<S>(const BlockEstimate<S>&, BlockKind, int);                         \
  template void boxplus<S>(const BlockInfo&, BlockEstimate<S>&,                               \
                           const Eigen::Ref<const Eigen::Matrix<S, Eigen::Dynamic, 1>>&);     \
  template Eigen::Matrix<S, Eigen::Dynamic, 1> boxminus<S>(const BlockInfo&,                  \
                                                           const BlockEstimate<S>&,           \
                                                           const BlockEstimate<S>&);
GVINS_SRI_INSTANTIATE(float)
GVINS_SRI_INSTANTIATE(double)
#undef GVINS_SRI_INSTANTIATE

}  // namespace gvins::sri
