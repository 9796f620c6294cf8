// SPDX-License-Identifier: MIT
// Mission kinds: peeks stay outside the room they look into, partial and full visits enter, a
// mission with no shared rooms plans for any fleet size, start delays shift the robots' walks.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <string>
#include <vector>

#include "mission.hpp"
#include "scene.hpp"
#include "world.hpp"

namespace msgraphs::sim {
namespace {

World Load(const char* name) {
  std::string error;
  return LoadWorld(std::string(MSGRAPHS_WORLDS_DIR) + "/" + name, error).value();
}

// How far p lies inside the polygon (0 outside or on it).
double DepthInside(const Room& room, const Eigen::Vector2d& p) {
  if (!room.Contains(p)) return 0.0;
  double d = std::numeric_limits<double>::infinity();
  const auto& poly = room.polygon;
  for (std::size_t i = 0; i < poly.size(); ++i) {
    const Eigen::Vector2d a = poly[i], b = poly[(i + 1) % poly.size()];
    const double s = std::clamp((p - a).dot(b - a) / (b - a).squaredNorm(), 0.0, 1.0);
    d = std::min(d, (p - (a + s * (b - a))).norm());
  }
  return d;
}

double DistanceToRoom(const Room& room, const Eigen::Vector2d& p) {
  if (room.Contains(p)) return 0.0;
  double d = std::numeric_limits<double>::infinity();
  const auto& poly = room.polygon;
  for (std::size_t i = 0; i < poly.size(); ++i) {
    const Eigen::Vector2d a = poly[i], b = poly[(i + 1) % poly.size()];
    const double s = std::clamp((p - a).dot(b - a) / (b - a).squaredNorm(), 0.0, 1.0);
    d = std::min(d, (p - (a + s * (b - a))).norm());
  }
  return d;
}

const Room& RoomById(const World& w, const std::string& id) {
  return *std::find_if(w.rooms.begin(), w.rooms.end(), [&](const Room& r) { return r.id == id; });
}

class MissionKinds : public ::testing::TestWithParam<const char*> {};

// A peek stops in or just outside the doorway: from the moment the robot sets off towards the
// room until its next visit is over, its base never gets past the doorway (the polygons run
// along the walls' centre lines, so the doorway is the wall's half thickness deep).
TEST_P(MissionKinds, PeeksNeverEnterPartialAndFullVisitsDo) {
  const World world = Load(GetParam());
  const Scene scene(world, 0);
  MissionConfig config;
  config.robots = 3;
  config.duration_s = 240;
  config.seed = 5;
  config.shared_rooms = 0;
  config.visit_kinds = {0.5, 0.25, 0.25};
  std::string error;
  const auto mission = PlanMission(world, scene, config, error);
  ASSERT_TRUE(mission.has_value()) << error;
  double min_half_thickness = 1e9;
  for (const Wall& w : world.walls)
    min_half_thickness = std::min(min_half_thickness, 0.5 * w.thickness_m);
  std::map<VisitKind, int> kinds;
  double worst_depth = 0;
  for (const RobotPlan& r : mission->robots) {
    for (std::size_t i = 0; i < r.visits.size(); ++i) {
      const Visit& v = r.visits[i];
      ++kinds[v.kind];
      const Room& room = RoomById(world, v.room);
      const bool complete = v.end_s < config.duration_s - 0.05;
      const auto at = [&](double mission_t) {
        const PlanarPose p = r.trajectory.Planar(mission_t - r.start_delay_s);
        return Eigen::Vector2d(p.x, p.y);
      };
      if (v.kind == VisitKind::kPeek) {
        double until = v.end_s;
        if (i + 1 < r.visits.size() && r.visits[i + 1].room != v.room)
          until = r.visits[i + 1].end_s;
        if (i + 1 == r.visits.size()) until = config.duration_s;
        for (double t = v.start_s; t <= until; t += 0.02) {
          const double depth = DepthInside(room, at(t));
          worst_depth = std::max(worst_depth, depth);
          ASSERT_LE(depth, min_half_thickness) << r.id << " peeking into " << v.room << " at " << t;
        }
        // It did look in: it ended up at the doorway.
        if (complete) {
          EXPECT_LT(DistanceToRoom(room, at(v.end_s)), config.peek_stand_max_m + 0.15) << v.room;
        }
      } else if (v.kind != VisitKind::kStart && complete) {
        EXPECT_TRUE(room.Contains(at(v.end_s))) << r.id << " " << ToString(v.kind) << " " << v.room;
        if (v.kind == VisitKind::kFull) {
          EXPECT_GE(v.points, std::min(3, static_cast<int>(room.Area() / 4)))
              << r.id << " " << v.room << " " << room.Area() << " m2 at " << v.start_s;
        }
        if (v.kind == VisitKind::kPartial) {
          EXPECT_LE(v.points, 2);
        }
      }
      EXPECT_LE(v.start_s, v.end_s);
    }
  }
  EXPECT_GT(kinds[VisitKind::kPeek], 2);
  EXPECT_GT(kinds[VisitKind::kPartial] + kinds[VisitKind::kFull], 2);
  RecordProperty("worst_peek_depth_m", std::to_string(worst_depth));
}

// With no shared rooms asked for, any fleet of 2 to 5 robots plans, with or without start delays.
TEST_P(MissionKinds, ZeroSharedRoomsNeverFails) {
  const World world = Load(GetParam());
  const Scene scene(world, 0);
  for (int robots = 2; robots <= 5; ++robots) {
    for (const std::uint64_t seed : {1u, 2u}) {
      MissionConfig config;
      config.robots = robots;
      config.duration_s = 45;
      config.seed = seed;
      config.shared_rooms = 0;
      config.start_delays.mode = StartDelays::Mode::kRandom;
      std::string error;
      const auto mission = PlanMission(world, scene, config, error);
      ASSERT_TRUE(mission.has_value()) << robots << " robots, seed " << seed << ": " << error;
      for (const RobotPlan& r : mission->robots) {
        EXPECT_GE(r.start_delay_s, 0.0);
        EXPECT_LE(r.start_delay_s, 15.0);  // random: up to a third of the duration
        EXPECT_NEAR(r.trajectory.start_s(), r.start_delay_s, 1e-12);
        EXPECT_NEAR(r.trajectory.duration_s() + r.start_delay_s, 45.0, 0.011);
        // It stands still at its start, level: the odometry's first sample defines a
        // gravity-aligned frame, as the stack assumes.
        const Eigen::Isometry3d T0 = r.trajectory.Pose(0.02);
        EXPECT_EQ(T0.linear()(2, 2), 1.0);
        EXPECT_EQ(T0.translation().z(), 0.5);
      }
    }
  }
}

INSTANTIATE_TEST_SUITE_P(
    Worlds,
    MissionKinds,
    ::testing::Values("office.world", "construction.world", "apartment.world", "rotated.world"));

TEST(StartDelays, ParseAndApply) {
  std::string error;
  EXPECT_EQ(StartDelays::Parse("none", error)->mode, StartDelays::Mode::kNone);
  EXPECT_EQ(StartDelays::Parse("random", error)->mode, StartDelays::Mode::kRandom);
  const auto d = StartDelays::Parse("2=35.5,3=0", error);
  ASSERT_TRUE(d.has_value()) << error;
  EXPECT_EQ(d->explicit_s.at(2), 35.5);
  for (const char* bad : {"2=-1", "x=3", "2=", "0=4", "2=3s", "sometimes"}) {
    EXPECT_FALSE(StartDelays::Parse(bad, error).has_value()) << bad;
  }
  const World world = Load("office.world");
  const Scene scene(world, 0);
  MissionConfig config;
  config.robots = 3;
  config.duration_s = 120;
  config.shared_rooms = 0;
  config.start_delays = *d;
  const auto mission = PlanMission(world, scene, config, error);
  ASSERT_TRUE(mission.has_value()) << error;
  EXPECT_EQ(mission->robots[0].start_delay_s, 0.0);
  EXPECT_EQ(mission->robots[1].start_delay_s, 35.5);
  EXPECT_NEAR(mission->robots[1].trajectory.duration_s(), 120.0 - 35.5, 0.011);
  EXPECT_EQ(mission->robots[1].visits.front().start_s, 35.5);
  config.start_delays.explicit_s[2] = 120.0;  // nothing left to walk
  EXPECT_FALSE(PlanMission(world, scene, config, error).has_value());
  config.start_delays.explicit_s = {{4, 1.0}};  // no robot 4
  EXPECT_FALSE(PlanMission(world, scene, config, error).has_value());
}

TEST(VisitKinds, Parse) {
  std::string error;
  const auto k = VisitKinds::Parse("peek=0.5,full=1", error);
  ASSERT_TRUE(k.has_value()) << error;
  EXPECT_EQ(k->peek, 0.5);
  EXPECT_EQ(k->partial, 0.0);
  EXPECT_EQ(k->full, 1.0);
  for (const char* bad : {"peek=-1", "look=1", "peek", "peek=0,partial=0,full=0", "full=1x"}) {
    EXPECT_FALSE(VisitKinds::Parse(bad, error).has_value()) << bad;
  }
}

}  // namespace
}  // namespace msgraphs::sim
