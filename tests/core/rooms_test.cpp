// SPDX-License-Identifier: MIT
// Room segmentation and detection on synthetic floors: two rooms joined by a door, a room and a
// corridor, the same building rotated by 30 degrees, degenerate input, no allocation per call.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <numbers>
#include <optional>
#include <vector>

#include "alloc_counter.hpp"
#include "msgraphs/core/perception/free_space_grid.hpp"
#include "msgraphs/core/perception/room_segmentation.hpp"

namespace msgraphs::core {
namespace {

struct Segment2 {
  Eigen::Vector2d a, b;
};

// A floor plan as wall-face segments (the lidar sees faces), turned by `yaw` about the origin.
struct Plan {
  std::vector<Segment2> faces;
  double yaw = 0;
  Eigen::Vector2d R(const Eigen::Vector2d& p) const { return Eigen::Rotation2Dd(yaw) * p; }
  void Face(double x1, double y1, double x2, double y2) { faces.push_back({R({x1, y1}), R({x2, y2})}); }
};

std::optional<double> Intersect(const Eigen::Vector2d& o, const Eigen::Vector2d& d, const Segment2& s) {
  const Eigen::Vector2d e = s.b - s.a;
  const double den = d.x() * e.y() - d.y() * e.x();
  if (std::fabs(den) < 1e-12) return std::nullopt;
  const Eigen::Vector2d w = s.a - o;
  const double t = (w.x() * e.y() - w.y() * e.x()) / den;
  const double u = (w.x() * d.y() - w.y() * d.x()) / den;
  if (t <= 0 || u < 0 || u > 1) return std::nullopt;
  return t;
}

// Scans from each position: 720 horizontal rays at 1 m height, plus floor points.
// With `follow`, the grid window follows the sensor first (as the mapper does).
void Scan(FreeSpaceGrid& grid, const Plan& plan, const std::vector<Eigen::Vector2d>& positions,
          bool follow = false) {
  std::vector<Eigen::Vector3f> points;
  for (const Eigen::Vector2d& local : positions) {
    const Eigen::Vector2d o = plan.R(local);
    points.clear();
    for (int i = 0; i < 720; ++i) {
      const double a = i * std::numbers::pi / 360.0;
      const Eigen::Vector2d d(std::cos(a), std::sin(a));
      double best = 30;
      for (const auto& s : plan.faces) {
        if (auto t = Intersect(o, d, s); t && *t < best) best = *t;
      }
      const Eigen::Vector2d p = o + d * best;
      points.emplace_back(static_cast<float>(p.x()), static_cast<float>(p.y()), 1.0f);
      const Eigen::Vector2d f = o + d * std::min(best - 0.1, 3.0);
      points.emplace_back(static_cast<float>(f.x()), static_cast<float>(f.y()), 0.0f);
    }
    if (follow) grid.Follow(o.cast<float>());
    grid.Integrate(Eigen::Vector3f(static_cast<float>(o.x()), static_cast<float>(o.y()), 0.8f), points, 0.0f);
  }
}

MapWall Wall(const Plan& plan, std::uint32_t id, double x1, double y1, double x2, double y2, const Eigen::Vector2d& inward) {
  MapWall w;
  w.id = id;
  w.a = plan.R({x1, y1});
  w.b = plan.R({x2, y2});
  w.normal = plan.R(inward);
  w.d = -w.normal.dot(w.a);
  return w;
}

// Two 6 x 5 m rooms side by side (x 0..6 and 6..12), a 1 m door between them at y 2..3, and a
// 2.4 m wide corridor along y 5..7.4 with a door to each room.
struct TwoRoomsAndCorridor {
  Plan plan;
  std::vector<MapWall> walls;
  explicit TwoRoomsAndCorridor(double yaw) {
    plan.yaw = yaw;
    plan.Face(0, 0, 12, 0);     // south
    plan.Face(0, 0, 0, 7.4);    // west
    plan.Face(12, 0, 12, 7.4);  // east
    plan.Face(0, 7.4, 12, 7.4); // north (corridor)
    plan.Face(6, 0, 6, 2);      // middle wall, door at y 2..3
    plan.Face(6, 3, 6, 5);
    plan.Face(0, 5, 2, 5);      // room/corridor wall, doors at x 2..3 and 9..10
    plan.Face(3, 5, 9, 5);
    plan.Face(10, 5, 12, 5);
    const Eigen::Vector2d px(1, 0), nx(-1, 0), py(0, 1), ny(0, -1);
    walls = {Wall(plan, 0, 0, 0, 6, 0, py),      Wall(plan, 1, 0, 0, 0, 5, px),      Wall(plan, 2, 6, 0, 6, 5, nx),
             Wall(plan, 3, 0, 5, 6, 5, ny),      Wall(plan, 4, 6, 0, 12, 0, py),     Wall(plan, 5, 6, 0, 6, 5, px),
             Wall(plan, 6, 12, 0, 12, 5, nx),    Wall(plan, 7, 6, 5, 12, 5, ny),     Wall(plan, 8, 0, 5, 12, 5, py),
             Wall(plan, 9, 0, 7.4, 12, 7.4, ny)};
  }
};

class Rooms : public ::testing::TestWithParam<double> {};

TEST_P(Rooms, TwoRoomsAndACorridorWithTheirTrueOrientation) {
  const double yaw = GetParam() * std::numbers::pi / 180.0;
  TwoRoomsAndCorridor world(yaw);
  FreeSpaceGridConfig gc;
  gc.width = gc.height = 400;
  gc.origin_m = {-10, -10};
  FreeSpaceGrid grid;
  ASSERT_TRUE(grid.Init(gc));
  Scan(grid, world.plan, {{1.5, 1.5}, {4.5, 3.5}, {3, 2.5}, {7.5, 1.5}, {10.5, 3.5}, {9, 2.5}, {1, 6.2}, {6, 6.2}, {11, 6.2}});
  RoomSegmenter segmenter;
  ASSERT_TRUE(segmenter.Init(400, 400, 64, 64));
  BoundedVector<RoomRegion> regions(64);
  ASSERT_TRUE(segmenter.Segment(grid, {}, regions));
  EXPECT_EQ(regions.size(), 3u) << "two rooms and the corridor, split at the doors";
  BoundedVector<DetectedRoom> rooms(16);
  ASSERT_TRUE(segmenter.DetectRooms(grid, regions.span(), world.walls, {}, rooms));
  int found_rooms = 0, found_corridors = 0;
  const double expected_yaw = std::remainder(yaw, std::numbers::pi / 2);
  for (const DetectedRoom& r : rooms) {
    EXPECT_NEAR(std::remainder(r.yaw_rad - expected_yaw, std::numbers::pi / 2), 0.0, 0.02) << "orientation";
    const Eigen::Vector2d local = Eigen::Rotation2Dd(-yaw) * r.centre;
    if (r.kind == RoomKind::kRoom) {
      ++found_rooms;
      const bool left = local.x() < 6;
      EXPECT_NEAR(local.x(), left ? 3.0 : 9.0, 0.05);
      EXPECT_NEAR(local.y(), 2.5, 0.05);
      EXPECT_NEAR(std::max(r.size_x_m, r.size_y_m), 6.0, 0.05);
      EXPECT_NEAR(std::min(r.size_x_m, r.size_y_m), 5.0, 0.05);
      for (std::int32_t w : r.walls) EXPECT_GE(w, 0);
    } else {
      ++found_corridors;
      EXPECT_NEAR(local.y(), 6.2, 0.05) << "across the corridor from its walls";
      EXPECT_NEAR(local.x(), 6.0, 0.6) << "along it from the free space";
      EXPECT_NEAR(r.size_x_m, 2.4, 0.05);
    }
  }
  EXPECT_EQ(found_rooms, 2);
  EXPECT_EQ(found_corridors, 1);
}

INSTANTIATE_TEST_SUITE_P(Yaws, Rooms, ::testing::Values(0.0, 30.0, -20.0, 44.0));

TEST(Rooms, AWideOpeningBetweenCollinearWallPiecesStillSeparatesRooms) {
  // Two 8 x 6 m halls joined by a 2 m opening (x = 8, y 2..4): wider than the door cut.
  Plan plan;
  plan.Face(0, 0, 16, 0);
  plan.Face(0, 6, 16, 6);
  plan.Face(0, 0, 0, 6);
  plan.Face(16, 0, 16, 6);
  plan.Face(8, 0, 8, 2);
  plan.Face(8, 4, 8, 6);
  const Eigen::Vector2d px(1, 0), nx(-1, 0), py(0, 1), ny(0, -1);
  // The middle wall seen from the west hall: two collinear pieces with the opening between.
  std::vector<MapWall> walls = {Wall(plan, 0, 0, 0, 8, 0, py),   Wall(plan, 1, 0, 6, 8, 6, ny),
                                Wall(plan, 2, 0, 0, 0, 6, px),   Wall(plan, 3, 8, 0, 8, 2, nx),
                                Wall(plan, 4, 8, 4, 8, 6, nx),   Wall(plan, 5, 8, 0, 16, 0, py),
                                Wall(plan, 6, 8, 6, 16, 6, ny),  Wall(plan, 7, 16, 0, 16, 6, nx),
                                Wall(plan, 8, 8, 0, 8, 2, px),   Wall(plan, 9, 8, 4, 8, 6, px)};
  FreeSpaceGridConfig gc;
  gc.width = gc.height = 300;
  gc.origin_m = {-5, -10};
  FreeSpaceGrid grid;
  ASSERT_TRUE(grid.Init(gc));
  Scan(grid, plan, {{2, 2}, {6, 4}, {4, 3}, {10, 2}, {14, 4}, {12, 3}, {8, 3}});
  RoomSegmenter segmenter;
  ASSERT_TRUE(segmenter.Init(300, 300, 16, 16));
  BoundedVector<RoomRegion> regions(16);
  ASSERT_TRUE(segmenter.Segment(grid, {}, regions));
  EXPECT_EQ(regions.size(), 1u) << "without walls the opening joins the halls";
  ASSERT_TRUE(segmenter.Segment(grid, {}, regions, walls));
  EXPECT_EQ(regions.size(), 2u) << "the opening between collinear pieces is closed";
  BoundedVector<DetectedRoom> rooms(8);
  ASSERT_TRUE(segmenter.DetectRooms(grid, regions.span(), walls, {}, rooms));
  ASSERT_EQ(rooms.size(), 2u);
  for (const auto& r : rooms) {
    EXPECT_EQ(r.kind, RoomKind::kRoom);
    EXPECT_NEAR(r.centre.y(), 3.0, 0.05);
    EXPECT_NEAR(std::fabs(r.centre.x() - 8.0), 4.0, 0.05);
  }
}

// The openings closure at the generator's extremes (docs/perception.md, "Openings"): its
// doorless openings reach 3.0 m and its corridors narrow to 1.8 m, on either side of the 2.2 m
// default, so each side's outcome is pinned here.
std::size_t RegionsOf(const Plan& plan, const std::vector<MapWall>& walls, const std::vector<Eigen::Vector2d>& at,
                      float close_openings_up_to_m) {
  FreeSpaceGridConfig gc;
  gc.width = gc.height = 300;
  gc.origin_m = {-5, -10};
  FreeSpaceGrid grid;
  EXPECT_TRUE(grid.Init(gc));
  Scan(grid, plan, at);
  RoomSegmenter segmenter;
  EXPECT_TRUE(segmenter.Init(300, 300, 16, 16));
  BoundedVector<RoomRegion> regions(16);
  RoomSegmentationConfig config;
  config.close_openings_up_to_m = close_openings_up_to_m;
  EXPECT_TRUE(segmenter.Segment(grid, config, regions, walls));
  return regions.size();
}

TEST(Rooms, AThreeMetreDoorlessOpeningJoinsTwoHallsUnlessTheClosureReachesIt) {
  Plan plan;  // the halls of the test above, joined by 3 m (x = 8, y 1.5..4.5)
  plan.Face(0, 0, 16, 0);
  plan.Face(0, 6, 16, 6);
  plan.Face(0, 0, 0, 6);
  plan.Face(16, 0, 16, 6);
  plan.Face(8, 0, 8, 1.5);
  plan.Face(8, 4.5, 8, 6);
  const Eigen::Vector2d px(1, 0), nx(-1, 0), py(0, 1), ny(0, -1);
  const std::vector<MapWall> walls = {Wall(plan, 0, 0, 0, 16, 0, py), Wall(plan, 1, 0, 6, 16, 6, ny),
                                      Wall(plan, 2, 0, 0, 0, 6, px),  Wall(plan, 3, 16, 0, 16, 6, nx),
                                      Wall(plan, 4, 8, 0, 8, 1.5, nx), Wall(plan, 5, 8, 4.5, 8, 6, nx)};
  const std::vector<Eigen::Vector2d> at = {{2, 2}, {6, 4}, {4, 3}, {10, 2}, {14, 4}, {12, 3}, {8, 3}};
  EXPECT_EQ(RegionsOf(plan, walls, at, RoomSegmentationConfig{}.close_openings_up_to_m), 1u)
      << "at the default, a 3 m opening leaves one larger region (never a wrong room)";
  EXPECT_EQ(RegionsOf(plan, walls, at, 3.2f), 2u) << "a closure configured past it separates the halls";
}

TEST(Rooms, ACorridorNarrowerThanTheClosureIsCutWherePartitionsLineUpAcrossIt) {
  // A 1.8 m corridor (y 0..1.8, x 0..16) between two rows of two closed 8 x 5 m rooms whose
  // partitions (x = 8) line up across it.
  Plan plan;
  plan.Face(0, -5, 16, -5);
  plan.Face(0, 6.8, 16, 6.8);
  plan.Face(0, -5, 0, 6.8);
  plan.Face(16, -5, 16, 6.8);
  plan.Face(0, 0, 16, 0);
  plan.Face(0, 1.8, 16, 1.8);
  plan.Face(8, -5, 8, 0);
  plan.Face(8, 1.8, 8, 6.8);
  const Eigen::Vector2d px(1, 0), py(0, 1), ny(0, -1);
  const std::vector<MapWall> walls = {Wall(plan, 0, 0, 0, 16, 0, py), Wall(plan, 1, 0, 1.8, 16, 1.8, ny),
                                      Wall(plan, 2, 8, -5, 8, 0, px), Wall(plan, 3, 8, 1.8, 8, 6.8, px)};
  const std::vector<Eigen::Vector2d> at = {{2, 0.9}, {6, 0.9}, {10, 0.9}, {14, 0.9}, {4, -2.5},
                                           {12, -2.5}, {4, 4.3}, {12, 4.3}};
  EXPECT_EQ(RegionsOf(plan, walls, at, RoomSegmentationConfig{}.close_openings_up_to_m), 6u)
      << "four rooms and the corridor in two pieces at the default";
  EXPECT_EQ(RegionsOf(plan, walls, at, 1.6f), 5u) << "a closure below the corridor's width keeps it whole";
}

TEST(Rooms, EmptyGridsAndRoomlessInputGiveNothingAndNoCrash) {
  FreeSpaceGridConfig gc;
  gc.width = gc.height = 100;
  gc.origin_m = {-5, -5};
  FreeSpaceGrid grid;
  ASSERT_TRUE(grid.Init(gc));
  RoomSegmenter segmenter;
  ASSERT_TRUE(segmenter.Init(100, 100, 8, 8));
  BoundedVector<RoomRegion> regions(8);
  ASSERT_TRUE(segmenter.Segment(grid, {}, regions));
  EXPECT_EQ(regions.size(), 0u);
  BoundedVector<DetectedRoom> rooms(8);
  ASSERT_TRUE(segmenter.DetectRooms(grid, regions.span(), {}, {}, rooms));
  EXPECT_EQ(rooms.size(), 0u);
  // A sensor outside the grid: counted, ignored.
  std::vector<Eigen::Vector3f> pts = {{1, 1, 1}, {std::nanf(""), 0, 0}};
  grid.Integrate(Eigen::Vector3f(100, 100, 1), pts, 0);
  EXPECT_EQ(grid.outside(), 2u);
  // Open space without walls: a region, but no room.
  Plan open;
  Scan(grid, open, {{0, 0}});
  ASSERT_TRUE(segmenter.Segment(grid, {}, regions));
  ASSERT_TRUE(segmenter.DetectRooms(grid, regions.span(), {}, {}, rooms));
  EXPECT_EQ(rooms.size(), 0u);
  RoomSegmenter wrong;
  ASSERT_TRUE(wrong.Init(50, 50, 8, 8));
  EXPECT_EQ(wrong.Segment(grid, {}, regions).error().code, Errc::kInvalidArgument);
  FreeSpaceGridConfig bad;
  bad.resolution_m = 0;
  EXPECT_EQ(grid.Init(bad).error().code, Errc::kInvalidConfig);
}

// A building longer than the grid: the window follows the robot down it, what stays inside
// keeps its cells, and rooms at the far end are found as they would be in a grid that held all.
TEST(Rooms, TheGridWindowFollowsTheRobotThroughABuildingLargerThanIt) {
  TwoRoomsAndCorridor near(0), far(0);
  const Eigen::Vector2d shift(40, 0);  // the same two rooms and corridor 40 m on
  for (auto& f : far.plan.faces) {
    f.a += shift;
    f.b += shift;
  }
  for (auto& w : far.walls) {
    w.a += shift;
    w.b += shift;
    w.d = -w.normal.dot(w.a);
  }
  FreeSpaceGridConfig gc;
  gc.width = gc.height = 240;  // 24 m: less than the 52 m building
  gc.origin_m = {-6, -6};
  gc.max_range_m = 8;
  FreeSpaceGrid grid;
  ASSERT_TRUE(grid.Init(gc));
  Scan(grid, near.plan, {{1.5, 1.5}, {4.5, 3.5}}, true);
  EXPECT_EQ(grid.moves(), 0u) << "the sensor is well inside";
  // A step that moves the window: cells that stay inside keep their state where they are.
  const Eigen::Vector2d probe(3.0, 2.5);  // free, in the first room
  int px = 0, py = 0;
  ASSERT_TRUE(grid.ToCell(probe, px, py));
  const FreeSpaceGrid::Cell before = grid.state(px, py);
  ASSERT_EQ(before, FreeSpaceGrid::Cell::kFree);
  // Crossed from both positions, rays 100 degrees apart; the directions move with the window too.
  const Eigen::Vector2d crossed(3.0, 1.0);
  int cx = 0, cy = 0;
  ASSERT_TRUE(grid.ToCell(crossed, cx, cy));
  ASSERT_TRUE(grid.clear_across(cx, cy));
  {
    test::AllocationScope scope;
    EXPECT_TRUE(grid.Follow(Eigen::Vector2f(13.0f, 2.0f)));
    EXPECT_EQ(scope.allocations(), 0u);
  }
  EXPECT_EQ(grid.moves(), 1u);
  EXPECT_NE(grid.origin_m().x(), -6.0f);
  EXPECT_FLOAT_EQ(std::fmod(grid.origin_m().x() + 6.0f, 4.0f), 0.0f) << "whole steps of 40 cells";
  ASSERT_TRUE(grid.ToCell(probe, px, py));
  EXPECT_EQ(grid.state(px, py), before);
  ASSERT_TRUE(grid.ToCell(crossed, cx, cy));
  EXPECT_TRUE(grid.clear_across(cx, cy));
  EXPECT_FALSE(grid.Follow(Eigen::Vector2f(13.0f, 2.0f))) << "inside now: no move";
  // Down the corridor to the far rooms: the window follows; the near rooms leave it.
  Scan(grid, near.plan, {{11, 6.2}}, true);
  Scan(grid, far.plan, {{41.5, 1.5}, {44.5, 3.5}, {43, 2.5}, {47.5, 1.5}, {50.5, 3.5}, {49, 2.5},
                        {41, 6.2}, {46, 6.2}, {51, 6.2}}, true);
  EXPECT_GE(grid.moves(), 2u);
  EXPECT_FALSE(grid.ToCell(probe, px, py)) << "the first room is behind the window now";
  RoomSegmenter segmenter;
  ASSERT_TRUE(segmenter.Init(240, 240, 64, 64));
  BoundedVector<RoomRegion> regions(64);
  ASSERT_TRUE(segmenter.Segment(grid, {}, regions));
  BoundedVector<DetectedRoom> rooms(16);
  ASSERT_TRUE(segmenter.DetectRooms(grid, regions.span(), far.walls, {}, rooms));
  int found = 0;
  for (const DetectedRoom& r : rooms) {
    if (r.kind != RoomKind::kRoom) continue;
    EXPECT_NEAR(r.centre.y(), 2.5, 0.05);
    EXPECT_NEAR(std::fabs(r.centre.x() - 46.0), 3.0, 0.05) << "the far rooms, in map coordinates";
    ++found;
  }
  EXPECT_EQ(found, 2);
  // Not finite: nothing moves.
  EXPECT_FALSE(grid.Follow(Eigen::Vector2f(std::nanf(""), 0.0f)));
}

TEST(Rooms, SegmentingAndDetectingAllocateNothing) {
  TwoRoomsAndCorridor world(0.3);
  FreeSpaceGridConfig gc;
  gc.width = gc.height = 400;
  gc.origin_m = {-10, -10};
  FreeSpaceGrid grid;
  ASSERT_TRUE(grid.Init(gc));
  Scan(grid, world.plan, {{1.5, 1.5}, {7.5, 1.5}, {6, 6.2}});
  RoomSegmenter segmenter;
  ASSERT_TRUE(segmenter.Init(400, 400, 64, 64));
  BoundedVector<RoomRegion> regions(64);
  BoundedVector<DetectedRoom> rooms(16);
  std::vector<Eigen::Vector3f> points(720, Eigen::Vector3f(1, 1, 1));
  test::AllocationScope scope;
  grid.Integrate(Eigen::Vector3f(0, 0, 0.8f), points, 0.0f);
  ASSERT_TRUE(segmenter.Segment(grid, {}, regions));
  ASSERT_TRUE(segmenter.DetectRooms(grid, regions.span(), world.walls, {}, rooms));
  EXPECT_EQ(scope.allocations(), 0u);
}

}  // namespace
}  // namespace msgraphs::core
