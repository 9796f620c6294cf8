// SPDX-License-Identifier: MIT
// Wall and floor extraction on synthetic rooms with known planes: every face found with the
// right Hesse form, normals towards the sensor, real covariances, collinear walls split,
// rotated buildings, degenerate input, zero allocation per keyframe.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <cmath>
#include <limits>
#include <numbers>

#include "alloc_counter.hpp"
#include "msgraphs/core/perception/covariances.hpp"
#include "msgraphs/core/perception/kdtree.hpp"
#include "msgraphs/core/perception/plane_extraction.hpp"
#include "msgraphs/core/perception/voxel_grid.hpp"
#include "synthetic_clouds.hpp"

namespace msgraphs::core {
namespace {

struct Keyframe {
  BoundedVector<Eigen::Vector3f> points{200000}, normals{200000};
  BoundedVector<Eigen::Matrix3f> covs{200000};
  KdTree tree;
  Keyframe() { tree.Init(200000); }
  void From(const std::vector<Eigen::Vector3f>& raw) {
    VoxelDownsampler grid;
    grid.Init(200000);
    ASSERT_TRUE(grid.Downsample(raw, 0.1f, points));
    ASSERT_TRUE(tree.Build(points.span()));
    const Eigen::Vector3f origin(0, 0, 0);
    ASSERT_TRUE(EstimateCovariances(points.span(), tree, {}, normals, covs, &origin).has_value());
  }
};

// An 8 x 6 x 3 m room with the sensor at (2, 3, 0.8) in room coordinates, turned by `yaw`.
std::vector<Eigen::Vector3f> RoomSeenFrom(double yaw, std::uint32_t seed) {
  const Eigen::Isometry3d T_sensor_room =
      Eigen::Isometry3d(Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ())) * Eigen::Translation3d(-2, -3, -0.8);
  return test::BoxRoom(8, 6, 3, 60000, 0.03, seed, T_sensor_room);
}

const ExtractedPlane* Find(const BoundedVector<ExtractedPlane>& planes, const Eigen::Vector3d& n, double d) {
  for (const auto& p : planes) {
    if (p.normal.dot(n) > std::cos(2.0 * std::numbers::pi / 180.0) && std::fabs(p.d - d) < 0.05) return &p;
  }
  return nullptr;
}

class RoomPlanes : public ::testing::TestWithParam<double> {};

TEST_P(RoomPlanes, EveryFaceIsFoundInHesseFormFacingTheSensor) {
  const double yaw = GetParam() * std::numbers::pi / 180.0;
  Keyframe kf;
  kf.From(RoomSeenFrom(yaw, 3));
  PlaneExtractor extractor;
  extractor.Init(200000);
  BoundedVector<ExtractedPlane> planes(64);
  ASSERT_TRUE(extractor.Extract(kf.points.span(), kf.normals.span(), {}, planes));
  const Eigen::Matrix3d R = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  // Walls at x = 0 (2 m behind... the sensor is 2 m from it), x = 8, y = 0, y = 6; floor 0.8 m
  // below, ceiling 2.2 m above. Normals point at the sensor, so d is the distance to it.
  struct Expected {
    Eigen::Vector3d n;
    double d;
    PlaneKind kind;
  } expected[] = {{R * Eigen::Vector3d(1, 0, 0), 2.0, PlaneKind::kVertical},
                  {R * Eigen::Vector3d(-1, 0, 0), 6.0, PlaneKind::kVertical},
                  {R * Eigen::Vector3d(0, 1, 0), 3.0, PlaneKind::kVertical},
                  {R * Eigen::Vector3d(0, -1, 0), 3.0, PlaneKind::kVertical},
                  {Eigen::Vector3d(0, 0, 1), 0.8, PlaneKind::kHorizontal},
                  {Eigen::Vector3d(0, 0, -1), 2.2, PlaneKind::kHorizontal}};
  for (const auto& e : expected) {
    const ExtractedPlane* p = Find(planes, e.n, e.d);
    ASSERT_NE(p, nullptr) << "missing plane n=" << e.n.transpose() << " d=" << e.d;
    EXPECT_EQ(p->kind, e.kind);
    EXPECT_NEAR(std::acos(std::min(1.0, p->normal.dot(e.n))) * 180.0 / std::numbers::pi, 0.0, 0.5);
    EXPECT_NEAR(p->d, e.d, 0.02);
    EXPECT_NEAR(p->rms_m, 0.03, 0.01) << "the residual reflects the 3 cm noise";
    // A covariance from the fit: positive definite, small for a whole wall.
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(p->covariance);
    EXPECT_GT(eig.eigenvalues().minCoeff(), 0.0);
    EXPECT_LT(std::sqrt(p->covariance(2, 2)), 0.01);
  }
  EXPECT_EQ(planes.size(), 6u) << "nothing spurious";
}

INSTANTIATE_TEST_SUITE_P(Yaws, RoomPlanes, ::testing::Values(0.0, 30.0, 45.0, -71.0));

// A walking robot pitches and rolls by a few degrees: heights measured along the frame's z
// would stretch an 8 m wall's 3 m by 8 sin(4 deg) = 0.56 m (and a 3 m desk face from 0.75 m
// to a "wall" 0.96 m tall). Along the given up, the wall is as tall as the room.
TEST(Planes, HeightsAreMeasuredAlongTheGivenUp) {
  const Eigen::Matrix3d R_room_sensor = (Eigen::AngleAxisd(4.0 * std::numbers::pi / 180.0, Eigen::Vector3d::UnitY()) *
                                         Eigen::AngleAxisd(-3.0 * std::numbers::pi / 180.0, Eigen::Vector3d::UnitX()))
                                            .toRotationMatrix();
  const Eigen::Isometry3d T_sensor_room =
      Eigen::Isometry3d(Eigen::Matrix3d(R_room_sensor.transpose())) * Eigen::Translation3d(-2, -3, -0.8);
  Keyframe kf;
  kf.From(test::BoxRoom(8, 6, 3, 60000, 0.03, 5, T_sensor_room));
  PlaneExtractor extractor;
  extractor.Init(200000);
  BoundedVector<ExtractedPlane> planes(64);
  const Eigen::Vector3d up_sensor = R_room_sensor.transpose() * Eigen::Vector3d::UnitZ();
  const Eigen::Vector3d n_far_wall = R_room_sensor.transpose() * Eigen::Vector3d(0, -1, 0);  // the wall y = 6
  ASSERT_TRUE(extractor.Extract(kf.points.span(), kf.normals.span(), {}, planes, up_sensor));
  const ExtractedPlane* along_up = Find(planes, n_far_wall, 3.0);
  ASSERT_NE(along_up, nullptr);
  EXPECT_NEAR(along_up->z_max - along_up->z_min, 3.0, 0.1);
  EXPECT_NEAR(along_up->z_max, 2.2, 0.1);  // the ceiling, 2.2 m above the sensor
  ASSERT_TRUE(extractor.Extract(kf.points.span(), kf.normals.span(), {}, planes));
  const ExtractedPlane* along_z = Find(planes, n_far_wall, 3.0);
  ASSERT_NE(along_z, nullptr);
  EXPECT_GT(along_z->z_max - along_z->z_min, 3.3);
  // An up that is no up is refused, not used.
  EXPECT_EQ(extractor.Extract(kf.points.span(), kf.normals.span(), {}, planes, Eigen::Vector3d::UnitX()).error().code,
            Errc::kInvalidArgument);
  EXPECT_EQ(extractor.Extract(kf.points.span(), kf.normals.span(), {}, planes,
                              Eigen::Vector3d(0, 0, std::numeric_limits<double>::quiet_NaN()))
                .error()
                .code,
            Errc::kInvalidArgument);
}

TEST(Planes, CollinearWallsWithAGapAreSeparateSegments) {
  // Two 3 m pieces of the wall y = 4 with a 2 m doorway-sized gap between x = 3 and x = 5.
  std::vector<Eigen::Vector3f> raw;
  auto a = test::BoxRoom(3, 0.01, 2.5, 20000, 0.01, 1, Eigen::Isometry3d(Eigen::Translation3d(0, 4, -0.8)));
  auto b = test::BoxRoom(3, 0.01, 2.5, 20000, 0.01, 2, Eigen::Isometry3d(Eigen::Translation3d(5, 4, -0.8)));
  raw.insert(raw.end(), a.begin(), a.end());
  raw.insert(raw.end(), b.begin(), b.end());
  Keyframe kf;
  kf.From(raw);
  PlaneExtractor extractor;
  extractor.Init(200000);
  BoundedVector<ExtractedPlane> planes(64);
  ASSERT_TRUE(extractor.Extract(kf.points.span(), kf.normals.span(), {}, planes));
  int segments = 0;
  for (const auto& p : planes) {
    if (p.kind == PlaneKind::kVertical && std::fabs(p.normal.y()) > 0.99 && std::fabs(p.d - 4.0) < 0.05) {
      ++segments;
      EXPECT_NEAR(p.u_max - p.u_min, 3.0, 0.25);
    }
  }
  EXPECT_EQ(segments, 2);
}

TEST(Planes, AFarSmallPatchIsLessCertainThanANearLargeWall) {
  PlaneExtractionConfig config;
  config.min_vertical_inliers = 50;
  // A 6 x 3 m wall 2 m away and a 1 x 1 m patch 15 m away, same point spacing.
  auto near = test::BoxRoom(0.01, 6, 3, 30000, 0.02, 1, Eigen::Isometry3d(Eigen::Translation3d(2, -3, -1)));
  auto far = test::BoxRoom(0.01, 1, 1, 2000, 0.02, 2, Eigen::Isometry3d(Eigen::Translation3d(-15, 4, 0)));
  near.insert(near.end(), far.begin(), far.end());
  Keyframe kf;
  kf.From(near);
  PlaneExtractor extractor;
  extractor.Init(200000);
  BoundedVector<ExtractedPlane> planes(64);
  ASSERT_TRUE(extractor.Extract(kf.points.span(), kf.normals.span(), config, planes));
  const ExtractedPlane* wall = Find(planes, Eigen::Vector3d(-1, 0, 0), 2.0);
  const ExtractedPlane* patch = Find(planes, Eigen::Vector3d(1, 0, 0), 15.0);
  ASSERT_NE(wall, nullptr);
  ASSERT_NE(patch, nullptr);
  EXPECT_GT(patch->covariance.trace(), 10.0 * wall->covariance.trace());
}

TEST(Planes, DegenerateInputGivesNoPlanesAndNoCrash) {
  PlaneExtractor extractor;
  extractor.Init(1000);
  BoundedVector<ExtractedPlane> planes(8);
  EXPECT_TRUE(extractor.Extract({}, {}, {}, planes));
  EXPECT_EQ(planes.size(), 0u);
  std::vector<Eigen::Vector3f> same(500, Eigen::Vector3f(1, 1, 1)), zero_normals(500, Eigen::Vector3f::Zero());
  EXPECT_TRUE(extractor.Extract(same, zero_normals, {}, planes));
  EXPECT_EQ(planes.size(), 0u);
  std::vector<Eigen::Vector3f> nan(500, Eigen::Vector3f(std::nanf(""), 0, 0)), up(500, Eigen::Vector3f::UnitZ());
  EXPECT_TRUE(extractor.Extract(nan, up, {}, planes));
  EXPECT_EQ(planes.size(), 0u);
  EXPECT_EQ(extractor.Extract(same, up, {}, planes).has_value(), true);
  std::vector<Eigen::Vector3f> many(2000, Eigen::Vector3f::UnitX());
  EXPECT_EQ(extractor.Extract(many, many, {}, planes).error().code, Errc::kCapacityExceeded);
  PlaneExtractionConfig bad;
  bad.distance_threshold_m = 0;
  EXPECT_EQ(extractor.Extract(same, up, bad, planes).error().code, Errc::kInvalidConfig);
}

TEST(Planes, ExtractionAllocatesNothingPerKeyframe) {
  Keyframe kf;
  kf.From(RoomSeenFrom(0.3, 5));
  PlaneExtractor extractor;
  extractor.Init(200000);
  BoundedVector<ExtractedPlane> planes(64);
  ASSERT_TRUE(extractor.Extract(kf.points.span(), kf.normals.span(), {}, planes));
  test::AllocationScope scope;
  ASSERT_TRUE(extractor.Extract(kf.points.span(), kf.normals.span(), {}, planes));
  EXPECT_EQ(scope.allocations(), 0u);
}

}  // namespace
}  // namespace msgraphs::core
