// SPDX-License-Identifier: MIT
// The LiDAR thread's copy of a sweep into a scan slot: a slot reserved by SweepCapacity takes a
// sweep as large as the assembler can hold without allocating; a slot reserved for less keeps
// its capacity and counts what it left out, with what the assembler itself dropped.
#include <gtest/gtest.h>

#include <vector>

#include "alloc_counter.hpp"
#include "msgraphs/runtime/pipeline/sweep_copy.hpp"

namespace msgraphs::runtime {
namespace {

drivers::velodyne::Scan FullSweep(std::size_t points) {
  drivers::velodyne::Scan scan;
  scan.points.Init(points);
  for (std::size_t i = 0; i < points; ++i) {
    drivers::velodyne::VelodynePoint p;
    p.x_m = static_cast<float>(i);
    p.y_m = 1.0f;
    p.z_m = -0.5f;
    p.time_offset_ns = static_cast<std::uint32_t>(i * 1000u);
    EXPECT_TRUE(scan.points.try_push_back(p));
  }
  return scan;
}

TEST(SweepCopy, ASlotReservedForTheAssemblersCapacityTakesAFullSweepWithoutAllocating) {
  const drivers::velodyne::ScanAssemblerConfig assembler;
  // The mapper's default takes fewer points than the assembler holds: the slot must not.
  const std::size_t capacity = SweepCapacity(assembler, 60000);
  EXPECT_EQ(capacity, assembler.capacity_points);
  EXPECT_EQ(SweepCapacity(assembler, 100000), 100000u);
  const drivers::velodyne::Scan scan = FullSweep(assembler.capacity_points);
  std::vector<Eigen::Vector3f> points;
  std::vector<float> times;
  points.reserve(capacity);
  times.reserve(capacity);
  std::size_t cut = 1;
  {
    test::AllocationScope scope;
    for (int i = 0; i < 3; ++i) cut = CopySweep(scan, points, times);
    EXPECT_EQ(scope.allocations(), 0u);
  }
  EXPECT_EQ(cut, 0u);
  ASSERT_EQ(points.size(), assembler.capacity_points);
  ASSERT_EQ(times.size(), assembler.capacity_points);
  EXPECT_EQ(points[1234].x(), 1234.0f);
  EXPECT_FLOAT_EQ(times[1234], 1234e-6f);
}

TEST(SweepCopy, ASmallerSlotKeepsItsCapacityAndCountsWhatItLeftOut) {
  drivers::velodyne::Scan scan = FullSweep(5000);
  scan.dropped_points = 7;  // the assembler was full too
  std::vector<Eigen::Vector3f> points;
  std::vector<float> times;
  points.reserve(4000);
  times.reserve(4000);
  const std::size_t reserved = points.capacity();
  test::AllocationScope scope;
  const std::size_t cut = CopySweep(scan, points, times);
  EXPECT_EQ(scope.allocations(), 0u);
  EXPECT_EQ(points.capacity(), reserved);
  EXPECT_EQ(points.size(), reserved);
  EXPECT_EQ(cut, 5000u - reserved + 7u);
}

}  // namespace
}  // namespace msgraphs::runtime
