// SPDX-License-Identifier: MIT
// Keyframe slots reused after sparsification: the time-ordered walk (FirstKeyframe /
// NextKeyframe), and SGraph::RemoveKeyframe, the removal a caller asks for (what it refuses and
// what it must never lose). That it removes as sparsification does:
// SGraphSparsification.RemovingAKeyframeOnRequestIsSparsifyingIt (s_graph_sparsify_test.cpp).
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <array>
#include <cstdint>

#include "msgraphs/core/graph/s_graph.hpp"
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

}  // namespace
}  // namespace msgraphs::core
