// Estimate of one state block (vector, rotation or pose) and its boxplus / boxminus.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "gvins/sri/block.hpp"

namespace gvins::sri {

/// Value of a state block:
/// - kVector:   `vector` holds the `dim` entries, `rotation` is unused (identity);
/// - kRotation: `rotation` holds the unit quaternion, `vector` is empty;
/// - kPose:     `rotation` and `vector` = position (3 entries).
template <typename Scalar>
struct BlockEstimate {
  using Vector = Eigen::Matrix<Scalar, Eigen::Dynamic, 1>;
  using Quaternion = Eigen::Quaternion<Scalar>;

  Quaternion rotation = Quaternion::Identity();
  Vector vector;

  static BlockEstimate fromVector(const Vector& v) { return {Quaternion::Identity(), v}; }
  static BlockEstimate fromRotation(const Quaternion& q) { return {q.normalized(), Vector()}; }
  static BlockEstimate fromPose(const Quaternion& q, const Eigen::Matrix<Scalar, 3, 1>& p) {
    return {q.normalized(), Vector(p)};
  }
  /// Zero vector, identity rotation or identity pose for a block of the given kind.
  static BlockEstimate zero(BlockKind kind, int dim);
};

/// The same value in another scalar type (rounded when narrowing).
template <typename To, typename From>
BlockEstimate<To> castEstimate(const BlockEstimate<From>& e) {
  return {e.rotation.template cast<To>(), e.vector.template cast<To>()};
}

/// True if `value` has the shape required by a block of this kind and dimension.
template <typename Scalar>
bool hasShape(const BlockEstimate<Scalar>& value, BlockKind kind, int dim);

/// x ← x ⊞ δ with the block's convention (block.hpp): vector x + δ; rotation R̂·Exp(δθ) or
/// Exp(δθ)·R̂; pose: rotation as before, p + δp. `delta` has `info.dim` entries.
template <typename Scalar>
void boxplus(const BlockInfo& info, BlockEstimate<Scalar>& x,
             const Eigen::Ref<const Eigen::Matrix<Scalar, Eigen::Dynamic, 1>>& delta);

/// δ = a ⊟ b such that a = b ⊞ δ (rotation part via Log, principal branch).
template <typename Scalar>
Eigen::Matrix<Scalar, Eigen::Dynamic, 1> boxminus(const BlockInfo& info,
                                                  const BlockEstimate<Scalar>& a,
                                                  const BlockEstimate<Scalar>& b);

extern template struct BlockEstimate<float>;
extern template struct BlockEstimate<double>;

}  // namespace gvins::sri
