// SPDX-License-Identifier: MIT
// Preprocessing: k-d tree against brute force, voxel grid and its overflow policy, range filter,
// normals and covariances on known planes, deskewing a sweep taken while moving, and zero
// allocation per call after Init.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>
#include <random>

#include "alloc_counter.hpp"
#include "msgraphs/core/geometry/se3.hpp"
#include "msgraphs/core/perception/covariances.hpp"
#include "msgraphs/core/perception/deskew.hpp"
#include "msgraphs/core/perception/kdtree.hpp"
#include "msgraphs/core/perception/voxel_grid.hpp"
#include "synthetic_clouds.hpp"

namespace msgraphs::core {
namespace {

std::vector<Eigen::Vector3f> RandomPoints(std::size_t n, std::uint32_t seed, float extent = 10.0f) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(-extent, extent);
  std::vector<Eigen::Vector3f> p(n);
  for (auto& q : p) q = {u(rng), u(rng), u(rng)};
  return p;
}

TEST(KdTree, KnnEqualsBruteForce) {
  const auto points = RandomPoints(5000, 1);
  KdTree tree;
  tree.Init(8000);
  ASSERT_TRUE(tree.Build(points));
  const auto queries = RandomPoints(200, 2, 12.0f);
  std::uint32_t idx[20];
  float d2[20];
  for (const auto& q : queries) {
    const std::size_t n = tree.Knn(q, 20, idx, d2);
    ASSERT_EQ(n, 20u);
    std::vector<float> all;
    for (const auto& p : points) all.push_back((p - q).squaredNorm());
    std::sort(all.begin(), all.end());
    for (std::size_t i = 0; i < 20; ++i) {
      EXPECT_FLOAT_EQ(d2[i], all[i]);
      EXPECT_FLOAT_EQ((points[idx[i]] - q).squaredNorm(), d2[i]);
    }
  }
  // Radius limit, duplicates, the empty tree.
  EXPECT_EQ(tree.Knn(Eigen::Vector3f(100, 100, 100), 5, idx, d2, 1.0f), 0u);
  std::vector<Eigen::Vector3f> same(50, Eigen::Vector3f(1, 2, 3));
  ASSERT_TRUE(tree.Build(same));
  EXPECT_EQ(tree.Knn(Eigen::Vector3f(1, 2, 3), 10, idx, d2), 10u);
  EXPECT_EQ(d2[9], 0.0f);
  ASSERT_TRUE(tree.Build({}));
  EXPECT_EQ(tree.Knn(Eigen::Vector3f(0, 0, 0), 3, idx, d2), 0u);
}

TEST(KdTree, RejectsTooManyAndNonFinitePoints) {
  KdTree tree;
  tree.Init(10);
  EXPECT_EQ(tree.Build(RandomPoints(11, 3)).error().code, Errc::kCapacityExceeded);
  auto p = RandomPoints(5, 3);
  p[2].x() = std::numeric_limits<float>::quiet_NaN();
  EXPECT_EQ(tree.Build(p).error().code, Errc::kInvalidArgument);
}

TEST(VoxelGrid, CentroidsOfOccupiedVoxels) {
  VoxelDownsampler grid;
  grid.Init(100);
  BoundedVector<Eigen::Vector3f> out(100);
  const std::vector<Eigen::Vector3f> points = {{0.1f, 0.1f, 0.1f}, {0.3f, 0.3f, 0.3f}, {1.5f, 0.2f, 0.2f}, {-0.2f, 0.2f, 0.2f}};
  ASSERT_TRUE(grid.Downsample(points, 1.0f, out));
  ASSERT_EQ(out.size(), 3u);
  EXPECT_TRUE(out[0].isApprox(Eigen::Vector3f(0.2f, 0.2f, 0.2f)));
  EXPECT_EQ(grid.stats().output, 3u);
}

TEST(VoxelGrid, OverflowDropsAndCountsAndNonFiniteIsRejected) {
  VoxelDownsampler grid;
  grid.Init(10);
  BoundedVector<Eigen::Vector3f> out(10);
  auto points = RandomPoints(1000, 4);
  points[0].y() = std::numeric_limits<float>::infinity();
  points[1] = Eigen::Vector3f(1e9f, 0, 0);  // beyond the key range at this leaf
  const Status s = grid.Downsample(points, 0.1f, out);
  ASSERT_FALSE(s.has_value());
  EXPECT_EQ(s.error().code, Errc::kCapacityExceeded);
  EXPECT_EQ(out.size(), 10u);
  EXPECT_EQ(grid.stats().rejected, 2u);
  EXPECT_EQ(grid.stats().overflowed, 998u - 10u);
  EXPECT_EQ(grid.peak_voxels(), 10u);
  EXPECT_EQ(grid.Downsample(points, 0.0f, out).error().code, Errc::kInvalidArgument);
}

TEST(RangeFilter, KeepsTheBandAndCountsTheRest) {
  BoundedVector<Eigen::Vector3f> out(10);
  const std::vector<Eigen::Vector3f> p = {{0.1f, 0, 0}, {1, 0, 0}, {200, 0, 0}, {std::nanf(""), 0, 0}, {0, 5, 0}};
  const auto s = RangeFilter(p, 0.5f, 100.0f, out);
  EXPECT_EQ(s.kept, 2u);
  EXPECT_EQ(s.out_of_range, 2u);
  EXPECT_EQ(s.non_finite, 1u);
}

TEST(Covariances, NormalsOfABoxRoomPointInwardsAndCovariancesAreFlat) {
  const auto points = test::BoxRoom(6, 4, 3, 20000, 0.005, 5);
  KdTree tree;
  tree.Init(points.size());
  ASSERT_TRUE(tree.Build(points));
  BoundedVector<Eigen::Vector3f> normals(points.size());
  BoundedVector<Eigen::Matrix3f> covs(points.size());
  const Eigen::Vector3f centre(3, 2, 1.5);
  auto stats = EstimateCovariances(points, tree, {}, normals, covs, &centre);
  ASSERT_TRUE(stats.has_value());
  int good = 0, checked = 0;
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Eigen::Vector3f& p = points[i];
    // Away from edges, the normal is the face's, pointing into the room.
    Eigen::Vector3f expected = Eigen::Vector3f::Zero();
    if (std::fabs(p.x()) < 0.02f && p.y() > 0.3f && p.y() < 3.7f && p.z() > 0.3f && p.z() < 2.7f) expected = {1, 0, 0};
    if (std::fabs(p.z()) < 0.02f && p.x() > 0.3f && p.x() < 5.7f && p.y() > 0.3f && p.y() < 3.7f) expected = {0, 0, 1};
    if (expected.isZero()) continue;
    ++checked;
    // The normal is the face's; the covariance is flat across the face (variance 1e-3 of the
    // in-plane ones along the normal, plus what a few degrees of normal error adds).
    if (normals[i].dot(expected) > 0.98f && expected.dot(covs[i] * expected) < 0.02f) ++good;
  }
  ASSERT_GT(checked, 1000);
  EXPECT_GT(static_cast<double>(good) / checked, 0.98);
}

