// SPDX-License-Identifier: MIT
// The free-space summary's openings: where a robot saw through one of its own walls, and only
// there; and Build and Decode allocate nothing.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <span>
#include <vector>

#include "alloc_counter.hpp"
#include "msgraphs/core/collab/free_space_codec.hpp"
#include "msgraphs/core/collab/free_space_summary.hpp"

namespace msgraphs::core {
namespace {

// A 6 m wall on y = 0 from x = 0 to 6, a 1 m door from x = 2 to 3; floor at z = 0.
constexpr float kDoorFrom = 2.0f, kDoorTo = 3.0f, kWallTo = 6.0f;

bool InDoor(float x) { return x > kDoorFrom && x < kDoorTo; }

// What a sensor at (x, y_side, 0.8) sees looking at the wall across x from -1 to 7: the wall's
// face where it stands, the floor beyond it (as far behind the wall's line as the sensor is in
// front) through the door or past its ends. Every ray descends, so it clears below the sensor.
std::vector<Eigen::Vector3f> LookAtTheWall(const Eigen::Vector3f& sensor) {
  std::vector<Eigen::Vector3f> points;
  for (float x = -1.0f; x <= 7.0f; x += 0.02f) {
    const bool solid = x >= 0.0f && x <= kWallTo && !InDoor(x);
    if (solid) {
      points.emplace_back(x, 0.0f, 0.5f);
    } else {
      // Beyond the wall's line, as far again as the sensor is in front of it.
      points.emplace_back(sensor.x() + 2.0f * (x - sensor.x()), -sensor.y(), 0.3f);
    }
  }
  return points;
}

FreeSpaceGrid Grid() {
  FreeSpaceGridConfig config;
  config.width = 200;
  config.height = 200;
  config.origin_m = {-10.0f, -10.0f};
  FreeSpaceGrid grid;
  EXPECT_TRUE(grid.Init(config).has_value());
  return grid;
}

// The wall looked at from 2.8 m in front of its door and from 2.8 m behind it.
void LookFromBothSides(FreeSpaceGrid& grid) {
  for (const Eigen::Vector3f& sensor : {Eigen::Vector3f(3, 2.8f, 0.8f), Eigen::Vector3f(3, -2.8f, 0.8f)}) {
    const auto points = LookAtTheWall(sensor);
    grid.Integrate(sensor, points, 0.0f);
  }
}

DistilledWall TheWall() {
  DistilledWall wall;
  wall.normal = Eigen::Vector3d::UnitY();
  wall.d = 0;
  wall.a = {0, 0};
  wall.b = {kWallTo, 0};
  return wall;
}

std::vector<Opening> Openings(const FreeSpaceGrid& grid) {
  FreeSpaceSummary summary;
  EXPECT_TRUE(summary.Init({}).has_value());
  const DistilledWall wall = TheWall();
  EXPECT_TRUE(summary.Build(grid, std::span<const DistilledWall>(&wall, 1)).has_value());
  return {summary.openings().begin(), summary.openings().end()};
}

void ExpectOnlyTheDoor(const std::vector<Opening>& openings) {
  ASSERT_EQ(openings.size(), 1u);
  const double from = std::min(openings[0].a.x(), openings[0].b.x());
  const double to = std::max(openings[0].a.x(), openings[0].b.x());
  EXPECT_NEAR(from, kDoorFrom, 0.2);
  EXPECT_NEAR(to, kDoorTo, 0.2);
}

TEST(FreeSpaceSummary, ADoorSeenFromBothSidesIsAnOpening) {
  FreeSpaceGrid grid = Grid();
  LookFromBothSides(grid);
  ExpectOnlyTheDoor(Openings(grid));
}

// A robot walking along the wall's line sees the wall edge-on: its rays graze along the wall's
// cells many times while the face is hit a few times from either side. The wall is still solid
// there, and a peer's true wall must not be contradicted by a false opening.
TEST(FreeSpaceSummary, AWallSeenEdgeOnIsNoOpening) {
  FreeSpaceGrid grid = Grid();
  LookFromBothSides(grid);
  const Eigen::Vector3f in_line(-3, 0, 0.8f);
  const std::vector<Eigen::Vector3f> grazing(100, Eigen::Vector3f(9.5f, 0, 0.5f));
  grid.Integrate(in_line, grazing, 0.0f);
  ExpectOnlyTheDoor(Openings(grid));
}

// The same wall, seen edge-on again and again (a robot standing in a doorway in its line): the
// grazing rays outnumber the returns off its face, so the fine grid reads its cells "not
// occupied", but they did return points in the obstacle band, and the summary must not claim
// them free: a peer's true wall there would count against the true transform (benchmark
// m010-warehouse), and a robot's own wall against its own map (m034). In front of the wall,
// where nothing ever returned, the summary stays free.
TEST(FreeSpaceSummary, AWallSeenEdgeOnIsNotFree) {
  FreeSpaceGrid grid = Grid();
  LookFromBothSides(grid);
  const Eigen::Vector3f in_line(-3, -0.05f, 0.8f);
  const std::vector<Eigen::Vector3f> grazing(400, Eigen::Vector3f(9.5f, -0.05f, 0.5f));
  grid.Integrate(in_line, grazing, 0.0f);
  int x = 0, y = 0;
  ASSERT_TRUE(grid.ToCell({4.55, -0.05}, x, y));
  ASSERT_NE(grid.state(x, y), FreeSpaceGrid::Cell::kOccupied);  // the fine grid's reading, as described
  ASSERT_TRUE(grid.ever_occupied(x, y));
  FreeSpaceSummary summary;
  ASSERT_TRUE(summary.Init({}));
  const DistilledWall wall = TheWall();
  ASSERT_TRUE(summary.Build(grid, std::span<const DistilledWall>(&wall, 1)));
  for (double along = 0.5; along < static_cast<double>(kWallTo) - 0.5; along += 0.1) {
    if (InDoor(static_cast<float>(along)) || InDoor(static_cast<float>(along - 0.3)) ||
        InDoor(static_cast<float>(along + 0.3)))
      continue;
    EXPECT_NE(summary.state_at({along, -0.05}), SummaryCell::kFree) << "at x = " << along;
  }
  EXPECT_EQ(summary.state_at({4.5, 1.5}), SummaryCell::kFree);
}

// A place crossed from two directions was seen through, whatever returned from it once: a
// person who stood there, or the wall copy a slipped map holds (the evidence merge rule 6
// needs). It stays free.
TEST(FreeSpaceSummary, APlaceSeenThroughFromTwoDirectionsIsFreeWhateverReturnedOnce) {
  FreeSpaceGrid grid = Grid();
  const Eigen::Vector3f person(0.05f, 0.05f, 1.0f);
  grid.Integrate({0, -3, 0.8f}, std::span<const Eigen::Vector3f>(&person, 1), 0.0f);
  int x = 0, y = 0;
  ASSERT_TRUE(grid.ToCell({0.05, 0.05}, x, y));
  ASSERT_TRUE(grid.ever_occupied(x, y));
  // Then the floor behind the place, from the south and from the west.
  std::vector<Eigen::Vector3f> floor;
  for (float a = -1.0f; a <= 1.0f; a += 0.02f) {
    for (float b = 1.0f; b <= 3.0f; b += 0.05f) floor.emplace_back(a, b, 0.0f);
  }
  grid.Integrate({0, -3, 0.8f}, floor, 0.0f);
  for (Eigen::Vector3f& p : floor) p = {p.y(), p.x(), 0.0f};
  grid.Integrate({-3, 0, 0.8f}, floor, 0.0f);
  ASSERT_NE(grid.state(x, y), FreeSpaceGrid::Cell::kOccupied);
  ASSERT_TRUE(grid.clear_across(x, y));
  FreeSpaceSummary summary;
  ASSERT_TRUE(summary.Init({}));
  ASSERT_TRUE(summary.Build(grid, {}));
  EXPECT_EQ(summary.state_at({0.05, 0.05}), SummaryCell::kFree);
}

// Each descending ray marks the cells it crosses with the sector (8 over a half turn) of its
// line's direction, whichever way it points: rays every 5 degrees round the full turn, each into
// a fresh grid, from the cell centre at the origin to a floor point 4 m away.
TEST(FreeSpaceGrid, ARayMarksTheSectorOfItsLineDirection) {
  for (int k = 0; k < 72; ++k) {
    const double angle = (5.0 * k + 1.3) * std::numbers::pi / 180.0;
    FreeSpaceGrid grid = Grid();
    const Eigen::Vector3f end(static_cast<float>(4.0 * std::cos(angle)) + 0.05f,
                              static_cast<float>(4.0 * std::sin(angle)) + 0.05f, 0.0f);
    grid.Integrate({0.05f, 0.05f, 0.8f}, std::span<const Eigen::Vector3f>(&end, 1), 0.0f);
    int x0 = 0, y0 = 0, x1 = 0, y1 = 0;
    ASSERT_TRUE(grid.ToCell({0.05, 0.05}, x0, y0));
    ASSERT_TRUE(grid.ToCell(end.head<2>().cast<double>(), x1, y1));
    // The sector of the cell-to-cell direction the grid traces (within a cell of the angle's).
    double line = std::atan2(static_cast<double>(y1 - y0), static_cast<double>(x1 - x0));
    if (line < 0) line += std::numbers::pi;
    const int sector = std::min(7, static_cast<int>(line / std::numbers::pi * 8));
    EXPECT_EQ(grid.clear_directions(x0, y0), 1u << sector) << 5 * k + 1.3 << " degrees";
  }
}

// free_space_summary.hpp: "Build and Decode allocate nothing". The grid, both summaries (Init)
// and the message buffer are set up first; the first Build and the first Decode are counted.
TEST(FreeSpaceSummary, BuildAndDecodeAllocateNothing) {
  FreeSpaceGrid grid = Grid();
  LookFromBothSides(grid);
  const DistilledWall wall = TheWall();
  FreeSpaceSummary summary;
  ASSERT_TRUE(summary.Init({}));
  FreeSpaceSummary received;
  ASSERT_TRUE(received.Init({}));
  std::vector<std::uint8_t> bytes(1 << 20);

  std::uint64_t build_allocations = 0;
  {
    test::AllocationScope scope;
    const Status built = summary.Build(grid, std::span<const DistilledWall>(&wall, 1));
    build_allocations = scope.allocations();
    ASSERT_TRUE(built) << built.error().detail;
  }
  EXPECT_EQ(build_allocations, 0u);
  EXPECT_GT(summary.free_cells(), 0u);
  ExpectOnlyTheDoor(std::vector<Opening>(summary.openings().begin(), summary.openings().end()));

  const Expected<std::size_t> n = EncodeFreeSpace({3, 9}, summary, bytes);
  ASSERT_TRUE(n) << n.error().detail;
  const std::span<const std::uint8_t> message(bytes.data(), *n);
  std::uint64_t decode_allocations = 0;
  {
    test::AllocationScope scope;
    const Expected<FreeSpaceHeader> header = DecodeFreeSpace(message, received);
    decode_allocations = scope.allocations();
    ASSERT_TRUE(header) << header.error().detail;
    EXPECT_EQ(header->robot, 3);
    EXPECT_EQ(header->version, 9u);
  }
  EXPECT_EQ(decode_allocations, 0u);
  ASSERT_EQ(received.cells(), summary.cells());
  EXPECT_TRUE(std::equal(received.raw().begin(), received.raw().end(), summary.raw().begin()));
  EXPECT_EQ(received.free_cells(), summary.free_cells());
  EXPECT_EQ(received.openings().size(), summary.openings().size());
}

}  // namespace
}  // namespace msgraphs::core
