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
#include "mixed_mission.hpp"

namespace msgraphs::core {
namespace {

using namespace sgraph_test;  // NOLINT(google-build-using-namespace): test fixtures

TEST(SGraphOrder, AGraphRebuiltInAnotherOrderSolvesBitForBitAsBefore) {
  const MissionOutcome kept = RunMixedMission({});
  ASSERT_FALSE(HasFailure());
  const MissionOutcome rebuilt = RunMixedMission([](std::unique_ptr<SGraph>& g, std::size_t i) {
    if (i % 23 == 22) {
      EXPECT_TRUE(g->RebuildProblem());
    }
  });
  ASSERT_FALSE(HasFailure());
  // The mission reached what it is meant to exercise.
  EXPECT_GT(kept.stats.sparsified, 50u);
  EXPECT_GT(kept.stats.relative_factors[static_cast<std::size_t>(RelativePoseKind::kLoopClosure)], 0u);
  EXPECT_EQ(kept.stats.wall_wall_factors, 1u);
  EXPECT_EQ(kept.stats.plane_prior_factors, 1u);
  EXPECT_EQ(kept.stats.background_applied, 1u);
  ExpectSameOutcome(kept, rebuilt);
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
