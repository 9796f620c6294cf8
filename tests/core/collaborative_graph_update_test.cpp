// SPDX-License-Identifier: MIT
// The collaborative graph is persistent (collaborative_graph.hpp): each update declares the
// graph as it should now be; unchanged factors stay, changed measurements are replaced in
// place, what the update left out goes. The reference is always a fresh graph declared once
// with the same content: the persistent one must solve to the same estimate.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <tuple>
#include <vector>

#include "distilled_rooms.hpp"
#include "msgraphs/core/graph/collaborative_graph.hpp"
#include "synthetic_clouds.hpp"

namespace msgraphs::core {
namespace {

Eigen::Isometry3d Planar(double x, double y, double yaw) { return test::PlanarPose(x, y, yaw); }

// Three rooms of robot 1 and robot `robot`'s view of them through T_1_robot (its map frame in
// robot 1's). Robot ids differ by room and wall ids, as two robots' would.
struct TwoMaps {
  DistilledGraph a, b;
  TwoMaps(const Eigen::Isometry3d& T_1_robot, std::uint32_t id_base) {
    a.Init(16, 4);
    b.Init(16, 4);
    const Eigen::Isometry3d rooms[3] = {Planar(2, 3, 0.3), Planar(10, 2, 0.3), Planar(5, 9, 0.3)};
    for (std::uint32_t r = 0; r < 3; ++r) {
      test::AddRoom(a, 4 * r, r, rooms[r], 1);
      test::AddRoom(b, id_base + 4 * r, id_base + r, T_1_robot.inverse() * rooms[r], 1);
    }
  }
};

struct Tie {
  bool rooms[3] = {true, true, true};
  bool walls = true;
};

// What one collaborative solve declares: robot `robot`'s origin, the floor, its fine alignment,
// and room to room (walls to walls) for the tied rooms.
void Declare(CollaborativeGraph& g, std::uint16_t robot, const TwoMaps& maps, const Eigen::Isometry3d& initial,
             const Eigen::Isometry3d& fine, const Tie& tie) {
  ASSERT_TRUE(g.SetInitial(robot, initial));
  ASSERT_TRUE(g.AddSameFloor(robot, Eigen::Vector3d(4, 4, 0), 0.0, 0.02));
  ASSERT_TRUE(g.AddOriginMeasurement(robot, fine, 0.03, 0.005));
  for (std::size_t r = 0; r < 3; ++r) {
    if (!tie.rooms[r]) continue;
    auto ra = g.AddRoom(1, maps.a.rooms[r], 0.0);
    auto rb = g.AddRoom(robot, maps.b.rooms[r], 0.0);
    ASSERT_TRUE(ra && rb);
    ASSERT_TRUE(g.AddRoomRoom(*ra, *rb));
    if (!tie.walls) continue;
    for (std::size_t w = 0; w < 4; ++w) {
      auto wa = g.AddWall(1, maps.a.walls[r * 4 + w]);
      auto wb = g.AddWall(robot, maps.b.walls[r * 4 + w]);
      ASSERT_TRUE(wa && wb);
      ASSERT_TRUE(g.AddWallWall(*wa, *wb));
    }
  }
}

double Distance(const Eigen::Isometry3d& A, const Eigen::Isometry3d& B) {
  const Eigen::Isometry3d e = A.inverse() * B;
  return e.translation().norm() + Eigen::AngleAxisd(e.linear()).angle();
}

// Robot 2's map as it sends it later: corrected by a loop closure (its whole map moved by 5 cm
// and 0.5 degrees), one wall 3 cm off the others' agreement, so that the optimum has a residual.
TwoMaps Corrected(const Eigen::Isometry3d& truth) {
  TwoMaps later(truth * Planar(0.05, -0.03, 0.009), 100);
  later.b.walls[5].d += 0.03;
  return later;
}

const Eigen::Isometry3d kTruth = Planar(7.0, -3.0, 1.1);
const Eigen::Isometry3d kMerge = kTruth * Planar(0.3, -0.2, 0.05);  // where the merge placed robot 2

TEST(CollaborativeGraphUpdate, ARedeclaredGraphKeepsItsFactorsAndSolvesAsAFreshOne) {
  const TwoMaps first(kTruth, 100);
  CollaborativeGraph g;
  ASSERT_TRUE(g.Init({}, 1));
  g.BeginUpdate();
  Declare(g, 2, first, kMerge, kTruth, {});
  ASSERT_TRUE(g.Solve());
  // 1 floor + 1 fine + 3 x (2 rooms + room-room + yaw + 8 walls + 4 wall-wall) = 50.
  EXPECT_EQ(g.last_update().added, 50u);
  EXPECT_EQ(g.last_update().removed, 0u);
  EXPECT_LT(Distance(g.T_self_robot(2), kTruth), 1e-6);

  // The same declaration again, from the estimate it holds (as the session does): nothing
  // added or removed, and the estimate stays.
  const Eigen::Isometry3d solved = g.T_self_robot(2);
  g.BeginUpdate();
  Declare(g, 2, first, g.T_self_robot(2), kTruth, {});
  ASSERT_TRUE(g.Solve());
  EXPECT_EQ(g.last_update().added, 0u);
  EXPECT_EQ(g.last_update().kept, 50u);
  EXPECT_EQ(g.last_update().removed, 0u);
  EXPECT_LT(Distance(g.T_self_robot(2), solved), 1e-8);

  // Robot 2's map changed and room 2 is no longer matched: its measurements are replaced in
  // place, room 2's nodes and ties leave, and the estimate is a fresh graph's.
  const TwoMaps later = Corrected(kTruth);
  Tie two_rooms;
  two_rooms.rooms[2] = false;
  g.BeginUpdate();
  Declare(g, 2, later, g.T_self_robot(2), kTruth, two_rooms);
  ASSERT_TRUE(g.Solve());
  EXPECT_EQ(g.last_update().added, 0u);
  EXPECT_EQ(g.last_update().kept, 2u + 2 * 16);
  EXPECT_EQ(g.last_update().removed, 2u + 2 + 8 + 4);  // room 2: its nodes and their ties
  EXPECT_EQ(g.rooms(), 4u);
  EXPECT_EQ(g.walls(), 16u);

  CollaborativeGraph fresh;
  ASSERT_TRUE(fresh.Init({}, 1));
  Declare(fresh, 2, later, solved, kTruth, two_rooms);
  ASSERT_TRUE(fresh.Solve());
  // The changed map moved the estimate by centimetres; the two graphs agree far below that.
  EXPECT_GT(Distance(fresh.T_self_robot(2), solved), 0.01);
  EXPECT_LT(Distance(g.T_self_robot(2), fresh.T_self_robot(2)), 1e-5);
  for (std::uint32_t handle = 0; handle < 32; ++handle) {
    // Handles are slots; compare the nodes by robot and id.
    const DistilledWall w = g.wall(handle);
    if (g.wall_robot(handle) == 0) continue;
    bool found = false;
    for (std::uint32_t k = 0; k < 32 && !found; ++k) {
      const DistilledWall f = fresh.wall(k);
      if (fresh.wall_robot(k) != g.wall_robot(handle) || f.id != w.id) continue;
      found = true;
      EXPECT_NEAR(f.d, w.d, 1e-5) << "wall " << w.id;
      EXPECT_GT(f.normal.dot(w.normal), std::cos(1e-5)) << "wall " << w.id;
    }
    EXPECT_TRUE(found) << "wall " << w.id << " of robot " << g.wall_robot(handle);
  }
}

TEST(CollaborativeGraphUpdate, ARobotLeftOutLeavesTheGraphAndComesBackWhenDeclaredAgain) {
  const TwoMaps two(kTruth, 100);
  const Eigen::Isometry3d truth3 = Planar(-4.0, 6.0, -2.0);
  const TwoMaps three(truth3, 200);
  CollaborativeGraph g;
  ASSERT_TRUE(g.Init({}, 1));
  g.BeginUpdate();
  Declare(g, 2, two, kMerge, kTruth, {});
  Declare(g, 3, three, truth3 * Planar(-0.2, 0.1, -0.04), truth3, {});
  ASSERT_TRUE(g.Solve());
  EXPECT_TRUE(g.has_robot(3));
  EXPECT_GT(g.factors(3), 0u);
  EXPECT_EQ(g.rooms(), 9u);

  // Robot 3 is no longer merged: its origin, nodes and ties go; robot 2 is unchanged.
  g.BeginUpdate();
  Declare(g, 2, two, g.T_self_robot(2), kTruth, {});
  EXPECT_FALSE(g.AddRoom(3, three.b.rooms[0], 0.0)) << "robot 3 was not declared in this update";
  ASSERT_TRUE(g.Solve());
  EXPECT_FALSE(g.has_robot(3));
  EXPECT_EQ(g.factors(3), 0u);
  EXPECT_EQ(g.rooms(), 6u);
  EXPECT_EQ(g.last_update().removed, 2u + 3 * (1 + 4 + 2 + 4));  // floor, fine; rooms, walls, ties
  EXPECT_LT(Distance(g.T_self_robot(2), kTruth), 1e-6);

  // Merged again: back, from its new placement.
  g.BeginUpdate();
  Declare(g, 2, two, g.T_self_robot(2), kTruth, {});
  Declare(g, 3, three, truth3 * Planar(0.2, 0.2, 0.03), truth3, {});
  ASSERT_TRUE(g.Solve());
  EXPECT_EQ(g.last_update().added, 2u + 3 * (1 + 4 + 2 + 4));
  EXPECT_LT(Distance(g.T_self_robot(3), truth3), 1e-6);
}

// A merge that changed its mind: the origin is set elsewhere, and that robot's nodes restart
// from their measurements through the new placement instead of holding the old one's values.
TEST(CollaborativeGraphUpdate, AMovedOriginRestartsItsNodes) {
  const TwoMaps maps(kTruth, 100);
  // First placed a quarter turn wrong, held there by a (wrong) fine alignment alone.
  const Eigen::Isometry3d wrong = kTruth * Planar(0.0, 0.0, M_PI / 2);
  Tie rooms_only;
  rooms_only.walls = false;
  CollaborativeGraph g;
  ASSERT_TRUE(g.Init({}, 1));
  g.BeginUpdate();
  ASSERT_TRUE(g.SetInitial(2, wrong));
  ASSERT_TRUE(g.AddOriginMeasurement(2, wrong, 0.03, 0.005));
  for (std::size_t r = 0; r < 3; ++r) {
    ASSERT_TRUE(g.AddRoom(2, maps.b.rooms[r], 0.0));
    for (std::size_t w = 0; w < 4; ++w) ASSERT_TRUE(g.AddWall(2, maps.b.walls[r * 4 + w]));
  }
  ASSERT_TRUE(g.Solve());
  ASSERT_LT(Distance(g.T_self_robot(2), wrong), 1e-6);

  g.BeginUpdate();
  Declare(g, 2, maps, kMerge, kTruth, {});
  // Before the solve, robot 2's nodes already sit where its measurements put them through the
  // new placement, not where the old one left them.
  for (std::size_t r = 0; r < 3; ++r) {
    const auto room = g.AddRoom(2, maps.b.rooms[r], 0.0);
    ASSERT_TRUE(room);
    const Eigen::Vector3d c(maps.b.rooms[r].centre.x(), maps.b.rooms[r].centre.y(), 0.0);
    EXPECT_LT((g.room_centre(*room) - kMerge * c).norm(), 1e-9) << "room " << r;
    const auto wall = g.AddWall(2, maps.b.walls[4 * r]);
    ASSERT_TRUE(wall);
    const Eigen::Vector3d n = kMerge.linear() * maps.b.walls[4 * r].normal;
    EXPECT_GT(g.wall(*wall).normal.dot(n), std::cos(1e-9)) << "wall " << 4 * r;
  }
  ASSERT_TRUE(g.Solve());
  CollaborativeGraph fresh;
  ASSERT_TRUE(fresh.Init({}, 1));
  Declare(fresh, 2, maps, kMerge, kTruth, {});
  ASSERT_TRUE(fresh.Solve());
  EXPECT_LT(Distance(g.T_self_robot(2), fresh.T_self_robot(2)), 1e-6);
  EXPECT_LT(Distance(g.T_self_robot(2), kTruth), 1e-6);
}

TEST(CollaborativeGraphUpdate, CapacityCountsWhatAnUpdateDeclaresAndStaleHandlesAreRefused) {
  CollaborativeGraphConfig config;
  config.max_walls = 8;
  config.max_rooms = 2;
  const TwoMaps maps(kTruth, 100);
  CollaborativeGraph g;
  ASSERT_TRUE(g.Init(config, 1));
  Tie room0, room1;
  room0.rooms[1] = room0.rooms[2] = false;
  room1.rooms[0] = room1.rooms[2] = false;
  g.BeginUpdate();
  Declare(g, 2, maps, kMerge, kTruth, room0);
  ASSERT_TRUE(g.Solve());
  const auto stale_a = g.AddWall(1, maps.a.walls[0]);
  const auto stale_b = g.AddWall(2, maps.b.walls[0]);
  ASSERT_TRUE(stale_a && stale_b);
  // A whole new set of 8 walls and 2 rooms fits beside the old one until the sweep.
  g.BeginUpdate();
  Declare(g, 2, maps, g.T_self_robot(2), kTruth, room1);
  EXPECT_EQ(g.AddWall(1, maps.a.walls[8]).error().code, Errc::kCapacityExceeded);
  EXPECT_EQ(g.AddRoom(1, maps.a.rooms[2], 0.0).error().code, Errc::kCapacityExceeded);
  EXPECT_EQ(g.AddWallWall(*stale_a, *stale_b).error().code, Errc::kNotFound) << "not declared in this update";
  ASSERT_TRUE(g.Solve());
  EXPECT_EQ(g.walls(), 8u);
  EXPECT_EQ(g.rooms(), 2u);
  EXPECT_LT(Distance(g.T_self_robot(2), kTruth), 1e-6);
}

// Each room is tied to its walls: its centre midway between each facing pair. Two robots tied
// room to room only, robot 2's room centres measured 15 cm off along x (a room seen from its
// door: the centre of what was seen) while its walls are right: the edges bring the centres,
// and with them robot 2's origin, back between the walls.
TEST(CollaborativeGraphUpdate, ARoomIsHeldMidwayBetweenItsWalls) {
  TwoMaps maps(kTruth, 100);
  for (DistilledRoom& r : maps.b.rooms) {
    r.centre += Eigen::Vector2d(std::cos(r.yaw_rad), std::sin(r.yaw_rad)) * 0.15;
  }
  auto solve = [&](bool edges) {
    CollaborativeGraph g;
    EXPECT_TRUE(g.Init({}, 1));
    Tie rooms_only;
    rooms_only.walls = false;
    EXPECT_TRUE(g.SetInitial(2, kMerge));
    for (std::size_t r = 0; r < 3; ++r) {
      auto ra = g.AddRoom(1, maps.a.rooms[r], 0.0);
      auto rb = g.AddRoom(2, maps.b.rooms[r], 0.0);
      EXPECT_TRUE(ra && rb && g.AddRoomRoom(*ra, *rb));
      for (const auto& [robot, graph, room] : {std::tuple{1, &maps.a, *ra}, std::tuple{2, &maps.b, *rb}}) {
        std::uint32_t w[4];
        for (std::size_t k = 0; k < 4; ++k) w[k] = *g.AddWall(static_cast<std::uint16_t>(robot), graph->walls[r * 4 + k]);
        if (!edges) continue;
        EXPECT_TRUE(g.AddRoomWalls(room, w[0], w[1]));
        EXPECT_TRUE(g.AddRoomWalls(room, w[2], w[3]));
        // Walls that do not face each other, or another robot's, are no room's pair.
        EXPECT_EQ(g.AddRoomWalls(room, w[0], w[2]).error().code, Errc::kInvalidArgument);
      }
    }
    EXPECT_TRUE(g.Solve());
    return g.T_self_robot(2);
  };
  const double without = Distance(solve(false), kTruth), with = Distance(solve(true), kTruth);
  std::printf("robot 2's origin off by %.4f (room to room alone), %.4f (rooms held by their walls)\n", without, with);
  EXPECT_GT(without, 0.05) << "room to room alone follows the shifted centres";
  EXPECT_LT(with, 0.5 * without);
  // Another robot's walls are not this room's.
  CollaborativeGraph g;
  ASSERT_TRUE(g.Init({}, 1));
  ASSERT_TRUE(g.SetInitial(2, kTruth));
  auto room = g.AddRoom(1, maps.a.rooms[0], 0.0);
  auto wa = g.AddWall(2, maps.b.walls[0]), wb = g.AddWall(2, maps.b.walls[1]);
  ASSERT_TRUE(room && wa && wb);
  EXPECT_EQ(g.AddRoomWalls(*room, *wa, *wb).error().code, Errc::kInvalidArgument);
}

}  // namespace
}  // namespace msgraphs::core
