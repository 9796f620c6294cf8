// SPDX-License-Identifier: MIT
// The world format writer: every shipped world and generated buildings come back from
// ParseWorld(WriteWorld(w)) unchanged, and the written text is a fixed point.
#include "world_writer.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "building/generate.hpp"
#include "world.hpp"

namespace msgraphs::sim {
namespace {

World Reparse(const World& w) {
  ParseError error;
  auto again = ParseWorld(WriteWorld(w), error);
  EXPECT_TRUE(again.has_value()) << "line " << error.line << ": " << error.reason;
  return again.value_or(World{});
}

// Lengths must come back bit for bit; yaw angles to 1e-9 degrees (the file's unit).
void ExpectSame(const World& a, const World& b) {
  EXPECT_EQ(a.name, b.name);
  ASSERT_EQ(a.levels.size(), b.levels.size());
  for (std::size_t i = 0; i < a.levels.size(); ++i) {
    EXPECT_EQ(a.levels[i].index, b.levels[i].index);
    EXPECT_EQ(a.levels[i].floor_z_m, b.levels[i].floor_z_m);
    EXPECT_EQ(a.levels[i].ceiling_height_m, b.levels[i].ceiling_height_m);
  }
  ASSERT_EQ(a.walls.size(), b.walls.size());
  for (std::size_t i = 0; i < a.walls.size(); ++i) {
    const Wall &x = a.walls[i], &y = b.walls[i];
    EXPECT_EQ(x.id, y.id);
    EXPECT_EQ(x.start, y.start);
    EXPECT_EQ(x.end, y.end);
    EXPECT_EQ(x.thickness_m, y.thickness_m);
    EXPECT_EQ(x.height_m, y.height_m);
    EXPECT_EQ(x.level, y.level);
    EXPECT_EQ(x.material, y.material);
    ASSERT_EQ(x.doors.size(), y.doors.size()) << x.id;
    for (std::size_t d = 0; d < x.doors.size(); ++d) {
      EXPECT_EQ(x.doors[d].offset_m, y.doors[d].offset_m);
      EXPECT_EQ(x.doors[d].width_m, y.doors[d].width_m);
      EXPECT_EQ(x.doors[d].height_m, y.doors[d].height_m);
    }
  }
  ASSERT_EQ(a.rooms.size(), b.rooms.size());
  for (std::size_t i = 0; i < a.rooms.size(); ++i) {
    EXPECT_EQ(a.rooms[i].id, b.rooms[i].id);
    EXPECT_EQ(a.rooms[i].name, b.rooms[i].name);
    EXPECT_EQ(a.rooms[i].level, b.rooms[i].level);
    EXPECT_EQ(a.rooms[i].polygon, b.rooms[i].polygon) << a.rooms[i].id;
  }
  ASSERT_EQ(a.boxes.size(), b.boxes.size());
  for (std::size_t i = 0; i < a.boxes.size(); ++i) {
    EXPECT_EQ(a.boxes[i].centre, b.boxes[i].centre);
    EXPECT_NEAR(a.boxes[i].yaw_rad, b.boxes[i].yaw_rad, 1e-9 * std::numbers::pi / 180.0 + 1e-15);
    EXPECT_EQ(a.boxes[i].size_m, b.boxes[i].size_m);
    EXPECT_EQ(a.boxes[i].material, b.boxes[i].material);
    EXPECT_EQ(a.boxes[i].level, b.boxes[i].level);
  }
  ASSERT_EQ(a.cylinders.size(), b.cylinders.size());
  for (std::size_t i = 0; i < a.cylinders.size(); ++i) {
    EXPECT_EQ(a.cylinders[i].centre, b.cylinders[i].centre);
    EXPECT_EQ(a.cylinders[i].radius_m, b.cylinders[i].radius_m);
    EXPECT_EQ(a.cylinders[i].height_m, b.cylinders[i].height_m);
    EXPECT_EQ(a.cylinders[i].material, b.cylinders[i].material);
  }
}

class ShippedWorldRoundTrip : public ::testing::TestWithParam<const char*> {};

TEST_P(ShippedWorldRoundTrip, ParseWriteParseGivesTheSameWorld) {
  std::string error;
  const auto world = LoadWorld(std::string(MSGRAPHS_WORLDS_DIR) + "/" + GetParam(), error);
  ASSERT_TRUE(world.has_value()) << error;
  const World again = Reparse(*world);
  ExpectSame(*world, again);
  EXPECT_EQ(WriteWorld(*world), WriteWorld(again));
}

INSTANTIATE_TEST_SUITE_P(
    Worlds,
    ShippedWorldRoundTrip,
    ::testing::Values("office.world", "construction.world", "apartment.world", "rotated.world"));

TEST(WorldWriter, GeneratedBuildingsRoundTripExactly) {
  for (std::uint64_t seed = 1; seed <= 40; ++seed) {
    const World w = building::GenerateBuilding(seed, {});
    const World again = Reparse(w);
    ExpectSame(w, again);
    // Generated numbers sit on the file's grid, so even yaw angles come back exactly.
    for (std::size_t i = 0; i < w.boxes.size() && i < again.boxes.size(); ++i) {
      ASSERT_EQ(w.boxes[i].yaw_rad, again.boxes[i].yaw_rad) << "seed " << seed;
    }
    ASSERT_EQ(WriteWorld(w), WriteWorld(again)) << "seed " << seed;
  }
}

TEST(WorldWriter, NamesAndIdsBecomeTokensTheParserReads) {
  World w;
  w.name = "A  name # with = odd\tcharacters ";
  w.levels.push_back({0, 0.0, std::nullopt});
  w.levels.push_back({2, 3.5, 2.75});
  Wall wall;
  wall.id = "a wall#1";
  wall.start = {0, 0};
  wall.end = {4.25, 0};
  wall.level = 2;
  wall.material = Material::kGlass;
  wall.doors.push_back({1.0, 0.9, 2.0});
  w.walls.push_back(wall);
  Room room;
  room.id = "r=1";
  room.name = "";
  room.level = 2;
  room.polygon = {{0, 0}, {4, 0}, {4, 4}, {0, 4}};
  w.rooms.push_back(room);
  w.boxes.push_back({{1, 1}, 0.3, {1, 1, 1}, 2, Material::kMetal});
  w.cylinders.push_back({{3, 3}, 0.2, 3.0, 2, Material::kConcrete});
  const World again = Reparse(w);
  EXPECT_EQ(again.name, "A name with _ odd characters");
  ASSERT_EQ(again.walls.size(), 1u);
  EXPECT_EQ(again.walls[0].id, "a_wall_1");
  EXPECT_EQ(again.walls[0].doors.size(), 1u);
  EXPECT_EQ(again.walls[0].material, Material::kGlass);
  EXPECT_EQ(again.rooms[0].id, "r_1");
  EXPECT_EQ(again.rooms[0].name, "room");
  EXPECT_EQ(again.rooms[0].level, 2);
  EXPECT_FALSE(again.levels[0].ceiling_height_m.has_value());
  EXPECT_EQ(again.levels[1].ceiling_height_m, 2.75);
  EXPECT_NEAR(again.boxes[0].yaw_rad, 0.3, 1e-10);
  EXPECT_EQ(again.boxes[0].material, Material::kMetal);
  EXPECT_EQ(again.cylinders[0].level, 2);
}

}  // namespace
}  // namespace msgraphs::sim
