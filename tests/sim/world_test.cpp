// SPDX-License-Identifier: MIT
// The world format: parsing, validation errors with line numbers, the shipped worlds, and ray
// casting against known geometry.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <set>

#include "mission.hpp"
#include "scene.hpp"
#include "truth.hpp"
#include "world.hpp"

namespace msgraphs::sim {
namespace {

// A 10 x 6 m room split by a wall at x = 5 with a 1 m door; a column and a table.
const char* kTwoRooms = R"(msgraphs-world 1
name Two rooms
level 0 0.0 3.0
wall s 0 0 10 0 0.2 3.0
wall n 0 6 10 6 0.2 3.0
wall w 0 0 0 6 0.2 3.0
wall e 10 0 10 6 0.2 3.0
wall mid 5 0 5 6 0.1 3.0   # the middle wall
door mid 2.5 1.0 2.0
room a office 0 0 5 0 5 6 0 6
room b office 5 0 10 0 10 6 5 6
cylinder 7.5 1.0 0.25 3.0
box 2.0 5.0 0 1.0 0.6 0.75 material=wood
)";

World Parse(const std::string& text) {
  ParseError error;
  auto world = ParseWorld(text, error);
  EXPECT_TRUE(world.has_value()) << "line " << error.line << ": " << error.reason;
  return world.value_or(World{});
}

TEST(WorldFormat, ParsesAllElements) {
  const World w = Parse(kTwoRooms);
  EXPECT_EQ(w.name, "Two rooms");
  ASSERT_EQ(w.walls.size(), 5u);
  EXPECT_EQ(w.walls[4].doors.size(), 1u);
  ASSERT_EQ(w.rooms.size(), 2u);
  EXPECT_NEAR(w.rooms[0].Area(), 30.0, 1e-9);
  EXPECT_TRUE(w.rooms[1].Contains({7, 3}));
  EXPECT_EQ(w.RoomAt({1, 1}, 0)->id, "a");
  EXPECT_EQ(w.boxes[0].material, Material::kWood);
  EXPECT_EQ(w.cylinders[0].material, Material::kConcrete);
  ASSERT_TRUE(w.levels[0].ceiling_height_m.has_value());
}

struct BadCase {
  const char* replace_line;  // appended to a valid prefix
  int line;
  const char* reason_part;
};

TEST(WorldFormat, ErrorsNameTheLineAndTheReason) {
  const std::string prefix = "msgraphs-world 1\nlevel 0 0 3\nwall a 0 0 4 0 0.1 3\nroom r x 0 0 4 0 4 4 0 4\n";
  const BadCase cases[] = {
      {"bogus 1 2", 5, "unknown keyword"},
      {"wall b 0 0 0 0.01 0.1 3", 5, "shorter than 5 cm"},
      {"wall a 0 1 4 1 0.1 3", 5, "used twice"},
      {"wall b 0 0 4 4 0.1 nan", 5, "not a finite number"},
      {"wall b 0 0 4 4 0.1 3 material=marble", 5, "unknown material"},
      {"wall b 0 0 4 4 0.1 3 colour=red", 5, "unknown option"},
      {"door a 3.5 1.0 2.0", 5, "inside its wall"},
      {"door zz 1 1 2", 5, "unknown wall"},
      {"room q x 0 0 4 4 4 0 0 4", 5, "intersects itself"},
      {"room q x 0 0 1 0", 5, "at least 3 vertices"},
      {"box 50 50 0 1 1 1", 0, "in no room"},
      {"level 0 0 3", 5, "defined twice"},
      {"level 1 3 1.0", 5, "ceiling height"},
      {"cylinder 1 1 0.2 3 level=4", 0, "undefined level"},
  };
  for (const BadCase& c : cases) {
    ParseError error;
    EXPECT_FALSE(ParseWorld(prefix + c.replace_line + "\n", error).has_value()) << c.replace_line;
    EXPECT_EQ(error.line, c.line) << c.replace_line << ": " << error.reason;
    EXPECT_NE(error.reason.find(c.reason_part), std::string::npos) << c.replace_line << ": " << error.reason;
  }
  ParseError error;
  EXPECT_FALSE(ParseWorld("msgraphs-world 2\n", error).has_value());
  EXPECT_NE(error.reason.find("version 2"), std::string::npos);
  EXPECT_FALSE(ParseWorld("", error).has_value());
  EXPECT_FALSE(ParseWorld("msgraphs-world 1\nlevel 0 0 3\n", error).has_value());
  EXPECT_NE(error.reason.find("no walls"), std::string::npos);
}

TEST(Scene, RaysHitWallsFloorCeilingColumnsAndPassDoors) {
  const World w = Parse(kTwoRooms);
  const Scene scene(w, 0);
  auto scratch = scene.MakeScratch();
  // From (2.5, 1, 1) along +x: the middle wall's face at x = 4.95.
  auto hit = scene.Cast({2.5, 1.0, 1.0}, {1, 0, 0}, 100, scratch);
  ASSERT_TRUE(hit.has_value());
  EXPECT_NEAR(hit->range_m, 2.45, 1e-9);
  EXPECT_NEAR(hit->normal.x(), -1.0, 1e-12);
  // Through the door (y in 2.5..3.5 at x = 5) to the east wall's face at x = 9.9.
  hit = scene.Cast({4.0, 2.9, 1.0}, {1, 0, 0}, 100, scratch);  // y = 2.9 is inside the door
  EXPECT_NEAR(hit->range_m, 5.9, 1e-9);
  // Above the door (z 2.0..3.0) the lintel blocks.
  hit = scene.Cast({4.0, 2.9, 2.5}, {1, 0, 0}, 100, scratch);
  EXPECT_NEAR(hit->range_m, 0.95, 1e-9);
  // Straight down: the floor; up: the ceiling.
  EXPECT_NEAR(scene.Cast({3, 3, 0.8}, {0, 0, -1}, 100, scratch)->range_m, 0.8, 1e-9);
  EXPECT_NEAR(scene.Cast({3, 3, 0.8}, {0, 0, 1}, 100, scratch)->range_m, 2.2, 1e-9);
  // The column at (7.5, 1) radius 0.25, seen from (7.5, 3) looking -y.
  hit = scene.Cast({7.5, 3.0, 1.0}, {0, -1, 0}, 100, scratch);
  EXPECT_NEAR(hit->range_m, 1.75, 1e-9);
  EXPECT_NEAR(hit->normal.y(), 1.0, 1e-9);
  // The table top from above.
  hit = scene.Cast({2.0, 5.0, 2.0}, {0, 0, -1}, 100, scratch);
  EXPECT_NEAR(hit->range_m, 1.25, 1e-9);
  EXPECT_EQ(hit->material, Material::kWood);
  // Max range: nothing within 0.5 m.
  EXPECT_FALSE(scene.Cast({2.5, 1.0, 1.0}, {1, 0, 0}, 0.5, scratch).has_value());
  // Rays on a grid-cell boundary (y = 2.9 here) and diagonal ones walk the grid correctly.
  hit = scene.Cast({1.0, 1.0, 1.0}, Eigen::Vector3d(1, 1, 0).normalized(), 100, scratch);
  ASSERT_TRUE(hit.has_value());
  EXPECT_NEAR(hit->range_m, 3.95 * std::sqrt(2.0), 1e-9);  // the mid wall's face at x = 4.95
  // Distances to surfaces: next to a wall, and in a doorway (to the door's edge).
  EXPECT_NEAR(scene.DistanceToSurface({4.9, 1.0, 1.0}), 0.05, 1e-9);
  EXPECT_NEAR(scene.DistanceToSurface({4.9, 3.0, 1.0}), std::hypot(0.5, 0.05), 1e-9);
  EXPECT_NEAR(scene.DistanceToSurface({3.0, 3.0, 0.1}), 0.1, 1e-9);
}

// An opening up to the ceiling (door height = wall height, no lintel) is a valid door, and the
// scene leaves it open from floor to ceiling.
TEST(WorldFormat, ADoorAsHighAsItsWallIsAnOpeningWithoutLintel) {
  std::string text = kTwoRooms;
  text.replace(text.find("door mid 2.5 1.0 2.0"), 20, "door mid 2.5 1.0 3.0");
  const World w = Parse(text);
  ASSERT_EQ(w.walls[4].doors.size(), 1u);
  EXPECT_EQ(w.walls[4].doors[0].height_m, w.walls[4].height_m);
  const Scene scene(w, 0);
  auto scratch = scene.MakeScratch();
  // At 2.9 m (where a lintel would be) the ray passes the doorway to the east wall at x = 9.9.
  const auto hit = scene.Cast({4.0, 2.9, 2.9}, {1, 0, 0}, 100, scratch);
  ASSERT_TRUE(hit.has_value());
  EXPECT_NEAR(hit->range_m, 5.9, 1e-9);
  // Taller than the wall is still refused.
  ParseError error;
  text.replace(text.find("door mid 2.5 1.0 3.0"), 20, "door mid 2.5 1.0 3.1");
  EXPECT_FALSE(ParseWorld(text, error).has_value());
  EXPECT_NE(error.reason.find("door height"), std::string::npos);
}

TEST(Scene, ARotatedWallIsHitWhereGeometrySaysSo) {
  // A single wall along the 30-degree diagonal; a ray along its normal from 2 m away.
  const double a = 30.0 * std::numbers::pi / 180.0;
  const Eigen::Vector2d d(std::cos(a), std::sin(a)), n(-std::sin(a), std::cos(a));
  char text[512];
  std::snprintf(text, sizeof(text),
                "msgraphs-world 1\nlevel 0 0 3\nwall w %.9f %.9f %.9f %.9f 0.2 3\nroom r x -10 -10 10 -10 10 10 -10 10\n",
                -5 * d.x(), -5 * d.y(), 5 * d.x(), 5 * d.y());
  const World w = Parse(text);
  const Scene scene(w, 0);
  auto scratch = scene.MakeScratch();
  const Eigen::Vector3d origin(2 * n.x(), 2 * n.y(), 1.0);
  const auto hit = scene.Cast(origin, Eigen::Vector3d(-n.x(), -n.y(), 0), 100, scratch);
  ASSERT_TRUE(hit.has_value());
  EXPECT_NEAR(hit->range_m, 1.9, 1e-9);
  EXPECT_NEAR(hit->normal.head<2>().dot(n), 1.0, 1e-9);
}

TEST(Truth, MinAreaRectangleGivesTheRoomsOrientation) {
  Room r;
  const double a = 30.0 * std::numbers::pi / 180.0;
  const Eigen::Rotation2Dd R(a);
  for (const auto& p : {Eigen::Vector2d(0, 0), Eigen::Vector2d(6, 0), Eigen::Vector2d(6, 4), Eigen::Vector2d(0, 4)}) {
    r.polygon.push_back(R * p + Eigen::Vector2d(5, 2));
  }
  const RoomRectangle rect = MinAreaRectangle(r);
  EXPECT_NEAR(rect.width_m, 4.0, 1e-9);
  EXPECT_NEAR(rect.length_m, 6.0, 1e-9);
  EXPECT_NEAR(std::fmod(rect.orientation_deg, 90.0), 30.0, 1e-6);
  EXPECT_NEAR((rect.centre - (R * Eigen::Vector2d(3, 2) + Eigen::Vector2d(5, 2))).norm(), 0.0, 1e-9);
}

class ShippedWorlds : public ::testing::TestWithParam<const char*> {};

TEST_P(ShippedWorlds, ParseAndPlanADefaultMissionWhereEveryPairSharesTwoRooms) {
  std::string error;
  auto world = LoadWorld(std::string(MSGRAPHS_WORLDS_DIR) + "/" + GetParam(), error);
  ASSERT_TRUE(world.has_value()) << error;
  const Scene scene(*world, 0);
  for (int robots : {2, 3, 5}) {
    MissionConfig config;
    config.robots = robots;
    config.duration_s = 300;
    config.seed = 7;
    auto mission = PlanMission(*world, scene, config, error);
    ASSERT_TRUE(mission.has_value()) << GetParam() << " with " << robots << " robots: " << error;
    ASSERT_EQ(mission->robots.size(), static_cast<std::size_t>(robots));
    std::set<std::pair<int, int>> starts;
    for (const RobotPlan& r : mission->robots) {
      EXPECT_NEAR(r.trajectory.duration_s(), 300.0, 0.02);
      // Walking speed is Spot's, never above 1 m/s.
      const auto& s = r.trajectory.samples();
      double max_speed = 0;
      for (std::size_t i = 1; i < s.size(); ++i) max_speed = std::max(max_speed, std::hypot(s[i].x - s[i - 1].x, s[i].y - s[i - 1].y) / 0.01);
      EXPECT_LE(max_speed, 1.0 + 1e-9);
      EXPECT_GT(r.trajectory.PathLength(300), 60.0) << "robot " << r.id << " barely moved";
      starts.insert({static_cast<int>(std::lround(r.start.x * 10)), static_cast<int>(std::lround(r.start.y * 10))});
    }
    EXPECT_EQ(starts.size(), static_cast<std::size_t>(robots)) << "start poses differ";
  }
}

INSTANTIATE_TEST_SUITE_P(Worlds, ShippedWorlds,
                         ::testing::Values("office.world", "construction.world", "apartment.world", "rotated.world"));

}  // namespace
}  // namespace msgraphs::sim
