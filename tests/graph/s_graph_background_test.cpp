// SPDX-License-Identifier: MIT
// The full solve in the background (SGraphSolveJob): it solves what a full solve would, while
// the graph goes on taking keyframes, local solves and removals on another thread; it carries
// what the graph did meanwhile; its result does not depend on who ran it; begin and apply do
// not allocate.
#include <gtest/gtest.h>

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

// A row of rooms walked with odometry 2 % long, each keyframe locally solved, then a loop
// closure from the first keyframe to the newest with the true relative pose: only a full
// solve spreads it down the row. Returns the loop factor.
std::uint32_t WalkAndClose(RoomRow& row, int keyframes) {
  for (int i = 0; i < keyframes; ++i) {
    row.Step();
    EXPECT_TRUE(row.graph.Solve(SolveKind::kLocal));
  }
  Matrix6d information = OdometryInformation();
  auto loop = row.graph.AddRelativePose(row.ids.front(), row.ids.back(),
                                        row.truth.front().inverse() * row.truth.back(), information,
                                        RelativePoseKind::kLoopClosure);
  EXPECT_TRUE(loop);
  return loop ? *loop : 0;
}

double WorstError(const RoomRow& row) { return MaxPositionError(row.graph, row.ids, row.truth); }

TEST(SGraphBackground, SolvesWhatAFullSolveWould) {
  SGraphConfig config;
  config.max_keyframes = 256;
  RoomRow inline_row(config), job_row(config);
  WalkAndClose(inline_row, 60);
  WalkAndClose(job_row, 60);
  const double before_m = WorstError(job_row);
  ASSERT_TRUE(inline_row.graph.Solve(SolveKind::kFull));
  SGraphSolveJob job;
  ASSERT_TRUE(job.Init(config));
  ASSERT_TRUE(job_row.graph.BeginFullSolve(job));
  job.Complete();
  auto report = job_row.graph.ApplyFullSolve(job);
  ASSERT_TRUE(report);
  EXPECT_TRUE(report->usable);
  EXPECT_FALSE(job.pending());
  EXPECT_LT(WorstError(job_row), 0.25 * before_m);
  for (std::size_t i = 0; i < job_row.ids.size(); ++i) {
    EXPECT_LT((job_row.graph.keyframe_pose(job_row.ids[i]).translation() -
               inline_row.graph.keyframe_pose(inline_row.ids[i]).translation())
                  .norm(),
              1e-4)
        << i;
  }
  for (std::uint32_t p = 0; p < job_row.graph.plane_slots(); ++p)
    EXPECT_NEAR(job_row.graph.plane(p).d, inline_row.graph.plane(p).d, 1e-4) << p;
  for (std::uint32_t r = 0; r < job_row.graph.room_slots(); ++r)
    EXPECT_LT((job_row.graph.room(r).centre - inline_row.graph.room(r).centre).norm(), 1e-4) << r;
  EXPECT_EQ(job_row.graph.stats().background_applied, 1u);
}

