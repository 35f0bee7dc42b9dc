// Named state blocks of the square-root inverse (SRI) estimator: identifiers, kinds and the
// error-state (perturbation) convention of rotations.
#pragma once

#include <compare>
#include <cstdint>
#include <functional>
#include <string>
#include <utility>

namespace gvins::sri {

/// Opaque, never reused handle of a state block. Default-constructed ids are invalid.
struct BlockId {
  std::uint64_t value = 0;
  constexpr bool valid() const { return value != 0; }
  friend constexpr auto operator<=>(BlockId, BlockId) = default;
};

/// What a block's estimate is and how its error state is defined.
enum class BlockKind : std::uint8_t {
  kVector,    ///< Euclidean vector of `dim` entries; x = x̂ + δx.
  kRotation,  ///< SO(3) rotation, error state δθ ∈ R³ (see RotationPerturbation).
  kPose,      ///< SO(3) × R³ (rotation then position), error state [δθ; δp] ∈ R⁶, p = p̂ + δp.
};

/// Perturbation convention of the rotation part of kRotation and kPose blocks. It is a property
/// of each block, fixed when the block is created. Exp is the SO(3) exponential (Rodrigues).
enum class RotationPerturbation : std::uint8_t {
  kRight,  ///< R = R̂ · Exp(δθ): δθ expressed in the rotated (body) frame. Default.
  kLeft,   ///< R = Exp(δθ) · R̂: δθ expressed in the reference (world) frame.
};

/// Description of a block to create. Use the factory functions.
struct BlockSpec {
  std::string name;  ///< Free text for logs and lookups; need not be unique, may be empty.
  BlockKind kind = BlockKind::kVector;
  int dim = 0;  ///< Error-state dimension: `n` for kVector, 3 for kRotation, 6 for kPose.
  RotationPerturbation perturbation = RotationPerturbation::kRight;

  static BlockSpec vector(std::string name, int dim) {
    return {std::move(name), BlockKind::kVector, dim, RotationPerturbation::kRight};
  }
  static BlockSpec rotation(std::string name,
                            RotationPerturbation p = RotationPerturbation::kRight) {
    return {std::move(name), BlockKind::kRotation, 3, p};
  }
  static BlockSpec pose(std::string name, RotationPerturbation p = RotationPerturbation::kRight) {
    return {std::move(name), BlockKind::kPose, 6, p};
  }
};

/// A block as placed in the current state: its spec plus id and column offset.
struct BlockInfo {
  BlockId id;
  std::string name;
  BlockKind kind = BlockKind::kVector;
  int dim = 0;
  RotationPerturbation perturbation = RotationPerturbation::kRight;
  int offset = 0;  ///< First error-state column of the block in the current order.
};

}  // namespace gvins::sri

template <>
struct std::hash<gvins::sri::BlockId> {
  std::size_t operator()(gvins::sri::BlockId id) const noexcept {
    return std::hash<std::uint64_t>{}(id.value);
  }
};
