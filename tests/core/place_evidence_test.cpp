// SPDX-License-Identifier: MIT
// The merge decision's fallback (place_evidence.hpp, place_messages.hpp): a peer's points around
// a place, laid into this robot's free space by two transforms the walls cannot tell apart,
// set the contradicted one aside; in rooms that truly repeat they decide nothing; and the
// messages that carry them refuse what is malformed.
#include <gtest/gtest.h>

#include <cmath>
#include <optional>
#include <vector>

#include "alloc_counter.hpp"
#include "merge_fixture.hpp"
#include "msgraphs/core/collab/place_decision.hpp"
#include "msgraphs/core/collab/place_evidence.hpp"
#include "msgraphs/core/collab/place_messages.hpp"

namespace msgraphs::core {
namespace {

using test::Decide;
using test::PlanBuilding;
using test::Pose2;
using test::Robot;
using test::Seen;
using test::Truth;

// A 60 m corridor with ten identical 6 x 5 m rooms on its south side (merge_rule_test.cpp's
// symmetry trap); space k + 1 is room k.
PlanBuilding IdenticalRooms() {
  PlanBuilding b;
  b.spaces.push_back({0, 0, 60, 2.4});
  for (int k = 0; k < 10; ++k) {
    b.spaces.push_back({6.0 * k + 0.075, -5, 6.0 * k + 6 - 0.075, -0.15});
    b.doors.push_back({{6.0 * k + 1, -0.075}, {6.0 * k + 2, -0.075}, 0, k + 1});
  }
  return b;
}

// A 1 m cabinet in room 3 (x 18-24), the one thing that tells the rooms apart.
constexpr double kBoxX0 = 20.5, kBoxY0 = -3.0, kBoxSide = 1.0;

// The cells a robot's summary would hold occupied where it saw the cabinet.
void AddBox(Robot& r) {
  FreeSpaceSummary& s = r.free;
  const double cell = static_cast<double>(s.cell_m());
  for (double y = kBoxY0; y <= kBoxY0 + kBoxSide; y += 0.05) {
    for (double x = kBoxX0; x <= kBoxX0 + kBoxSide; x += 0.05) {
      const Eigen::Vector2d p = r.T_map_world * Eigen::Vector2d(x, y);
      const int cx = static_cast<int>((p.x() - s.origin_m().x()) / cell), cy = static_cast<int>((p.y() - s.origin_m().y()) / cell);
      if (cx < 0 || cy < 0 || cx >= s.width() || cy >= s.height()) continue;
      s.set(static_cast<std::size_t>(cy) * static_cast<std::size_t>(s.width()) + static_cast<std::size_t>(cx),
            SummaryCell::kOccupied);
    }
  }
  s.ComputeClearance();
}

// What robot r's place cloud around `centre_world` would hold: the faces of the spaces it saw
// (and the cabinet), every 0.2 m at three heights, relative to the centre (r's map frame) and
// the floor.
std::vector<Eigen::Vector3f> PlaceCloudOf(const PlanBuilding& b, const std::vector<Seen>& seen, const Robot& r,
                                          const Eigen::Vector2d& centre_world, double radius_m, bool box) {
  std::vector<Eigen::Vector3f> out;
  const Eigen::Vector2d centre = r.T_map_world * centre_world;
  auto add_segment = [&](const Eigen::Vector2d& a, const Eigen::Vector2d& e) {
    const int steps = static_cast<int>((e - a).norm() / 0.2);
    for (int i = 0; i <= steps; ++i) {
      const Eigen::Vector2d p = r.T_map_world * (a + (e - a) * (static_cast<double>(i) / std::max(1, steps)));
      if ((p - centre).norm() > radius_m) continue;
      for (const float z : {0.5f, 1.0f, 1.5f})
        out.emplace_back(static_cast<float>(p.x() - centre.x()), static_cast<float>(p.y() - centre.y()), z);
    }
  };
  for (const Seen& v : seen) {
    const test::PlanSpace& s = b.spaces[static_cast<std::size_t>(v.space)];
    const double x0 = std::max(s.x0, v.x0), x1 = std::min(s.x1, v.x1);
    add_segment({x0, s.y0}, {x1, s.y0});
    add_segment({x0, s.y1}, {x1, s.y1});
    if (x0 == s.x0) add_segment({x0, s.y0}, {x0, s.y1});
    if (x1 == s.x1) add_segment({x1, s.y0}, {x1, s.y1});
  }
  if (box) {
    const Eigen::Vector2d c0(kBoxX0, kBoxY0), c1(kBoxX0 + kBoxSide, kBoxY0), c2(kBoxX0 + kBoxSide, kBoxY0 + kBoxSide),
        c3(kBoxX0, kBoxY0 + kBoxSide);
    add_segment(c0, c1);
    add_segment(c1, c2);
    add_segment(c2, c3);
    add_segment(c3, c0);
  }
  return out;
}

struct Views {
  std::vector<Seen> seen_a{{0, 8, 30}, {3}, {4}, {5}};  // the corridor past rooms 2-4
  std::vector<Seen> seen_b{{0, 14, 36}, {4}, {5}, {6}};  // past rooms 3-5: shifted by one room
  Eigen::Isometry2d Ta = Pose2(-20, 3, 0.7), Tb = Pose2(10, -40, -2.1);
};

constexpr double kClearanceM = 0.3;  // FreeSpaceConflictConfig::clearance_m
constexpr std::size_t kMinCells = 5;  // min_stretch_m (1 m) in 0.2 m cells
constexpr double kMarginRatio = 1.5;  // MergeRuleConfig::margin_ratio

// Robot a saw rooms 0-6 with the cabinet wherever a shift by one room takes it: before any
// place, the rule cannot tell the truth from that shift (kAmbiguous).
struct Undecided {
  PlanBuilding building = IdenticalRooms();
  Views v = [] {
    Views w;
    w.seen_a = {{0, 0, 42}, {1}, {2}, {3}, {4}, {5}, {6}, {7}};
    return w;
  }();
  Robot a{building, v.seen_a, v.Ta};
  Robot b{building, v.seen_b, v.Tb};
  AlignmentSearch search;
  PlaceScorer scorer;
  PlaceChooser chooser;
  BoundedVector<PlanarTransform> set_aside;
  MergeInputs in;
  MergeDecision d;
  Undecided() {
    AddBox(a);
    AddBox(b);
    EXPECT_TRUE(search.Init({}));
    scorer.Init(4000);
    chooser.Init(1 << 19);
    set_aside.Init(8);
    search.Search(a.walls, {}, b.walls, {}, {}, false);
    in = test::InputsOf(a, b, search);
    d = DecideMerge(in, search, {}, nullptr);  // the rule's first decision
  }
};

TEST(PlaceEvidence, TheDuelSetsAsideWhatThePointsContradictAndTheTruthMerges) {
  Undecided u;
  const PlanBuilding& building = u.building;
  const Views& v = u.v;
  Robot& a = u.a;
  Robot& b = u.b;
  AlignmentSearch& search = u.search;
  PlaceScorer& scorer = u.scorer;
  PlaceChooser& chooser = u.chooser;
  BoundedVector<PlanarTransform>& set_aside = u.set_aside;
  MergeInputs& in = u.in;
  MergeDecision d = u.d;
  const PlaceEvidenceConfig config;
  const PlanarTransform truth = Truth(a, b);
  // As the session does (collab_places.cpp): weigh the decision on the places held; while they
  // cannot tell the leader from its blocker, ask for a place that can.
  std::vector<Eigen::Vector2d> places;  // b's map frame
  std::vector<std::vector<Eigen::Vector3f>> clouds;
  ASSERT_EQ(d.verdict, MergeVerdict::kAmbiguous) << ToString(d.verdict);
  for (std::size_t asked = 0;; ++asked) {
    std::vector<PlaceView> views;
    for (std::size_t i = 0; i < places.size(); ++i) views.push_back({places[i], clouds[i]});
    in.set_aside = {};
    const PlaceDecision pd = DecideWithPlaces(in, search, {}, d, views, 0.2, scorer, set_aside);
    for (const PlanarTransform& T : set_aside) EXPECT_FALSE(SameTransform(T, truth, 0.3, 0.026)) << "the truth was set aside";
    if (!pd.wants_place) {
      d = pd.decision;
      break;
    }
    ASSERT_LT(asked, config.max_places_per_peer) << "undecided after every place";
    const auto c = chooser.Choose(b.walls, b.free, a.free, pd.first, pd.second, places, config);
    ASSERT_TRUE(c.has_value());
    places.push_back(*c);
    clouds.push_back(PlaceCloudOf(building, v.seen_b, b, b.T_map_world.inverse() * *c, config.radius_m, true));
  }
  ASSERT_EQ(d.verdict, MergeVerdict::kMerge) << ToString(d.verdict);
  EXPECT_TRUE(SameTransform(d.leader.T_a_b, truth, 0.05, 0.005));
  EXPECT_FALSE(set_aside.empty());
}

TEST(PlaceEvidence, InRoomsThatTrulyRepeatThePointsDecideNothing) {
  const PlanBuilding building = IdenticalRooms();
  const Views v;
  Robot a(building, v.seen_a, v.Ta);
  Robot b(building, v.seen_b, v.Tb);
  const Eigen::Vector2d centre_world(21, -1);
  const std::vector<Eigen::Vector3f> cloud = PlaceCloudOf(building, v.seen_b, b, centre_world, 5.0, false);
  AlignmentSearch search;
  ASSERT_TRUE(search.Init({}));
  PlaceScorer scorer;
  scorer.Init(cloud.size());
  search.Search(a.walls, {}, b.walls, {}, {}, false);
  MergeInputs in = test::InputsOf(a, b, search);
  const MergeDecision d = DecideMerge(in, search, {}, nullptr);
  ASSERT_EQ(d.verdict, MergeVerdict::kAmbiguous) << ToString(d.verdict);
  const Eigen::Vector2d centre_b = b.T_map_world * centre_world;
  const PlaceTally first = scorer.Score(cloud, centre_b, d.leader.T_a_b, a.free, kClearanceM);
  const PlaceTally second = scorer.Score(cloud, centre_b, d.rival.T_a_b, a.free, kClearanceM);
  EXPECT_GT(first.explained, 50u);
  EXPECT_GT(second.explained, 50u);
  EXPECT_EQ(Duel(first, second, kMarginRatio, kMinCells), DuelOutcome::kUndecided);
  // Weighed as the session does: nothing set aside, still ambiguous, another place wanted.
  BoundedVector<PlanarTransform> set_aside;
  set_aside.Init(8);
  const std::vector<PlaceView> views{{centre_b, cloud}};
  const PlaceDecision pd = DecideWithPlaces(in, search, {}, d, views, 0.2, scorer, set_aside);
  EXPECT_EQ(pd.decision.verdict, MergeVerdict::kAmbiguous);
  EXPECT_EQ(set_aside.size(), 0u);
  EXPECT_TRUE(pd.wants_place);
  EXPECT_EQ(pd.duels, 1u);
}

TEST(PlaceEvidence, TheDuelNeedsContradictionByTheMarginAndNoLessNetSupport) {
  // Contradicted by the margin, as well supported: the first wins.
  EXPECT_EQ(Duel({200, 2}, {190, 10}, kMarginRatio, kMinCells), DuelOutcome::kFirstWins);
  EXPECT_EQ(Duel({190, 10}, {200, 2}, kMarginRatio, kMinCells), DuelOutcome::kSecondWins);
  // Contradicted, but not by the margin (1.5 x 4 + 5 = 11 > 10).
  EXPECT_EQ(Duel({200, 4}, {190, 10}, kMarginRatio, kMinCells), DuelOutcome::kUndecided);
  // A transform that lays the points where the robot never looked (nothing explained, nothing
  // contradicted) wins nothing against one a closed door contradicts by a little.
  EXPECT_EQ(Duel({0, 0}, {300, 6}, kMarginRatio, kMinCells), DuelOutcome::kUndecided);
  EXPECT_EQ(Duel({0, 0}, {0, 0}, kMarginRatio, kMinCells), DuelOutcome::kUndecided);
}

TEST(PlaceEvidence, APlaceIsChosenWhereTheTwoTransformsDifferOnGroundBothKnow) {
  const PlanBuilding building = IdenticalRooms();
  const Views v;
  Robot a(building, v.seen_a, v.Ta);
  Robot b(building, v.seen_b, v.Tb);
  AlignmentSearch search;
  ASSERT_TRUE(search.Init({}));
  const MergeDecision d = Decide(a, b, search);
  ASSERT_EQ(d.verdict, MergeVerdict::kAmbiguous);
  const PlaceEvidenceConfig config;
  PlaceChooser chooser;
  chooser.Init(1 << 19);
  const auto c = chooser.Choose(b.walls, b.free, a.free, d.leader.T_a_b, d.rival.T_a_b, {}, config);
  ASSERT_TRUE(c.has_value());
  EXPECT_GE((d.leader.T_a_b * *c - d.rival.T_a_b * *c).norm(), config.min_separation_m);
  EXPECT_NE(b.free.state_at(*c), SummaryCell::kUnknown);
  // Not the same place twice; nothing where the two transforms agree.
  const std::vector<Eigen::Vector2d> asked{*c};
  const auto next = chooser.Choose(b.walls, b.free, a.free, d.leader.T_a_b, d.rival.T_a_b, asked, config);
  if (next) {
    EXPECT_GE((*next - *c).norm(), 0.5 * static_cast<double>(config.radius_m));
  }
  EXPECT_FALSE(chooser.Choose(b.walls, b.free, a.free, d.leader.T_a_b, d.leader.T_a_b, {}, config).has_value());
}

TEST(PlaceMessages, RoundTripAndRefusals) {
  std::vector<std::uint8_t> bytes(kPlaceRequestBytes);
  const PlaceRequest q{3, 7, 42, {12.5f, -3.25f}, 5.0f};
  ASSERT_EQ(*EncodePlaceRequest(q, bytes), kPlaceRequestBytes);
  auto back = DecodePlaceRequest(bytes);
  ASSERT_TRUE(back);
  EXPECT_EQ(back->from, 3);
  EXPECT_EQ(back->to, 7);
  EXPECT_EQ(back->place, 42u);
  EXPECT_EQ(back->centre_m, q.centre_m);
  EXPECT_EQ(back->radius_m, 5.0f);
  std::vector<std::uint8_t> bad = bytes;
  bad[10] ^= 1;
  EXPECT_EQ(DecodePlaceRequest(bad).error().code, Errc::kChecksum);
  EXPECT_FALSE(DecodePlaceRequest(std::span(bytes).first(20)));
  EXPECT_FALSE(EncodePlaceRequest({3, 7, 1, {0, 0}, 0.0f}, bytes));    // no radius
  EXPECT_FALSE(EncodePlaceRequest({3, 7, 1, {0, 0}, 13.0f}, bytes));   // beyond 8-bit units
  EXPECT_FALSE(EncodePlaceRequest({3, 7, 1, {NAN, 0}, 5.0f}, bytes));  // not finite

  const float step = PlaceCloudStep(5.0f);
  EXPECT_FLOAT_EQ(step, 0.04f);
  const std::vector<Eigen::Vector3f> points{{0, 0, 0.5f}, {-4.9f, 3.0f, 1.9f}, {2.0f, -1.0f, 0.25f}};
  std::vector<std::uint8_t> cloud(PlaceCloudEncodedSize(points.size()));
  const PlaceCloudHeader h{7, 3, 42, {12.5f, -3.25f}, -0.5f, step};
  ASSERT_EQ(*EncodePlaceCloud(h, points, cloud), cloud.size());
  BoundedVector<Eigen::Vector3f> decoded;
  decoded.Init(8);
  auto hb = DecodePlaceCloud(cloud, decoded);
  ASSERT_TRUE(hb);
  EXPECT_EQ(hb->robot, 7);
  EXPECT_EQ(hb->to, 3);
  EXPECT_EQ(hb->place, 42u);
  EXPECT_EQ(hb->floor_z_m, -0.5f);
  ASSERT_EQ(decoded.size(), points.size());
  for (std::size_t i = 0; i < points.size(); ++i) EXPECT_LE((decoded[i] - points[i]).norm(), 0.5f * std::sqrt(3.0f) * step);
  EXPECT_EQ(PeekPlaceCloudHeader(cloud)->place, 42u);
  // Beyond the 8-bit range; more points than the receiver holds; a trailing byte; equal ids.
  std::vector<std::uint8_t> scratch(cloud.size());
  EXPECT_FALSE(EncodePlaceCloud(h, std::vector<Eigen::Vector3f>{{6.0f, 0, 0}}, scratch));
  BoundedVector<Eigen::Vector3f> small;
  small.Init(2);
  EXPECT_EQ(DecodePlaceCloud(cloud, small).error().code, Errc::kCapacityExceeded);
  std::vector<std::uint8_t> longer = cloud;
  longer.insert(longer.end() - 4, 0);
  EXPECT_FALSE(DecodePlaceCloud(longer, decoded));
  std::vector<std::uint8_t> same(cloud.size());
  ASSERT_TRUE(EncodePlaceCloud({7, 7, 1, {0, 0}, 0, step}, points, same));
  EXPECT_EQ(DecodePlaceCloud(same, decoded).error().code, Errc::kMalformed);
}

TEST(PlaceEvidence, CodingAndScoringAllocateNothing) {
  const PlanBuilding building = IdenticalRooms();
  const Views v;
  Robot a(building, v.seen_a, v.Ta);
  Robot b(building, v.seen_b, v.Tb);
  const std::vector<Eigen::Vector3f> cloud = PlaceCloudOf(building, v.seen_b, b, {21, -1}, 5.0, true);
  PlaceScorer scorer;
  scorer.Init(cloud.size());
  std::vector<std::uint8_t> bytes(PlaceCloudEncodedSize(cloud.size()));
  std::vector<std::uint8_t> request(kPlaceRequestBytes);
  BoundedVector<Eigen::Vector3f> decoded;
  decoded.Init(cloud.size());
  const PlanarTransform truth = Truth(a, b);
  test::AllocationScope scope;
  const PlaceTally t = scorer.Score(cloud, b.T_map_world * Eigen::Vector2d(21, -1), truth, a.free, kClearanceM);
  const bool encoded = EncodePlaceCloud({7, 3, 1, {0, 0}, 0, 0.04f}, cloud, bytes).has_value() &&
                       EncodePlaceRequest({3, 7, 1, {0, 0}, 5.0f}, request).has_value();
  const bool decoded_ok = DecodePlaceCloud(bytes, decoded).has_value() && DecodePlaceRequest(request).has_value();
  EXPECT_EQ(scope.allocations(), 0u);
  EXPECT_TRUE(encoded && decoded_ok);
  EXPECT_GT(t.explained, 0u);
}

// place_decision.hpp and place_evidence.hpp promise no allocation after Init: the weighing of
// an undecided merge on the places held (none, then one) and the choice of the next place.
TEST(PlaceEvidence, WeighingOnPlacesAndChoosingOneAllocateNothing) {
  Undecided u;
  const PlanBuilding& building = u.building;
  const Views& v = u.v;
  Robot& a = u.a;
  Robot& b = u.b;
  MergeInputs& in = u.in;
  const MergeDecision& d = u.d;
  const PlaceEvidenceConfig config;
  ASSERT_EQ(d.verdict, MergeVerdict::kAmbiguous) << ToString(d.verdict);
  std::vector<Eigen::Vector2d> places;
  places.reserve(1);
  PlaceDecision pd;
  std::optional<Eigen::Vector2d> chosen;
  {
    test::AllocationScope scope;
    pd = DecideWithPlaces(in, u.search, {}, d, {}, 0.2, u.scorer, u.set_aside);
    if (pd.wants_place) chosen = u.chooser.Choose(b.walls, b.free, a.free, pd.first, pd.second, places, config);
    EXPECT_EQ(scope.allocations(), 0u) << "no place held";
  }
  ASSERT_TRUE(pd.wants_place);
  ASSERT_TRUE(chosen.has_value());
  places.push_back(*chosen);
  const std::vector<Eigen::Vector3f> cloud =
      PlaceCloudOf(building, v.seen_b, b, b.T_map_world.inverse() * *chosen, config.radius_m, true);
  const PlaceView views[1] = {{*chosen, cloud}};
  in.set_aside = {};
  {
    test::AllocationScope scope;
    pd = DecideWithPlaces(in, u.search, {}, d, views, 0.2, u.scorer, u.set_aside);
    EXPECT_EQ(scope.allocations(), 0u) << "one place held";
  }
  EXPECT_GT(pd.duels, 0u) << "the place was weighed";
}

}  // namespace
}  // namespace msgraphs::core