TEST(Deskew, ASweepTakenWhileTurningBecomesStraight) {
  // A wall at x = 5 seen during a 0.1 s sweep while the sensor yaws 0.2 rad and moves 0.1 m.
  const Eigen::Isometry3d T_start_end = Eigen::Translation3d(0.1, 0, 0) * Eigen::AngleAxisd(0.2, Eigen::Vector3d::UnitZ());
  std::vector<Eigen::Vector3f> points;
  std::vector<float> times;
  for (int i = 0; i <= 100; ++i) {
    const double alpha = i / 100.0;
    const Eigen::Isometry3d T_start_t = Interpolate(Eigen::Isometry3d::Identity(), T_start_end, alpha);
    const Eigen::Vector3d world(5.0, -2.0 + 4.0 * alpha, 1.0);  // start frame = world
    points.push_back((T_start_t.inverse() * world).cast<float>());
    times.push_back(static_cast<float>(0.1 * alpha));
  }
  ASSERT_TRUE(DeskewToEnd(points, times, 0.1, T_start_end));
  for (const auto& p : points) {
    const Eigen::Vector3d in_start = T_start_end * p.cast<double>();
    EXPECT_NEAR(in_start.x(), 5.0, 0.01);  // 256 slots: at most half a slot of motion remains
  }
  EXPECT_FALSE(DeskewToEnd(points, std::span<const float>(times).first(3), 0.1, T_start_end).has_value());
  EXPECT_FALSE(DeskewToEnd(points, times, 0.0, T_start_end).has_value());
}

