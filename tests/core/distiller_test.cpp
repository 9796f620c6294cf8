// SPDX-License-Identifier: MIT
// Distillation (Distiller): walls with covariances and rooms, sent again only when changed; the
// walls' marginal covariances computed in the background (MarginalsTiming::kBackground) are the
// ones computed on the spot for the graph they copied, and the Update that uses them allocates
// nothing.
#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <cmath>
#include <numbers>
#include <thread>
#include <vector>

#include "alloc_counter.hpp"
#include "msgraphs/core/collab/distilled_codec.hpp"
#include "msgraphs/core/collab/distiller.hpp"
#include "msgraphs/core/geometry/se3.hpp"
#include "msgraphs/core/graph/s_graph_solve_job.hpp"
#include "synthetic_clouds.hpp"

namespace msgraphs::core {
namespace {

// A 6 x 4 m room at T_room seen by keyframes walking across it, each seeing its four walls at
// 1 cm, with the room node on them.
struct OneRoom {
  SGraph graph;
  SGraphConfig config;
  PlaneMapper planes;
  Eigen::Isometry3d T_room = test::PlanarPose(2, 3, 0.3);
  std::vector<std::uint32_t> walls, keyframes;

  OneRoom() {
    EXPECT_TRUE(graph.Init(config));
    EXPECT_TRUE(planes.Init(64, {}));
  }
  std::pair<Eigen::Vector3d, double> Wall(std::size_t w) const {
    const Eigen::Vector3d ex = T_room.linear().col(0), ey = T_room.linear().col(1);
    const Eigen::Vector3d c = T_room.translation();
    const std::pair<Eigen::Vector3d, double> faces[4] = {{ex, 3}, {-ex, 3}, {ey, 2}, {-ey, 2}};
    const Eigen::Vector3d& n = faces[w].first;
    return {n, -n.dot(c - n * faces[w].second)};
  }
  void AddKeyframe() {
    const int k = static_cast<int>(keyframes.size());
    const Eigen::Isometry3d T = T_room * test::PlanarPose(0.5 * k - 0.5, 0.2, 0.1 * k);
    const std::uint32_t kf = *graph.AddKeyframe(k, T);
    if (k > 0) {
      ASSERT_TRUE(graph.AddRelativePose(keyframes.back(), kf,
                                        graph.keyframe_pose(keyframes.back()).inverse() * T,
                                        Matrix6d::Identity() * 1e4, RelativePoseKind::kOdometry));
    }
    keyframes.push_back(kf);
    for (std::size_t w = 0; w < 4; ++w) {
      const auto [n, d] = Wall(w);
      if (k == 0) walls.push_back(*graph.AddPlane(n, d, PlaneClass::kWall));
      PlaneMeasurement z;
      z.normal = T.linear().transpose() * n;
      z.d = d + n.dot(T.translation());
      WallBasis(z.normal, z.basis_u, z.basis_v);
      z.covariance = Eigen::Matrix3d::Identity() * 1e-4;
      ASSERT_TRUE(graph.AddPlaneObservation(kf, walls[w], z));
    }
  }
  void AddRoom() {
    MapRoom room;
    room.centre = T_room.translation().head<2>();
    for (std::size_t w = 0; w < 4; ++w) room.walls[w] = static_cast<std::int32_t>(walls[w]);
    ASSERT_TRUE(graph.AddRoom(room));
  }
};

TEST(Distiller, SharesWallsWithCovariancesAndRoomsOnlyWhenChanged) {
  OneRoom f;
  for (int k = 0; k < 3; ++k) f.AddKeyframe();
  f.AddRoom();
  Distiller distiller;
  ASSERT_TRUE(distiller.Init(1, f.config, {}));
  ASSERT_TRUE(distiller.Update(f.graph, f.planes));
  const DistilledGraph& g = distiller.graph();
  EXPECT_EQ(g.version, 1u);
  ASSERT_EQ(g.walls.size(), 4u);
  ASSERT_EQ(g.rooms.size(), 1u);
  for (const DistilledWall& w : g.walls) {
    EXPECT_EQ(Eigen::LLT<Eigen::Matrix3d>(w.covariance).info(), Eigen::Success);
    // Three observations at 1 cm, 3-4 m from the map origin: the offset there is known to a few cm.
    EXPECT_LT(w.covariance(2, 2), 1e-3);
  }
  EXPECT_NEAR(g.rooms[0].size_x_m, 6.0, 1e-6);
  EXPECT_NEAR(g.rooms[0].size_y_m, 4.0, 1e-6);
  EXPECT_NEAR(std::remainder(g.rooms[0].yaw_rad - 0.3, std::numbers::pi / 2), 0.0, 1e-6);
  // Nothing changed: no new version, nothing to send.
  EXPECT_FALSE(distiller.Update(f.graph, f.planes));
  std::vector<std::uint8_t> buffer(4096);
  EXPECT_EQ(*EncodeDistilled(g, g.version, buffer),
            kDistilledHeaderBytes + 4);  // no floor in this graph
  // Without marginals, distilling and encoding allocate nothing (distiller.hpp,
  // distilled_codec.hpp); with them computed here (kNow), ceres::Covariance does.
  DistillerConfig conditional;
  conditional.marginal_covariances = false;
  Distiller plain;
  ASSERT_TRUE(plain.Init(1, f.config, conditional));
  {
    test::AllocationScope scope;
    EXPECT_TRUE(plain.Update(f.graph, f.planes));
    EXPECT_FALSE(plain.Update(f.graph, f.planes));
    EXPECT_TRUE(EncodeDistilled(plain.graph(), 0, buffer));
    EXPECT_EQ(scope.allocations(), 0u);
  }
  EXPECT_EQ(plain.graph().walls.size(), 4u);
}

// What the node does: the exchange begins the marginals of the map as it is
// (BeginMarginals), the marginals thread runs them, the exchange goes out when they are done
// (Update, kBackground) with those covariances and the estimates of that moment. A wall that
// became shareable in between waits for the next exchange, never goes out with its
// conditional covariance.
TEST(Distiller, MarginalsFromTheBackgroundAreTheOnSpotOnesOfTheGraphTheyCopied) {
  OneRoom f;
  for (int k = 0; k < 3; ++k) f.AddKeyframe();
  f.AddRoom();
  // Every change of covariance is sent, so that the two distillers' walls show what each
  // computed (the resend thresholds would otherwise hide a difference).
  DistillerConfig config;
  config.resend_covariance_ratio = 1e-9;
  Distiller reference, background;
  ASSERT_TRUE(reference.Init(1, f.config, config));
  ASSERT_TRUE(background.Init(1, f.config, config));
  const DistilledGraph& sent = background.graph();
  const DistilledGraph& spot = reference.graph();
  // The marginals as computed on the spot for the graph now; the background job copies it.
  ASSERT_TRUE(reference.Update(f.graph, f.planes));
  ASSERT_TRUE(background.BeginMarginals(f.graph));
  EXPECT_FALSE(background.marginals_ready());
  EXPECT_FALSE(background.BeginMarginals(f.graph));  // one at a time
  SGraphSolveJob* job = background.marginals_job();
  ASSERT_NE(job, nullptr);
  // Meanwhile the graph goes on (the job runs on its copy) ...
  std::jthread worker([job] {
    if (job->TryClaim()) job->Run();
  });
  for (int k = 0; k < 3; ++k) f.AddKeyframe();
  ASSERT_TRUE(f.graph.Solve(SolveKind::kLocal));
  worker.join();
  EXPECT_TRUE(background.marginals_ready());
  EXPECT_EQ(background.marginals_job(), nullptr);  // run: nothing left to claim
  // ... and the exchange sends the walls with the marginals of the graph it copied, without
  // allocating: the factorisation ran on the worker.
  bool changed = false;
  {
    test::AllocationScope scope;
    changed = background.Update(f.graph, f.planes, MarginalsTiming::kBackground);
    EXPECT_EQ(scope.allocations(), 0u);
  }
  EXPECT_TRUE(changed);
  EXPECT_EQ(background.stats().marginals_run_at_update, 0u);
  EXPECT_EQ(background.stats().walls_awaiting_marginals, 0u);
  ASSERT_EQ(sent.walls.size(), 4u);
  ASSERT_EQ(sent.rooms.size(), 1u);
  for (std::size_t i = 0; i < 4; ++i) {
    EXPECT_EQ(sent.walls[i].id, spot.walls[i].id);
    EXPECT_TRUE(sent.walls[i].covariance.isApprox(spot.walls[i].covariance, 1e-9))
        << sent.walls[i].covariance << "\nvs\n" << spot.walls[i].covariance;
  }
  const std::vector<DistilledWall> at_three(sent.walls.begin(), sent.walls.end());

  // Nobody runs the next job: the exchange runs it itself, with the same result.
  EXPECT_TRUE(reference.Update(f.graph, f.planes));
  ASSERT_TRUE(background.BeginMarginals(f.graph));
  // A fifth wall becomes shareable after the copy: it waits for the next exchange.
  const Eigen::Vector3d n(std::cos(0.3 + 0.7), std::sin(0.3 + 0.7), 0);
  const std::uint32_t pillar = *f.graph.AddPlane(n, -1.0, PlaneClass::kWall);
  for (std::uint32_t kf : f.keyframes) {
    const Eigen::Isometry3d T = f.graph.keyframe_pose(kf);
    PlaneMeasurement z;
    z.normal = T.linear().transpose() * n;
    z.d = -1.0 + n.dot(T.translation());
    WallBasis(z.normal, z.basis_u, z.basis_v);
    z.covariance = Eigen::Matrix3d::Identity() * 1e-4;
    ASSERT_TRUE(f.graph.AddPlaneObservation(kf, pillar, z));
  }
  EXPECT_TRUE(background.Update(f.graph, f.planes, MarginalsTiming::kBackground));
  EXPECT_EQ(background.stats().marginals_run_at_update, 1u);
  EXPECT_EQ(background.stats().walls_awaiting_marginals, 1u);
  ASSERT_EQ(sent.walls.size(), 4u);
  for (std::size_t i = 0; i < 4; ++i) {
    EXPECT_TRUE(sent.walls[i].covariance.isApprox(spot.walls[i].covariance, 1e-9)) << i;
    EXPECT_FALSE(sent.walls[i].covariance.isApprox(at_three[i].covariance, 1e-6)) << i;
  }
  // The next exchange has its marginal.
  ASSERT_TRUE(background.BeginMarginals(f.graph));
  background.Update(f.graph, f.planes, MarginalsTiming::kBackground);
  EXPECT_EQ(sent.walls.size(), 5u);
  // Unchanged graph: nothing to begin, nothing new to send.
  EXPECT_FALSE(background.BeginMarginals(f.graph));
  EXPECT_FALSE(background.Update(f.graph, f.planes, MarginalsTiming::kBackground));
  // A kNow exchange computes its own: a job begun before is released, not run.
  f.AddKeyframe();
  const std::uint64_t run_here = background.stats().marginals_run_at_update;
  ASSERT_TRUE(background.BeginMarginals(f.graph));
  EXPECT_TRUE(background.Update(f.graph, f.planes, MarginalsTiming::kNow));
  EXPECT_EQ(background.stats().marginals_run_at_update, run_here);
  EXPECT_EQ(background.marginals_job(), nullptr);
  EXPECT_TRUE(reference.Update(f.graph, f.planes));
  for (std::size_t i = 0; i < 4; ++i)
    EXPECT_TRUE(sent.walls[i].covariance.isApprox(spot.walls[i].covariance, 1e-9)) << i;
  // The graph lends nothing any more: it can be re-initialised.
  EXPECT_TRUE(f.graph.Init(f.config));
}

}  // namespace
}  // namespace msgraphs::core
