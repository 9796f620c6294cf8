// SPDX-License-Identifier: MIT
#include "msgraphs/base/fixed_vector.hpp"

#include <gtest/gtest.h>

#include <string>

namespace msgraphs {
namespace {

// Counts live instances so construct/destroy balance can be checked.
struct Tracked {
  static inline int live = 0;
  int v = 0;
  explicit Tracked(int x) : v(x) { ++live; }
  Tracked(const Tracked& o) : v(o.v) { ++live; }
  Tracked& operator=(const Tracked&) = default;
  ~Tracked() { --live; }
};

TEST(FixedVector, PushUntilFullThenRejects) {
  FixedVector<int, 3> v;
  EXPECT_TRUE(v.try_push_back(1));
  EXPECT_TRUE(v.try_push_back(2));
  EXPECT_TRUE(v.try_push_back(3));
  EXPECT_TRUE(v.full());
  EXPECT_FALSE(v.try_push_back(4));
  EXPECT_EQ(v.size(), 3u);
  EXPECT_EQ(v[2], 3);
  int sum = 0;
  for (int x : v) sum += x;
  EXPECT_EQ(sum, 6);
}

TEST(FixedVector, ConstructsAndDestroysEveryElement) {
  {
    FixedVector<Tracked, 8> v;
    for (int i = 0; i < 5; ++i) v.emplace_back(i);
    EXPECT_EQ(Tracked::live, 5);
    FixedVector<Tracked, 8> copy = v;
    EXPECT_EQ(Tracked::live, 10);
    copy.pop_back();
    EXPECT_EQ(Tracked::live, 9);
    EXPECT_EQ(copy.back().v, 3);
  }
  EXPECT_EQ(Tracked::live, 0);
}

TEST(FixedVector, HoldsNonTrivialTypes) {
  FixedVector<std::string, 2> v;
  v.push_back("wall");
  v.emplace_back("room");
  EXPECT_EQ(v[1], "room");
  v.clear();
  EXPECT_TRUE(v.empty());
}

TEST(FixedVectorDeathTest, PushBackOnFullIsAContractViolation) {
  FixedVector<int, 1> v;
  v.push_back(1);
  EXPECT_DEATH(v.push_back(2), "FixedVector capacity exceeded");
}

}  // namespace
}  // namespace msgraphs
