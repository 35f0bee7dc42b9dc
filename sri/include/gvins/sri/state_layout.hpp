// Bookkeeping of the ordered state blocks: ids, names, dimensions, column offsets.
//
// The order of the blocks is the column order of the square-root information matrix R. It is
// also the elimination order: blocks in front are cheap to marginalize (a prefix is dropped for
// free), blocks at the back are cheap to touch with measurements and to ask a covariance of.
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <string_view>
#include <unordered_map>
#include <vector>

#include "gvins/sri/block.hpp"

namespace gvins::sri {

/// Where a new block goes in the order.
struct Placement {
  enum class Where : std::uint8_t { kBack, kFront, kBefore, kAfter };
  Where where = Where::kBack;
  BlockId anchor;  ///< For kBefore / kAfter.

  static Placement back() { return {Where::kBack, {}}; }
  static Placement front() { return {Where::kFront, {}}; }
  static Placement before(BlockId id) { return {Where::kBefore, id}; }
  static Placement after(BlockId id) { return {Where::kAfter, id}; }
};

class StateLayout {
 public:
  /// Ids of inserted blocks are first_id, first_id + 1, ... (never reused).
  explicit StateLayout(std::uint64_t first_id = 1) : next_id_(first_id) {}
  /// The id the next inserted block gets.
  std::uint64_t nextId() const { return next_id_; }
  /// Number of blocks and total error-state dimension.
  int size() const { return static_cast<int>(blocks_.size()); }
  int dim() const { return dim_; }
  bool empty() const { return blocks_.empty(); }

  /// Blocks in order (offsets are current).
  const std::vector<BlockInfo>& blocks() const { return blocks_; }
  const BlockInfo& at(int index) const { return blocks_.at(static_cast<std::size_t>(index)); }

  bool contains(BlockId id) const { return index_.count(id) != 0; }
  /// Position of the block in the order; throws std::out_of_range for an unknown id.
  int index(BlockId id) const;
  /// Throws std::out_of_range for an unknown id.
  const BlockInfo& block(BlockId id) const { return blocks_[static_cast<std::size_t>(index(id))]; }
  /// nullptr for an unknown id.
  const BlockInfo* find(BlockId id) const;
  /// First block with this name in the order (linear search).
  std::optional<BlockId> findByName(std::string_view name) const;

  /// Position (index in the order) a placement resolves to. Throws std::out_of_range for an
  /// unknown anchor.
  int resolve(const Placement& where) const;

  /// Inserts a block before position `index` (0 = front, size() = back) and returns its new id.
  /// Throws std::invalid_argument for an inconsistent spec (dim ≤ 0, rotation dim ≠ 3, pose ≠ 6).
  BlockId insert(const BlockSpec& spec, int index);
  /// Removes a block (bookkeeping only). Throws std::out_of_range for an unknown id.
  void erase(BlockId id);
  /// Removes several blocks at once (one re-indexing pass).
  void erase(std::span<const BlockId> ids);
  /// Reorders the blocks; `order` must list every block exactly once (std::invalid_argument
  /// otherwise).
  void reorder(std::span<const BlockId> order);

  /// Validates a spec as insert() does.
  static void validate(const BlockSpec& spec);

 private:
  void reindex(int from);

  std::vector<BlockInfo> blocks_;
  std::unordered_map<BlockId, int> index_;
  std::uint64_t next_id_ = 1;
  int dim_ = 0;
};

}  // namespace gvins::sri
