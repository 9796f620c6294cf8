// SPDX-License-Identifier: MIT
// Competing room-match hypotheses told apart by the walls (core/collab/hypothesis_check.hpp),
// on the distilled walls of the simulator's office floor: a 40 m corridor with a row of 6 m
// rooms on one side and 8 m rooms on the other (tools/sim/worlds/office.world).
#include <gtest/gtest.h>

#include <algorithm>
#include <limits>
#include <numbers>
#include <vector>

#include "alloc_counter.hpp"
#include "msgraphs/core/collab/hypothesis_check.hpp"
#include "msgraphs/core/collab/room_matcher.hpp"
#include "synthetic_clouds.hpp"

namespace msgraphs::core {
namespace {

Eigen::Isometry3d Planar(double x, double y, double yaw) { return test::PlanarPose(x, y, yaw); }

struct Segment {
  double x0, y0, x1, y1;
};

// The office's walls, each as seen from one side, in a map frame; those within [x_min, x_max]
// (a robot that explored part of the floor), clipped to it.
DistilledGraph OfficeWalls(const Eigen::Isometry3d& T_map_world, double x_min, double x_max) {
  std::vector<Segment> segments = {{0, -6, 40, -6}, {0, 8.4, 40, 8.4}, {0, -6, 0, 8.4},
                                   {40, -6, 40, 8.4}, {0, 0, 40, 0},   {0, 2.4, 40, 2.4}};
  for (double x : {6.0, 12.0, 18.0, 24.0, 30.0}) segments.push_back({x, -6, x, 0});
  for (double x : {8.0, 16.0, 24.0, 32.0}) segments.push_back({x, 2.4, x, 8.4});
  DistilledGraph g;
  g.Init(64, 8);
  std::uint32_t id = 0;
  for (Segment s : segments) {
    s.x0 = std::max(s.x0, x_min);
    s.x1 = std::min(s.x1, x_max);
    if (s.x0 > s.x1) continue;
    DistilledWall w;
    w.id = id++;
    const Eigen::Vector2d a_world(s.x0, s.y0), b_world(s.x1, s.y1);
    const Eigen::Vector2d along = (b_world - a_world).normalized();
    const Eigen::Vector3d n_world(-along.y(), along.x(), 0);
    w.normal = T_map_world.linear() * n_world;
    w.d = -w.normal.dot(T_map_world * Eigen::Vector3d(s.x0, s.y0, 0));
    w.a = (T_map_world * Eigen::Vector3d(a_world.x(), a_world.y(), 0)).head<2>();
    w.b = (T_map_world * Eigen::Vector3d(b_world.x(), b_world.y(), 0)).head<2>();
    static_cast<void>(g.walls.try_push_back(w));
  }
  return g;
}

TEST(HypothesisCheck, TheTrueTransformLaysTheWallsOnEachOther) {
  // Robot a explored x in [0, 28], robot b x in [10, 40]; each map frame is its own start.
  const Eigen::Isometry3d T_a_world = Planar(-2, 1, 0.3), T_b_world = Planar(-30, -1, 2.5);
  const DistilledGraph a = OfficeWalls(T_a_world, 0, 28), b = OfficeWalls(T_b_world, 10, 40);
  const Eigen::Isometry3d truth = T_a_world * T_b_world.inverse();
  HypothesisCheckConfig config;
  const double true_m = WallAgreement_m(a, b, truth, config);
  // The shared part, x in [10, 28]: four long walls of 18 m, the partitions at 12, 18, 24 (6 m
  // each) and at 16 and 24 (6 m each).
  EXPECT_NEAR(true_m, 4 * 18 + 3 * 6 + 2 * 6, 1e-6);
  // Shifted by the south rooms' period: the long walls overlap 6 m less, the north partitions
  // (8 m period) fall where there is no wall, one south partition is lost at the end.
  const Eigen::Isometry3d shifted = T_a_world * Planar(6, 0, 0) * T_b_world.inverse();
  const double shifted_m = WallAgreement_m(a, b, shifted, config);
  EXPECT_NEAR(shifted_m, 4 * 12 + 2 * 6, 1e-6);
  // A small error of the transform (a few cm, a tenth of a degree) costs nothing.
  EXPECT_NEAR(WallAgreement_m(a, b, Planar(0.05, -0.03, 0.002) * truth, config), true_m, 0.2);
  // Facing matters: the same walls turned half a turn agree nowhere.
  EXPECT_EQ(WallAgreement_m(a, b, truth * Planar(0, 0, std::numbers::pi), config), 0.0);
}

TEST(HypothesisCheck, ScoringAllocatesNothing) {
  const Eigen::Isometry3d T_b_world = Planar(3, 4, 1);
  const DistilledGraph a = OfficeWalls(Planar(0, 0, 0), 0, 40), b = OfficeWalls(T_b_world, 0, 40);
  HypothesisCheckConfig config;
  double sum = 0;
  test::AllocationScope scope;
  for (int i = 0; i < 10; ++i)
    sum += WallAgreement_m(a, b, Planar(0.01 * i, 0, 0) * T_b_world.inverse(), config);
  EXPECT_EQ(scope.allocations(), 0u);
  EXPECT_GT(sum, 0);
}

TEST(HypothesisCheck, WallsDecideBeforeMatchCounts) {
  HypothesisCheckConfig config;
  const std::size_t tie[] = {3, 3}, more[] = {3, 2};
  // Walls clearly better for the second set: it wins, even against a larger first set.
  EXPECT_EQ(ChooseHypothesis(tie, std::vector<double>{60, 102}, 2, config), 1);
  EXPECT_EQ(ChooseHypothesis(more, std::vector<double>{60, 102}, 2, config), 1);
  // Walls that cannot tell: the larger set wins, a tie waits.
  EXPECT_EQ(ChooseHypothesis(more, std::vector<double>{60, 62}, 2, config), 0);
  EXPECT_EQ(ChooseHypothesis(tie, std::vector<double>{60, 62}, 2, config), -1);
  // Three sets: the clear best of them.
  const std::size_t three[] = {3, 3, 2};
  EXPECT_EQ(ChooseHypothesis(three, std::vector<double>{40, 45, 90}, 2, config), 2);
  // One set alone is taken; none is none; a single match alone is not enough.
  const std::size_t one[] = {2}, single[] = {1};
  EXPECT_EQ(ChooseHypothesis(one, std::vector<double>{0}, 2, config), 0);
  EXPECT_EQ(ChooseHypothesis({}, {}, 2, config), -1);
  EXPECT_EQ(ChooseHypothesis(single, std::vector<double>{100}, 2, config), -1);
  // A single match whose walls agree clearly better vetoes a set (a symmetric mismatch that
  // gathered two matches before the true one's second arrived); an unclear one does not.
  const std::size_t set_and_singles[] = {2, 1, 1};
  EXPECT_EQ(ChooseHypothesis(set_and_singles, std::vector<double>{144, 60, 230}, 2, config), -1);
  EXPECT_EQ(ChooseHypothesis(set_and_singles, std::vector<double>{144, 60, 150}, 2, config), 0);
}

TEST(HypothesisCheck, MatchHypothesesListsDisjointSetsLargestFirst) {
  const Eigen::Isometry3d truth = Planar(4.0, -2.0, 0.7);
  std::vector<RoomMatch> matches;
  auto add = [&](const Eigen::Isometry3d& T) {
    RoomMatch m;
    m.room_a = static_cast<std::uint32_t>(matches.size());
    m.T_a_b = T;
    matches.push_back(m);
  };
  add(truth * Planar(6, 0, 0));
  add(truth);
  add(truth * Planar(6, 0.05, 0));
  add(truth * Planar(0.02, 0, 0));
  add(truth * Planar(0, 0.01, 0.001));
  add(truth * Planar(12, 0, 0));  // alone: below min_consistent
  RoomMatchConfig config;
  std::uint64_t sets[4];
  ASSERT_EQ(MatchHypotheses(matches, config, 2, sets), 2u);
  EXPECT_EQ(sets[0], 0b011010u);
  EXPECT_EQ(sets[1], 0b000101u);
  std::uint32_t members[8];
  ASSERT_EQ(HypothesisMembers(sets[1], members), 2u);
  EXPECT_EQ(members[0], 0u);
  EXPECT_EQ(members[1], 2u);
  // Down to single matches: the lone one comes last.
  ASSERT_EQ(MatchHypotheses(matches, config, 1, sets), 3u);
  EXPECT_EQ(sets[2], 0b100000u);
}

TEST(HypothesisCheck, ConfigIsValidated) {
  HypothesisCheckConfig config;
  EXPECT_TRUE(config.Validate());
  config.margin_ratio = 0.5;
  EXPECT_FALSE(config.Validate());
  config = {};
  config.wall_offset_m = std::numeric_limits<double>::quiet_NaN();
  EXPECT_FALSE(config.Validate());
}

}  // namespace
}  // namespace msgraphs::core
