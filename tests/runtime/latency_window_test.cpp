// SPDX-License-Identifier: MIT
// The node's latency window: nearest-rank percentiles of the newest samples, and no allocation
// in Add or Percentile (the SLAM thread reads p50 and p99 after every keyframe).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>

#include "alloc_counter.hpp"
#include "msgraphs/runtime/pipeline/latency_window.hpp"

namespace msgraphs::runtime {
namespace {

TEST(LatencyWindow, NearestRankPercentilesOfTheNewestSamples) {
  LatencyWindow w(100);
  EXPECT_EQ(w.Percentile(0.5), 0.0) << "empty";
  // 1..100 ms in a scrambled order (37 is coprime with 100).
  for (int i = 0; i < 100; ++i) w.Add(static_cast<double>((i * 37) % 100 + 1));
  EXPECT_EQ(w.Percentile(0.5), 50.0);
  EXPECT_EQ(w.Percentile(0.99), 99.0);
  EXPECT_EQ(w.Percentile(1.0), 100.0);
  EXPECT_EQ(w.Percentile(0.0), 1.0);
  EXPECT_EQ(w.Percentile(-3.0), 1.0) << "clamped";
  EXPECT_EQ(w.Percentile(std::nan("")), 100.0) << "not a number: the largest";
  // 100 more samples of 1000 ms push every earlier one out.
  for (int i = 0; i < 100; ++i) w.Add(1000.0);
  EXPECT_EQ(w.Percentile(0.0), 1000.0);
  EXPECT_EQ(w.count(), 200u);
  // Half of them replaced by 2 ms: the median is the lower half's.
  for (int i = 0; i < 50; ++i) w.Add(2.0);
  EXPECT_EQ(w.Percentile(0.5), 2.0);
  EXPECT_EQ(w.Percentile(0.51), 1000.0);
}

TEST(LatencyWindow, AddAndPercentileAllocateNothing) {
  LatencyWindow w(4096);
  std::uint64_t allocations = 0;
  double sum = 0;
  {
    test::AllocationScope scope;
    for (int i = 0; i < 10000; ++i) {
      w.Add(static_cast<double>(i % 321));
      if (i % 100 == 0) sum += w.Percentile(0.5) + w.Percentile(0.99);
    }
    allocations = scope.allocations();
  }
  EXPECT_EQ(allocations, 0u);
  EXPECT_GT(sum, 0.0);
}

}  // namespace
}  // namespace msgraphs::runtime
