// SPDX-License-Identifier: MIT
// Room descriptors at the generator's extremes: the crop follows the ceiling each room measures
// (2.3 m offices, 6 m halls), never a fixed height; and building one allocates nothing.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <vector>

#include "alloc_counter.hpp"
#include "msgraphs/core/collab/room_descriptor.hpp"
#include "msgraphs/core/slam/local_mapper.hpp"
#include "synthetic_clouds.hpp"

namespace msgraphs::core {
namespace {

constexpr double kSx = 10.0, kSy = 8.0;  // the room, corner at the world origin

// The room seen by a mapper driven along its middle.
void MapTheRoom(double ceiling_m, LocalMapper& mapper) {
  LocalMapperConfig config;
  config.max_scan_points = 25000;
  config.cloud_store_points = 32 * 6000;
  config.graph.max_keyframes = 32;
  config.graph.max_factors = 32 * 64;
  config.grid.width = config.grid.height = 256;
  config.grid.origin_m = Eigen::Vector2f(-7.8f, -12.8f);  // the map frame starts at (2, 4)
  const Status init = mapper.Init(config);
  ASSERT_TRUE(init) << init.error().detail;
  // Perfect odometry along the room's middle, a keyframe a metre; the map frame is the first
  // base pose (2, 4, 0.5 m above the floor).
  const Eigen::Isometry3d T_world_first = [] {
    Eigen::Isometry3d T = test::PlanarPose(2.0, 4.0, 0.0);
    T.translation().z() = 0.5;
    return T;
  }();
  std::vector<float> times(20000, 0.1f);
  for (int i = 0; i < 7; ++i) {
    Eigen::Isometry3d T_world_base = T_world_first;
    T_world_base.translation().x() += i;
    const Eigen::Isometry3d odometry = T_world_first.inverse() * T_world_base;
    const double t = 10.0 + i;
    ASSERT_TRUE(mapper.AddOdometry(t - 0.15, odometry));
    ASSERT_TRUE(mapper.AddOdometry(t + 0.05, odometry));
    const auto points = test::BoxRoom(kSx, kSy, ceiling_m, 20000, 0.01, static_cast<std::uint32_t>(i + 1),
                                      (T_world_base * config.T_base_lidar).inverse());
    ASSERT_TRUE(mapper.AddScan({points, times, t - 0.1, t}));
  }
  ASSERT_TRUE(mapper.Finish());
}

DistilledRoom TheRoom() {
  DistilledRoom room;
  room.centre = Eigen::Vector2d(kSx / 2 - 2.0, kSy / 2 - 4.0);  // in the map frame
  room.size_x_m = kSx;
  room.size_y_m = kSy;
  return room;
}

class DescriptorCeiling : public ::testing::TestWithParam<double> {};

TEST_P(DescriptorCeiling, CropsBelowTheCeilingTheRoomMeasured) {
  const double ceiling_m = GetParam();
  LocalMapper mapper;
  ASSERT_NO_FATAL_FAILURE(MapTheRoom(ceiling_m, mapper));
  const DistilledRoom room = TheRoom();
  RoomDescriptorBuilder builder;
  ASSERT_TRUE(builder.Init({}));
  BoundedVector<Eigen::Vector3f> cloud(builder.config().max_cloud_points);
  ScanContext descriptor;
  ASSERT_TRUE(builder.Build(mapper, room, cloud, descriptor));
  EXPECT_TRUE(builder.last_found_ceiling());
  const double expected_crop_m = ceiling_m - static_cast<double>(builder.config().ceiling_margin_m);
  // Found in windows of two 0.1 m layers: the crop is up to two layers below ceiling - margin.
  const auto crop_m = static_cast<double>(builder.last_crop_height_m());
  EXPECT_LE(crop_m, expected_crop_m + 0.05);
  EXPECT_GE(crop_m, expected_crop_m - 0.25);
  float top_m = 0;
  for (const Eigen::Vector3f& p : cloud) top_m = std::max(top_m, p.z());
  EXPECT_LT(static_cast<double>(top_m), ceiling_m - 0.1) << "the ceiling is not in the room cloud";
  EXPECT_GT(static_cast<double>(top_m), expected_crop_m - 0.3) << "the walls are kept up to the crop";
}

INSTANTIATE_TEST_SUITE_P(GeneratorExtremes, DescriptorCeiling, ::testing::Values(2.3, 6.0));

// room_descriptor.hpp: "Sized at Init; Build allocates nothing". The mapper, the builder (Init),
// the cloud and the descriptor are set up first; the first Build and a second one are counted.
TEST(RoomDescriptor, BuildAllocatesNothing) {
  LocalMapper mapper;
  ASSERT_NO_FATAL_FAILURE(MapTheRoom(2.3, mapper));
  const DistilledRoom room = TheRoom();
  RoomDescriptorBuilder builder;
  ASSERT_TRUE(builder.Init({}));
  BoundedVector<Eigen::Vector3f> cloud(builder.config().max_cloud_points);
  ScanContext descriptor;

  Status first, second;
  std::uint64_t allocations = 0;
  {
    test::AllocationScope scope;
    first = builder.Build(mapper, room, cloud, descriptor);
    second = builder.Build(mapper, room, cloud, descriptor);
    allocations = scope.allocations();
  }
  EXPECT_EQ(allocations, 0u);
  ASSERT_TRUE(first) << first.error().detail;
  ASSERT_TRUE(second) << second.error().detail;
  EXPECT_TRUE(builder.last_found_ceiling());
  EXPECT_GE(cloud.size(), 100u);
  EXPECT_LE(cloud.size(), builder.config().max_cloud_points);
  EXPECT_GE(descriptor.points_used(), cloud.size() / 2);
}

}  // namespace
}  // namespace msgraphs::core
