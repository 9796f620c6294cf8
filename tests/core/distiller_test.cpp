// SPDX-License-Identifier: MIT
// Distillation (Distiller): walls with covariances and rooms, sent again only when changed; the
// walls' marginal covariances computed in the background (MarginalsTiming::kBackground) are the
// ones computed on the spot for the graph they copied, and the Update that uses them allocates
// nothing; what is distilled holds the robot's own evidence only, whatever came back to it.
#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <algorithm>
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
  double step_m = 0.5;  // along the room's x, from 0.5 m short of its centre

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
    const Eigen::Isometry3d T = T_room * test::PlanarPose(step_m * k - 0.5, 0.2, 0.1 * k);
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

// A wall whose observers were all sparsified away has no marginal (Ceres would call it
// certain): it is held back and counted, and the others' marginals still come.
TEST(Distiller, HoldsBackAWallNothingMeasuresAnyMore) {
  OneRoom f;
  f.config.max_keyframes = 8;
  f.config.local_window_keyframes = 2;
  f.config.sparsify_plane_share = 0;  // observations dropped with their keyframe, not carried
  f.step_m = 0.25;  // 12 keyframes inside the room
  ASSERT_TRUE(f.graph.Init(f.config));
  // Every keyframe also sees a wall of its own (parallel to wall 0, further out), so a full
  // store must take some wall's last observer.
  std::vector<std::uint32_t> own;
  for (int k = 0; k < 12; ++k) {
    ASSERT_NO_FATAL_FAILURE(f.AddKeyframe());
    const auto [n, d0] = f.Wall(0);
    const double d = d0 + 1.0 + k;
    own.push_back(*f.graph.AddPlane(n, d, PlaneClass::kWall));
    const Eigen::Isometry3d T = f.graph.keyframe_pose(f.keyframes.back());
    PlaneMeasurement z;
    z.normal = T.linear().transpose() * n;
    z.d = d + n.dot(T.translation());
    WallBasis(z.normal, z.basis_u, z.basis_v);
    z.covariance = Eigen::Matrix3d::Identity() * 1e-4;
    ASSERT_TRUE(f.graph.AddPlaneObservation(f.keyframes.back(), own.back(), z));
  }
  ASSERT_GT(f.graph.stats().planes_unobserved, 0u);
  DistillerConfig config;
  config.min_wall_observations = 1;  // share the single-observation walls too
  Distiller distiller;
  ASSERT_TRUE(distiller.Init(1, f.config, config));
  ASSERT_TRUE(distiller.Update(f.graph, f.planes));
  EXPECT_EQ(distiller.stats().walls_unobserved, f.graph.stats().planes_unobserved);
  EXPECT_EQ(distiller.stats().marginal_failures, 0u);
  std::size_t shared_own = 0;
  for (const DistilledWall& w : distiller.graph().walls) {
    EXPECT_GT(f.graph.plane(w.id).live_observations, 0u) << "wall " << w.id;
    EXPECT_GT(w.covariance.diagonal().minCoeff(), 1e-8) << "wall " << w.id;
    if (std::find(own.begin(), own.end(), w.id) != own.end()) ++shared_own;
  }
  EXPECT_EQ(distiller.graph().walls.size(), 4 + shared_own);
  EXPECT_EQ(shared_own + f.graph.stats().planes_unobserved, own.size());
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

// What CollabSession::PlanePriors makes of a peer's distilled walls (the two maps share a frame
// here): one prior per wall, its covariance as sent, `shift_m` added to its offset (a peer whose
// origin is off). The priors of the last call are replaced, as LocalMapper::SetPlanePriors does.
void FeedBack(SGraph& graph, const DistilledGraph& from, std::vector<std::uint32_t>& prior_ids,
              double shift_m = 0) {
  for (std::uint32_t id : prior_ids) ASSERT_TRUE(graph.RemoveFactor(id));
  prior_ids.clear();
  for (const DistilledWall& w : from.walls) {
    PlanePrior prior;
    prior.plane = w.id;
    prior.normal = w.normal;
    prior.d = w.d + shift_m;
    prior.covariance = w.covariance;
    auto id = graph.AddPlanePrior(prior);
    ASSERT_TRUE(id);
    prior_ids.push_back(*id);
  }
}

// The distilled graph holds this robot's own evidence only: `now` against `own` (what it sent
// before any prior), wall by wall and room by room.
void ExpectOwnEvidence(const DistilledGraph& now, const std::vector<DistilledWall>& own_walls,
                       const std::vector<DistilledRoom>& own_rooms, int round) {
  ASSERT_EQ(now.walls.size(), own_walls.size()) << "round " << round;
  for (std::size_t i = 0; i < own_walls.size(); ++i) {
    EXPECT_EQ(now.walls[i].id, own_walls[i].id);
    EXPECT_NEAR(now.walls[i].d, own_walls[i].d, 1e-5) << "round " << round << " wall " << i;
    EXPECT_GT(now.walls[i].normal.dot(own_walls[i].normal), 1 - 1e-9);
    EXPECT_TRUE(now.walls[i].covariance.isApprox(own_walls[i].covariance, 1e-3))
        << "round " << round << " wall " << i << "\n" << now.walls[i].covariance << "\nvs own\n"
        << own_walls[i].covariance;
  }
  ASSERT_EQ(now.rooms.size(), own_rooms.size());
  for (std::size_t i = 0; i < own_rooms.size(); ++i) {
    EXPECT_LT((now.rooms[i].centre - own_rooms[i].centre).norm(), 1e-5) << "round " << round;
    EXPECT_NEAR(now.rooms[i].size_x_m, own_rooms[i].size_x_m, 1e-5);
  }
}

// Rumour-free distillation (distiller.hpp): a robot whose walls come back to it as priors, from
// itself (an echo 3 cm off, the worst case) or through a peer that feeds them into its own map
// and distils again, sends what its own evidence says, round after round. A distiller that
// took the graph as it is would send walls twice as certain after the first round (the
// graph's marginals with the priors, checked beside) and pulled towards the echo.
TEST(Distiller, ARobotThatGetsItsOwnWallsBackSendsOnlyItsOwnEvidence) {
  DistillerConfig config;
  config.resend_covariance_ratio = 1e-9;  // every change goes out: nothing is hidden
  config.resend_distance_m = 1e-7;
  config.resend_angle_rad = 1e-7;
  // Robot a, and a peer b that saw the same room 2 cm further along x.
  OneRoom a, b;
  b.T_room.translation().x() += 0.02;
  // The graphs' own full solves must reach the optimum the own-evidence job's solve (no time
  // limit) reaches, also under qemu.
  for (OneRoom* f : {&a, &b}) {
    f->config.local_max_seconds = f->config.full_max_seconds = 600.0;
    ASSERT_TRUE(f->graph.Init(f->config));
  }
  for (OneRoom* f : {&a, &b}) {
    for (int k = 0; k < 3; ++k) f->AddKeyframe();
    f->AddRoom();
    ASSERT_TRUE(f->graph.Solve(SolveKind::kFull));
  }
  Distiller da, db;
  ASSERT_TRUE(da.Init(1, a.config, config));
  ASSERT_TRUE(db.Init(2, b.config, config));
  ASSERT_TRUE(da.Update(a.graph, a.planes));
  ASSERT_TRUE(db.Update(b.graph, b.planes));
  const std::vector<DistilledWall> own_a(da.graph().walls.begin(), da.graph().walls.end());
  const std::vector<DistilledRoom> own_ra(da.graph().rooms.begin(), da.graph().rooms.end());
  const std::vector<DistilledWall> own_b(db.graph().walls.begin(), db.graph().walls.end());
  const std::vector<DistilledRoom> own_rb(db.graph().rooms.begin(), db.graph().rooms.end());
  ASSERT_EQ(own_a.size(), 4u);
  ASSERT_EQ(own_ra.size(), 1u);

  // The echo: a's own walls back into a, 3 cm off. A distiller that has seen a before and a
  // fresh one (no memory of what a sent) both send the own evidence.
  std::vector<std::uint32_t> priors_a, priors_b;
  for (int round = 1; round <= 4; ++round) {
    ASSERT_NO_FATAL_FAILURE(FeedBack(a.graph, da.graph(), priors_a, 0.03));
    ASSERT_TRUE(a.graph.Solve(SolveKind::kFull));
    EXPECT_TRUE(a.graph.estimates_hold_priors());
    da.Update(a.graph, a.planes);
    ASSERT_NO_FATAL_FAILURE(ExpectOwnEvidence(da.graph(), own_a, own_ra, round));
    Distiller fresh;
    ASSERT_TRUE(fresh.Init(1, a.config, config));
    ASSERT_TRUE(fresh.Update(a.graph, a.planes));
    ASSERT_NO_FATAL_FAILURE(ExpectOwnEvidence(fresh.graph(), own_a, own_ra, round));
    EXPECT_EQ(fresh.stats().own_evidence_jobs, 1u);
  }
  EXPECT_EQ(da.stats().walls_awaiting_marginals + da.stats().walls_awaiting_estimates +
                da.stats().rooms_awaiting_estimates + da.stats().own_solve_failures +
                da.stats().own_solve_unconverged,
            0u);
  // The priors are in the graph: its estimates moved towards them, and its marginals are
  // about half its own (what it would have sent, had it distilled the graph as it is).
  std::vector<std::uint32_t> ids;
  for (const DistilledWall& w : own_a) ids.push_back(w.id);
  std::vector<Eigen::Matrix3d> with_priors(ids.size());
  ASSERT_TRUE(a.graph.PlaneMarginals(ids, with_priors));
  for (std::size_t i = 0; i < ids.size(); ++i) {
    EXPECT_GT(std::fabs(a.graph.plane(ids[i]).d - own_a[i].d), 0.005) << i;
    EXPECT_LT(with_priors[i](2, 2), 0.7 * own_a[i].covariance(2, 2)) << i;
  }
  EXPECT_EQ(da.stats().own_evidence_jobs, 4u);

  // Through a peer: b takes a's walls, a takes b's, four exchanges each way.
  for (int round = 1; round <= 4; ++round) {
    ASSERT_NO_FATAL_FAILURE(FeedBack(b.graph, da.graph(), priors_b));
    ASSERT_TRUE(b.graph.Solve(SolveKind::kFull));
    db.Update(b.graph, b.planes);
    ASSERT_NO_FATAL_FAILURE(ExpectOwnEvidence(db.graph(), own_b, own_rb, round));
    ASSERT_NO_FATAL_FAILURE(FeedBack(a.graph, db.graph(), priors_a));
    ASSERT_TRUE(a.graph.Solve(SolveKind::kFull));
    da.Update(a.graph, a.planes);
    ASSERT_NO_FATAL_FAILURE(ExpectOwnEvidence(da.graph(), own_a, own_ra, round));
  }
  // b's map agrees with a's walls now (the priors pulled it), yet b still sends its own 2 cm.
  EXPECT_NEAR(db.graph().walls[0].d, own_b[0].d, 1e-5);
  EXPECT_GT(std::fabs(own_b[0].d - own_a[0].d), 0.015);
  EXPECT_GT(std::fabs(b.graph.plane(own_b[0].id).d - own_b[0].d), 0.005);

  // The peer goes: b's priors are removed, but until a full solve its map still holds their
  // pull, and what it sends is still its own evidence. After the full solve the graph is
  // distilled as it is again, and says the same.
  // b distilled by a distiller that never saw it: its own evidence, from a job solved without
  // the priors (`own_jobs` 1) or from the graph as it is (0).
  const auto distil_b_afresh = [&](std::uint64_t own_jobs, int round) {
    Distiller fresh;
    ASSERT_TRUE(fresh.Init(2, b.config, config));
    ASSERT_TRUE(fresh.Update(b.graph, b.planes));
    ASSERT_NO_FATAL_FAILURE(ExpectOwnEvidence(fresh.graph(), own_b, own_rb, round));
    EXPECT_EQ(fresh.stats().own_evidence_jobs, own_jobs);
  };
  for (std::uint32_t id : priors_b) ASSERT_TRUE(b.graph.RemoveFactor(id));
  priors_b.clear();
  EXPECT_TRUE(b.graph.estimates_hold_priors());
  ASSERT_NO_FATAL_FAILURE(distil_b_afresh(1, 5));
  ASSERT_TRUE(b.graph.Solve(SolveKind::kFull));
  EXPECT_FALSE(b.graph.estimates_hold_priors());
  ASSERT_NO_FATAL_FAILURE(distil_b_afresh(0, 6));

  // The node's path: the job begun at the exchange and run on another thread gives the same.
  a.AddKeyframe();
  ASSERT_NO_FATAL_FAILURE(FeedBack(a.graph, db.graph(), priors_a));
  ASSERT_TRUE(a.graph.Solve(SolveKind::kFull));
  Distiller background, spot;
  ASSERT_TRUE(background.Init(1, a.config, config));
  ASSERT_TRUE(spot.Init(1, a.config, config));
  ASSERT_TRUE(background.BeginMarginals(a.graph));
  SGraphSolveJob* job = background.marginals_job();
  ASSERT_NE(job, nullptr);
  std::jthread worker([job] {
    if (job->TryClaim()) job->Run();
  });
  worker.join();
  ASSERT_TRUE(background.Update(a.graph, a.planes, MarginalsTiming::kBackground));
  ASSERT_TRUE(spot.Update(a.graph, a.planes, MarginalsTiming::kNow));
  const std::vector<DistilledWall> spot_walls(spot.graph().walls.begin(), spot.graph().walls.end());
  const std::vector<DistilledRoom> spot_rooms(spot.graph().rooms.begin(), spot.graph().rooms.end());
  ASSERT_EQ(spot_walls.size(), 4u);
  ASSERT_EQ(spot_rooms.size(), 1u);
  ASSERT_NO_FATAL_FAILURE(ExpectOwnEvidence(background.graph(), spot_walls, spot_rooms, 0));
  EXPECT_EQ(background.stats().own_evidence_jobs, 1u);
  EXPECT_TRUE(a.graph.Init(a.config));  // nothing borrowed any more
}

}  // namespace
}  // namespace msgraphs::core