TEST(SGraphBackground, TheGraphGoesOnWhileAWorkerSolves) {
  SGraphConfig config;
  config.max_keyframes = 256;
  RoomRow row(config);
  const std::uint32_t loop = WalkAndClose(row, 60);
  const std::size_t held = row.ids.size();
  SGraphSolveJob job;
  ASSERT_TRUE(job.Init(config));
  ASSERT_TRUE(row.graph.BeginFullSolve(job));
  EXPECT_FALSE(row.graph.BeginFullSolve(job));  // one at a time
  std::jthread worker([&job] {
    if (job.TryClaim()) job.Run();
  });
  // Meanwhile: 15 more keyframes (new walls, a new room), local solves, and the loop factor
  // removed and added again (its cost retired while the worker may be evaluating it).
  for (int i = 0; i < 15; ++i) {
    row.Step();
    ASSERT_TRUE(row.graph.Solve(SolveKind::kLocal));
  }
  ASSERT_TRUE(row.graph.RemoveFactor(loop));
  auto again = row.graph.AddRelativePose(row.ids.front(), row.ids[held - 1],
                                         row.truth.front().inverse() * row.truth[held - 1],
                                         OdometryInformation(), RelativePoseKind::kLoopClosure);
  ASSERT_TRUE(again);
  worker.join();
  job.Complete();
  EXPECT_TRUE(job.done());
  // The job judges factors it held, not ones added after it began.
  EXPECT_FALSE(row.graph.FactorChi2(job, *again));
  const Eigen::Isometry3d anchor_before = row.graph.keyframe_pose(row.ids[held - 1]);
  std::vector<Eigen::Isometry3d> newer_before;
  for (std::size_t i = held; i < row.ids.size(); ++i)
    newer_before.push_back(row.graph.keyframe_pose(row.ids[i]));
  auto report = row.graph.ApplyFullSolve(job);
  ASSERT_TRUE(report);
  ASSERT_TRUE(report->usable);
  // The held part of the row is where the loop put it; the keyframes added meanwhile kept their
  // pose relative to the newest held one (a rigid carry), so they are corrected too.
  double worst_held_m = 0;
  for (std::size_t i = 0; i < held; ++i) {
    worst_held_m = std::max(
        worst_held_m,
        (row.graph.keyframe_pose(row.ids[i]).translation() - row.truth[i].translation()).norm());
  }
  EXPECT_LT(worst_held_m, 0.05);
  const Eigen::Isometry3d anchor_after = row.graph.keyframe_pose(row.ids[held - 1]);
  for (std::size_t i = held; i < row.ids.size(); ++i) {
    const Eigen::Isometry3d rel_before = anchor_before.inverse() * newer_before[i - held];
    const Eigen::Isometry3d rel_after =
        anchor_after.inverse() * row.graph.keyframe_pose(row.ids[i]);
    EXPECT_LT((rel_before.translation() - rel_after.translation()).norm(), 0.03) << i;
    EXPECT_LT(
        (row.graph.keyframe_pose(row.ids[i]).translation() - row.truth[i].translation()).norm(),
        0.25)
        << i;
  }
  // The graph takes the next job, which keeps the loop's correction.
  ASSERT_TRUE(row.graph.BeginFullSolve(job));
  job.Complete();
  ASSERT_TRUE(row.graph.ApplyFullSolve(job));
  for (std::size_t i = 0; i < held; ++i) {
    EXPECT_LT(
        (row.graph.keyframe_pose(row.ids[i]).translation() - row.truth[i].translation()).norm(),
        0.05);
  }
}

TEST(SGraphBackground, TheResultDoesNotDependOnWhoRanIt) {
  SGraphConfig config;
  config.max_keyframes = 256;
  // No solve may stop on its time limit: under qemu-aarch64 the walk's local solves (50 ms)
  // did, at different iterations in the two graphs, and the results differed by 2e-8 m.
  config.local_max_seconds = config.full_max_seconds = 600.0;
  RoomRow a(config), b(config);
  WalkAndClose(a, 50);
  WalkAndClose(b, 50);
  SGraphSolveJob job_a, job_b;
  ASSERT_TRUE(job_a.Init(config));
  ASSERT_TRUE(job_b.Init(config));
  ASSERT_TRUE(a.graph.BeginFullSolve(job_a));
  ASSERT_TRUE(b.graph.BeginFullSolve(job_b));
  std::jthread worker([&job_a] {
    if (job_a.TryClaim()) job_a.Run();
  });
  // Keyframes keep coming meanwhile (no local solves here: their time limit would make the two
  // graphs differ on a busy machine, whoever runs the job).
  for (int i = 0; i < 5; ++i) {
    a.Step();
    b.Step();
  }
  worker.join();
  job_a.Complete();
  job_b.Complete();  // runs here: nobody claimed it
  EXPECT_EQ(job_a.report().iterations, job_b.report().iterations);
  ASSERT_TRUE(a.graph.ApplyFullSolve(job_a));
  ASSERT_TRUE(b.graph.ApplyFullSolve(job_b));
  // Not bit for bit: the local solves order their blocks by address, which differs between the
  // two graphs, so the two agree to rounding before the job already, and the solves' convergence
  // tolerances let rounding grow: a micrometre is far below anything a map shows.
  for (std::size_t i = 0; i < a.ids.size(); ++i) {
    EXPECT_LT((a.graph.keyframe_pose(a.ids[i]).translation() -
               b.graph.keyframe_pose(b.ids[i]).translation())
                  .norm(),
              1e-6)
        << i;
  }
}

