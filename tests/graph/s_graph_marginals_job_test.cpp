// SPDX-License-Identifier: MIT
// The walls' marginal covariances off the graph's thread (SGraph::BeginPlaneMarginals): a job
// gives what PlaneMarginals gave when it began, while the graph goes on taking keyframes and
// removing factors; it lends the graph's costs back when its Run ends; a removed cost is kept
// only for the jobs begun before its removal; beginning allocates nothing; a job released unrun
// runs nothing; a kOwn job leaves the plane priors out.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <thread>
#include <vector>

#include "alloc_counter.hpp"
#include "msgraphs/core/graph/s_graph.hpp"
#include "msgraphs/core/graph/s_graph_solve_job.hpp"
#include "s_graph_fixtures.hpp"

namespace msgraphs::core {
namespace {

using namespace sgraph_test;  // NOLINT(google-build-using-namespace): test fixtures

std::vector<std::uint32_t> Walls(const SGraph& graph) {
  std::vector<std::uint32_t> ids;
  for (std::uint32_t id = 0; id < graph.plane_slots(); ++id) {
    const MapPlane p = graph.plane(id);
    if (p.active && p.plane_class == PlaneClass::kWall && p.observations > 0) ids.push_back(id);
  }
  return ids;
}

// A loop closure from the row's first keyframe to its newest, with the true relative pose.
Expected<std::uint32_t> CloseLoop(RoomRow& row) {
  return row.graph.AddRelativePose(row.ids.front(), row.ids.back(),
                                   row.truth.front().inverse() * row.truth.back(),
                                   OdometryInformation(), RelativePoseKind::kLoopClosure);
}

// A row walked 40 keyframes with a loop closure back to its start.
std::uint32_t WalkWithLoop(RoomRow& row) {
  for (int i = 0; i < 40; ++i) {
    row.Step();
    EXPECT_TRUE(row.graph.Solve(SolveKind::kLocal));
  }
  auto loop = CloseLoop(row);
  EXPECT_TRUE(loop);
  return loop ? *loop : 0;
}

TEST(SGraphMarginalsJob, GivesWhatPlaneMarginalsGaveWhileTheGraphGoesOn) {
  SGraphConfig config;
  config.max_keyframes = 256;
  RoomRow row(config);
  const std::uint32_t loop = WalkWithLoop(row);
  const std::vector<std::uint32_t> walls = Walls(row.graph);
  ASSERT_GE(walls.size(), 16u);
  std::vector<Eigen::Matrix3d> expected(walls.size());
  ASSERT_TRUE(row.graph.PlaneMarginals(walls, expected));

  SGraphSolveJob job;
  ASSERT_TRUE(job.Init(config));
  ASSERT_TRUE(row.graph.BeginPlaneMarginals(job, walls));
  EXPECT_FALSE(row.graph.BeginPlaneMarginals(job, walls));  // pending
  // Claimed before the graph goes on, so the removals below happen while the job holds the
  // costs, whenever the worker gets to run it: the loop's cost is retired, not freed (ASan
  // would see a freed cost evaluated).
  ASSERT_TRUE(job.TryClaim());
  EXPECT_FALSE(job.TryClaim());
  EXPECT_FALSE(row.graph.Init(config));  // a job borrows: the graph refuses to start over
  std::jthread worker([&job] { job.Run(); });
  for (int i = 0; i < 10; ++i) {
    row.Step();
    ASSERT_TRUE(row.graph.Solve(SolveKind::kLocal));
  }
  ASSERT_TRUE(row.graph.RemoveFactor(loop));
  worker.join();
  job.Complete();
  ASSERT_EQ(job.marginal_planes().size(), walls.size());
  ASSERT_EQ(job.plane_marginals().size(), walls.size());
  for (std::size_t i = 0; i < walls.size(); ++i) {
    EXPECT_EQ(job.marginal_planes()[i], walls[i]);
    EXPECT_TRUE(job.plane_marginals()[i].isApprox(expected[i], 1e-9)) << i;
  }
  // A marginals job is not applied to the graph; it is released.
  EXPECT_FALSE(row.graph.ApplyFullSolve(job));
  ASSERT_TRUE(job.Release());
  EXPECT_FALSE(job.pending());
  EXPECT_TRUE(job.plane_marginals().empty());
  // Its Run ended the borrowing: the next removal frees what was kept for it.
  row.Step();
  ASSERT_TRUE(row.graph.Solve(SolveKind::kLocal));
  auto again = CloseLoop(row);
  ASSERT_TRUE(again);
  ASSERT_TRUE(row.graph.RemoveFactor(*again));
  EXPECT_EQ(row.graph.stats().retired_costs, 0u);
  EXPECT_TRUE(row.graph.Init(config));
}

// A cost is kept only for the jobs begun before its removal: with a full solve and a marginals
// job taking turns so that one of them always borrows (the mapper's and the distiller's jobs
// when their runners lag), removed costs are still freed, and never while a job that may hold
// them borrows.
TEST(SGraphMarginalsJob, RemovedCostsAreFreedWhileNewerJobsBorrow) {
  SGraphConfig config;
  config.max_keyframes = 256;
  RoomRow row(config);
  WalkWithLoop(row);
  const std::vector<std::uint32_t> walls = Walls(row.graph);
  SGraphSolveJob marginals, full;
  ASSERT_TRUE(marginals.Init(config));
  ASSERT_TRUE(full.Init(config));
  ASSERT_TRUE(row.graph.BeginPlaneMarginals(marginals, walls));
  std::size_t peak = 0;
  for (int round = 0; round < 6; ++round) {
    // A removal while the marginals job borrows: kept.
    auto loop = CloseLoop(row);
    ASSERT_TRUE(loop);
    ASSERT_TRUE(row.graph.RemoveFactor(*loop));
    peak = std::max(peak, row.graph.stats().retired_costs);
    // The full solve begins before the marginals job ends: somebody borrows throughout. The
    // removed cost stays while the older marginals job still borrows ...
    ASSERT_TRUE(row.graph.BeginFullSolve(full));
    EXPECT_GE(row.graph.stats().retired_costs, 1u);
    ASSERT_TRUE(marginals.Release());  // not run: its borrowing ends
    // ... and goes at the next begin, though the full solve (begun after the removal) borrows.
    ASSERT_TRUE(row.graph.BeginPlaneMarginals(marginals, walls));
    EXPECT_EQ(row.graph.stats().retired_costs, 0u);
    full.Complete();
    ASSERT_TRUE(row.graph.ApplyFullSolve(full));
    row.Step();
  }
  // Each round's removed loop went once the job that could hold it ended: one kept at a time
  // (a count of borrowing jobs would have kept all six).
  EXPECT_EQ(peak, 1u);
  ASSERT_TRUE(marginals.Release());
  EXPECT_TRUE(row.graph.Init(config));
}

TEST(SGraphMarginalsJob, BeginAllocatesNothingAndAJobReleasedUnrunRunsNothing) {
  SGraphConfig config;
  config.max_keyframes = 256;
  RoomRow row(config);
  for (int i = 0; i < 30; ++i) row.Step();
  const std::vector<std::uint32_t> walls = Walls(row.graph);
  SGraphSolveJob job;
  ASSERT_TRUE(job.Init(config));
  // A first round sizes the scratch vectors the graph keeps.
  ASSERT_TRUE(row.graph.BeginPlaneMarginals(job, walls));
  job.Complete();
  ASSERT_TRUE(job.Release());
  std::size_t begin_allocations = 0;
  {
    test::AllocationScope scope;
    ASSERT_TRUE(row.graph.BeginPlaneMarginals(job, walls));
    begin_allocations = scope.allocations();
  }
  EXPECT_EQ(begin_allocations, 0u);
  // Released before anybody ran it: not run, nothing to claim, the graph lends nothing.
  ASSERT_TRUE(job.Release());
  EXPECT_FALSE(job.TryClaim());
  EXPECT_TRUE(job.plane_marginals().empty());
  EXPECT_TRUE(row.graph.Init(config));
  // Planes that are not in the optimisation, or more than the job holds, are refused.
  RoomRow other(config);
  other.Step();
  const std::uint32_t unknown = static_cast<std::uint32_t>(other.graph.plane_slots()) + 5;
  EXPECT_FALSE(other.graph.BeginPlaneMarginals(job, std::vector<std::uint32_t>{unknown}));
  EXPECT_FALSE(job.pending());
}

// PlaneEvidence::kOwn (rumour-free distillation): the plane priors, what other robots said, are
// left out of the copy and the copy is solved without them: its covariances and estimates are
// those of the graph before the priors came, however far they pulled it. Beginning one
// allocates nothing.
TEST(SGraphMarginalsJob, OwnEvidenceLeavesThePriorsOutAndSolvesWithoutThem) {
  SGraphConfig config;
  config.max_keyframes = 256;
  // The reference (the graph's own full solve before the priors) must reach the optimum the
  // job's solve (no time limit) reaches: under qemu a 2 s limit stopped it 0.15 mm short.
  config.local_max_seconds = config.full_max_seconds = 600.0;
  RoomRow row(config);
  for (int i = 0; i < 30; ++i) {
    row.Step();
    ASSERT_TRUE(row.graph.Solve(SolveKind::kLocal));
  }
  ASSERT_TRUE(row.graph.Solve(SolveKind::kFull));
  const std::vector<std::uint32_t> walls = Walls(row.graph);
  ASSERT_GE(walls.size(), 8u);
  std::vector<Eigen::Matrix3d> own(walls.size());
  ASSERT_TRUE(row.graph.PlaneMarginals(walls, own));
  std::vector<double> own_d;
  for (std::uint32_t id : walls) own_d.push_back(row.graph.plane(id).d);
  const Eigen::Vector2d own_room = row.graph.room(0).centre;
  SGraphSolveJob job;
  ASSERT_TRUE(job.Init(config));
  // Never pulled: a kOwn job is the graph as it is, not solved.
  EXPECT_FALSE(row.graph.estimates_hold_priors());
  ASSERT_TRUE(row.graph.BeginPlaneMarginals(job, walls, PlaneEvidence::kOwn));
  job.Complete();
  EXPECT_FALSE(job.own_solved());
  ASSERT_EQ(job.plane_marginals().size(), walls.size());
  EXPECT_TRUE(job.plane_marginals()[0].isApprox(own[0], 1e-9));
  ASSERT_TRUE(job.Release());
  // Three walls get a peer's word, as sure as this graph and one of its sigmas off (within the
  // robust losses' quadratic range): the map follows part of the way.
  std::vector<double> sigma_d;
  for (std::size_t i = 0; i < 3; ++i) {
    sigma_d.push_back(std::sqrt(own[i](2, 2)));
    PlanePrior prior;
    prior.plane = walls[i];
    prior.normal = row.graph.plane(walls[i]).normal;
    prior.d = own_d[i] + sigma_d[i];
    prior.covariance = Eigen::Matrix3d(own[i].diagonal().asDiagonal());
    ASSERT_TRUE(row.graph.AddPlanePrior(prior));
  }
  ASSERT_TRUE(row.graph.Solve(SolveKind::kFull));
  std::vector<double> pull_m;
  for (std::size_t i = 0; i < 3; ++i) {
    pull_m.push_back(std::fabs(row.graph.plane(walls[i]).d - own_d[i]));
    EXPECT_GT(pull_m[i], 0.1 * sigma_d[i]) << i;
  }
  EXPECT_TRUE(row.graph.estimates_hold_priors());

  // kAll: the graph as it is, priors and all.
  ASSERT_TRUE(row.graph.BeginPlaneMarginals(job, walls, PlaneEvidence::kAll));
  job.Complete();
  EXPECT_EQ(job.priors_left_out(), 0u);
  ASSERT_EQ(job.plane_marginals().size(), walls.size());
  for (std::size_t i = 0; i < 3; ++i) EXPECT_LT(job.plane_marginals()[i](2, 2), 0.7 * own[i](2, 2)) << i;
  ASSERT_TRUE(job.Release());
  // kOwn: as if the priors had never come.
  ASSERT_TRUE(row.graph.BeginPlaneMarginals(job, walls, PlaneEvidence::kOwn));
  job.Complete();
  EXPECT_EQ(job.priors_left_out(), 3u);
  EXPECT_TRUE(job.own_solved());
  EXPECT_TRUE(job.own_solve_usable());
  EXPECT_TRUE(job.own_solve_converged());
  ASSERT_EQ(job.plane_marginals().size(), walls.size());
  for (std::size_t i = 0; i < walls.size(); ++i) {
    EXPECT_TRUE(job.plane_marginals()[i].isApprox(own[i], 1e-3)) << i;
    Eigen::Vector3d n;
    double d = 0;
    ASSERT_TRUE(job.PlaneEstimate(walls[i], n, d));
    // Back at the own optimum, within the solvers' tolerances: the row slides along its length
    // at almost no cost, and where the two solves stop there differs by up to 0.15 mm on
    // aarch64 (5 um on x86_64), 4 % of a wall's sigma. The priors' pull is undone.
    EXPECT_LT(std::fabs(d - own_d[i]), 0.1 * std::sqrt(own[i](2, 2))) << i;
    if (i < 3) {
      EXPECT_LT(std::fabs(d - own_d[i]), 0.25 * pull_m[i]) << i;
    }
  }
  Eigen::Vector2d centre;
  ASSERT_TRUE(job.RoomCentre(0, centre));
  EXPECT_LT((centre - own_room).norm(), 1e-5);
  EXPECT_FALSE(job.RoomCentre(1000, centre));
  ASSERT_TRUE(job.Release());
  // Beginning one allocates nothing (the list of priors to leave out is sized at Init).
  std::size_t allocations = 0;
  {
    test::AllocationScope scope;
    ASSERT_TRUE(row.graph.BeginPlaneMarginals(job, walls, PlaneEvidence::kOwn));
    allocations = scope.allocations();
  }
  EXPECT_EQ(allocations, 0u);
  ASSERT_TRUE(job.Release());
}

}  // namespace
}  // namespace msgraphs::core
