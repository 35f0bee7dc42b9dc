#include "gvins/sri/state_layout.hpp"

#include <algorithm>
#include <stdexcept>
#include <string>

namespace gvins::sri {

int StateLayout::index(BlockId id) const {
  const auto it = index_.find(id);
  if (it == index_.end()) {
    throw std::out_of_range("sri::StateLayout: unknown block id " + std::to_string(id.value));
  }
  return it->second;
}

const BlockInfo* StateLayout::find(BlockId id) const {
  const auto it = index_.find(id);
  return it == index_.end() ? nullptr : &blocks_[static_cast<std::size_t>(it->second)];
}

std::optional<BlockId> StateLayout::findByName(std::string_view name) const {
  for (const BlockInfo& b : blocks_) {
    if (b.name == name) return b.id;
  }
  return std::nullopt;
}

int StateLayout::resolve(const Placement& where) const {
  switch (where.where) {
    case Placement::Where::kBack:
      return size();
    case Placement::Where::kFront:
      return 0;
    case Placement::Where::kBefore:
      return index(where.anchor);
    case Placement::Where::kAfter:
      return index(where.anchor) + 1;
  }
  return size();
}

void StateLayout::validate(const BlockSpec& spec) {
  const bool ok = (spec.kind == BlockKind::kVector && spec.dim > 0) ||
                  (spec.kind == BlockKind::kRotation && spec.dim == 3) ||
                  (spec.kind == BlockKind::kPose && spec.dim == 6);
  if (!ok) {
    throw std::invalid_argument("sri::StateLayout: inconsistent dimension " +
                                std::to_string(spec.dim) + " for block '" + spec.name + "'");
  }
}

BlockId StateLayout::insert(const BlockSpec& spec, int index) {
  validate(spec);
  if (index < 0 || index > size()) {
    throw std::out_of_range("sri::StateLayout::insert: position out of range");
  }
  BlockInfo info;
  info.id = BlockId{next_id_++};
  info.name = spec.name;
  info.kind = spec.kind;
  info.dim = spec.dim;
  info.perturbation = spec.perturbation;
  blocks_.insert(blocks_.begin() + index, std::move(info));
  dim_ += spec.dim;
  reindex(index);
  return blocks_[static_cast<std::size_t>(index)].id;
}

void StateLayout::erase(BlockId id) {
  const int i = index(id);
  dim_ -= blocks_[static_cast<std::size_t>(i)].dim;
  index_.erase(id);
  blocks_.erase(blocks_.begin() + i);
  reindex(i);
}

void StateLayout::erase(std::span<const BlockId> ids) {
  if (ids.empty()) return;
  int first = size();
  for (BlockId id : ids) first = std::min(first, index(id));
  for (BlockId id : ids) {
    const auto it = index_.find(id);
    if (it == index_.end()) continue;  // listed twice
    dim_ -= blocks_[static_cast<std::size_t>(it->second)].dim;
    blocks_[static_cast<std::size_t>(it->second)].id = BlockId{};  // mark
    index_.erase(it);
  }
  blocks_.erase(std::remove_if(blocks_.begin(), blocks_.end(),
                               [](const BlockInfo& b) { return !b.id.valid(); }),
                blocks_.end());
  reindex(first);
}

void StateLayout::reorder(std::span<const BlockId> order) {
  if (static_cast<int>(order.size()) != size()) {
    throw std::invalid_argument("sri::StateLayout::reorder: order must list every block once");
  }
  std::vector<BlockInfo> next;
  next.reserve(blocks_.size());
  std::vector<char> seen(blocks_.size(), 0);
  for (BlockId id : order) {
    const int i = index(id);
    if (seen[static_cast<std::size_t>(i)]) {
      throw std::invalid_argument("sri::StateLayout::reorder: block listed twice");
    }
    seen[static_cast<std::size_t>(i)] = 1;
    next.push_back(blocks_[static_cast<std::size_t>(i)]);
  }
  blocks_ = std::move(next);
  reindex(0);
}

void StateLayout::reindex(int from) {
  int offset = 0;
  if (from > 0 && from <= size()) {
    const BlockInfo& prev = blocks_[static_cast<std::size_t>(from - 1)];
    offset = prev.offset + prev.dim;
  } else {
    from = 0;
  }
  for (int i = from; i < size(); ++i) {
    BlockInfo& b = blocks_[static_cast<std::size_t>(i)];
    b.offset = offset;
    offset += b.dim;
    index_[b.id] = i;
  }
}

}  // namespace gvins::sri
