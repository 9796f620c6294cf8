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
#include "mapped_room.hpp"

namespace msgraphs::core {
namespace {

using test::kSx;
using test::kSy;
using test::MapTheRoom;

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
