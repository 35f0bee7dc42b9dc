// Bookkeeping of state blocks: insertion anywhere, removal of the first/middle/last block,
// reordering, lookups, and the same edge cases through the filter (empty state, single block),
// checked against the covariance they must leave behind.
#include <gtest/gtest.h>

#include <stdexcept>
#include <vector>

#include "gvins/sri/sri_filter.hpp"
#include "gvins/sri/state_layout.hpp"

namespace gvins::sri {
namespace {

std::vector<int> offsets(const StateLayout& l) {
  std::vector<int> o;
  for (const BlockInfo& b : l.blocks()) o.push_back(b.offset);
  return o;
}

TEST(StateLayout, InsertEraseReorderAndLookups) {
  StateLayout l;
  EXPECT_TRUE(l.empty());
  EXPECT_EQ(l.dim(), 0);
  const BlockId a = l.insert(BlockSpec::vector("a", 3), 0);
  const BlockId c = l.insert(BlockSpec::pose("c"), 1);
  const BlockId b = l.insert(BlockSpec::rotation("b"), 1);  // between a and c
  const BlockId f = l.insert(BlockSpec::vector("f", 1), 0);  // front
  ASSERT_EQ(l.size(), 4);
  EXPECT_EQ(l.dim(), 1 + 3 + 3 + 6);
  EXPECT_EQ(offsets(l), (std::vector<int>{0, 1, 4, 7}));
  EXPECT_EQ(l.index(f), 0);
  EXPECT_EQ(l.index(a), 1);
  EXPECT_EQ(l.index(b), 2);
  EXPECT_EQ(l.index(c), 3);
  EXPECT_EQ(l.block(c).kind, BlockKind::kPose);
  EXPECT_EQ(l.block(b).dim, 3);
  EXPECT_EQ(l.findByName("b"), b);
  EXPECT_FALSE(l.findByName("zz").has_value());
  EXPECT_EQ(l.find(BlockId{999}), nullptr);
  EXPECT_THROW((void)l.index(BlockId{999}), std::out_of_range);
  // Ids are unique and never reused.
  EXPECT_NE(a, b);
  EXPECT_NE(b, c);
  // Placement resolution.
  EXPECT_EQ(l.resolve(Placement::front()), 0);
  EXPECT_EQ(l.resolve(Placement::back()), 4);
  EXPECT_EQ(l.resolve(Placement::before(b)), 2);
  EXPECT_EQ(l.resolve(Placement::after(b)), 3);
  // Erase middle, first, last.
  l.erase(b);
  EXPECT_EQ(offsets(l), (std::vector<int>{0, 1, 4}));
  l.erase(f);
  EXPECT_EQ(offsets(l), (std::vector<int>{0, 3}));
  EXPECT_EQ(l.index(c), 1);
  l.erase(c);
  EXPECT_EQ(l.size(), 1);
  EXPECT_EQ(l.dim(), 3);
  const BlockId d = l.insert(BlockSpec::vector("d", 2), 1);
  EXPECT_GT(d.value, c.value);
  // Reorder.
  const std::vector<BlockId> order{d, a};
  l.reorder(order);
  EXPECT_EQ(offsets(l), (std::vector<int>{0, 2}));
  EXPECT_EQ(l.index(a), 1);
  const std::vector<BlockId> bad{d};
  EXPECT_THROW(l.reorder(bad), std::invalid_argument);
  const std::vector<BlockId> twice{d, d};
  EXPECT_THROW(l.reorder(twice), std::invalid_argument);
  // Invalid specs.
  EXPECT_THROW(l.insert(BlockSpec::vector("x", 0), 0), std::invalid_argument);
  EXPECT_THROW(l.insert(BlockSpec{"r", BlockKind::kRotation, 4, RotationPerturbation::kRight}, 0),
               std::invalid_argument);
  EXPECT_THROW(l.insert(BlockSpec::vector("x", 1), 5), std::out_of_range);
  // Erase of several at once.
  const std::vector<BlockId> both{a, d};
  l.erase(both);
  EXPECT_TRUE(l.empty());
  EXPECT_EQ(l.dim(), 0);
}

// A filter with independent priors: marginalizing or reordering blocks must leave exactly the
// other blocks' priors (block-diagonal covariance), whatever the position.
// Ids count up from SriOptions::first_block_id and are never reused, also after marginalization;
// a filter that replaces another continues its numbering.
TEST(SriFilterBookkeeping, BlockIdsContinueAcrossFilters) {
  SriFilter<double> a;
  const auto mk = [](SriFilter<double>& f) {
    return f.addBlock(BlockSpec::vector("b", 1), BlockEstimate<double>::fromVector(Eigen::VectorXd::Zero(1)),
                      Prior<double>::stdDev(1, 1.0));
  };
  const BlockId a1 = mk(a);
  const BlockId a2 = mk(a);
  EXPECT_EQ(a1.value, 1u);
  EXPECT_EQ(a2.value, 2u);
  a.marginalize(a2);
  EXPECT_EQ(mk(a).value, 3u);  // not 2 again
  SriOptions o;
  o.first_block_id = a.nextBlockId();
  SriFilter<double> b(o);
  const BlockId b1 = mk(b);
  EXPECT_EQ(b1.value, 4u);
  EXPECT_FALSE(b.layout().contains(a1));
  EXPECT_EQ(StateLayout(7).nextId(), 7u);
}

TEST(SriFilterBookkeeping, RemoveFirstMiddleLastAndEmptyState) {
  SriFilter<double> f;
  EXPECT_EQ(f.dim(), 0);
  EXPECT_EQ(f.solve().size(), 0);
  EXPECT_EQ(f.fullCovariance().size(), 0);
  f.correct();  // no-op on an empty state
  std::vector<BlockId> ids;
  std::vector<double> sigma;
  for (int i = 0; i < 5; ++i) {
    sigma.push_back(1.0 + i);
    ids.push_back(f.addBlock(BlockSpec::vector("b", 2),
                             BlockEstimate<double>::fromVector(Eigen::Vector2d(i, -i)),
                             Prior<double>::stdDev(2, sigma.back())));
  }
  // Couple everything with one measurement so that marginalization is not trivial.
  Measurement<double> z(3);
  for (BlockId id : ids) z.jacobian(id, 2) = Eigen::MatrixXd::Random(3, 2);
  z.residual() = Eigen::Vector3d(0.1, -0.2, 0.3);
  z.whitenStdDev(0.5);
  f.update(z);
  const Eigen::MatrixXd P = f.fullCovariance();
  auto sub = [&](const std::vector<int>& keep) {
    std::vector<int> idx;
    for (int k : keep) {
      idx.push_back(2 * k);
      idx.push_back(2 * k + 1);
    }
    Eigen::MatrixXd S(idx.size(), idx.size());
    for (std::size_t a = 0; a < idx.size(); ++a) {
      for (std::size_t b = 0; b < idx.size(); ++b) S(a, b) = P(idx[a], idx[b]);
    }
    return S;
  };
  f.marginalize(ids[2]);  // middle
  EXPECT_LT((f.fullCovariance() - sub({0, 1, 3, 4})).norm(), 1e-12);
  f.marginalize(ids[0]);  // first
  EXPECT_LT((f.fullCovariance() - sub({1, 3, 4})).norm(), 1e-12);
  f.marginalize(ids[4]);  // last
  EXPECT_LT((f.fullCovariance() - sub({1, 3})).norm(), 1e-12);
  EXPECT_EQ(f.layout().size(), 2);
  EXPECT_EQ(f.estimate(ids[3]).vector, Eigen::Vector2d(3, -3));
  f.marginalize(ids[3]);  // single block left
  EXPECT_EQ(f.dim(), 2);
  EXPECT_LT((f.fullCovariance() - sub({1})).norm(), 1e-12);
  f.marginalize(ids[1]);  // empty again
  EXPECT_EQ(f.dim(), 0);
  EXPECT_TRUE(f.layout().empty());
  EXPECT_THROW(f.marginalize(ids[1]), std::out_of_range);
  // The filter is usable after being emptied.
  const BlockId g = f.addBlock(BlockSpec::vector("g", 1),
                               BlockEstimate<double>::fromVector(Eigen::VectorXd::Constant(1, 2.0)),
                               Prior<double>::stdDev(1, 3.0));
  EXPECT_NEAR(f.fullCovariance()(0, 0), 9.0, 1e-12);
  EXPECT_NEAR(f.covariance(std::vector<BlockId>{g})(0, 0), 9.0, 1e-12);
}

TEST(SriFilterBookkeeping, InsertionAnywhereKeepsTheOtherBlocks) {
  // Insert blocks at the front, in the middle and at the back of a coupled state, many times so
  // that storage is re-centred and grown; the covariance of the old blocks must not change and
  // the new blocks must be independent with their prior.
  SriFilter<double> f;
  std::vector<BlockId> ids;
  for (int i = 0; i < 3; ++i) {
    ids.push_back(f.addBlock(BlockSpec::vector("b", 3), BlockEstimate<double>::zero(BlockKind::kVector, 3),
                             Prior<double>::stdDev(3, 1.0)));
  }
  Measurement<double> z(4);
  for (BlockId id : ids) z.jacobian(id, 3) = Eigen::Matrix<double, 4, 3>::Random();
  z.whitenStdDev(0.3);
  f.update(z);
  const Eigen::MatrixXd P0 = f.fullCovariance();
  std::vector<BlockId> added;
  for (int round = 0; round < 40; ++round) {
    const int where = round % 3;
    const Placement p = where == 0 ? Placement::front()
                        : where == 1 ? Placement::after(ids[0])
                                     : Placement::back();
    added.push_back(f.addBlock(BlockSpec::vector("n", 2), BlockEstimate<double>::zero(BlockKind::kVector, 2),
                               Prior<double>::stdDev(2, 2.0), p));
  }
  EXPECT_EQ(f.dim(), 9 + 80);
  EXPECT_LT((f.covariance(ids) - P0).norm(), 1e-12);
  for (BlockId id : added) {
    const auto C = f.covariance(std::vector<BlockId>{id, ids[1]});
    EXPECT_LT((C.topLeftCorner(2, 2) - 4.0 * Eigen::Matrix2d::Identity()).norm(), 1e-12);
    EXPECT_LT(C.topRightCorner(2, 3).norm(), 1e-12);
  }
  // And removing them again (front, middle and back positions) restores the original state.
  f.marginalize(added);
  EXPECT_EQ(f.dim(), 9);
  EXPECT_LT((f.fullCovariance() - P0).norm(), 1e-12);
}

}  // namespace
}  // namespace gvins::sri
