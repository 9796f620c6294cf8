// SPDX-License-Identifier: MIT
// The local solve's window problem (s_graph_solve.cpp): it moves the newest keyframes and what
// they see, nothing older, and what it hands to Ceres follows the window, not the graph: a
// robot walking down a row of rooms gives the same window at 100 keyframes as at 600.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "msgraphs/core/geometry/se3.hpp"
#include "msgraphs/core/graph/s_graph.hpp"
#include "s_graph_fixtures.hpp"

namespace msgraphs::core {
namespace {

using namespace sgraph_test;  // NOLINT(google-build-using-namespace): test fixtures

TEST(SGraphWindow, ALocalSolveMovesOnlyItsWindowAndWhatItSees) {
  SGraphConfig config;
  config.local_window_keyframes = 10;
  RoomRow row(config);
  for (int i = 0; i < 60; ++i) {
    ASSERT_NO_FATAL_FAILURE(row.Step());
    if (i < 59) {
      ASSERT_TRUE(row.graph.Solve(SolveKind::kLocal));
    }
  }
  std::vector<Eigen::Isometry3d> before;
  for (std::uint32_t id : row.ids) before.push_back(row.graph.keyframe_pose(id));
  std::vector<MapPlane> planes_before;
  for (std::size_t p = 0; p < row.graph.plane_slots(); ++p)
    planes_before.push_back(row.graph.plane(static_cast<std::uint32_t>(p)));
  auto report = row.graph.Solve(SolveKind::kLocal);
  ASSERT_TRUE(report);
  EXPECT_TRUE(report->usable);
  EXPECT_EQ(report->free_keyframes, 10u);
  // Everything older than the window is exactly where it was; the window moved.
  for (std::size_t i = 0; i + 10 < row.ids.size(); ++i)
    EXPECT_TRUE(row.graph.keyframe_pose(row.ids[i]).isApprox(before[i], 0.0)) << i;
  double moved_m = 0;
  for (std::size_t i = row.ids.size() - 10; i < row.ids.size(); ++i) {
    moved_m = std::max(
        moved_m, (row.graph.keyframe_pose(row.ids[i]).translation() - before[i].translation()).norm());
  }
  EXPECT_GT(moved_m, 1e-4);
  // The walls of rooms left behind (newest observer older than the window) and the floor (held
  // in a local solve) did not move; the walls the window sees did.
  const auto& last_room = row.walls.back();
  for (std::size_t p = 0; p < row.graph.plane_slots(); ++p) {
    const MapPlane now = row.graph.plane(static_cast<std::uint32_t>(p));
    const bool seen_in_window =
        row.graph.keyframe_stamp(now.last_keyframe) >= row.graph.keyframe_stamp(row.ids[row.ids.size() - 10]);
    if (seen_in_window) continue;
    EXPECT_EQ(now.d, planes_before[p].d) << p;
  }
  EXPECT_NE(row.graph.plane(static_cast<std::uint32_t>(last_room[0])).d,
            planes_before[static_cast<std::size_t>(last_room[0])].d);
  // It brought the window's factors into agreement (a new room's walls start where the drifted
  // estimate puts them, so nothing here holds the drift along the row: no truth to compare).
  EXPECT_LT(report->final_cost, report->initial_cost);
}

TEST(SGraphWindow, WhatALocalSolveHandsToCeresDoesNotGrowWithTheGraph) {
  SGraphConfig config;
  config.max_keyframes = 1024;
  config.max_planes = 512;
  // The floor is seen from every keyframe, and moves with the window: its observations by the
  // held keyframes enter as one sum, not one residual block each.
  RoomRow row(config);
  std::size_t peak_at_100 = 0;
  for (int i = 0; i < 600; ++i) {
    ASSERT_NO_FATAL_FAILURE(row.Step());
    ASSERT_TRUE(row.graph.Solve(SolveKind::kLocal));
    if (i == 99) peak_at_100 = row.graph.stats().window_residuals_peak;
  }
  const std::size_t peak_at_600 = row.graph.stats().window_residuals_peak;
  EXPECT_GT(peak_at_100, 0u);
  EXPECT_EQ(peak_at_600, peak_at_100);
  // Against the graph: 600 keyframes, about 6 factors each.
  EXPECT_GT(row.graph.stats().factors, 10 * peak_at_600);
  auto full = row.graph.Solve(SolveKind::kFull);
  ASSERT_TRUE(full);
  EXPECT_TRUE(full->usable);
}

}  // namespace
}  // namespace msgraphs::core
