// SPDX-License-Identifier: MIT
// S-Graph sparsification on synthetic graphs with known truth: the keyframe store stays within
// capacity through walks several times longer than it, also when every keyframe carries a loop
// closure (the loops are carried to a neighbour, exactly when the measurements agree), and the
// graph stays connected, solvable and consistent with its factors.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <array>
#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

#include "msgraphs/core/geometry/se3.hpp"
#include "msgraphs/core/graph/s_graph.hpp"
#include "s_graph_fixtures.hpp"

namespace msgraphs::core {
namespace {

using namespace sgraph_test;  // NOLINT(google-build-using-namespace): test fixtures

// The truth index of a keyframe (the tests stamp keyframe i with i).
std::size_t TruthIndex(const SGraph& g, std::uint32_t keyframe) {
  return static_cast<std::size_t>(std::lround(g.keyframe_stamp(keyframe)));
}

TEST(SGraphSparsification, KeepsTheGraphWithinCapacity) {
  SGraphConfig config;
  config.max_keyframes = 12;
  config.local_window_keyframes = 4;
  SGraph g;
  ASSERT_TRUE(g.Init(config));
  const Room room;
  const Walk walk(room, 60);
  auto walls = room.walls();
  walls.push_back({Eigen::Vector3d::UnitZ(), 0.5});  // the floor holds z, roll and pitch
  std::mt19937 rng(5);
  std::vector<std::uint32_t> plane_ids;
  std::uint32_t prev = 0;
  std::vector<std::uint32_t> ids;
  for (std::size_t i = 0; i < walk.truth.size(); ++i) {
    const Eigen::Isometry3d guess =
        i == 0 ? walk.truth[0]
               : g.keyframe_pose(prev) * (walk.odometry[i - 1].inverse() * walk.odometry[i]);
    const std::uint32_t k = *g.AddKeyframe(static_cast<double>(i), guess);
    if (i == 0) {
      for (const TruePlane& w : walls) {
        plane_ids.push_back(
            *g.AddPlane(w.n, w.d, w.n.z() > 0.5 ? PlaneClass::kFloor : PlaneClass::kWall));
      }
    } else {
      ASSERT_TRUE(g.AddRelativePose(prev, k, walk.odometry[i - 1].inverse() * walk.odometry[i],
                                    OdometryInformation(), RelativePoseKind::kOdometry));
    }
    for (std::size_t w = 0; w < walls.size(); ++w) {
      ASSERT_TRUE(
          g.AddPlaneObservation(k, plane_ids[w], Measure(walls[w], walk.truth[i], rng, 0.005)));
    }
    ASSERT_TRUE(g.Solve(SolveKind::kLocal));
    EXPECT_LE(g.stats().keyframes, config.max_keyframes);
    prev = k;
  }
  const SGraphStats s = g.stats();
  EXPECT_EQ(s.keyframes, config.max_keyframes);
  EXPECT_EQ(s.keyframes_peak, config.max_keyframes);
  EXPECT_EQ(s.sparsified, walk.truth.size() - config.max_keyframes);
  EXPECT_GT(s.relative_factors[static_cast<std::size_t>(RelativePoseKind::kSparsified)], 0u);
  EXPECT_TRUE(g.keyframe_active(0));  // the origin is never sparsified
  ASSERT_TRUE(g.Solve(SolveKind::kFull));
  // The survivors are still where they belong.
  std::array<std::uint32_t, 12> recent{};
  const std::size_t n = g.RecentKeyframes(recent);
  EXPECT_EQ(n, config.max_keyframes);
  for (std::size_t i = 0; i < n; ++i) {
    const double stamp = g.keyframe_stamp(recent[i]);
    const auto& truth = walk.truth[static_cast<std::size_t>(stamp)];
    EXPECT_LT((g.keyframe_pose(recent[i]).translation() - truth.translation()).norm(), 0.05)
        << "keyframe at " << stamp;
  }
}

// Exact measurements (the truth's relative poses) along a path that climbs, rolls and pitches,
// so that a wrong adjoint or a wrong direction shows; loops in both directions, some between
// neighbours, so that every keyframe outside the local window soon carries one. The estimates
// stay at the truth (no solve): every factor that sparsification composes, carries or fuses must
// still agree with it exactly.
TEST(SGraphSparsification, CarriedLoopsAreExactWhenTheMeasurementsAgree) {
  SGraphConfig config;
  config.max_keyframes = 8;
  config.local_window_keyframes = 2;
  SGraph g;
  ASSERT_TRUE(g.Init(config));
  std::vector<Eigen::Isometry3d> truth;
  for (int i = 0; i < 40; ++i) {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear() = (Eigen::AngleAxisd(0.3 * i, Eigen::Vector3d::UnitZ()) *
                  Eigen::AngleAxisd(0.05 * std::sin(i), Eigen::Vector3d::UnitX()) *
                  Eigen::AngleAxisd(0.04 * std::cos(i), Eigen::Vector3d::UnitY()))
                     .toRotationMatrix();
    T.translation() << 3 * std::cos(0.3 * i) + 0.1 * i, 3 * std::sin(0.3 * i), 0.05 * i;
    truth.push_back(T);
  }
  // Correlated, anisotropic information (a fixed well-conditioned SPD matrix).
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Matrix6d M;
  for (int r = 0; r < 6; ++r) {
    for (int c = 0; c < 6; ++c) M(r, c) = u(rng);
  }
  const Matrix6d information = 100.0 * (M.transpose() * M + 6.0 * Matrix6d::Identity());
  std::vector<std::uint32_t> ids;
  std::size_t loops_added = 0;
  const auto latest_active_at_most = [&](std::size_t step) -> std::int64_t {
    std::int64_t best = -1;
    for (std::uint32_t k = 0; k < g.keyframe_slots(); ++k) {
      if (g.keyframe_active(k) && TruthIndex(g, k) <= step &&
          (best < 0 || TruthIndex(g, k) > TruthIndex(g, static_cast<std::uint32_t>(best)))) {
        best = k;
      }
    }
    return best;
  };
  for (std::size_t i = 0; i < truth.size(); ++i) {
    auto id = g.AddKeyframe(static_cast<double>(i), truth[i]);
    ASSERT_TRUE(id);
    if (i > 0) {
      ASSERT_TRUE(g.AddRelativePose(ids.back(), *id, truth[i - 1].inverse() * truth[i], information,
                                    RelativePoseKind::kOdometry));
    }
    ids.push_back(*id);
    if (i >= 3) {  // a loop to the newest keyframe three or more steps back
      const auto k = static_cast<std::uint32_t>(latest_active_at_most(i - 3));
      const Eigen::Isometry3d T_k_i = truth[TruthIndex(g, k)].inverse() * truth[i];
      ASSERT_TRUE(
          i % 2 == 0 ? g.AddRelativePose(k, *id, T_k_i, information, RelativePoseKind::kLoopClosure)
                     : g.AddRelativePose(*id, k, T_k_i.inverse(), information,
                                         RelativePoseKind::kLoopClosure));
      ++loops_added;
    }
    if (i >= 2 && i % 4 == 0) {  // and one to the previous keyframe, its neighbour in the chain
      ASSERT_TRUE(g.AddRelativePose(ids[i - 1], *id, truth[i - 1].inverse() * truth[i], information,
                                    RelativePoseKind::kLoopClosure));
      ++loops_added;
    }
    for (std::uint32_t f = 0; f < config.max_factors; ++f) {
      const auto chi2 = g.FactorChi2(f);
      if (chi2) {
        EXPECT_LT(*chi2, 1e-12) << "factor " << f << " after keyframe " << i;
      }
    }
  }
  const SGraphStats s = g.stats();
  EXPECT_EQ(s.keyframes, config.max_keyframes);
  EXPECT_EQ(s.sparsified, truth.size() - config.max_keyframes);
  EXPECT_GT(s.sparsified_with_loops, 0u);
  EXPECT_GT(s.sparsify_carried, 0u);
  EXPECT_GT(s.sparsify_merged, 0u);
  EXPECT_EQ(s.sparsify_dropped, 0u);
  EXPECT_EQ(s.relative_factors[static_cast<std::size_t>(RelativePoseKind::kLoopClosure)] +
                s.sparsify_merged,
            loops_added);
  // The truth is the graph's optimum: a full solve does not move it.
  auto report = g.Solve(SolveKind::kFull);
  ASSERT_TRUE(report);
  EXPECT_TRUE(report->usable);
  for (std::uint32_t k = 0; k < g.keyframe_slots(); ++k) {
    if (!g.keyframe_active(k)) continue;
    EXPECT_LT((g.keyframe_pose(k).translation() - truth[TruthIndex(g, k)].translation()).norm(),
              1e-6);
  }
}

// Nine keyframes (one more than the store) on a climbing, turning path, keyframe 2 closest to
// its neighbours, three planes seen from keyframe `observer` only. Estimates and measurements at
// the truth. Returns the planes' marginal covariances, which carry the observer's pose
// uncertainty. With `loops`, every candidate for sparsification (1..6) carries one loop:
// (0,2), (1,4), (0,3), (5,7), (6,7): keyframe 2's goes to the origin, and 3 is tied to the
// origin too, so that both neighbours of keyframe 2 are pinned from two sides.
struct MarginalsCase {
  std::size_t max_keyframes = 8;  // 8: keyframe 2 is sparsified; more: kept
  bool loops = false;
  bool strong_prev_hop = false;  // hop 1 -> 2 four times more informative: loops carried to 1
  bool cut_hop_into_3 = false;   // no odometry 2 -> 3: nothing to compose (3 hangs on its loop)
  std::uint32_t observer = 3;
  bool remove_2_on_request = false;  // SGraph::RemoveKeyframe(2) once all nine are in
};

std::array<Eigen::Matrix3d, 3> ObserverPlaneMarginals(const MarginalsCase& c, SGraphStats& stats) {
  const std::size_t max_keyframes = c.max_keyframes;
  const bool loops = c.loops, strong_prev_hop = c.strong_prev_hop;
  const std::uint32_t observer = c.observer;
  SGraphConfig config;
  config.max_keyframes = max_keyframes;
  config.local_window_keyframes = 2;
  SGraph g;
  EXPECT_TRUE(g.Init(config));
  std::vector<Eigen::Isometry3d> truth;
  double along_m = 0;
  for (int i = 0; i < 9; ++i) {
    along_m += i == 0 ? 0.0 : (i == 2 || i == 3 ? 0.3 : 1.0);
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear() = (Eigen::AngleAxisd(0.4 * along_m, Eigen::Vector3d::UnitZ()) *
                  Eigen::AngleAxisd(0.1 * std::sin(i), Eigen::Vector3d::UnitX()))
                     .toRotationMatrix();
    T.translation() << 4 * std::cos(0.25 * along_m), 4 * std::sin(0.25 * along_m), 0.1 * along_m;
    truth.push_back(T);
  }
  Matrix6d information = Matrix6d::Zero();
  information.diagonal() << 1 / (0.03 * 0.03), 1 / (0.02 * 0.02), 1 / (0.04 * 0.04),
      1 / (0.01 * 0.01), 1 / (0.02 * 0.02), 1 / (0.005 * 0.005);
  const auto exact = [&](std::uint32_t a, std::uint32_t b) {
    return truth[a].inverse() * truth[b];
  };
  for (std::uint32_t i = 0; i < 9; ++i) {
    EXPECT_TRUE(g.AddKeyframe(i, truth[i]));
    if (i > 0 && !(c.cut_hop_into_3 && i == 3)) {
      const double scale = strong_prev_hop && i == 2 ? 4.0 : 1.0;
      EXPECT_TRUE(g.AddRelativePose(i - 1, i, exact(i - 1, i), scale * information,
                                    RelativePoseKind::kOdometry));
    }
    if (i == 7 && loops) {
      for (const auto& [a, b] : {std::pair{0u, 2u}, {1u, 4u}, {0u, 3u}, {5u, 7u}, {6u, 7u}}) {
        EXPECT_TRUE(
            g.AddRelativePose(a, b, exact(a, b), information, RelativePoseKind::kLoopClosure));
      }
    }
  }
  if (c.remove_2_on_request) {
    EXPECT_TRUE(g.RemoveKeyframe(2));
  }
  std::array<std::uint32_t, 3> planes{};
  const Eigen::Isometry3d& T = truth[observer];
  for (int axis = 0; axis < 3; ++axis) {
    const Eigen::Vector3d n = Eigen::Vector3d::Unit(axis);  // 2 m from the observer, facing it
    const double d = 2.0 - n.dot(T.translation());
    planes[static_cast<std::size_t>(axis)] =
        *g.AddPlane(n, d, axis == 2 ? PlaneClass::kFloor : PlaneClass::kWall);
    PlaneMeasurement z;
    z.normal = T.linear().transpose() * n;
    z.d = 2.0;
    z.basis_u = z.normal.unitOrthogonal();
    z.basis_v = z.normal.cross(z.basis_u);
    z.covariance = Eigen::Matrix3d::Identity() * 0.002 * 0.002;
    EXPECT_TRUE(g.AddPlaneObservation(observer, planes[static_cast<std::size_t>(axis)], z));
  }
  std::array<Eigen::Matrix3d, 3> marginals{};
  EXPECT_TRUE(g.PlaneMarginals(planes, marginals));
  stats = g.stats();
  return marginals;
}

TEST(SGraphSparsification, ComposedUncertaintyIsTheMarginalOfTheRemovedKeyframe) {
  const auto expect_equal = [](const auto& x, const auto& y, const char* what) {
    for (std::size_t i = 0; i < 3; ++i) {
      EXPECT_LT((x[i] - y[i]).norm(), 1e-6 * y[i].norm()) << what << ", plane " << i;
    }
  };
  SGraphStats kept, sparsified;
  // Only the chain: sparsifying keyframe 2 is exact (to first order), so keyframe 3 beyond it is
  // exactly as uncertain as with keyframe 2 kept.
  expect_equal(ObserverPlaneMarginals({.max_keyframes = 8}, sparsified),
               ObserverPlaneMarginals({.max_keyframes = 16}, kept), "chain");
  ASSERT_EQ(kept.sparsified, 0u);
  ASSERT_EQ(sparsified.sparsified, 1u);
  // The chain cut after keyframe 2: its loop to the origin is carried to keyframe 1 through the
  // one hop it has, which nothing else rests on: exact again, for 1 and for 3 (tied to the
  // origin by its own loop).
  for (const std::uint32_t observer : {1u, 3u}) {
    const MarginalsCase cut{.loops = true, .cut_hop_into_3 = true, .observer = observer};
    MarginalsCase cut_kept = cut;
    cut_kept.max_keyframes = 16;
    expect_equal(ObserverPlaneMarginals(cut, sparsified), ObserverPlaneMarginals(cut_kept, kept),
                 "cut chain");
    ASSERT_EQ(sparsified.sparsified_with_loops, 1u);
    ASSERT_EQ(sparsified.sparsify_carried, 1u);
    ASSERT_EQ(sparsified.sparsify_dropped, 0u);
    ASSERT_EQ(sparsified.relative_factors[static_cast<std::size_t>(RelativePoseKind::kSparsified)],
              0u);
  }
  // With loops on every candidate the victim is still keyframe 2, and its loop to the origin is
  // carried to a neighbour through a hop that the composed 1 -> 3 also rests on. Both then pin
  // that neighbour from two sides: counting the hop twice would make it more certain than it
  // is. Covariance intersection may only lose information: no keyframe is more certain than
  // with keyframe 2 kept, and the loop still makes it more certain than the chain alone.
  for (const bool strong_prev_hop : {false, true}) {
    for (const std::uint32_t observer : {1u, 3u}) {
      const MarginalsCase looped_case{
          .loops = true, .strong_prev_hop = strong_prev_hop, .observer = observer};
      MarginalsCase reference_case = looped_case, chain_case = looped_case;
      reference_case.max_keyframes = chain_case.max_keyframes = 16;
      chain_case.loops = false;
      const auto looped_reference = ObserverPlaneMarginals(reference_case, kept);
      const auto chain_only = ObserverPlaneMarginals(chain_case, kept);
      const auto looped = ObserverPlaneMarginals(looped_case, sparsified);
      ASSERT_EQ(sparsified.sparsified, 1u);
      ASSERT_EQ(sparsified.sparsified_with_loops, 1u);
      ASSERT_EQ(sparsified.sparsify_carried, 1u);
      for (std::size_t i = 0; i < 3; ++i) {
        const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> lost(looped[i] - looped_reference[i]);
        EXPECT_GT(lost.eigenvalues().minCoeff(), -1e-9 * looped_reference[i].norm())
            << "plane " << i << " seen from " << observer << (strong_prev_hop ? " (via 1)" : "");
        EXPECT_LT(looped[i].trace(), chain_only[i].trace())
            << "plane " << i << " seen from " << observer << (strong_prev_hop ? " (via 1)" : "");
      }
    }
  }
}

// SGraph::RemoveKeyframe is sparsification with the victim named: keyframe 2 removed on request
// from a store with room leaves the graph that a full store leaves when it picks keyframe 2.
TEST(SGraphSparsification, RemovingAKeyframeOnRequestIsSparsifyingIt) {
  for (const bool loops : {false, true}) {
    for (const std::uint32_t observer : {1u, 3u}) {
      MarginalsCase full_store;
      full_store.loops = loops;
      full_store.observer = observer;
      MarginalsCase on_request = full_store;
      on_request.max_keyframes = 9;
      on_request.remove_2_on_request = true;
      SGraphStats a, b;
      const auto sparsified = ObserverPlaneMarginals(full_store, a);
      const auto removed = ObserverPlaneMarginals(on_request, b);
      EXPECT_EQ(a.sparsified, 1u);
      EXPECT_EQ(a.removed_keyframes, 0u);
      EXPECT_EQ(b.sparsified, 0u);
      EXPECT_EQ(b.removed_keyframes, 1u);
      EXPECT_EQ(b.keyframes, a.keyframes);
      EXPECT_EQ(b.sparsified_with_loops, a.sparsified_with_loops);
      EXPECT_EQ(b.sparsify_carried, a.sparsify_carried);
      EXPECT_EQ(b.relative_factors, a.relative_factors);
      for (std::size_t i = 0; i < 3; ++i) {
        EXPECT_LT((removed[i] - sparsified[i]).norm(), 1e-9 * sparsified[i].norm())
            << "plane " << i << " seen from " << observer << (loops ? " with loops" : "");
      }
    }
  }
}

// A patrol: laps of the room's ellipse (24 keyframes a lap, 0.57 m apart) on drifting odometry.
// From the second lap on, every third keyframe closes a loop on the active keyframe nearest to
// it that is at least half a lap back (as LoopCloser would: far back along the path, close in
// space), with a full solve after it.
struct Patrol {
  std::size_t loops_added = 0;
  std::vector<std::uint32_t> ids;  // per step (sparsified ones included)
};

void WalkPatrol(SGraph& g, const Walk& walk, Patrol& patrol) {
  const std::size_t max_keyframes = g.config().max_keyframes;
  std::mt19937 rng(11);
  std::normal_distribution<double> noise(0.0, 1.0);
  for (std::size_t i = 0; i < walk.truth.size(); ++i) {
    ASSERT_NO_FATAL_FAILURE(AddWalkStep(g, walk, i, patrol.ids));
    ASSERT_LE(g.keyframe_slots(), max_keyframes + 1);
    ASSERT_LE(g.stats().keyframes, max_keyframes);
    bool loop = false;
    if (i >= 24 && i % 3 == 0) {
      std::int64_t partner = -1;
      double nearest_m = 1.5;  // within reach of the drift, as LoopCloser's gate
      for (std::uint32_t k = 0; k < g.keyframe_slots(); ++k) {
        if (!g.keyframe_active(k) || TruthIndex(g, k) + 12 > i) continue;
        const double d =
            (walk.truth[TruthIndex(g, k)].translation() - walk.truth[i].translation()).norm();
        if (d < nearest_m) {
          nearest_m = d;
          partner = k;
        }
      }
      if (partner >= 0) {
        const auto k = static_cast<std::uint32_t>(partner);
        Vector6d xi;
        xi << 0.01 * noise(rng), 0.01 * noise(rng), 0.01 * noise(rng), 0.002 * noise(rng),
            0.002 * noise(rng), 0.002 * noise(rng);
        const Eigen::Isometry3d Z =
            walk.truth[TruthIndex(g, k)].inverse() * walk.truth[i] * Se3Exp(xi);
        ASSERT_TRUE(g.AddRelativePose(k, patrol.ids.back(), Z, LoopInformation(),
                                      RelativePoseKind::kLoopClosure));
        ++patrol.loops_added;
        loop = true;
      }
    }
    auto report = g.Solve(loop ? SolveKind::kFull : SolveKind::kLocal);
    ASSERT_TRUE(report);
    ASSERT_TRUE(report->usable);
  }
  auto report = g.Solve(SolveKind::kFull);
  ASSERT_TRUE(report);
  ASSERT_TRUE(report->usable);
}

// Six times as many keyframes as the store holds. Soon every keyframe outside the local window
// carries a loop: the first version then found nothing to sparsify, ignored that, and wrote the
// next keyframe past the end of its arrays.
TEST(SGraphSparsification, PatrolClosingALoopEveryFewKeyframesStaysWithinCapacity) {
  SGraphConfig config;
  config.max_keyframes = 16;
  config.local_window_keyframes = 4;
  const Room room;
  const Walk walk(room, static_cast<int>(6 * config.max_keyframes));
  SGraph g;
  ASSERT_TRUE(g.Init(config));
  Patrol patrol;
  ASSERT_NO_FATAL_FAILURE(WalkPatrol(g, walk, patrol));
  const SGraphStats s = g.stats();
  EXPECT_EQ(s.keyframes, config.max_keyframes);
  EXPECT_EQ(s.sparsified, walk.truth.size() - config.max_keyframes);
  EXPECT_EQ(s.rejected_keyframes, 0u);
  EXPECT_EQ(s.sparsify_failed, 0u);
  EXPECT_EQ(s.rejected_capacity, 0u);
  // Loops were everywhere: keyframes carrying them were sparsified, and every loop survived,
  // carried to a neighbour (possibly fused with a loop already there), none dropped.
  EXPECT_GT(patrol.loops_added, 15u);
  EXPECT_GT(s.sparsified_with_loops, 0u);
  EXPECT_GT(s.sparsify_carried, 0u);
  EXPECT_EQ(s.sparsify_dropped, 0u);
  const std::size_t loops =
      s.relative_factors[static_cast<std::size_t>(RelativePoseKind::kLoopClosure)];
  EXPECT_EQ(loops + s.sparsify_merged, patrol.loops_added);
  // The chain is whole: every active keyframe in time order from the origin.
  std::vector<std::uint32_t> chain(config.max_keyframes + 1);
  const std::size_t count = g.RecentKeyframes(chain);
  ASSERT_EQ(count, config.max_keyframes);
  EXPECT_EQ(chain[0], patrol.ids[0]);
  for (std::size_t i = 0; i < count; ++i) {
    EXPECT_LT(chain[i], config.max_keyframes + 1);
    if (i > 0) {
      EXPECT_LT(g.keyframe_stamp(chain[i - 1]), g.keyframe_stamp(chain[i]));
    }
  }
  // Consistent: after the full solve no factor, composed, carried or fused, contradicts the
  // rest (squared whitened residual within chi2(6, 99.9 %)).
  std::size_t evaluated = 0;
  for (std::uint32_t f = 0; f < config.max_factors; ++f) {
    const auto chi2 = g.FactorChi2(f);
    if (!chi2) continue;
    ++evaluated;
    EXPECT_LT(*chi2, 22.46) << "factor " << f;
  }
  EXPECT_EQ(evaluated, s.factors);
  EXPECT_TRUE(g.keyframe_pose(patrol.ids[0]).isApprox(walk.truth[0], 1e-12));
  // Accurate: the same patrol with room for every keyframe (nothing sparsified) is the
  // reference. The survivors are about as close to the truth as it holds those keyframes, and
  // far closer than the odometry alone.
  SGraphConfig roomy = config;
  roomy.max_keyframes = walk.truth.size() + 1;
  SGraph reference;
  ASSERT_TRUE(reference.Init(roomy));
  Patrol full;
  ASSERT_NO_FATAL_FAILURE(WalkPatrol(reference, walk, full));
  ASSERT_EQ(reference.stats().sparsified, 0u);
  double worst_m = 0, reference_worst_m = 0, odometry_worst_m = 0;
  for (std::size_t i = 0; i < count; ++i) {
    const std::size_t j = TruthIndex(g, chain[i]);
    worst_m = std::max(
        worst_m, (g.keyframe_pose(chain[i]).translation() - walk.truth[j].translation()).norm());
    reference_worst_m = std::max(
        reference_worst_m,
        (reference.keyframe_pose(full.ids[j]).translation() - walk.truth[j].translation()).norm());
    odometry_worst_m = std::max(
        odometry_worst_m, (walk.odometry[j].translation() - walk.truth[j].translation()).norm());
  }
  EXPECT_LT(worst_m, reference_worst_m + 0.03);
  EXPECT_LT(worst_m, 0.25 * odometry_worst_m);
  std::printf(
      "loops %zu (reference %zu), in the graph %zu, merged %zu, carried %zu, loop victims "
      "%zu; worst %.4f m, reference %.4f m, odometry %.3f m\n",
      patrol.loops_added, full.loops_added, loops, s.sparsify_merged, s.sparsify_carried,
      s.sparsified_with_loops, worst_m, reference_worst_m, odometry_worst_m);
}

}  // namespace
}  // namespace msgraphs::core
