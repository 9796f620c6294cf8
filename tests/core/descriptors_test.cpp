// SPDX-License-Identifier: MIT
// Scan Context: the yaw of a rotated room recovered within one sector, same room versus other
// rooms, degenerate input, the bounded database, zero allocation per build and query.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>
#include <vector>

#include "alloc_counter.hpp"
#include "msgraphs/core/descriptors/scan_context.hpp"
#include "synthetic_clouds.hpp"

namespace msgraphs::core {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

// A furnished room centred on the origin (the room frame), z = height above the floor.
std::vector<Eigen::Vector3f> Room(double sx, double sy, std::uint32_t seed, double yaw_rad = 0.0, double noise = 0.02,
                                  int furniture_variant = 0) {
  const Eigen::Isometry3d T = Eigen::Isometry3d(Eigen::AngleAxisd(yaw_rad, Eigen::Vector3d::UnitZ())) *
                              Eigen::Translation3d(-sx / 2, -sy / 2, 0);
  auto room = test::BoxRoom(sx, sy, 3.0, 30000, noise, seed, T, false);
  const double fx = furniture_variant == 0 ? 0.8 : 0.55, fy = furniture_variant == 0 ? 0.3 : 0.7;
  auto desk = test::BoxRoom(1.6, 0.8, 0.75, 3000, noise, seed + 1, T * Eigen::Translation3d(sx * fx, sy * fy, 0));
  auto shelf = test::BoxRoom(0.4, 2.0, 2.0, 3000, noise, seed + 2, T * Eigen::Translation3d(0.1, sy * 0.6, 0));
  room.insert(room.end(), desk.begin(), desk.end());
  room.insert(room.end(), shelf.begin(), shelf.end());
  return room;
}

ScanContext Build(const std::vector<Eigen::Vector3f>& cloud, ScanContextConfig c = {}) {
  ScanContext sc;
  EXPECT_TRUE(sc.Build(cloud, c));
  return sc;
}

TEST(ScanContext, RecoversTheYawOfARotatedRoomWithinOneSector) {
  const ScanContext a = Build(Room(6, 5, 1));
  for (double yaw_deg : {0.0, 17.0, 37.0, 90.0, -123.0, 179.0}) {
    const ScanContext b = Build(Room(6, 5, 7, yaw_deg * kDeg));  // same room, new samples, turned
    for (bool all : {false, true}) {
      const ScanContextMatch m = ScanContextDistance(a, b, all).value();
      // p_a = Rz(yaw) p_b, and b = Rz(yaw_deg) a: so yaw = -yaw_deg.
      const double error_deg = std::remainder(static_cast<double>(m.yaw_rad) / kDeg + yaw_deg, 360.0);
      EXPECT_LE(std::fabs(error_deg), 6.0 + 1e-3) << yaw_deg << " all shifts " << all;
      EXPECT_LT(m.distance, 0.15) << yaw_deg;
    }
  }
}

TEST(ScanContext, SameRoomIsCloserThanOtherRooms) {
  const ScanContext a = Build(Room(6, 5, 1));
  const ScanContext same = Build(Room(6, 5, 2, 30 * kDeg));
  const ScanContext bigger = Build(Room(9, 7, 3));
  const ScanContext other_furniture = Build(Room(6, 5, 4, 0, 0.02, 1));
  const float d_same = ScanContextDistance(a, same, true)->distance;
  EXPECT_LT(d_same, ScanContextDistance(a, bigger, true)->distance);
  EXPECT_LT(d_same, ScanContextDistance(a, other_furniture, true)->distance);
}

TEST(ScanContext, DegenerateAndMismatchedInput) {
  ScanContext sc;
  EXPECT_EQ(sc.Build({}, {}).error().code, Errc::kDegenerate);
  std::vector<Eigen::Vector3f> far = {{100, 0, 1}, {std::nanf(""), 0, 0}};
  EXPECT_EQ(sc.Build(far, {}).error().code, Errc::kDegenerate);
  ScanContextConfig bad;
  bad.rings = 0;
  EXPECT_EQ(sc.Build(far, bad).error().code, Errc::kInvalidConfig);
  const ScanContext a = Build(Room(6, 5, 1));
  ScanContextConfig small;
  small.sectors = 30;
  const ScanContext b = Build(Room(6, 5, 1), small);
  EXPECT_EQ(ScanContextDistance(a, b).error().code, Errc::kInvalidArgument);
  // No column non-empty in both (here: an all-empty descriptor): distance 1, not NaN.
  std::vector<float> zeros(20 * 60, 0.0f);
  ScanContext empty;
  ASSERT_TRUE(empty.FromCells(20, 60, 12.0f, zeros));
  EXPECT_EQ(ScanContextDistance(a, empty, true)->distance, 1.0f);
  // Descriptors received from another robot are checked.
  std::vector<float> cells(20 * 60, 1.0f);
  EXPECT_TRUE(sc.FromCells(20, 60, 12.0f, cells));
  cells[5] = std::nanf("");
  EXPECT_EQ(sc.FromCells(20, 60, 12.0f, cells).error().code, Errc::kMalformed);
  EXPECT_EQ(sc.FromCells(20, 60, 12.0f, std::span<const float>(cells).first(10)).error().code, Errc::kInvalidArgument);
}

// The room matcher's path (collab_room_matching.cpp): an own room's descriptor built, then
// compared over every shift with each peer room's.
TEST(ScanContext, BuildAndCompareAllocateNothing) {
  std::vector<ScanContext> peers(100);
  for (std::size_t i = 0; i < peers.size(); ++i)
    ASSERT_TRUE(peers[i].Build(Room(4 + 0.05 * static_cast<double>(i), 5, static_cast<std::uint32_t>(i)), {}));
  const auto cloud = Room(6, 5, 1);
  ScanContext sc;
  float best = 2.0f;
  test::AllocationScope scope;
  ASSERT_TRUE(sc.Build(cloud, {}));
  for (const ScanContext& peer : peers) {
    const auto match = ScanContextDistance(sc, peer, true);
    ASSERT_TRUE(match);
    best = std::min(best, match->distance);
  }
  EXPECT_EQ(scope.allocations(), 0u);
  EXPECT_LT(best, 0.2f) << "the 6 x 5 m room is among them";
}

}  // namespace
}  // namespace msgraphs::core
