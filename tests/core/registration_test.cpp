// SPDX-License-Identifier: MIT
// VGICP: synthetic alignment with a known answer, degenerate inputs, threads, zero allocation
// per alignment, and the public registration pairs (label external) against their ground truth
// and published fitness.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <cmath>
#include <filesystem>
#include <limits>
#include <thread>
#include <vector>

#include "alloc_counter.hpp"
#include "cloud_files.hpp"
#include "msgraphs/core/geometry/se3.hpp"
#include "msgraphs/core/perception/covariances.hpp"
#include "msgraphs/core/perception/voxel_grid.hpp"
#include "msgraphs/core/registration/vgicp.hpp"
#include "synthetic_clouds.hpp"
#include "test_data.hpp"

namespace msgraphs::core {
namespace {

// A cloud prepared as the pipeline does: downsampled, indexed, with covariances.
struct Prepared {
  BoundedVector<Eigen::Vector3f> points;
  BoundedVector<Eigen::Vector3f> normals;
  BoundedVector<Eigen::Matrix3f> covs;
  KdTree tree;
  explicit Prepared(std::size_t capacity) : points(capacity), normals(capacity), covs(capacity) { tree.Init(capacity); }
  void From(const std::vector<Eigen::Vector3f>& raw, float leaf) {
    VoxelDownsampler grid;
    grid.Init(raw.size());
    ASSERT_TRUE(grid.Downsample(raw, leaf, points));
    ASSERT_TRUE(tree.Build(points.span()));
    CovarianceConfig c;
    c.neighbours = 10;
    ASSERT_TRUE(EstimateCovariances(points.span(), tree, c, normals, covs).has_value());
  }
};

double RotationErrorDeg(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
  return So3Log(a.linear().transpose() * b.linear()).norm() * 180.0 / 3.14159265358979;
}

// A room with a pillar and a cabinet, so that the alignment is fully constrained.
std::vector<Eigen::Vector3f> Scene(std::uint32_t seed, const Eigen::Isometry3d& T) {
  auto room = test::BoxRoom(8, 6, 3, 40000, 0.01, seed, T);
  auto pillar = test::BoxRoom(0.4, 0.4, 3, 3000, 0.01, seed + 1, T * Eigen::Translation3d(5, 2, 0));
  auto cabinet = test::BoxRoom(1.0, 0.5, 1.2, 2000, 0.01, seed + 2, T * Eigen::Translation3d(1, 4.8, 0));
  room.insert(room.end(), pillar.begin(), pillar.end());
  room.insert(room.end(), cabinet.begin(), cabinet.end());
  return room;
}

class Threads : public ParallelExecutor {
 public:
  void Run(std::size_t chunks, void (*fn)(void*, std::size_t), void* context) const override {
    std::vector<std::thread> t;
    for (std::size_t c = 0; c < chunks; ++c) t.emplace_back(fn, context, c);
    for (auto& th : t) th.join();
  }
  std::size_t concurrency() const override { return 4; }
};

TEST(Vgicp, RecoversAKnownTransform) {
  const Eigen::Isometry3d truth = Eigen::Translation3d(0.3, -0.2, 0.1) * Eigen::AngleAxisd(0.15, Eigen::Vector3d::UnitZ()) *
                                  Eigen::AngleAxisd(0.03, Eigen::Vector3d::UnitX());
  // Target in its frame; source = the same room seen from a frame moved by truth^-1, sampled anew.
  Prepared target(60000), source(60000);
  target.From(Scene(10, Eigen::Isometry3d::Identity()), 0.1f);
  source.From(Scene(20, truth.inverse()), 0.1f);
  GaussianVoxelMap map;
  map.Init(50000);
  ASSERT_TRUE(map.Build(target.points.span(), target.covs.span(), 0.5));
  Vgicp vgicp;
  vgicp.Init(70000);
  auto r = vgicp.Align(source.points.span(), source.covs.span(), map, target.points.span(), target.tree,
                       Eigen::Isometry3d::Identity(), {});
  ASSERT_TRUE(r.has_value()) << r.error().detail;
  EXPECT_TRUE(r->converged);
  EXPECT_LT((r->T_target_source.translation() - truth.translation()).norm(), 0.01);
  EXPECT_LT(RotationErrorDeg(r->T_target_source, truth), 0.1);
  EXPECT_LT(r->fitness, 0.01);  // ~ (sampling spacing)^2
  EXPECT_GT(r->correspondences, source.points.size() / 2);
  // The Hessian is positive definite: the pose is observable in all six directions.
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 6, 6>> eig(r->hessian);
  EXPECT_GT(eig.eigenvalues().minCoeff(), 0.0);

  // With an executor the answer is the same.
  Threads threads;
  auto rt = vgicp.Align(source.points.span(), source.covs.span(), map, target.points.span(), target.tree,
                        Eigen::Isometry3d::Identity(), {}, &threads);
  ASSERT_TRUE(rt.has_value());
  EXPECT_LT((rt->T_target_source.matrix() - r->T_target_source.matrix()).norm(), 1e-6);

  // And no allocation per alignment after warm-up.
  test::AllocationScope scope;
  auto again = vgicp.Align(source.points.span(), source.covs.span(), map, target.points.span(), target.tree,
                           Eigen::Isometry3d::Identity(), {});
  EXPECT_EQ(scope.allocations(), 0u);
  ASSERT_TRUE(again.has_value());
}

// gaussian_voxel_map.hpp: "Bounded hash map sized at Init; Build allocates nothing", the first
// Build, a rebuild at another resolution and an overflowing one alike. The clouds and both maps
// (Init) are set up first.
TEST(GaussianVoxelMap, BuildAllocatesNothing) {
  Prepared target(60000);
  target.From(Scene(10, Eigen::Isometry3d::Identity()), 0.1f);
  ASSERT_GT(target.points.size(), 1000u);
  GaussianVoxelMap map, tiny;
  map.Init(50000);
  tiny.Init(10);

  test::AllocationScope scope;
  const Status coarse = map.Build(target.points.span(), target.covs.span(), 1.0);
  const std::size_t coarse_voxels = map.voxels();
  const Status fine = map.Build(target.points.span(), target.covs.span(), 0.5);
  const Status overflow = tiny.Build(target.points.span(), target.covs.span(), 0.5);
  const GaussianVoxel* hit = map.Lookup(target.points[0].cast<double>());
  const GaussianVoxel* miss = map.Lookup(Eigen::Vector3d(500, 500, 500));
  const std::uint64_t allocations = scope.allocations();

  EXPECT_EQ(allocations, 0u);
  ASSERT_TRUE(coarse) << coarse.error().detail;
  ASSERT_TRUE(fine) << fine.error().detail;
  // Finer voxels: more of them, each still aggregating several points.
  EXPECT_GT(coarse_voxels, 0u);
  EXPECT_GT(map.voxels(), coarse_voxels);
  EXPECT_LT(map.voxels(), target.points.size());
  ASSERT_NE(hit, nullptr);
  EXPECT_GT(hit->points, 0u);
  EXPECT_LT((hit->mean - target.points[0].cast<double>()).cwiseAbs().maxCoeff(), 0.5 + 1e-6);
  EXPECT_EQ(miss, nullptr);
  ASSERT_FALSE(overflow);
  EXPECT_EQ(overflow.error().code, Errc::kCapacityExceeded);
  EXPECT_EQ(tiny.voxels(), 10u);
}

// A corridor without ends: its walls, floor and ceiling fix everything but the position along
// it. A prior (the encoders' step) holds that direction; where the clouds constrain (across
// the corridor) they win over a prior 5 cm off, as a slip would put it: it pulls them by what
// its weight against the clouds' calibrated 2 cm says (about a quarter of its offset here),
// not to itself. The reported Hessian is the clouds' alone.
std::vector<Eigen::Vector3f> EndlessCorridor(std::uint32_t seed, const Eigen::Isometry3d& T) {
  const Eigen::Isometry3d T_inv = T.inverse();
  std::vector<Eigen::Vector3f> out;
  for (const Eigen::Vector3f& p : test::BoxRoom(40, 2.4, 3, 30000, 0.01, seed, T)) {
    const double x = (T_inv * p.cast<double>()).x();  // drop the two end walls
    if (x > 0.05 && x < 39.95) out.push_back(p);
  }
  return out;
}

TEST(Vgicp, APriorHoldsWhatTheCloudsLeaveFreeAndNothingElse) {
  const Eigen::Isometry3d origin(Eigen::Translation3d(-20, -1.2, -1.0));
  const Eigen::Isometry3d truth(Eigen::Translation3d(0.5, 0.03, 0.0));
  Prepared target(40000), source(40000);
  target.From(EndlessCorridor(3, origin), 0.1f);
  source.From(EndlessCorridor(4, truth.inverse() * origin), 0.1f);
  GaussianVoxelMap map;
  map.Init(40000);
  ASSERT_TRUE(map.Build(target.points.span(), target.covs.span(), 0.4));
  Vgicp vgicp;
  vgicp.Init(40000);
  // Seeded 0.2 m along the corridor: the clouds alone leave it there.
  const Eigen::Isometry3d seed = Eigen::Translation3d(0.2, 0, 0) * truth;
  auto free = vgicp.Align(source.points.span(), source.covs.span(), map, target.points.span(),
                          target.tree, seed, {});
  ASSERT_TRUE(free.has_value()) << free.error().detail;
  EXPECT_GT(std::fabs(free->T_target_source.translation().x() - truth.translation().x()), 0.1);
  // The prior: along the corridor at the truth, across it 5 cm off.
  VgicpPrior prior;
  prior.T_target_source = Eigen::Translation3d(0, 0.05, 0) * truth;
  prior.information.diagonal() << Eigen::Vector3d::Constant(1 / (0.05 * 0.05)),
      Eigen::Vector3d::Constant(1 / (0.01 * 0.01));
  prior.clouds_sigma_m = 0.02;
  auto held = vgicp.Align(source.points.span(), source.covs.span(), map, target.points.span(),
                          target.tree, seed, {}, nullptr, &prior);
  ASSERT_TRUE(held.has_value()) << held.error().detail;
  EXPECT_TRUE(held->converged);
  EXPECT_NEAR(held->T_target_source.translation().x(), truth.translation().x(), 0.01);
  EXPECT_NEAR(held->T_target_source.translation().y(), truth.translation().y(), 0.02);
  // The Hessian is the clouds': as weak along the corridor as without the prior.
  const Eigen::Matrix3d held_tt = held->hessian.topLeftCorner<3, 3>();
  const Eigen::Matrix3d free_tt = free->hessian.topLeftCorner<3, 3>();
  EXPECT_NEAR(held_tt(0, 0), free_tt(0, 0), 1e-3 * held_tt.norm());
  // A prior that is not a rigid transform is refused.
  VgicpPrior bad = prior;
  bad.T_target_source.linear()(0, 0) = 2;
  EXPECT_FALSE(vgicp.Align(source.points.span(), source.covs.span(), map, target.points.span(),
                           target.tree, seed, {}, nullptr, &bad));
  test::AllocationScope scope;
  auto again = vgicp.Align(source.points.span(), source.covs.span(), map, target.points.span(),
                           target.tree, seed, {}, nullptr, &prior);
  EXPECT_EQ(scope.allocations(), 0u);
  EXPECT_TRUE(again.has_value());
}

TEST(Vgicp, DegenerateInputGivesAStatusNeverNaN) {
  Prepared target(60000);
  target.From(Scene(10, Eigen::Isometry3d::Identity()), 0.1f);
  GaussianVoxelMap map;
  map.Init(50000);
  ASSERT_TRUE(map.Build(target.points.span(), target.covs.span(), 0.5));
  Vgicp vgicp;
  vgicp.Init(70000);
  std::vector<Eigen::Vector3f> few(5, Eigen::Vector3f(1, 1, 1));
  std::vector<Eigen::Matrix3f> few_cov(5, Eigen::Matrix3f::Identity());
  auto r = vgicp.Align(few, few_cov, map, target.points.span(), target.tree, Eigen::Isometry3d::Identity(), {});
  ASSERT_FALSE(r.has_value());
  EXPECT_EQ(r.error().code, Errc::kDegenerate);
  // Far away from the target: no correspondence.
  std::vector<Eigen::Vector3f> far(100, Eigen::Vector3f(500, 500, 500));
  std::vector<Eigen::Matrix3f> far_cov(100, Eigen::Matrix3f::Identity());
  r = vgicp.Align(far, far_cov, map, target.points.span(), target.tree, Eigen::Isometry3d::Identity(), {});
  ASSERT_FALSE(r.has_value());
  EXPECT_EQ(r.error().code, Errc::kDegenerate);
  // NaN in the source.
  auto nan = far;
  nan[3].x() = std::numeric_limits<float>::quiet_NaN();
  EXPECT_EQ(vgicp.Align(nan, far_cov, map, target.points.span(), target.tree, Eigen::Isometry3d::Identity(), {}).error().code,
            Errc::kInvalidArgument);
  // A bad initial guess.
  Eigen::Isometry3d bad = Eigen::Isometry3d::Identity();
  bad.matrix()(0, 0) = 2.0;
  EXPECT_EQ(vgicp.Align(far, far_cov, map, target.points.span(), target.tree, bad, {}).error().code, Errc::kInvalidArgument);
  // A single plane (the floor): under-constrained along it, but the answer stays finite.
  std::vector<Eigen::Vector3f> floor;
  for (int i = 0; i < 40; ++i)
    for (int j = 0; j < 40; ++j) floor.emplace_back(0.1f * static_cast<float>(i) + 2.0f, 0.1f * static_cast<float>(j) + 1.0f, 0.0f);
  Prepared plane(2000);
  plane.From(floor, 0.05f);
  r = vgicp.Align(plane.points.span(), plane.covs.span(), map, target.points.span(), target.tree,
                  Eigen::Isometry3d(Eigen::Translation3d(0, 0, 0.05)), {});
  ASSERT_TRUE(r.has_value());
  EXPECT_TRUE(r->T_target_source.matrix().allFinite());
  EXPECT_NEAR(r->T_target_source.translation().z(), 0.0, 0.02) << "the constrained direction is still recovered";
}

TEST(VgicpExternal, SmallGicpPairMatchesItsGroundTruth) {
  std::filesystem::path src, tgt, gt;
  MSGRAPHS_REQUIRE_DATA("registration/small_gicp_source.ply", src);
  MSGRAPHS_REQUIRE_DATA("registration/small_gicp_target.ply", tgt);
  MSGRAPHS_REQUIRE_DATA("registration/small_gicp_T_target_source.txt", gt);
  const auto source_raw = test::ReadCloud(src.string());
  const auto target_raw = test::ReadCloud(tgt.string());
  ASSERT_EQ(source_raw.size(), 69792u);
  Eigen::Isometry3d truth;
  truth.matrix() = test::ReadMatrix4(gt.string());
  Prepared source(70000), target(70000);
  source.From(source_raw, 0.25f);
  target.From(target_raw, 0.25f);
  GaussianVoxelMap map;
  map.Init(70000);
  ASSERT_TRUE(map.Build(target.points.span(), target.covs.span(), 1.0));
  Vgicp vgicp;
  vgicp.Init(70000);
  auto r = vgicp.Align(source.points.span(), source.covs.span(), map, target.points.span(), target.tree,
                       Eigen::Isometry3d::Identity(), {});
  ASSERT_TRUE(r.has_value()) << r.error().detail;
  const double dt = (r->T_target_source.translation() - truth.translation()).norm();
  const double dr = RotationErrorDeg(r->T_target_source, truth);
  EXPECT_LT(dt, 0.05);
  EXPECT_LT(dr, 0.5);
  RecordProperty("translation_error_m", std::to_string(dt));
  RecordProperty("rotation_error_deg", std::to_string(dr));
  RecordProperty("fitness", std::to_string(r->fitness));
}

TEST(VgicpExternal, FastGicpPairReachesThePublishedFitness) {
  std::filesystem::path a, b;
  MSGRAPHS_REQUIRE_DATA("registration/fast_gicp_251370668.pcd", a);
  MSGRAPHS_REQUIRE_DATA("registration/fast_gicp_251371071.pcd", b);
  const auto target_raw = test::ReadCloud(a.string());
  const auto source_raw = test::ReadCloud(b.string());
  ASSERT_EQ(target_raw.size(), 69088u);
  // fast_gicp's gicp_align downsamples both clouds with a 0.1 m ApproximateVoxelGrid (17,249
  // and 17,518 points) and reports PCL's getFitnessScore: the mean squared distance from each
  // aligned source point to its nearest target point. An exact 0.1 m grid keeps fewer points
  // (15,772 / 15,950), so nearest points lie a little farther: 0.224 here; at 0.09 m (17,383 /
  // 17,596 points) we measure 0.207 against the published 0.204.
  const float leaf = 0.1f;
  Prepared source(70000), target(70000);
  source.From(source_raw, leaf);
  target.From(target_raw, leaf);
  GaussianVoxelMap map;
  map.Init(70000);
  ASSERT_TRUE(map.Build(target.points.span(), target.covs.span(), 1.0));
  Vgicp vgicp;
  vgicp.Init(70000);
  auto r = vgicp.Align(source.points.span(), source.covs.span(), map, target.points.span(), target.tree,
                       Eigen::Isometry3d::Identity(), {});
  ASSERT_TRUE(r.has_value()) << r.error().detail;
  EXPECT_TRUE(r->converged);
  EXPECT_NEAR(r->fitness, 0.204, 0.025);
  RecordProperty("fitness", std::to_string(r->fitness));
  RecordProperty("iterations", std::to_string(r->iterations));
}

}  // namespace
}  // namespace msgraphs::core
