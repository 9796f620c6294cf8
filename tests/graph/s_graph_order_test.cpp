// SPDX-License-Identifier: MIT
// What the graph computes does not depend on the order Ceres holds its blocks in, nor on their
// addresses (s_graph_residual_index.hpp): a graph whose problem is rebuilt now and then in
// reverse (SGraph::RebuildProblem, as a snapshot's load will) gives the same estimates and
// marginals, bit for bit, as one never rebuilt. Without that, a journal replay or a restored
// snapshot would round differently from the live map and part from it at the next close call.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <array>
#include <random>
#include <vector>

#include "msgraphs/core/graph/s_graph.hpp"
#include "msgraphs/core/graph/s_graph_solve_job.hpp"
#include "s_graph_fixtures.hpp"

namespace msgraphs::core {
namespace {

using namespace sgraph_test;  // NOLINT(google-build-using-namespace): test fixtures

struct Outcome {
  std::vector<double> values;  // every estimate, in slot order
  std::vector<Eigen::Matrix3d> marginals_now, marginals_job;
  SGraphStats stats;
};

// Laps of a room with every kind of node and factor: walls, the floor plane, a room and the
// floor node, loop closures one lap apart, a wall found twice, a plane prior later replaced,
// sparsification (120 keyframes kept of 200, so slots and factor slots are reused), local
// solves at every keyframe, full solves on the spot and in the background, a marginals job of
// the own evidence and marginals on the spot. `rebuild`: the problem is rebuilt every 23
// keyframes.
Outcome Mission(bool rebuild) {
  SGraphConfig config;
  config.max_keyframes = 120;
  config.local_window_keyframes = 10;
  config.local_max_seconds = 1e9;  // the iteration caps only: never the machine's load
  config.full_max_seconds = 1e9;
  SGraph g;
  EXPECT_TRUE(g.Init(config));
  SGraphSolveJob full_job, marginals_job;
  EXPECT_TRUE(full_job.Init(config));
  EXPECT_TRUE(marginals_job.Init(config));
  const Room room;
  const Walk walk(room, 200);
  std::mt19937 rng(3);
  std::vector<std::uint32_t> ids, walls;
  std::uint32_t floor_plane = 0, room_id = 0, twin = 0, prior = 0;
  Outcome out;
  for (std::size_t i = 0; i < walk.truth.size(); ++i) {
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
    if (rebuild && i % 23 == 22 && !full_job.pending()) {  // refused while a job borrows
      EXPECT_TRUE(g.RebuildProblem());
    }
  }
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

TEST(SGraphOrder, AGraphRebuiltInAnotherOrderSolvesBitForBitAsBefore) {
  const Outcome kept = Mission(false);
  ASSERT_FALSE(HasFailure());
  const Outcome rebuilt = Mission(true);
  ASSERT_FALSE(HasFailure());
  // The mission reached what it is meant to exercise.
  EXPECT_GT(kept.stats.sparsified, 50u);
  EXPECT_GT(kept.stats.relative_factors[static_cast<std::size_t>(RelativePoseKind::kLoopClosure)], 0u);
  EXPECT_EQ(kept.stats.wall_wall_factors, 1u);
  EXPECT_EQ(kept.stats.plane_prior_factors, 1u);
  EXPECT_EQ(kept.stats.background_applied, 1u);
  ASSERT_EQ(kept.values.size(), rebuilt.values.size());
  std::size_t differ = 0;
  for (std::size_t i = 0; i < kept.values.size(); ++i) differ += kept.values[i] != rebuilt.values[i];
  EXPECT_EQ(differ, 0u) << "of " << kept.values.size() << " estimates";
  for (std::size_t p = 0; p < kept.marginals_now.size(); ++p) {
    EXPECT_EQ(kept.marginals_now[p], rebuilt.marginals_now[p]) << p;
    EXPECT_EQ(kept.marginals_job[p], rebuilt.marginals_job[p]) << p;
  }
  EXPECT_EQ(kept.stats.solves, rebuilt.stats.solves);
  EXPECT_EQ(kept.stats.solves_not_converged, rebuilt.stats.solves_not_converged);
  EXPECT_EQ(kept.stats.held_sums_rebuilt, rebuilt.stats.held_sums_rebuilt);
}

TEST(SGraphOrder, NoRebuildWhileAJobBorrows) {
  SGraphConfig config;
  SGraph g;
  ASSERT_TRUE(g.Init(config));
  SGraphSolveJob job;
  ASSERT_TRUE(job.Init(config));
  ASSERT_TRUE(g.AddKeyframe(0.0, Eigen::Isometry3d::Identity()));
  ASSERT_TRUE(g.BeginFullSolve(job));
  const Status refused = g.RebuildProblem();
  ASSERT_FALSE(refused);
  EXPECT_EQ(refused.error().code, Errc::kWouldBlock);
  job.Complete();
  ASSERT_TRUE(g.ApplyFullSolve(job));
  EXPECT_TRUE(g.RebuildProblem());
}

}  // namespace
}  // namespace msgraphs::core