// Spot's trot rocks the sensor within one sweep: pitch 3 degrees at 2.5 steps a second. Poses
// at 17 instants (what the encoders' 50 Hz give, interpolated) straighten a wall 10 m ahead;
// constant velocity from the sweep's start to its end leaves its middle centimetres off.
TEST(Deskew, ASweepTakenWhileTheBaseRocksNeedsItsTrajectory) {
  const double duration = 0.1, amplitude = 3.0 * std::numbers::pi / 180.0, omega = 2 * std::numbers::pi * 2.5;
  auto pose_at = [&](double t) {  // the sensor in the world (the end's frame is not the world)
    return Eigen::Isometry3d(Eigen::AngleAxisd(amplitude * std::sin(omega * t + 0.3), Eigen::Vector3d::UnitY()));
  };
  std::vector<Eigen::Vector3f> points;
  std::vector<float> times;
  for (int i = 0; i <= 200; ++i) {
    const double t = duration * i / 200.0;
    const Eigen::Vector3d world(10.0, -3.0 + 6.0 * i / 200.0, 1.0 + 1.5 * std::sin(0.37 * i));
    points.push_back((pose_at(t).inverse() * world).cast<float>());
    times.push_back(static_cast<float>(t));
  }
  const Eigen::Isometry3d T_world_end = pose_at(duration);
  auto worst_off_wall = [&](const std::vector<Eigen::Vector3f>& deskewed) {
    double worst = 0;
    for (const auto& p : deskewed) worst = std::max(worst, std::fabs((T_world_end * p.cast<double>()).x() - 10.0));
    return worst;
  };
  std::vector<Eigen::Vector3f> constant = points, sampled = points;
  ASSERT_TRUE(DeskewToEnd(constant, times, duration, pose_at(0.0).inverse() * T_world_end));
  std::vector<Eigen::Isometry3d> trajectory;
  for (int k = 0; k <= 16; ++k) trajectory.push_back(T_world_end.inverse() * pose_at(duration * k / 16.0));
  ASSERT_TRUE(DeskewToEnd(sampled, times, duration, trajectory));
  EXPECT_LT(worst_off_wall(sampled), 0.002);
  EXPECT_GT(worst_off_wall(constant), 0.02);
  // Refused: fewer than two poses, a non-rigid one.
  EXPECT_FALSE(DeskewToEnd(sampled, times, duration, std::span(trajectory).first(1)).has_value());
  trajectory[3].linear()(0, 0) = 2.0;
  EXPECT_FALSE(DeskewToEnd(sampled, times, duration, trajectory).has_value());
}

TEST(Perception, PerScanPathsAllocateNothingAfterInit) {
  const auto raw = test::BoxRoom(8, 6, 3, 30000, 0.02, 6);
  VoxelDownsampler grid;
  grid.Init(40000);
  BoundedVector<Eigen::Vector3f> filtered(40000), down(40000), normals(40000);
  BoundedVector<Eigen::Matrix3f> covs(40000);
  KdTree tree;
  tree.Init(40000);
  std::vector<float> times(raw.size(), 0.05f);
  std::vector<Eigen::Vector3f> moving = raw;
  const Eigen::Isometry3d motion(Eigen::Translation3d(0.05, 0, 0));
  const std::array<Eigen::Isometry3d, 3> trajectory{motion.inverse(), Eigen::Isometry3d(Eigen::Translation3d(-0.025, 0, 0)),
                                                    Eigen::Isometry3d::Identity()};
  for (int round = 0; round < 2; ++round) {
    test::AllocationScope scope;
    RangeFilter(raw, 0.5f, 100.0f, filtered);
    ASSERT_TRUE(DeskewToEnd(moving, times, 0.1, motion));
    ASSERT_TRUE(DeskewToEnd(moving, times, 0.1, std::span<const Eigen::Isometry3d>(trajectory)));
    ASSERT_TRUE(grid.Downsample(filtered.span(), 0.1f, down));
    ASSERT_TRUE(tree.Build(down.span()));
    ASSERT_TRUE(EstimateCovariances(down.span(), tree, {}, normals, covs).has_value());
    EXPECT_EQ(scope.allocations(), 0u) << "round " << round;
  }
}

}  // namespace
}  // namespace msgraphs::core
