// SPDX-License-Identifier: MIT
// Relocalisation after a restart (core/slam/src/relocalise.cpp) and the search the node builds
// for it (core/slam/restart_prediction.hpp), on the synthetic box room.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "alloc_counter.hpp"
#include "box_room_walk.hpp"
#include "msgraphs/core/slam/local_mapper.hpp"
#include "msgraphs/core/slam/odometry_buffer.hpp"
#include "msgraphs/core/slam/restart_prediction.hpp"

namespace msgraphs::core {
namespace {

class Relocalisation : public ::testing::TestWithParam<double> {};

TEST_P(Relocalisation, AfterTheOdometryRestartedWhileTheRobotMoved) {
  // A node killed at step 11 of the walk and restarted at step 14: its odometry integration
  // begins again at identity, 2 m and 80 degrees of turning away from where the map stopped.
  // With the base rocking (the parameter, degrees), neither the last keyframe's base nor the
  // new one is level.
  const LocalMapperConfig config = SmallConfig(64, 256);
  LocalMapper mapper;
  ASSERT_TRUE(mapper.Init(config));
  const Walk walk(30, GetParam());
  std::vector<float> times(20000, 0.1f);
  WalkSteps(mapper, walk, config, 0, 12);
  const SGraph& g = mapper.graph();
  const std::uint32_t last = static_cast<std::uint32_t>(g.keyframe_slots() - 1);
  const Eigen::Isometry3d T_map_odom =
      g.keyframe_pose(last) * mapper.keyframe_odometry(last).inverse();
  // Where the node stopped, and where it would be had it kept its last step's motion three
  // more steps, times 1.5 (the caller's prediction over the downtime).
  RelocaliseSearch search;
  search.T_odom_from = walk.odometry[11];
  const Eigen::Isometry3d step = walk.odometry[10].inverse() * walk.odometry[11];
  Eigen::Isometry3d ahead = walk.odometry[11];
  for (int k = 0; k < 4; ++k) ahead = ahead * step;
  search.T_odom_to = ahead;
  const auto points = ScanAt(walk.truth[14], config, 15);
  const Eigen::Isometry3d T_new = Eigen::Isometry3d::Identity();  // the new integration
  test::AllocationScope scope;
  auto reloc = mapper.Relocalise({points, times, 23.9, 24.0}, T_new, T_new, search);
  EXPECT_EQ(scope.allocations(), 0u);
  ASSERT_TRUE(reloc) << reloc.error().detail;
  const Eigen::Isometry3d found = T_map_odom * reloc->T_odom_base;
  EXPECT_LT((found.translation() - walk.truth[14].translation()).norm(), 0.05);
  EXPECT_LT(Eigen::AngleAxisd(found.linear().transpose() * walk.truth[14].linear()).angle(), 0.01);
  EXPECT_GT(reloc->candidates, 100u);
  EXPECT_LE(reloc->registrations, search.registrations);
  EXPECT_LT(reloc->fitness_m2, config.scan_match_max_fitness_m2);
  // The map is untouched: same keyframes, same last pose.
  EXPECT_EQ(g.keyframe_slots(), last + 1);
  // Searching only where the robot is not (the stop point, no span, no sides or turns) fails.
  RelocaliseSearch narrow;
  narrow.T_odom_from = narrow.T_odom_to = walk.odometry[11];
  narrow.lateral_m = 0;
  narrow.yaw_rad = 0;
  narrow.registrations = 1;
  auto miss = mapper.Relocalise({points, times, 23.9, 24.0}, T_new, T_new, narrow);
  ASSERT_FALSE(miss);
  EXPECT_EQ(miss.error().code, Errc::kNotConverged);
  // The same narrow search with a reach (the robot's top speed times the downtime: it turned
  // off the predicted line) finds it all the same, off the line, without allocating.
  RelocaliseSearch reach = narrow;
  reach.yaw_rad = search.yaw_rad;
  reach.reach_m = 3.0;
  reach.registrations = search.registrations;
  test::AllocationScope reach_scope;
  auto wide = mapper.Relocalise({points, times, 23.9, 24.0}, T_new, T_new, reach);
  EXPECT_EQ(reach_scope.allocations(), 0u);
  ASSERT_TRUE(wide) << wide.error().detail;
  EXPECT_TRUE(wide->wide);
  const Eigen::Isometry3d found_wide = T_map_odom * wide->T_odom_base;
  EXPECT_LT((found_wide.translation() - walk.truth[14].translation()).norm(), 0.05);
  EXPECT_LT(Eigen::AngleAxisd(found_wide.linear().transpose() * walk.truth[14].linear()).angle(),
            0.01);
  // At the middle of the box room the scan aligns as well turned half round: off the predicted
  // path that is an ambiguity, never an answer (the node then resumes on the robot's motion).
  Eigen::Isometry3d T_middle = Pose(0.5 * kSx, 0.5 * kSy, 0.3);
  T_middle.translation().z() = 0.5;
  const Eigen::Vector3d middle_from_stop =
      T_middle.translation() - (T_map_odom * walk.odometry[11]).translation();
  RelocaliseSearch around = reach;
  around.reach_m = middle_from_stop.head<2>().norm() + 1.0;
  const auto middle_points = ScanAt(T_middle, config, 16);
  auto twofold = mapper.Relocalise({middle_points, times, 23.9, 24.0}, T_new, T_new, around);
  ASSERT_FALSE(twofold);
  EXPECT_EQ(twofold.error().code, Errc::kNotConverged);
  EXPECT_NE(std::string(twofold.error().detail).find("ambiguous"), std::string::npos)
      << twofold.error().detail;
  // Without a keyframe there is nothing to relocalise against.
  LocalMapper empty;
  ASSERT_TRUE(empty.Init(config));
  EXPECT_EQ(empty.Relocalise({points, times, 23.9, 24.0}, T_new, T_new, search).error().code,
            Errc::kNotFound);
}

INSTANTIATE_TEST_SUITE_P(LocalMapper, Relocalisation, ::testing::Values(0.0, 1.0, 2.0, 3.0));

// The box room with a 1.2 m doorway in its wall at x = kSx (y 3.4-4.6 m, 2.2 m high) and, 3 m
// beyond it, a wall and a floor seen only through the doorway.
constexpr double kDoorY0 = 3.4, kDoorY1 = 4.6, kDoorTop = 2.2, kBeyondX = kSx + 3.0;

std::vector<Eigen::Vector3f> DoorwayScanAt(const Eigen::Isometry3d& T_world_base,
                                           const LocalMapperConfig& config, std::uint32_t seed,
                                           std::size_t points) {
  const Eigen::Isometry3d T_world_lidar = T_world_base * config.T_base_lidar;
  const Eigen::Isometry3d T_lidar_world = T_world_lidar.inverse();
  const Eigen::Vector3d sensor = T_world_lidar.translation();
  const auto in_doorway = [](double y, double z) {
    return y > kDoorY0 && y < kDoorY1 && z < kDoorTop;
  };
  std::vector<Eigen::Vector3f> out;
  for (const Eigen::Vector3f& p_lidar : test::BoxRoom(kSx, kSy, kSz, points, 0.01, seed, T_lidar_world)) {
    const Eigen::Vector3d p = T_world_lidar * p_lidar.cast<double>();
    if (std::abs(p.x() - kSx) < 0.05 && in_doorway(p.y(), p.z())) continue;  // the opening
    out.push_back(p_lidar);
  }
  // Through the opening: rays from the lidar through points spread over it (some 600 a scan,
  // about what a VLP-16 puts through a door 4 m away) to the floor or the wall beyond.
  std::mt19937 rng(seed + 1000);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int k = 0; k < 600; ++k) {
    const Eigen::Vector3d o(kSx, kDoorY0 + u(rng) * (kDoorY1 - kDoorY0), u(rng) * kDoorTop);
    const Eigen::Vector3d ray = o - sensor;
    double t = (kBeyondX - sensor.x()) / ray.x();
    if (ray.z() < 0) t = std::min(t, -sensor.z() / ray.z());  // the floor beyond comes first
    out.push_back((T_lidar_world * (sensor + t * ray)).cast<float>());
  }
  return out;
}

// At the middle of the box room a scan aligns as well turned half round, and without negative
// evidence that is an ambiguity (the test above). With a doorway in one wall, the half-turned
// place puts the scan's blank wall where the map saw through the doorway: refused, and the
// robot's own place is the one answer. Without the test (max_seen_through 1) it is ambiguous.
TEST(Relocalisation, ADoorwayTellsTheRoomFromItselfTurnedHalfRound) {
  const LocalMapperConfig config = SmallConfig(64, 256);
  LocalMapper mapper;
  ASSERT_TRUE(mapper.Init(config));
  const Walk walk(30);
  WalkSteps(mapper, walk, config, 0, 15, DoorwayScanAt);  // a lap: the doorway seen from all round
  const SGraph& g = mapper.graph();
  const std::uint32_t last = static_cast<std::uint32_t>(g.keyframe_slots() - 1);
  const Eigen::Isometry3d T_map_odom =
      g.keyframe_pose(last) * mapper.keyframe_odometry(last).inverse();
  Eigen::Isometry3d T_middle = Pose(0.5 * kSx, 0.5 * kSy, 0.3);
  T_middle.translation().z() = 0.5;
  const auto points = DoorwayScanAt(T_middle, config, 77, 20000);
  const std::vector<float> times(points.size(), 0.1f);
  // Searched where the robot is, at every heading (seeds a step either side, no reach): the
  // place turned half round is among them.
  RelocaliseSearch wide;
  wide.T_odom_from = wide.T_odom_to = T_map_odom.inverse() * T_middle;
  wide.lateral_m = 0;
  wide.registrations = 6;
  const Eigen::Isometry3d T_new = Eigen::Isometry3d::Identity();
  test::AllocationScope scope;
  auto found = mapper.Relocalise({points, times, 43.9, 44.0}, T_new, T_new, wide);
  EXPECT_EQ(scope.allocations(), 0u);
  ASSERT_TRUE(found) << found.error().detail;
  const Eigen::Isometry3d at = T_map_odom * found->T_odom_base;
  EXPECT_LT((at.translation() - T_middle.translation()).head<2>().norm(), 0.05);
  EXPECT_LT(Eigen::AngleAxisd(at.linear().transpose() * T_middle.linear()).angle(), 0.02);
  EXPECT_GE(found->contradicted, 1u);  // the place turned half round aligned, and was refused
  RelocaliseSearch blind = wide;
  blind.max_seen_through = 1.0;
  auto twofold = mapper.Relocalise({points, times, 43.9, 44.0}, T_new, T_new, blind);
  ASSERT_FALSE(twofold);
  EXPECT_NE(std::string(twofold.error().detail).find("ambiguous"), std::string::npos)
      << twofold.error().detail;
  RelocaliseSearch bad = wide;
  bad.max_seen_through = std::nan("");
  EXPECT_EQ(mapper.Relocalise({points, times, 43.9, 44.0}, T_new, T_new, bad).error().code,
            Errc::kInvalidArgument);
}

TEST(RestartPrediction, KeepsTheLastHalfSecondsMotionAndReachesAtTopSpeed) {
  OdometryBuffer odometry;
  odometry.Init(64);
  // Walking at 1 m/s along x and turning 0.2 rad/s, the base pitched by 3 degrees.
  for (int i = 0; i <= 20; ++i) {
    const double t = 0.05 * i;
    Eigen::Isometry3d T = Pose(t, 0, 0.2 * t);
    T.linear() = T.linear() * Eigen::AngleAxisd(0.05, Eigen::Vector3d::UnitY()).toRotationMatrix();
    ASSERT_TRUE(odometry.Add(10.0 + t, T));
  }
  const Eigen::Isometry3d last = odometry.pose(odometry.size() - 1);
  const RestartPrediction prediction(odometry, last, 11.0);
  // Two seconds on: four half seconds of the last one's motion (0.5 m, 0.1 rad each).
  const Eigen::Isometry3d ahead = last.inverse() * prediction.KeptOn(2.0);
  EXPECT_NEAR(ahead.translation().head<2>().norm(), 2.0, 0.05);
  EXPECT_NEAR(Eigen::AngleAxisd(ahead.linear()).angle(), 0.4, 0.05);
  // At most 30 s of it; none before the stop.
  EXPECT_TRUE(prediction.KeptOn(60.0).isApprox(prediction.KeptOn(30.0)));
  EXPECT_FALSE(prediction.KeptOn(20.0).isApprox(prediction.KeptOn(30.0)));
  EXPECT_TRUE(prediction.KeptOn(-3.0).isApprox(last));
  const RelocaliseSearch search = prediction.Search(13.0, 1.6);  // a scan 2 s after the stop
  EXPECT_TRUE(search.T_odom_from.isApprox(last));
  EXPECT_NEAR((last.inverse() * search.T_odom_to).translation().head<2>().norm(), 3.0, 0.1);
  EXPECT_DOUBLE_EQ(search.reach_m, 3.2);
  EXPECT_DOUBLE_EQ(prediction.Search(10.5, 1.6).reach_m, 0.0);  // a scan before the stop
  // No odometry half a second before the stop: the robot is taken to have stood still.
  OdometryBuffer short_buffer;
  short_buffer.Init(4);
  ASSERT_TRUE(short_buffer.Add(11.0, last));
  EXPECT_TRUE(RestartPrediction(short_buffer, last, 11.0).KeptOn(5.0).isApprox(last));
}

}  // namespace
}  // namespace msgraphs::core
