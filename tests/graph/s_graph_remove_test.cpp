// SPDX-License-Identifier: MIT
// Keyframe slots reused after sparsification: the time-ordered walk (FirstKeyframe /
// NextKeyframe), and SGraph::RemoveKeyframe, the removal a caller asks for (what it refuses and
// what it must never lose), and planes whose observers go. That it removes as sparsification
// does: SGraphSparsification.RemovingAKeyframeOnRequestIsSparsifyingIt (s_graph_sparsify_test.cpp).
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <array>
#include <cstdint>
#include <random>
#include <vector>

#include "msgraphs/core/graph/s_graph.hpp"
#include "msgraphs/core/graph/s_graph_solve_job.hpp"
#include "s_graph_fixtures.hpp"

namespace msgraphs::core {
namespace {

using namespace sgraph_test;  // NOLINT(google-build-using-namespace): test fixtures

// A store of 16 with a local window of 3.
SGraphConfig SmallStore() {
  SGraphConfig config;
  config.max_keyframes = 16;
  config.local_window_keyframes = 3;
  return config;
}

// Keyframes 0..count-1 a metre apart along x, chained by exact odometry except into keyframe
// `cut` (no measurement there; 0: none cut). Keyframes from `aside_from` on start 0.3 m aside
// in y.
void StraightLine(SGraph& g, std::uint32_t count, std::uint32_t cut, std::uint32_t aside_from) {
  Eigen::Isometry3d step = Eigen::Isometry3d::Identity();
  step.translation().x() = 1;
  for (std::uint32_t i = 0; i < count; ++i) {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.translation() << i, i >= aside_from ? 0.3 : 0.0, 0;
    ASSERT_TRUE(g.AddKeyframe(i, T));
    if (i > 0 && i != cut) {
      ASSERT_TRUE(
          g.AddRelativePose(i - 1, i, step, OdometryInformation(), RelativePoseKind::kOdometry));
    }
  }
}

// Sparsified keyframes free their slots and later keyframes take them, so slot order stops being
// time order: the time-ordered walk must still give every active keyframe once, oldest first.
TEST(SGraphKeyframes, AreWalkedInTimeOrderOnceSlotsAreReused) {
  SGraphConfig config;
  config.max_keyframes = 12;
  config.local_window_keyframes = 4;
  SGraph g;
  ASSERT_TRUE(g.Init(config));
  EXPECT_EQ(g.FirstKeyframe(), SGraph::kNoKeyframe);
  const Room room;
  const Walk walk(room, 60);
  std::uint32_t prev = 0;
  for (std::size_t i = 0; i < walk.truth.size(); ++i) {
    const std::uint32_t k = *g.AddKeyframe(static_cast<double>(i), walk.truth[i]);
    if (i > 0) {
      ASSERT_TRUE(g.AddRelativePose(prev, k, walk.odometry[i - 1].inverse() * walk.odometry[i],
                                    OdometryInformation(), RelativePoseKind::kOdometry));
    }
    prev = k;
    std::size_t walked = 0;
    double last_stamp = -1;
    for (std::uint32_t w = g.FirstKeyframe(); w != SGraph::kNoKeyframe; w = g.NextKeyframe(w)) {
      ASSERT_TRUE(g.keyframe_active(w));
      ASSERT_GT(g.keyframe_stamp(w), last_stamp) << "after " << i << " keyframes";
      last_stamp = g.keyframe_stamp(w);
      ++walked;
    }
    ASSERT_EQ(walked, g.stats().keyframes);
    EXPECT_EQ(last_stamp, static_cast<double>(i));  // the newest is last
  }
  EXPECT_EQ(g.keyframe_stamp(g.FirstKeyframe()), 0.0);  // the origin is first
  // The walk was tested where it matters: some slot holds a newer keyframe than a later slot.
  bool slot_order_is_time_order = true;
  for (std::uint32_t k = 1; k < g.keyframe_slots(); ++k) {
    if (g.keyframe_active(k - 1) && g.keyframe_active(k) &&
        g.keyframe_stamp(k - 1) > g.keyframe_stamp(k))
      slot_order_is_time_order = false;
  }
  EXPECT_FALSE(slot_order_is_time_order);
  // A sparsified slot not yet reused (the last keyframe made room by freeing one), or one past
  // the slots handed out, has no successor.
  std::size_t free_slots = 0;
  for (std::uint32_t k = 0; k < g.keyframe_slots(); ++k) {
    if (g.keyframe_active(k)) continue;
    ++free_slots;
    EXPECT_EQ(g.NextKeyframe(k), SGraph::kNoKeyframe) << "freed slot " << k;
  }
  EXPECT_EQ(free_slots, 1u);
  EXPECT_EQ(g.NextKeyframe(static_cast<std::uint32_t>(g.keyframe_slots())), SGraph::kNoKeyframe);
}

// Never the origin, the local window, or what is not there; the chain joined over each removal.
TEST(SGraphRemoveKeyframe, NeverTheOriginOrTheWindowAndTheChainIsJoined) {
  // Estimates start off the truth (keyframes 3-5 0.3 m aside): only a joined chain brings them
  // back.
  SGraph g;
  ASSERT_TRUE(g.Init(SmallStore()));
  EXPECT_EQ(g.RemoveKeyframe(0).error().code, Errc::kNotFound);
  ASSERT_NO_FATAL_FAILURE(StraightLine(g, 6, 0, 3));
  EXPECT_EQ(g.RemoveKeyframe(0).error().code, Errc::kInvalidArgument);  // the origin
  for (std::uint32_t k : {3u, 4u, 5u}) {  // the window
    EXPECT_EQ(g.RemoveKeyframe(k).error().code, Errc::kInvalidArgument) << k;
  }
  EXPECT_EQ(g.RemoveKeyframe(6).error().code, Errc::kNotFound);
  EXPECT_EQ(g.stats().removed_keyframes, 0u);
  const auto composed = [&g] {
    return g.stats().relative_factors[static_cast<std::size_t>(RelativePoseKind::kSparsified)];
  };
  EXPECT_TRUE(g.RemoveKeyframe(2));
  EXPECT_EQ(composed(), 1u);  // 1 -> 3
  EXPECT_EQ(g.RemoveKeyframe(2).error().code, Errc::kNotFound);  // once
  EXPECT_EQ(g.NextKeyframe(2), SGraph::kNoKeyframe);
  EXPECT_TRUE(g.RemoveKeyframe(1));
  EXPECT_EQ(composed(), 1u);  // 0 -> 3, from 0 -> 1 and the composed 1 -> 3
  EXPECT_EQ(g.stats().keyframes, 4u);
  EXPECT_EQ(g.stats().removed_keyframes, 2u);
  EXPECT_EQ(g.NextKeyframe(0), 3u);  // the chain joined over both
  auto report = g.Solve(SolveKind::kFull);
  ASSERT_TRUE(report);
  EXPECT_TRUE(report->usable);
  for (std::uint32_t k : {3u, 4u, 5u}) {
    EXPECT_LT((g.keyframe_pose(k).translation() - Eigen::Vector3d(k, 0, 0)).norm(), 1e-6) << k;
  }
}

// A removal on request never loses a constraint, and keeps the keyframes of loops the caller
// still has to judge (a carried loop is another factor: it may take another id or be fused).
TEST(SGraphRemoveKeyframe, LosesNothing) {
  SGraph g;
  ASSERT_TRUE(g.Init(SmallStore()));
  ASSERT_NO_FATAL_FAILURE(StraightLine(g, 7, 3, 7));  // no measurement from 2 to 3: cut there
  Eigen::Isometry3d two = Eigen::Isometry3d::Identity();
  two.translation().x() = 2;
  const auto loop = g.AddRelativePose(1, 3, two, LoopInformation(), RelativePoseKind::kLoopClosure);
  ASSERT_TRUE(loop);
  EXPECT_EQ(g.RemoveKeyframe(2).error().code, Errc::kInvalidArgument);  // its hop into 3 is cut
  EXPECT_EQ(g.RemoveKeyframe(3).error().code, Errc::kInvalidArgument);  // so is its own
  const std::array<std::uint32_t, 1> judging{*loop};
  EXPECT_EQ(g.RemoveKeyframe(1, judging).error().code, Errc::kInvalidArgument);
  EXPECT_EQ(g.stats().removed_keyframes, 0u);
  ASSERT_TRUE(g.RemoveKeyframe(1));  // its loop to 3 is carried to keyframe 0 or 2
  EXPECT_EQ(g.stats().sparsify_carried, 1u);
  EXPECT_EQ(g.stats().sparsify_dropped, 0u);
  EXPECT_EQ(g.stats().relative_factors[static_cast<std::size_t>(RelativePoseKind::kLoopClosure)], 1u);
  auto report = g.Solve(SolveKind::kFull);
  ASSERT_TRUE(report);
  EXPECT_TRUE(report->usable);
}

// A carried loop is never fused into a loop the caller keeps: that one must keep its id and its
// measurement until judged.
TEST(SGraphRemoveKeyframe, NeverFusesIntoAKeptLoop) {
  for (const bool keep : {false, true}) {
    SGraph g;
    ASSERT_TRUE(g.Init(SmallStore()));
    ASSERT_NO_FATAL_FAILURE(StraightLine(g, 7, 0, 7));
    Eigen::Isometry3d one = Eigen::Isometry3d::Identity(), two = one;
    one.translation().x() = 1;
    two.translation().x() = 2;
    const auto judged = g.AddRelativePose(1, 3, two, LoopInformation(), RelativePoseKind::kLoopClosure);
    ASSERT_TRUE(judged);
    ASSERT_TRUE(g.AddRelativePose(2, 3, one, LoopInformation(), RelativePoseKind::kLoopClosure));
    // Keyframe 2's loop to 3 can only go through the hop to 1: as 3 -> 1, parallel to `judged`.
    const std::array<std::uint32_t, 1> kept{*judged};
    ASSERT_TRUE(g.RemoveKeyframe(2, keep ? std::span<const std::uint32_t>(kept)
                                         : std::span<const std::uint32_t>()));
    EXPECT_EQ(g.stats().sparsify_carried, 1u);
    EXPECT_EQ(g.stats().sparsify_merged, keep ? 0u : 1u) << "kept: " << keep;
    EXPECT_EQ(g.stats().relative_factors[static_cast<std::size_t>(RelativePoseKind::kLoopClosure)],
              keep ? 2u : 1u);
    if (keep) {
      EXPECT_TRUE(g.RemoveFactor(*judged));  // still there, under its id
    }
  }
}

// With carrying off (sparsify_plane_share 0) plane observations go with their keyframe. A plane
// whose every observer went would stay in the problem unmeasured, where Ceres gives it a zero
// covariance: a removal on request never takes a plane's last observer, and its marginal is
// refused. With carrying on (the default) the last observer goes like any other keyframe and
// its observation goes to a neighbour.
SGraphConfig DroppingStore() {
  SGraphConfig config = SmallStore();
  config.sparsify_plane_share = 0;
  return config;
}

class SGraphPlaneObservers : public ::testing::Test {
 protected:
  SGraphConfig config = DroppingStore();
  // StraightLine's line, as far as a store of 16 lets it grow; every keyframe sees wall
  // `seen_by_all` when added; keyframe `only` alone sees wall `seen_once` (`times` times: two
  // segments of one wall in one scan are two observations). ids[i]: keyframe i's.
  void Build(std::uint32_t count, std::uint32_t only, int times = 1) {
    ASSERT_TRUE(g.Init(config));
    seen_by_all = *g.AddPlane(all.n, all.d, PlaneClass::kWall);
    seen_once = *g.AddPlane(once.n, once.d, PlaneClass::kWall);
    Eigen::Isometry3d step = Eigen::Isometry3d::Identity();
    step.translation().x() = 1;
    for (std::uint32_t i = 0; i < count; ++i) {
      Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
      T.translation().x() = i;
      const auto k = g.AddKeyframe(i, T);
      ASSERT_TRUE(k);
      if (i > 0) {
        ASSERT_TRUE(
            g.AddRelativePose(ids.back(), *k, step, OdometryInformation(), RelativePoseKind::kOdometry));
      }
      ids.push_back(*k);
      Observe(*k, seen_by_all, all);
      for (int t = 0; t < times && i == only; ++t) Observe(*k, seen_once, once);
    }
  }
  void Observe(std::uint32_t k, std::uint32_t plane, const TruePlane& truth) {
    ASSERT_TRUE(g.AddPlaneObservation(k, plane, Measure(truth, g.keyframe_pose(k), rng, 0.01)));
  }
  const TruePlane all{Eigen::Vector3d::UnitY(), 2.0}, once{-Eigen::Vector3d::UnitX(), 40.0};
  std::mt19937 rng{7};
  SGraph g;
  std::uint32_t seen_by_all = 0, seen_once = 0;
  std::vector<std::uint32_t> ids;
};

TEST_F(SGraphPlaneObservers, ARemovalOnRequestNeverTakesTheLastObserver) {
  ASSERT_NO_FATAL_FAILURE(Build(7, 2));
  EXPECT_EQ(g.plane(seen_once).live_observations, 1u);
  const Status refused = g.RemoveKeyframe(2);
  ASSERT_FALSE(refused);
  EXPECT_EQ(refused.error().code, Errc::kInvalidArgument);
  ASSERT_NO_FATAL_FAILURE(Observe(1, seen_once, once));  // a second observer
  ASSERT_TRUE(g.RemoveKeyframe(2));
  EXPECT_EQ(g.plane(seen_once).observations, 2u);       // ever
  EXPECT_EQ(g.plane(seen_once).live_observations, 1u);  // now: keyframe 1's
  EXPECT_EQ(g.plane(seen_by_all).live_observations, 6u);
  const std::array<std::uint32_t, 2> both{seen_by_all, seen_once};
  std::array<Eigen::Matrix3d, 2> covariances{};
  ASSERT_TRUE(g.PlaneMarginals(both, covariances));
  for (const Eigen::Matrix3d& c : covariances) EXPECT_GT(c.diagonal().minCoeff(), 1e-8);
  EXPECT_EQ(g.stats().planes_unobserved, 0u);
}

TEST_F(SGraphPlaneObservers, SparsificationTakesALastObserverAfterTheOthersOfItsTier) {
  // Keyframe 1 would be the first victim (hops all alike: the oldest wins the tie), but it is
  // the only one to see `seen_once` (twice): 40 keyframes through a store of 16 leave it.
  ASSERT_NO_FATAL_FAILURE(Build(40, 1, 2));
  EXPECT_GT(g.stats().sparsified, 20u);
  EXPECT_TRUE(g.keyframe_active(ids[1]));
  EXPECT_EQ(g.keyframe_stamp(ids[1]), 1.0);
  EXPECT_EQ(g.plane(seen_once).live_observations, 2u);
  EXPECT_EQ(g.stats().planes_unobserved, 0u);

  // Every keyframe the only one to see its wall: sparsification must still make room, and the
  // walls it leaves unmeasured are counted, keep their estimate, and have no marginal. Keyframe
  // 5 sees no wall but closes a loop to the origin: a loop weighs more than a wall seen once,
  // so it stays while walls' only observers go.
  SGraph h;
  ASSERT_TRUE(h.Init(DroppingStore()));
  std::vector<std::uint32_t> walls;
  std::vector<double> offsets_m;
  std::uint32_t prev = 0;
  const std::size_t count = 24;
  for (std::uint32_t i = 0; i < count; ++i) {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.translation() << i, 0, 0;
    const auto k = h.AddKeyframe(i, T);
    ASSERT_TRUE(k);
    if (i > 0) {
      Eigen::Isometry3d step = Eigen::Isometry3d::Identity();
      step.translation().x() = 1;
      ASSERT_TRUE(h.AddRelativePose(prev, *k, step, OdometryInformation(), RelativePoseKind::kOdometry));
    }
    prev = *k;
    if (i == 5) {
      Eigen::Isometry3d five = Eigen::Isometry3d::Identity();
      five.translation().x() = 5;
      ASSERT_TRUE(h.AddRelativePose(0, *k, five, LoopInformation(), RelativePoseKind::kLoopClosure));
    }
    const TruePlane wall{-Eigen::Vector3d::UnitX(), i + 2.0};  // 2 m ahead of keyframe i
    if (i == 5) continue;
    walls.push_back(*h.AddPlane(wall.n, wall.d, PlaneClass::kWall));
    offsets_m.push_back(wall.d);
    ASSERT_TRUE(h.AddPlaneObservation(*k, walls.back(), Measure(wall, T, rng, 0.01)));
  }
  const std::size_t removed = h.stats().sparsified;
  EXPECT_EQ(removed, count - 16);
  EXPECT_EQ(h.stats().planes_unobserved, removed);
  std::size_t unobserved = 0;
  for (std::size_t i = 0; i < walls.size(); ++i) {
    const MapPlane p = h.plane(walls[i]);
    if (p.live_observations > 0) continue;
    ++unobserved;
    EXPECT_TRUE(p.active);
    EXPECT_NEAR(p.d, offsets_m[i], 1e-9);  // never moved: nothing measures it
    const std::array<std::uint32_t, 1> one{walls[i]};
    std::array<Eigen::Matrix3d, 1> covariance{};
    const Status s = h.PlaneMarginals(one, covariance);
    ASSERT_FALSE(s);
    EXPECT_EQ(s.error().code, Errc::kInvalidArgument);
    SGraphSolveJob job;
    const Status begun = h.BeginPlaneMarginals(job, one, PlaneEvidence::kOwn);
    ASSERT_FALSE(begun);
    EXPECT_EQ(begun.error().code, Errc::kInvalidArgument);
  }
  EXPECT_EQ(unobserved, removed);
  EXPECT_EQ(h.stats().sparsified_with_loops, 0u);
  EXPECT_TRUE(h.keyframe_active(5));
  EXPECT_EQ(h.keyframe_stamp(5), 5.0);
  const std::array<std::uint32_t, 1> newest{walls.back()};
  std::array<Eigen::Matrix3d, 1> covariance{};
  ASSERT_TRUE(h.PlaneMarginals(newest, covariance));  // the observed ones still have one
  EXPECT_GT(covariance[0].diagonal().minCoeff(), 1e-8);
}

TEST_F(SGraphPlaneObservers, CarriedTheLastObserverGoesAndItsWallStaysMeasured) {
  config = SmallStore();
  ASSERT_NO_FATAL_FAILURE(Build(7, 2));
  ASSERT_TRUE(g.RemoveKeyframe(2));
  EXPECT_EQ(g.plane(seen_once).live_observations, 1u);  // now a neighbour's
  EXPECT_EQ(g.plane(seen_by_all).live_observations, 6u);  // 2's fused into the neighbour's
  EXPECT_EQ(g.stats().sparsify_planes_carried, 2u);
  EXPECT_EQ(g.stats().sparsify_planes_fused, 1u);
  EXPECT_EQ(g.stats().planes_unobserved, 0u);
  const std::array<std::uint32_t, 2> both{seen_by_all, seen_once};
  std::array<Eigen::Matrix3d, 2> covariances{};
  ASSERT_TRUE(g.PlaneMarginals(both, covariances));
  for (const Eigen::Matrix3d& c : covariances) EXPECT_GT(c.diagonal().minCoeff(), 1e-8);
}

TEST_F(SGraphPlaneObservers, CarriedSparsificationTakesALastObserverLikeAnyOther) {
  // 40 keyframes through a store of 16: keyframe 1, the only one to see `seen_once` (twice),
  // is not held back as its last observer: it goes in its turn like any other, and the wall
  // stays measured through its carried observations.
  config = SmallStore();
  ASSERT_NO_FATAL_FAILURE(Build(40, 1, 2));
  EXPECT_FALSE(g.keyframe_active(ids[1]) && g.keyframe_stamp(ids[1]) == 1.0);
  EXPECT_GT(g.stats().sparsified, 20u);
  EXPECT_EQ(g.stats().planes_unobserved, 0u);
  EXPECT_GE(g.plane(seen_once).live_observations, 1u);
  EXPECT_EQ(g.stats().sparsify_planes_dropped, 0u);
  EXPECT_TRUE(g.Solve(SolveKind::kFull));
  EXPECT_NEAR(g.plane(seen_once).d, once.d, 0.05);
  EXPECT_NEAR(g.plane(seen_by_all).d, all.d, 0.05);
}

}  // namespace
}  // namespace msgraphs::core
