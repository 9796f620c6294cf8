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
#include "msgraphs/core/graph/s_graph_solve_job.hpp"
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
        now.last_observed_s >= row.graph.keyframe_stamp(row.ids[row.ids.size() - 10]);
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

// A patrol: laps of one room, every wall and the floor seen from every keyframe, so each free
// plane's held observations grow with the mission. The held sums kept between local solves
// (the default) must give what summing them afresh at every solve gives, through full solves,
// a plane observation added to an old keyframe, a wall found twice (wall-wall factor), a
// plane prior, a background full solve applied later; and they must not be taken afresh
// between full solves. The reference (incremental_held_sums off) collects the window as the
// graph did before the sums were kept: from every free node's residual blocks.
TEST(SGraphWindow, HeldSumsKeptBetweenSolvesGiveWhatSummingThemAfreshGives) {
  SGraphConfig incremental;
  incremental.local_window_keyframes = 10;
  incremental.local_max_seconds = 1e9;  // the iteration cap only: results never depend on load
  incremental.full_max_seconds = 1e9;
  SGraphConfig afresh = incremental;
  afresh.incremental_held_sums = false;
  const Room room;
  const Walk walk(room, 300);
  std::mt19937 rng(5);
  SGraph a, b;
  ASSERT_TRUE(a.Init(incremental));
  ASSERT_TRUE(b.Init(afresh));
  std::vector<std::uint32_t> ids_a, ids_b, walls;
  std::uint32_t floor = 0, twin = 0;
  const auto both = [&](auto&& f) {
    f(a);
    f(b);
  };
  std::uint64_t rebuilt_after_full = 0;
  SGraphSolveJob job_a, job_b;
  ASSERT_TRUE(job_a.Init(incremental));
  ASSERT_TRUE(job_b.Init(afresh));
  for (std::size_t i = 0; i < walk.truth.size(); ++i) {
    ASSERT_NO_FATAL_FAILURE(AddWalkStep(a, walk, i, ids_a));
    ASSERT_NO_FATAL_FAILURE(AddWalkStep(b, walk, i, ids_b));
    ASSERT_EQ(ids_a.back(), ids_b.back());
    const Eigen::Isometry3d& T = walk.truth[i];
    // Noise a fifth of the stated sigma: every observation within its Huber kernel, so both
    // sums are exact and the two graphs agree to rounding.
    std::vector<PlaneMeasurement> z;
    for (const TruePlane& w : room.walls()) {
      z.push_back(Measure(w, T, rng, 0.001));
      z.back().covariance *= 25;
    }
    z.push_back(Measure(TruePlane{Eigen::Vector3d::UnitZ(), 0.5}, T, rng, 0.001));
    z.back().covariance *= 25;
    if (i == 0) {
      for (const TruePlane& w : room.walls()) {
        both([&](SGraph& g) { static_cast<void>(g.AddPlane(w.n, w.d, PlaneClass::kWall)); });
        walls.push_back(static_cast<std::uint32_t>(walls.size()));
      }
      both([&](SGraph& g) { floor = *g.AddPlane(Eigen::Vector3d::UnitZ(), 0.5, PlaneClass::kFloor); });
    }
    for (std::size_t w = 0; w < 4; ++w) {
      ASSERT_TRUE(a.AddPlaneObservation(ids_a.back(), walls[w], z[w]));
      ASSERT_TRUE(b.AddPlaneObservation(ids_b.back(), walls[w], z[w]));
    }
    ASSERT_TRUE(a.AddPlaneObservation(ids_a.back(), floor, z[4]));
    ASSERT_TRUE(b.AddPlaneObservation(ids_b.back(), floor, z[4]));
    if (i == 60) {
      // The first wall found again as a new plane, tied to it; and a prior on the second.
      both([&](SGraph& g) {
        const MapPlane w0 = g.plane(walls[0]);
        twin = *g.AddPlane(w0.normal, w0.d + 0.01, PlaneClass::kWall);
        ASSERT_TRUE(g.AddPlaneObservation(static_cast<std::uint32_t>(ids_a.back()), twin, z[0]));
        ASSERT_TRUE(g.AddWallWall(walls[0], twin));
        PlanePrior prior;
        prior.plane = walls[1];
        prior.normal = g.plane(walls[1]).normal;
        prior.d = g.plane(walls[1]).d + 0.002;
        prior.covariance = Eigen::Matrix3d::Identity() * 1e-4;
        ASSERT_TRUE(g.AddPlanePrior(prior));
      });
    }
    const bool late = i == 170;
    if (late) {
      // An observation by a keyframe long held (well after the last full solve): its wall's
      // kept sum must be taken afresh, that wall's only.
      PlaneMeasurement m = Measure(room.walls()[2], walk.truth[20], rng, 0.001);
      m.covariance *= 25;
      ASSERT_TRUE(a.AddPlaneObservation(ids_a[20], walls[2], m));
      ASSERT_TRUE(b.AddPlaneObservation(ids_b[20], walls[2], m));
      EXPECT_EQ(a.plane(walls[2]).last_observed_s, a.keyframe_stamp(ids_a.back()));  // still the newest observer
    }
    const std::uint64_t rebuilt_before = a.stats().held_sums_rebuilt;
    if (i == 120) {
      // A full solve in the background, applied five keyframes later.
      ASSERT_TRUE(a.BeginFullSolve(job_a));
      ASSERT_TRUE(b.BeginFullSolve(job_b));
      job_a.Complete();
      job_b.Complete();
    }
    if (i == 125) {
      ASSERT_TRUE(a.ApplyFullSolve(job_a));
      ASSERT_TRUE(b.ApplyFullSolve(job_b));
      rebuilt_after_full = 0;
    }
    const bool full = i % 50 == 49;
    ASSERT_TRUE(a.Solve(full ? SolveKind::kFull : SolveKind::kLocal));
    ASSERT_TRUE(b.Solve(full ? SolveKind::kFull : SolveKind::kLocal));
    if (full) {
      rebuilt_after_full = 0;
    } else if (late) {
      EXPECT_EQ(a.stats().held_sums_rebuilt, rebuilt_before + 1);
    } else if (i > 60 && rebuilt_after_full++ > 0) {
      // Kept from one local solve to the next: nothing summed afresh.
      EXPECT_EQ(a.stats().held_sums_rebuilt, rebuilt_before) << i;
    }
    double worst_m = 0;
    for (std::size_t k = 0; k < ids_a.size(); ++k) {
      worst_m = std::max(worst_m, (a.keyframe_pose(ids_a[k]).translation() -
                                   b.keyframe_pose(ids_b[k]).translation())
                                      .norm());
    }
    for (std::uint32_t p = 0; p < a.plane_slots(); ++p)
      worst_m = std::max(worst_m, std::abs(a.plane(p).d - b.plane(p).d));
    ASSERT_LT(worst_m, 1e-7) << "keyframe " << i;
  }
  // The incremental graph summed as keyframes left the window; the other summed everything at
  // every solve.
  EXPECT_GT(a.stats().held_observations_added, 200u);
  EXPECT_LT(a.stats().held_sums_rebuilt, b.stats().held_sums_rebuilt / 10);
  EXPECT_EQ(a.stats().window_residuals_peak, b.stats().window_residuals_peak);
}

}  // namespace
}  // namespace msgraphs::core
