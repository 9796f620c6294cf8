// SPDX-License-Identifier: MIT
// Sparsification carries a removed keyframe's plane observations to a neighbour through the hop
// between them (s_graph_sparsify_planes.cpp). Where nothing else rests on that hop the carried
// observation is the removed keyframe marginalised out, to first order: the planes' marginals
// are those of the graph that kept it. Where the joined chain shares the hop, the carried
// observations never make a plane more certain than the kept graph does.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <array>
#include <cmath>
#include <string>
#include <vector>

#include "msgraphs/core/graph/s_graph.hpp"
#include "s_graph_fixtures.hpp"

namespace msgraphs::core {
namespace {

using namespace sgraph_test;  // NOLINT(google-build-using-namespace): test fixtures

enum class Cut { kNone, kIntoVictim, kOutOfVictim };

// Nine keyframes on a climbing, turning, rolling path (keyframe 2 between the closest
// neighbours, so it is the one a store of 8 sparsifies), chained by exact odometry except across
// `cut`; keyframe 3 closes a loop to the origin, so that a chain cut on either side of 2 leaves
// every keyframe tied to the origin. Plane `only` is seen from keyframe 2 alone, plane `shared`
// from its neighbour across the hop that is kept (from both neighbours when none is cut) and
// from 2, plane `far` from keyframes 5 and 6 only; keyframe 2 sees those of `seen_from_2`.
// Measurements exact, estimates at the truth.
struct PlaneCase {
  std::size_t max_keyframes = 8;
  Cut cut = Cut::kNone;
  double plane_share = 0.5;
  bool remove_2_on_request = false;
  std::array<bool, 2> seen_from_2{true, true};  // `only`, `shared`
};

struct PlaneResult {
  std::array<Eigen::Matrix3d, 3> marginals{};
  SGraphStats stats;
  std::array<std::uint32_t, 3> live{};
  bool keyframe_2_active = false;
};

const std::array<TruePlane, 3> kPlanes{{
    {Eigen::Vector3d(0.8, 0.6, 0.0), 1.5},
    {Eigen::Vector3d(-0.6, 0.8, 0.0), 6.0},
    {Eigen::Vector3d(0.0, 0.0, 1.0), 0.7},
}};

PlaneResult BuildAndMeasure(const PlaneCase& c) {
  SGraphConfig config;
  config.max_keyframes = c.max_keyframes;
  config.local_window_keyframes = 2;
  config.sparsify_plane_share = c.plane_share;
  SGraph g;
  EXPECT_TRUE(g.Init(config));
  std::vector<Eigen::Isometry3d> truth;
  double along_m = 0;
  for (int i = 0; i < 9; ++i) {
    along_m += i == 0 ? 0.0 : (i == 2 || i == 3 ? 0.3 : 1.0);
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear() = (Eigen::AngleAxisd(0.5 * along_m, Eigen::Vector3d::UnitZ()) *
                  Eigen::AngleAxisd(0.15 * std::sin(i), Eigen::Vector3d::UnitX()) *
                  Eigen::AngleAxisd(0.1 * std::cos(i), Eigen::Vector3d::UnitY()))
                     .toRotationMatrix();
    T.translation() << 3 * std::cos(0.3 * along_m), 3 * std::sin(0.3 * along_m), 0.2 * along_m;
    truth.push_back(T);
  }
  Matrix6d odometry = Matrix6d::Zero();
  odometry.diagonal() << 1 / (0.03 * 0.03), 1 / (0.02 * 0.02), 1 / (0.04 * 0.04),
      1 / (0.01 * 0.01), 1 / (0.02 * 0.02), 1 / (0.005 * 0.005);
  std::array<std::uint32_t, 3> planes{};
  for (std::size_t p = 0; p < kPlanes.size(); ++p)
    planes[p] = *g.AddPlane(kPlanes[p].n, kPlanes[p].d, p == 2 ? PlaneClass::kFloor : PlaneClass::kWall);
  const auto observe = [&](std::uint32_t k, std::size_t p, double sigma) {
    const TruePlane& w = kPlanes[p];
    PlaneMeasurement z;
    z.normal = truth[k].linear().transpose() * w.n;
    z.d = w.d + w.n.dot(truth[k].translation());
    z.basis_u = z.normal.unitOrthogonal();
    z.basis_v = z.normal.cross(z.basis_u);
    z.covariance = Eigen::Vector3d(sigma * sigma, 4 * sigma * sigma, 0.25 * sigma * sigma).asDiagonal();
    EXPECT_TRUE(g.AddPlaneObservation(k, planes[p], z)) << "keyframe " << k << ", plane " << p;
  };
  for (std::uint32_t i = 0; i < 9; ++i) {
    EXPECT_TRUE(g.AddKeyframe(i, truth[i]));
    const bool cut = (c.cut == Cut::kIntoVictim && i == 2) || (c.cut == Cut::kOutOfVictim && i == 3);
    if (i > 0 && !cut) {
      EXPECT_TRUE(g.AddRelativePose(i - 1, i, truth[i - 1].inverse() * truth[i], odometry,
                                    RelativePoseKind::kOdometry));
    }
    if (i == 3) {
      EXPECT_TRUE(g.AddRelativePose(0, 3, truth[0].inverse() * truth[3], LoopInformation(),
                                    RelativePoseKind::kLoopClosure));
    }
    if (i == 2 && c.seen_from_2[0]) observe(2, 0, 0.004);
    if (i == 2 && c.seen_from_2[1]) observe(2, 1, 0.003);
    if (i == 2 && !c.seen_from_2[0]) observe(1, 0, 0.004);  // measured, so that it has a marginal
    if ((i == 1 && c.cut != Cut::kIntoVictim) || (i == 3 && c.cut != Cut::kOutOfVictim)) observe(i, 1, 0.006);
    if (i == 5 || i == 6) observe(i, 2, 0.005);
  }
  if (c.remove_2_on_request) {
    EXPECT_TRUE(g.RemoveKeyframe(2));
  }
  PlaneResult r;
  EXPECT_TRUE(g.PlaneMarginals(planes, r.marginals));
  EXPECT_EQ(g.stats().planes_unobserved, 0u);
  r.stats = g.stats();
  for (std::size_t p = 0; p < planes.size(); ++p) r.live[p] = g.plane(planes[p]).live_observations;
  r.keyframe_2_active = g.keyframe_active(2);
  return r;
}

// Positive semi-definite to within `tolerance` of b's size: a is no more certain than b.
void ExpectNoMoreCertain(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b, const char* what) {
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> lost(a - b);
  EXPECT_GT(lost.eigenvalues().minCoeff(), -1e-9 * b.norm()) << what;
}

TEST(SGraphSparsifyPlanes, ThroughAHopNothingElseRestsOnTheCarriedObservationIsTheMarginal) {
  // The chain cut on one side of keyframe 2: nothing joins its neighbours, so its one plane
  // observation is all that rests on the other hop (to keyframe 1, or through the inverse hop to
  // keyframe 3). Marginalising keyframe 2 out of a tree is exact, and so, to first order, must
  // be carrying its observation: of `only` as a new factor, of `shared` fused into the
  // neighbour's own. With both, the two rest on one hop and each gets it twice over.
  for (const Cut cut : {Cut::kOutOfVictim, Cut::kIntoVictim}) {
    for (const bool fuse : {false, true}) {
      const std::string what = std::string(cut == Cut::kOutOfVictim ? "to keyframe 1" : "to keyframe 3") +
                               (fuse ? ", fused" : ", a factor of its own");
      PlaneCase c{.cut = cut, .seen_from_2 = {!fuse, fuse}};
      const PlaneResult carried = BuildAndMeasure(c);
      c.max_keyframes = 16;
      const PlaneResult kept = BuildAndMeasure(c);
      ASSERT_TRUE(kept.keyframe_2_active);
      ASSERT_FALSE(carried.keyframe_2_active) << what;
      EXPECT_EQ(carried.stats.sparsified, 1u);
      EXPECT_EQ(carried.stats.sparsify_planes_carried, 1u) << what;
      EXPECT_EQ(carried.stats.sparsify_planes_fused, fuse ? 1u : 0u) << what;
      EXPECT_EQ(carried.stats.sparsify_planes_dropped, 0u) << what;
      EXPECT_EQ(carried.live[0], 1u) << what;  // `only`: now the neighbour's
      EXPECT_EQ(carried.live[1], 1u) << what;  // `shared`: the neighbour's with 2's, one factor
      EXPECT_EQ(carried.stats.plane_factors, kept.stats.plane_factors - (fuse ? 1 : 0)) << what;
      for (std::size_t p = 0; p < 3; ++p) {
        EXPECT_LT((carried.marginals[p] - kept.marginals[p]).norm(), 1e-6 * kept.marginals[p].norm())
            << what << ", plane " << p << "\nkept\n" << kept.marginals[p] << "\ncarried\n"
            << carried.marginals[p];
      }
    }
    const PlaneResult both = BuildAndMeasure({.cut = cut});
    const PlaneResult kept = BuildAndMeasure({.max_keyframes = 16, .cut = cut});
    EXPECT_EQ(both.stats.sparsify_planes_carried, 2u);
    EXPECT_EQ(both.stats.sparsify_planes_fused, 1u);
    for (std::size_t p = 0; p < 3; ++p) ExpectNoMoreCertain(both.marginals[p], kept.marginals[p], "both");
  }
}

TEST(SGraphSparsifyPlanes, AHopSharedWithTheChainNeverMakesAPlaneMoreCertain) {
  // The chain whole: the joined neighbours and the carried observations rest on one hop, each
  // with an inflated share of it. No plane may come out more certain than with keyframe 2 kept,
  // whatever the share; and `only` stays measured, where dropping it (share 0) leaves it without
  // a marginal.
  const PlaneResult kept = BuildAndMeasure({.max_keyframes = 16});
  for (const double share : {0.1, 0.5, 0.9}) {
    for (const bool on_request : {false, true}) {
      PlaneCase c{.plane_share = share, .remove_2_on_request = on_request};
      if (on_request) c.max_keyframes = 16;
      const PlaneResult carried = BuildAndMeasure(c);
      ASSERT_FALSE(carried.keyframe_2_active);
      EXPECT_EQ(carried.stats.sparsify_planes_carried, 2u);
      EXPECT_EQ(carried.stats.planes_unobserved, 0u);
      for (std::size_t p = 0; p < 3; ++p) ExpectNoMoreCertain(carried.marginals[p], kept.marginals[p], "share");
    }
  }
}

// 0 turns carrying off (SGraphPlaneObservers.* test that mode); 1 would leave the chain nothing.
TEST(SGraphSparsifyPlanes, TheShareIsAtLeastZeroAndBelowOne) {
  SGraphConfig config;
  config.max_keyframes = 8;
  config.local_window_keyframes = 2;
  config.sparsify_plane_share = 0;
  SGraph g;
  ASSERT_TRUE(g.Init(config));
  config.sparsify_plane_share = 1;
  EXPECT_FALSE(g.Init(config));  // the chain always keeps a share
  config.sparsify_plane_share = -0.1;
  EXPECT_FALSE(g.Init(config));
  config.sparsify_plane_share = std::nan("");
  EXPECT_FALSE(g.Init(config));
}

}  // namespace
}  // namespace msgraphs::core
