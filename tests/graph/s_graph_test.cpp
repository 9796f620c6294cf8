// SPDX-License-Identifier: MIT
// The local S-Graph back end on synthetic graphs with known truth: odometry drift removed by
// walls, rooms and corridors placed by their walls, the gauge, and every kind of bad input refused
// and counted with the graph left finite. Sparsification: s_graph_sparsify_test.cpp.
#include "msgraphs/core/graph/s_graph.hpp"

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <cmath>
#include <numbers>
#include <random>
#include <vector>

#include "msgraphs/core/geometry/se3.hpp"
#include "s_graph_fixtures.hpp"

namespace msgraphs::core {
namespace {

using namespace sgraph_test;  // NOLINT(google-build-using-namespace): test fixtures

TEST(SGraph, WallsRemoveOdometryDriftAndTheOriginStays) {
  const Room room;
  const Walk walk(room, 48);
  const auto walls = room.walls();
  const TruePlane floor{Eigen::Vector3d::UnitZ(), 0.5};
  SGraph g;
  ASSERT_TRUE(g.Init({}));
  std::mt19937 rng(3);
  std::vector<std::uint32_t> ids;
  std::vector<std::uint32_t> plane_ids;
  for (std::size_t i = 0; i < walk.truth.size(); ++i) {
    ASSERT_NO_FATAL_FAILURE(AddWalkStep(g, walk, i, ids));
    const std::uint32_t id = ids.back();
    if (i == 0) {
      for (const TruePlane& w : walls)
        plane_ids.push_back(*g.AddPlane(w.n, w.d, PlaneClass::kWall));
      plane_ids.push_back(*g.AddPlane(floor.n, floor.d, PlaneClass::kFloor));
    }
    for (std::size_t w = 0; w < walls.size(); ++w) {
      ASSERT_TRUE(
          g.AddPlaneObservation(id, plane_ids[w], Measure(walls[w], walk.truth[i], rng, 0.005)));
    }
    ASSERT_TRUE(g.AddPlaneObservation(id, plane_ids[4], Measure(floor, walk.truth[i], rng, 0.005)));
    ASSERT_TRUE(g.Solve(SolveKind::kLocal));
  }
  // Odometry alone drifts by decimetres; the walls hold the estimate to centimetres.
  double odometry_error = 0;
  for (std::size_t i = 0; i < ids.size(); ++i) {
    odometry_error = std::max(
        odometry_error, (walk.odometry[i].translation() - walk.truth[i].translation()).norm());
  }
  auto report = g.Solve(SolveKind::kFull);
  ASSERT_TRUE(report);
  EXPECT_TRUE(report->usable);
  EXPECT_GT(odometry_error, 0.2);
  EXPECT_LT(MaxPositionError(g, ids, walk.truth), 0.03);
  // Gauge: the origin has not moved at all.
  EXPECT_TRUE(g.keyframe_pose(ids[0]).isApprox(walk.truth[0], 1e-12));
  for (std::size_t w = 0; w < walls.size(); ++w) {
    const MapPlane p = g.plane(plane_ids[w]);
    EXPECT_GT(p.normal.dot(walls[w].n), std::cos(0.5 * std::numbers::pi / 180));
    EXPECT_NEAR(p.d, walls[w].d, 0.02);
    EXPECT_EQ(p.observations, walk.truth.size());
  }
}

// Marginal wall covariances include the keyframes' uncertainty: never smaller than the plane's
// own (conditional) information says, and larger for walls seen only from far along the walk.
// A prior from outside (another robot's measurement) pulls a wall, and is removed again.
TEST(SGraph, PlaneMarginalsAndExternalPriors) {
  const Room room;
  const Walk walk(room, 24);
  const auto walls = room.walls();
  SGraph g;
  ASSERT_TRUE(g.Init({}));
  std::mt19937 rng(5);
  std::vector<std::uint32_t> ids, plane_ids;
  for (std::size_t i = 0; i < walk.truth.size(); ++i) {
    ASSERT_NO_FATAL_FAILURE(AddWalkStep(g, walk, i, ids));
    const std::uint32_t id = ids.back();
    if (i == 0) {
      for (const TruePlane& w : walls)
        plane_ids.push_back(*g.AddPlane(w.n, w.d, PlaneClass::kWall));
    }
    for (std::size_t w = 0; w < walls.size(); ++w)
      ASSERT_TRUE(
          g.AddPlaneObservation(id, plane_ids[w], Measure(walls[w], walk.truth[i], rng, 0.005)));
    ASSERT_TRUE(g.Solve(SolveKind::kLocal));  // leaves the older nodes constant
  }
  std::vector<Eigen::Matrix3d> marginals(plane_ids.size());
  ASSERT_TRUE(g.PlaneMarginals(plane_ids, marginals));
  for (std::size_t w = 0; w < plane_ids.size(); ++w) {
    const Eigen::Matrix3d conditional = g.plane(plane_ids[w]).information.inverse();
    // marginal - conditional is positive semi-definite (up to the linearisation point).
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(marginals[w] - conditional);
    EXPECT_GT(eig.eigenvalues().minCoeff(), -1e-3 * conditional.norm()) << "wall " << w;
    EXPECT_GT(marginals[w](2, 2), conditional(2, 2)) << "wall " << w;
    EXPECT_TRUE(marginals[w].allFinite());
  }
  std::vector<Eigen::Matrix3d> too_short(1);
  EXPECT_FALSE(g.PlaneMarginals(plane_ids, too_short));
  const std::uint32_t missing[] = {999};
  EXPECT_FALSE(g.PlaneMarginals(missing, marginals));

  // A confident prior 5 cm off pulls the wall most of the way; removed, the wall returns.
  ASSERT_TRUE(g.Solve(SolveKind::kFull));
  const MapPlane before = g.plane(plane_ids[0]);
  PlanePrior prior;
  prior.plane = plane_ids[0];
  prior.normal = before.normal;
  prior.d = before.d + 0.05;
  prior.covariance = Eigen::Vector3d(1e-6, 1e-6, 1e-6).asDiagonal();
  auto factor = g.AddPlanePrior(prior);
  ASSERT_TRUE(factor);
  ASSERT_TRUE(g.Solve(SolveKind::kFull));
  EXPECT_GT(g.plane(plane_ids[0]).d - before.d, 0.03);
  EXPECT_EQ(g.stats().plane_prior_factors, 1u);
  ASSERT_TRUE(g.RemoveFactor(*factor));
  ASSERT_TRUE(g.Solve(SolveKind::kFull));
  EXPECT_NEAR(g.plane(plane_ids[0]).d, before.d, 2e-3);
  EXPECT_EQ(g.stats().plane_prior_factors, 0u);
  // Refused: a prior facing the other way, a non-definite covariance, a missing plane.
  PlanePrior flipped = prior;
  flipped.normal = -prior.normal;
  EXPECT_FALSE(g.AddPlanePrior(flipped));
  PlanePrior singular = prior;
  singular.covariance.setZero();
  EXPECT_FALSE(g.AddPlanePrior(singular));
  PlanePrior nowhere = prior;
  nowhere.plane = 999;
  EXPECT_FALSE(g.AddPlanePrior(nowhere));
}

// Builds a graph of one keyframe seeing the four walls of `room`.
struct RoomFixture {
  SGraph g;
  std::array<std::int32_t, 4> walls{};
  explicit RoomFixture(const Room& room) {
    EXPECT_TRUE(g.Init({}));
    const auto truth = room.walls();
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.translation() << room.centre.x() + 0.5, room.centre.y() - 0.3, 0;
    const std::uint32_t k = *g.AddKeyframe(0.0, T);
    std::mt19937 rng(1);
    for (std::size_t i = 0; i < 4; ++i) {
      walls[i] = static_cast<std::int32_t>(*g.AddPlane(truth[i].n, truth[i].d, PlaneClass::kWall));
      EXPECT_TRUE(g.AddPlaneObservation(k, static_cast<std::uint32_t>(walls[i]),
                                        Measure(truth[i], T, rng, 0.0001)));
    }
  }
};

TEST(SGraph, FourWallRoomSitsWhereItsMidlinesCross) {
  for (double yaw : {0.0, 0.5, -1.2}) {
    Room room;
    room.yaw = yaw;
    RoomFixture f(room);
    MapRoom r;
    r.shape = RoomShape::kFourWall;
    r.centre = room.centre + Eigen::Vector2d(0.4, -0.3);  // a poor initial guess
    r.walls = f.walls;
    auto id = f.g.AddRoom(r);
    ASSERT_TRUE(id);
    ASSERT_TRUE(f.g.Solve(SolveKind::kFull));
    EXPECT_LT((f.g.room(*id).centre - room.centre).norm(), 1e-3) << "yaw " << yaw;
  }
}

TEST(SGraph, CorridorIsPlacedAcrossByItsWallsAndAlongByItsAnchor) {
  Room room;
  room.yaw = 0.3;
  RoomFixture f(room);
  MapRoom r;
  r.shape = RoomShape::kCorridor;
  r.walls = {f.walls[0], f.walls[1], -1, -1};  // the x pair only
  const Eigen::Vector2d along = RotZ(room.yaw).col(1).head<2>();
  r.corridor_anchor = room.centre + 1.5 * along;
  r.centre = room.centre;  // to be moved along to the anchor
  auto id = f.g.AddRoom(r);
  ASSERT_TRUE(id);
  ASSERT_TRUE(f.g.Solve(SolveKind::kFull));
  EXPECT_LT((f.g.room(*id).centre - r.corridor_anchor).norm(), 1e-3);
  // A corridor through the map origin is fine (the original's formula divides by |m|).
  EXPECT_TRUE(f.g.keyframe_pose(0).translation().allFinite());
}

TEST(SGraph, RoomsNeedObservedWallsAndCanBeCompletedAndRemoved) {
  const Room room;
  RoomFixture f(room);
  MapRoom r;
  r.walls = {f.walls[0], f.walls[1], f.walls[2], 999};
  EXPECT_FALSE(f.g.AddRoom(r));
  r.shape = RoomShape::kCorridor;
  auto id = f.g.AddRoom(r);
  ASSERT_TRUE(id);
  r.shape = RoomShape::kFourWall;
  r.walls[3] = f.walls[3];
  ASSERT_TRUE(f.g.UpdateRoom(*id, r));
  EXPECT_EQ(f.g.room(*id).shape, RoomShape::kFourWall);
  EXPECT_EQ(f.g.stats().room_factors, 1u);
  ASSERT_TRUE(f.g.SetFloor(room.centre));
  ASSERT_TRUE(f.g.AddFloorRoom(*id));
  ASSERT_TRUE(f.g.RemoveRoom(*id));
  EXPECT_EQ(f.g.stats().rooms, 0u);
  EXPECT_EQ(f.g.stats().room_factors, 0u);
  EXPECT_EQ(f.g.stats().floor_factors, 0u);
  EXPECT_TRUE(f.g.Solve(SolveKind::kFull));
}

TEST(SGraph, WallFoundTwiceIsTiedTogether) {
  SGraph g;
  ASSERT_TRUE(g.Init({}));
  const TruePlane wall{Eigen::Vector3d::UnitX(), 2.0};
  std::mt19937 rng(2);
  const std::uint32_t k0 = *g.AddKeyframe(0, Eigen::Isometry3d::Identity());
  const std::uint32_t a = *g.AddPlane(wall.n, wall.d, PlaneClass::kWall);
  const std::uint32_t b = *g.AddPlane(wall.n, wall.d + 0.1, PlaneClass::kWall);
  ASSERT_TRUE(
      g.AddPlaneObservation(k0, a, Measure(wall, Eigen::Isometry3d::Identity(), rng, 0.001)));
  // b carries a weaker observation 10 cm off; tied to a it comes back.
  PlaneMeasurement off = Measure(wall, Eigen::Isometry3d::Identity(), rng, 0.001);
  off.d += 0.1;
  off.covariance = Eigen::Matrix3d::Identity() * 0.1 * 0.1;
  ASSERT_TRUE(g.AddPlaneObservation(k0, b, off));
  ASSERT_TRUE(g.AddWallWall(a, b));
  ASSERT_TRUE(g.Solve(SolveKind::kFull));
  EXPECT_NEAR(g.plane(b).d, g.plane(a).d, 0.01);
  // Opposite faces are never tied.
  const std::uint32_t back = *g.AddPlane(-wall.n, -wall.d, PlaneClass::kWall);
  EXPECT_FALSE(g.AddWallWall(a, back));
}

TEST(SGraph, BadInputIsRefusedAndCounted) {
  SGraph g;
  ASSERT_TRUE(g.Init({}));
  Eigen::Isometry3d nan = Eigen::Isometry3d::Identity();
  nan.translation().x() = std::numeric_limits<double>::quiet_NaN();
  EXPECT_FALSE(g.AddKeyframe(0.0, nan));
  Eigen::Isometry3d skew = Eigen::Isometry3d::Identity();
  skew.linear()(0, 1) = 0.3;
  EXPECT_FALSE(g.AddKeyframe(0.0, skew));
  const std::uint32_t k0 = *g.AddKeyframe(1.0, Eigen::Isometry3d::Identity());
  // Duplicate and backwards stamps.
  auto dup = g.AddKeyframe(1.0, Eigen::Isometry3d::Identity());
  ASSERT_FALSE(dup);
  EXPECT_EQ(dup.error().code, Errc::kOutOfOrder);
  EXPECT_FALSE(g.AddKeyframe(0.5, Eigen::Isometry3d::Identity()));
  Eigen::Isometry3d step = Eigen::Isometry3d::Identity();
  step.translation().x() = 1.0;
  const std::uint32_t k1 = *g.AddKeyframe(2.0, step);
  // Information that is not positive definite, or not symmetric; a non-rigid measurement.
  Matrix6d indefinite = Matrix6d::Identity();
  indefinite(2, 2) = -1;
  EXPECT_FALSE(g.AddRelativePose(k0, k1, step, indefinite, RelativePoseKind::kOdometry));
  Matrix6d asymmetric = Matrix6d::Identity();
  asymmetric(0, 5) = 0.5;
  EXPECT_FALSE(g.AddRelativePose(k0, k1, step, asymmetric, RelativePoseKind::kOdometry));
  EXPECT_FALSE(g.AddRelativePose(k0, k1, skew, Matrix6d::Identity(), RelativePoseKind::kOdometry));
  EXPECT_FALSE(g.AddRelativePose(k0, 77, step, Matrix6d::Identity(), RelativePoseKind::kOdometry));
  ASSERT_TRUE(
      g.AddRelativePose(k0, k1, step, Matrix6d::Identity() * 100, RelativePoseKind::kOdometry));
  // A wall seen from behind: the keyframe stands behind the mapped face.
  const std::uint32_t wall =
      *g.AddPlane(Eigen::Vector3d::UnitX(), -0.5, PlaneClass::kWall);  // x = 0.5, facing +x
  std::mt19937 rng(4);
  const TruePlane true_wall{Eigen::Vector3d::UnitX(), -0.5};
  EXPECT_TRUE(g.AddPlaneObservation(k1, wall,
                                    Measure(true_wall, step, rng, 0.01)));  // k1 at x = 1: in front
  PlaneMeasurement from_behind;
  from_behind.normal = -Eigen::Vector3d::UnitX();
  from_behind.d = 0.5;
  from_behind.basis_u = Eigen::Vector3d::UnitY();
  from_behind.basis_v = Eigen::Vector3d::UnitZ();
  from_behind.covariance = Eigen::Matrix3d::Identity() * 1e-4;
  EXPECT_FALSE(g.AddPlaneObservation(k0, wall, from_behind));  // k0 at x = 0: behind it
  PlaneMeasurement bad_covariance = Measure(true_wall, step, rng, 0.01);
  bad_covariance.covariance(1, 1) = -1;
  EXPECT_FALSE(g.AddPlaneObservation(k1, wall, bad_covariance));
  PlaneMeasurement nan_plane = Measure(true_wall, step, rng, 0.01);
  nan_plane.d = std::numeric_limits<double>::infinity();
  EXPECT_FALSE(g.AddPlaneObservation(k1, wall, nan_plane));

  const SGraphStats s = g.stats();
  EXPECT_EQ(s.rejected_pose,
            4u);  // NaN keyframe, skewed keyframe, skewed measurement, infinite plane
  EXPECT_EQ(s.rejected_stamp, 2u);
  EXPECT_EQ(s.rejected_information, 3u);
  EXPECT_EQ(s.rejected_behind, 1u);
  EXPECT_EQ(s.rejected_missing_node, 1u);
  EXPECT_EQ(s.keyframes, 2u);
  EXPECT_EQ(s.factors, 2u);
  auto report = g.Solve(SolveKind::kFull);
  ASSERT_TRUE(report);
  EXPECT_TRUE(report->usable);
  EXPECT_TRUE(g.keyframe_pose(k1).matrix().allFinite());
}

TEST(SGraph, SolveAtItsIterationLimitIsReportedAndUsable) {
  SGraphConfig config;
  config.full_max_iterations = 1;
  SGraph g;
  ASSERT_TRUE(g.Init(config));
  const Room room;
  const Walk walk(room, 24);
  std::uint32_t prev = *g.AddKeyframe(0, walk.truth[0]);
  for (std::size_t i = 1; i < walk.truth.size(); ++i) {
    // Initial guesses far off so that one iteration cannot converge.
    Eigen::Isometry3d guess = walk.truth[i];
    guess.translation().x() += 2.0;
    const std::uint32_t k = *g.AddKeyframe(static_cast<double>(i), guess);
    ASSERT_TRUE(g.AddRelativePose(prev, k, walk.truth[i - 1].inverse() * walk.truth[i],
                                  OdometryInformation(), RelativePoseKind::kOdometry));
    prev = k;
  }
  auto report = g.Solve(SolveKind::kFull);
  ASSERT_TRUE(report);
  EXPECT_FALSE(report->converged);
  EXPECT_TRUE(report->usable);
  EXPECT_EQ(g.stats().solves_not_converged, 1u);
  EXPECT_EQ(g.stats().solves_undone, 0u);
}

TEST(SGraph, ConfigIsValidated) {
  SGraphConfig c;
  c.max_keyframes = 2;
  EXPECT_FALSE(c.Validate());
  c = {};
  c.huber_plane = 0;
  EXPECT_FALSE(c.Validate());
  c = {};
  c.local_window_keyframes = c.max_keyframes;
  EXPECT_FALSE(c.Validate());
  SGraph g;
  EXPECT_FALSE(g.Init(c));
}

}  // namespace
}  // namespace msgraphs::core
