// SPDX-License-Identifier: MIT
// A mission with every kind of S-Graph node and factor, for tests that compare two runs bit for
// bit (s_graph_order_test.cpp, s_graph_snapshot_test.cpp): laps of a room with its walls, the
// floor plane, a room and the floor node, loop closures one lap apart, a wall found twice, a
// plane prior later replaced, sparsification (120 keyframes kept of 200, so keyframe and factor
// slots are reused), local solves at every keyframe, full solves on the spot and in the
// background, a marginals job of the own evidence and marginals on the spot. Solves are bounded
// by their iteration caps only, never the machine's load.
#pragma once

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <array>
#include <functional>
#include <memory>
#include <random>
#include <vector>

#include "msgraphs/core/graph/s_graph.hpp"
#include "msgraphs/core/graph/s_graph_solve_job.hpp"
#include "s_graph_fixtures.hpp"

namespace msgraphs::core::sgraph_test {

struct MissionOutcome {
  std::vector<double> values;  // every estimate, in slot order
  std::vector<Eigen::Matrix3d> marginals_now, marginals_job;
  SGraphStats stats;
};

inline SGraphConfig MixedMissionConfig() {
  SGraphConfig config;
  config.max_keyframes = 120;
  config.local_window_keyframes = 10;
  config.local_max_seconds = 1e9;
  config.full_max_seconds = 1e9;
  return config;
}

// `between(graph, i)` runs after keyframe i's solve whenever no background solve is pending; it
// may replace the graph (a snapshot loaded into a new one).
using MissionHook = std::function<void(std::unique_ptr<SGraph>& graph, std::size_t i)>;

inline MissionOutcome RunMixedMission(const MissionHook& between) {
  const SGraphConfig config = MixedMissionConfig();
  auto graph = std::make_unique<SGraph>();
  EXPECT_TRUE(graph->Init(config));
  SGraphSolveJob full_job, marginals_job;
  EXPECT_TRUE(full_job.Init(config));
  EXPECT_TRUE(marginals_job.Init(config));
  const Room room;
  const Walk walk(room, 200);
  std::mt19937 rng(3);
  std::vector<std::uint32_t> ids, walls;
  std::uint32_t floor_plane = 0, room_id = 0, twin = 0, prior = 0;
  MissionOutcome out;
  for (std::size_t i = 0; i < walk.truth.size(); ++i) {
    SGraph& g = *graph;
    AddWalkStep(g, walk, i, ids);
    if (testing::Test::HasFatalFailure()) return out;
    const Eigen::Isometry3d& T = walk.truth[i];
    if (i == 0) {
      for (const TruePlane& w : room.walls()) walls.push_back(*g.AddPlane(w.n, w.d, PlaneClass::kWall));
      floor_plane = *g.AddPlane(Eigen::Vector3d::UnitZ(), 0.5, PlaneClass::kFloor);
    }
    for (std::size_t w = 0; w < 4; ++w)
      EXPECT_TRUE(g.AddPlaneObservation(ids.back(), walls[w], Measure(room.walls()[w], T, rng, 0.01)));
    EXPECT_TRUE(g.AddPlaneObservation(
        ids.back(), floor_plane, Measure(TruePlane{Eigen::Vector3d::UnitZ(), 0.5}, T, rng, 0.01)));
    if (i == 12) {
      MapRoom r;
      r.centre = room.centre;
      for (std::size_t w = 0; w < 4; ++w) r.walls[w] = static_cast<std::int32_t>(walls[w]);
      room_id = *g.AddRoom(r);
      EXPECT_TRUE(g.SetFloor(room.centre));
      EXPECT_TRUE(g.AddFloorRoom(room_id));
    }
    if (i == 40) {
      const MapPlane w0 = g.plane(walls[0]);
      twin = *g.AddPlane(w0.normal, w0.d + 0.01, PlaneClass::kWall);
      EXPECT_TRUE(g.AddPlaneObservation(ids.back(), twin, Measure(room.walls()[0], T, rng, 0.01)));
      EXPECT_TRUE(g.AddWallWall(walls[0], twin));
    }
    if (i == 50 || i == 130) {
      if (i == 130) {
        EXPECT_TRUE(g.RemoveFactor(prior));
      }
      PlanePrior p;
      p.plane = walls[1];
      p.normal = g.plane(walls[1]).normal;
      p.d = g.plane(walls[1]).d + 0.003;
      p.covariance = Eigen::Matrix3d::Identity() * 1e-4;
      prior = *g.AddPlanePrior(p);
    }
    // A loop to the keyframe one lap back, while it is still in the graph.
    if (i >= 24 && i % 6 == 0 && g.keyframe_active(ids[i - 24]) &&
        g.keyframe_stamp(ids[i - 24]) == static_cast<double>(i - 24)) {
      EXPECT_TRUE(g.AddRelativePose(ids[i - 24], ids.back(), walk.truth[i - 24].inverse() * T,
                                    LoopInformation(), RelativePoseKind::kLoopClosure));
    }
    if (i == 90) {
      EXPECT_TRUE(g.BeginFullSolve(full_job));
    }
    if (i == 95) {
      full_job.Complete();
      EXPECT_TRUE(g.ApplyFullSolve(full_job));
    }
    EXPECT_TRUE(g.Solve(i % 50 == 49 ? SolveKind::kFull : SolveKind::kLocal));
    if (between && !full_job.pending()) between(graph, i);
  }
  SGraph& g = *graph;
  const std::array<std::uint32_t, 5> planes{walls[0], walls[1], walls[2], walls[3], twin};
  EXPECT_TRUE(g.BeginPlaneMarginals(marginals_job, planes, PlaneEvidence::kOwn));
  marginals_job.Complete();
  for (const Eigen::Matrix3d& c : marginals_job.plane_marginals()) out.marginals_job.push_back(c);
  EXPECT_EQ(out.marginals_job.size(), planes.size());
  EXPECT_TRUE(marginals_job.Release());
  out.marginals_now.resize(planes.size());
  EXPECT_TRUE(g.PlaneMarginals(planes, out.marginals_now));
  for (std::size_t k = 0; k < g.keyframe_slots(); ++k) {
    if (!g.keyframe_active(static_cast<std::uint32_t>(k))) continue;
    const Eigen::Isometry3d T = g.keyframe_pose(static_cast<std::uint32_t>(k));
    const Eigen::Quaterniond q(T.linear());
    for (double v : {q.x(), q.y(), q.z(), q.w()}) out.values.push_back(v);
    for (int a = 0; a < 3; ++a) out.values.push_back(T.translation()[a]);
  }
  for (std::size_t p = 0; p < g.plane_slots(); ++p) {
    const MapPlane plane = g.plane(static_cast<std::uint32_t>(p));
    for (int a = 0; a < 3; ++a) out.values.push_back(plane.normal[a]);
    out.values.push_back(plane.d);
  }
  const MapRoom r = g.room(room_id);
  out.values.push_back(r.centre.x());
  out.values.push_back(r.centre.y());
  out.values.push_back(g.floor_centre().x());
  out.values.push_back(g.floor_centre().y());
  out.stats = g.stats();
  return out;
}

// The two outcomes are the same, bit for bit.
inline void ExpectSameOutcome(const MissionOutcome& a, const MissionOutcome& b) {
  ASSERT_EQ(a.values.size(), b.values.size());
  std::size_t differ = 0;
  for (std::size_t i = 0; i < a.values.size(); ++i) differ += a.values[i] != b.values[i];
  EXPECT_EQ(differ, 0u) << "of " << a.values.size() << " estimates";
  ASSERT_EQ(a.marginals_now.size(), b.marginals_now.size());
  ASSERT_EQ(a.marginals_job.size(), b.marginals_job.size());
  for (std::size_t p = 0; p < a.marginals_now.size(); ++p) {
    EXPECT_EQ(a.marginals_now[p], b.marginals_now[p]) << p;
    EXPECT_EQ(a.marginals_job[p], b.marginals_job[p]) << p;
  }
  EXPECT_EQ(a.stats.solves, b.stats.solves);
  EXPECT_EQ(a.stats.solves_not_converged, b.stats.solves_not_converged);
  EXPECT_EQ(a.stats.held_sums_rebuilt, b.stats.held_sums_rebuilt);
  EXPECT_EQ(a.stats.sparsified, b.stats.sparsified);
  EXPECT_EQ(a.stats.factors, b.stats.factors);
}

}  // namespace msgraphs::core::sgraph_test