TEST(SGraphBackground, ADroppedJobChangesNothingAndAJudgedLoopCanBeRefused) {
  SGraphConfig config;
  config.max_keyframes = 256;
  RoomRow row(config);
  const std::uint32_t loop = WalkAndClose(row, 40);
  SGraphSolveJob job;
  ASSERT_TRUE(job.Init(config));
  ASSERT_TRUE(row.graph.BeginFullSolve(job));
  job.Complete();
  auto chi2 = row.graph.FactorChi2(job, loop);
  ASSERT_TRUE(chi2);
  EXPECT_GE(*chi2, 0.0);
  std::vector<Eigen::Isometry3d> before;
  for (std::uint32_t id : row.ids) before.push_back(row.graph.keyframe_pose(id));
  row.graph.DropFullSolve(job);
  EXPECT_FALSE(job.pending());
  for (std::size_t i = 0; i < row.ids.size(); ++i)
    EXPECT_TRUE(row.graph.keyframe_pose(row.ids[i]).isApprox(before[i], 0.0));
  // Dropped before anybody ran it: nobody can claim it any more.
  ASSERT_TRUE(row.graph.BeginFullSolve(job));
  row.graph.DropFullSolve(job);
  EXPECT_FALSE(job.TryClaim());
  // A job sized for a smaller graph is refused.
  SGraphConfig small = config;
  small.max_keyframes = 64;
  SGraphSolveJob tiny;
  ASSERT_TRUE(tiny.Init(small));
  EXPECT_FALSE(row.graph.BeginFullSolve(tiny));
}

TEST(SGraphBackground, BeginAndApplyAllocateNothing) {
  SGraphConfig config;
  config.max_keyframes = 256;
  RoomRow row(config);
  WalkAndClose(row, 60);
  SGraphSolveJob job;
  ASSERT_TRUE(job.Init(config));
  // A first round sizes Ceres' scratch vectors the graph keeps.
  ASSERT_TRUE(row.graph.BeginFullSolve(job));
  job.Complete();
  ASSERT_TRUE(row.graph.ApplyFullSolve(job));
  std::size_t begin_allocations = 0, apply_allocations = 0;
  {
    test::AllocationScope scope;
    ASSERT_TRUE(row.graph.BeginFullSolve(job));
    begin_allocations = scope.allocations();
  }
  job.Complete();  // allocates (Ceres): the background path
  {
    test::AllocationScope scope;
    ASSERT_TRUE(row.graph.ApplyFullSolve(job));
    apply_allocations = scope.allocations();
  }
  EXPECT_EQ(begin_allocations, 0u);
  EXPECT_EQ(apply_allocations, 0u);
}

// A room factor has 9 parameter blocks, every other kind at most 4: the job's references to
// the copied blocks must hold a factor store full to its last slot with every room in it.
// Counted after a first round on a store still half empty (that round sizes Ceres' scratch
// vectors the graph keeps), so that only what the full store needs beyond it can allocate.
TEST(SGraphBackground, AStoreFullToItsLastSlotWithRoomsIsCopiedWithoutAllocating) {
  SGraphConfig config;
  config.max_keyframes = 256;
  std::size_t peak = 0;
  {
    RoomRow probe(config);
    WalkAndClose(probe, 60);
    peak = probe.graph.stats().factors_peak;
  }
  config.max_factors = peak;
  RoomRow row(config);
  SGraphSolveJob job;
  ASSERT_TRUE(job.Init(config));
  for (int i = 0; i < 30; ++i) {
    row.Step();
    ASSERT_TRUE(row.graph.Solve(SolveKind::kLocal));
  }
  ASSERT_TRUE(row.graph.BeginFullSolve(job));
  job.Complete();
  ASSERT_TRUE(row.graph.ApplyFullSolve(job));
  for (int i = 30; i < 60; ++i) {
    row.Step();
    ASSERT_TRUE(row.graph.Solve(SolveKind::kLocal));
  }
  ASSERT_TRUE(row.graph.AddRelativePose(row.ids.front(), row.ids.back(), row.truth.front().inverse() * row.truth.back(),
                                        OdometryInformation(), RelativePoseKind::kLoopClosure));
  ASSERT_EQ(row.graph.stats().factors_peak, config.max_factors) << "the store is full";
  ASSERT_GE(row.graph.stats().room_factors, 5u);
  std::size_t allocations = 0;
  {
    test::AllocationScope scope;
    ASSERT_TRUE(row.graph.BeginFullSolve(job));
    allocations = scope.allocations();
  }
  EXPECT_EQ(allocations, 0u);
  job.Complete();
  EXPECT_TRUE(row.graph.ApplyFullSolve(job));
}

}  // namespace
}  // namespace msgraphs::core
