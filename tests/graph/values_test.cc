// Keys, Values and FactorGraph bookkeeping: packing round trips, layout, fixed flags, stable
// factor indices.
#include "kinograph/graph/values.h"

#include <gtest/gtest.h>

#include <unordered_set>

#include "kinograph/graph/factor_graph.h"
#include "kinograph/graph/prior_factor.h"

namespace kinograph::graph {
namespace {

TEST(Key, PacksAndUnpacksEveryField) {
  const Key k('q', 12345, 4000000000u);
  EXPECT_EQ(k.kind(), 'q');
  EXPECT_EQ(k.index(), 12345u);
  EXPECT_EQ(k.step(), 4000000000u);
  EXPECT_EQ(Key::from_id(k.id()), k);
  EXPECT_EQ(k.to_string(), "q(12345,4000000000)");
  EXPECT_THROW(Key('q', Key::kMaxIndex + 1, 0), std::invalid_argument);
}

TEST(Key, DistinctFieldsGiveDistinctKeys) {
  std::unordered_set<Key> keys;
  for (char kind : {'q', 'v', 'a', 't'}) {
    for (uint32_t i = 0; i < 7; ++i) {
      for (uint32_t s = 0; s < 50; ++s) keys.insert(Key(kind, i, s));
    }
  }
  EXPECT_EQ(keys.size(), 4u * 7u * 50u);
  EXPECT_LT(Key('a', 9, 9), Key('q', 0, 0));  // kind is the most significant field
}

TEST(Values, ContiguousLayoutAndViews) {
  Values v;
  v.insert(Key('a', 0, 0), Eigen::Vector2d(1, 2));
  v.insert(Key('b', 0, 0), Eigen::Vector3d(3, 4, 5));
  EXPECT_EQ(v.size(), 2);
  EXPECT_EQ(v.total_dim(), 5);
  EXPECT_EQ(v.offset(1), 2);
  EXPECT_EQ(v.vector(), (Eigen::VectorXd(5) << 1, 2, 3, 4, 5).finished());
  v.at(Key('b', 0, 0))[1] = 40;
  EXPECT_EQ(v.vector()[3], 40);
  EXPECT_THROW(v.insert(Key('a', 0, 0), Eigen::Vector2d(0, 0)), std::invalid_argument);
  EXPECT_THROW(v.at(Key('c', 0, 0)), std::out_of_range);
  EXPECT_THROW(v.update(Key('a', 0, 0), Eigen::Vector3d::Zero()), std::invalid_argument);
  EXPECT_EQ(v.find(Key('c', 0, 0)), -1);
}

TEST(Values, RetractSkipsFixedVariablesAndFixingChangesLayoutId) {
  Values v;
  v.insert(Key('a', 0, 0), Eigen::Vector2d(1, 2));
  v.insert(Key('b', 0, 0), Eigen::Vector2d(3, 4));
  const uint64_t id = v.layout_id();
  v.set_fixed(Key('a', 0, 0));
  EXPECT_NE(v.layout_id(), id);
  v.retract(Eigen::Vector4d(10, 10, 10, 10));
  EXPECT_EQ(v.vector(), Eigen::Vector4d(1, 2, 13, 14));
  const uint64_t id2 = v.layout_id();
  v.update(Key('b', 0, 0), Eigen::Vector2d(0, 0));  // values change, layout does not
  EXPECT_EQ(v.layout_id(), id2);
  Values copy = v;
  EXPECT_EQ(copy.layout_id(), id2);
}

TEST(FactorGraph, RemovedSlotsStayEmptyAndIndicesStable) {
  FactorGraph g;
  const size_t i0 = g.add(std::make_shared<PriorFactor>(Key('x', 0, 0), Eigen::Vector2d(1, 1)));
  const size_t i1 = g.add(std::make_shared<PriorFactor>(Key('x', 0, 1), Eigen::Vector2d(2, 2)));
  const size_t i2 = g.add(std::make_shared<PriorFactor>(Key('x', 0, 2), Eigen::Vector2d(3, 3)));
  const uint64_t id = g.structure_id();
  g.remove(i1);
  EXPECT_NE(g.structure_id(), id);
  EXPECT_EQ(g.size(), 3u);
  EXPECT_EQ(g.num_factors(), 2u);
  EXPECT_EQ(g[i1], nullptr);
  EXPECT_EQ(g[i0]->keys()[0], Key('x', 0, 0));
  EXPECT_EQ(g[i2]->keys()[0], Key('x', 0, 2));
  EXPECT_THROW(g.remove(7), std::out_of_range);

  Values v;
  for (uint32_t k = 0; k < 3; ++k) v.insert(Key('x', 0, k), Eigen::Vector2d::Zero());
  EXPECT_DOUBLE_EQ(g.error(v), 0.5 * (2 + 18));  // removed factor no longer counts
}

}  // namespace
}  // namespace kinograph::graph
