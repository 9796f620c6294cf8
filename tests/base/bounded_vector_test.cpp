// SPDX-License-Identifier: MIT
#include "msgraphs/base/bounded_vector.hpp"

#include <gtest/gtest.h>

namespace msgraphs {
namespace {

TEST(BoundedVector, CapacityIsChosenAtInit) {
  BoundedVector<float> v;
  EXPECT_EQ(v.capacity(), 0u);
  EXPECT_FALSE(v.try_push_back(1.0F));
  v.Init(4);
  EXPECT_EQ(v.capacity(), 4u);
  EXPECT_EQ(v.rejected(), 0u);
  for (int i = 0; i < 6; ++i) static_cast<void>(v.try_push_back(static_cast<float>(i)));
  EXPECT_EQ(v.size(), 4u);
  EXPECT_EQ(v.rejected(), 2u);
  EXPECT_FLOAT_EQ(v[3], 3.0F);
}

TEST(BoundedVector, ReportsPeakAcrossClears) {
  BoundedVector<int> v(10);
  for (int i = 0; i < 7; ++i) v.push_back(i);
  v.clear();
  for (int i = 0; i < 3; ++i) v.push_back(i);
  EXPECT_EQ(v.size(), 3u);
  EXPECT_EQ(v.peak(), 7u);
  v.ResetPeak();
  EXPECT_EQ(v.peak(), 3u);
  v.resize_down(1);
  EXPECT_EQ(v.span().size(), 1u);
}

TEST(BoundedVectorDeathTest, PushBackOnFullIsAContractViolation) {
  BoundedVector<int> v(1);
  v.push_back(1);
  EXPECT_DEATH(v.push_back(2), "BoundedVector capacity exceeded");
}

}  // namespace
}  // namespace msgraphs
