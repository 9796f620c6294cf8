// SPDX-License-Identifier: MIT
// The scan-matching fitness gate: the floor until the robot has its own figures, then the upper
// outlier bound of its recent accepted fitnesses where that is higher; bad input ignored and
// counted; bad config refused; Add and Limit allocate nothing.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "alloc_counter.hpp"
#include "msgraphs/core/slam/fitness_gate.hpp"

namespace msgraphs::core {
namespace {

FitnessGate Gate(FitnessGateConfig config = {}) {
  FitnessGate g;
  EXPECT_TRUE(g.Init(config));
  return g;
}

TEST(FitnessGate, TheFloorHoldsUntilTheRobotHasItsOwnFigures) {
  FitnessGate g = Gate();
  EXPECT_DOUBLE_EQ(g.Limit(), 0.05);
  for (int i = 0; i < 9; ++i) g.Add(0.09 + 0.001 * i);  // high, but too few to say so
  EXPECT_DOUBLE_EQ(g.Limit(), 0.05);
}

TEST(FitnessGate, AQuietBuildingKeepsTheFloor) {
  FitnessGate g = Gate();
  for (int i = 0; i < 100; ++i) g.Add(0.010 + 0.0001 * (i % 20));  // median 0.011, MAD 0.0005
  EXPECT_DOUBLE_EQ(g.Limit(), 0.05);
}

TEST(FitnessGate, AnOpenBuildingWidensTheLimitToItsOwnOutlierBound) {
  FitnessGate g = Gate();
  // Fitnesses 0.040, 0.041, ..., 0.060 (twice, and the middle once more): median 0.050, MAD 0.005.
  for (int k = 0; k < 2; ++k)
    for (int i = 0; i <= 20; ++i) g.Add(0.040 + 0.001 * i);
  g.Add(0.050);
  const double expected = 0.050 + 3.5 * 1.4826 * 0.005;  // 0.0759
  EXPECT_NEAR(g.Limit(), expected, 1e-12);
  // A match fitting three times worse than this robot's matches do is still refused.
  EXPECT_LT(g.Limit(), 0.15);
}

TEST(FitnessGate, TheWindowForgetsTheOldBuilding) {
  FitnessGateConfig c;
  c.window = 20;
  FitnessGate g = Gate(c);
  for (int i = 0; i < 20; ++i) g.Add(0.08 + 0.002 * (i % 5));  // an open hall
  EXPECT_GT(g.Limit(), 0.08);
  for (int i = 0; i < 20; ++i) g.Add(0.01);  // back in small rooms: the hall is forgotten
  EXPECT_DOUBLE_EQ(g.Limit(), 0.05);
  EXPECT_EQ(g.samples(), 20u);
}

TEST(FitnessGate, BadFitnessIsIgnoredAndCounted) {
  FitnessGate g = Gate();
  g.Add(std::numeric_limits<double>::quiet_NaN());
  g.Add(std::numeric_limits<double>::infinity());
  g.Add(-0.01);
  EXPECT_EQ(g.ignored(), 3u);
  EXPECT_EQ(g.samples(), 0u);
  EXPECT_DOUBLE_EQ(g.Limit(), 0.05);
}

TEST(FitnessGate, BadConfigIsRefused) {
  FitnessGate g;
  FitnessGateConfig c;
  c.floor_m2 = 0;
  EXPECT_EQ(g.Init(c).error().code, Errc::kInvalidArgument);
  c = {};
  c.floor_m2 = std::numeric_limits<double>::quiet_NaN();
  EXPECT_FALSE(g.Init(c));
  c = {};
  c.window = 5;  // below min_samples
  EXPECT_FALSE(g.Init(c));
  c = {};
  c.outlier_z = -1;
  EXPECT_FALSE(g.Init(c));
  c = {};
  c.outlier_z = 0;  // the floor alone
  ASSERT_TRUE(g.Init(c));
  for (int i = 0; i < 50; ++i) g.Add(0.09);
  EXPECT_DOUBLE_EQ(g.Limit(), 0.05);
}

TEST(FitnessGate, AddAndLimitAllocateNothing) {
  FitnessGate g = Gate();
  test::AllocationScope scope;
  double sum = 0;
  for (int i = 0; i < 1000; ++i) {
    g.Add(0.02 + 0.0001 * (i % 97));
    sum += g.Limit();
  }
  EXPECT_EQ(scope.allocations(), 0u);
  EXPECT_GT(sum, 0);
}

}  // namespace
}  // namespace msgraphs::core
