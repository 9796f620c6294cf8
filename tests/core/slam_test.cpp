// SPDX-License-Identifier: MIT
// The local S-Graph front end: odometry buffer, plane association, the
// Hessian-shaped information, and the whole mapper on a synthetic room walked with biased
// odometry, also for laps on end with a keyframe store a third of the walk (loops everywhere)
// and with a cloud store that must keep a cloud of every place;
// bad input counted; no allocation on the per-scan path.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>
#include <span>
#include <string>
#include <thread>
#include <vector>

#include "alloc_counter.hpp"
#include "msgraphs/core/geometry/se3.hpp"
#include "msgraphs/core/slam/local_mapper.hpp"
#include "msgraphs/core/slam/loop_closer.hpp"
#include "msgraphs/core/slam/odometry_buffer.hpp"
#include "msgraphs/core/slam/plane_mapper.hpp"
#include "box_room_walk.hpp"
#include "synthetic_clouds.hpp"

namespace msgraphs::core {
namespace {

TEST(OdometryBuffer, InterpolatesAndRefusesDisorder) {
  OdometryBuffer b;
  b.Init(8, 0.15);
  ASSERT_TRUE(b.Add(1.0, Pose(0, 0, 0)));
  ASSERT_TRUE(b.Add(1.1, Pose(1, 0, 0.2)));
  auto mid = b.At(1.05);
  ASSERT_TRUE(mid);
  EXPECT_NEAR(mid->T_odom_base.translation().x(), 0.5, 1e-9);
  EXPECT_FALSE(mid->across_gap);
  EXPECT_EQ(b.At(1.2).error().code, Errc::kWouldBlock);
  EXPECT_EQ(b.At(0.9).error().code, Errc::kNotFound);
  EXPECT_EQ(b.Add(1.1, Pose(2, 0, 0)).error().code, Errc::kOutOfOrder);  // duplicate
  EXPECT_EQ(b.Add(1.0, Pose(2, 0, 0)).error().code, Errc::kOutOfOrder);  // backwards
  Eigen::Isometry3d nan = Pose(0, 0, 0);
  nan.translation().y() = std::nan("");
  EXPECT_EQ(b.Add(1.2, nan).error().code, Errc::kInvalidArgument);
  // A gap: the odometry stopped for half a second.
  ASSERT_TRUE(b.Add(1.6, Pose(2, 0, 0.2)));
  EXPECT_TRUE(b.At(1.3)->across_gap);
  EXPECT_EQ(b.stats().out_of_order, 2u);
  EXPECT_EQ(b.stats().invalid, 1u);
  // Full: the oldest go.
  for (int i = 0; i < 10; ++i) ASSERT_TRUE(b.Add(2.0 + i * 0.01, Pose(3, 0, 0)));
  EXPECT_EQ(b.size(), 8u);
  EXPECT_EQ(b.stats().overwritten, 5u);
  EXPECT_EQ(b.At(1.05).error().code, Errc::kNotFound);
}

ExtractedPlane Wall(const Eigen::Vector3d& n, double d, double u_min, double u_max) {
  ExtractedPlane p;
  p.kind = std::fabs(n.z()) > 0.9 ? PlaneKind::kHorizontal : PlaneKind::kVertical;
  p.normal = n.normalized();
  p.d = d;
  p.basis_u = p.kind == PlaneKind::kVertical
                  ? Eigen::Vector3d(-p.normal.y(), p.normal.x(), 0).normalized()
                  : Eigen::Vector3d::UnitX();
  p.basis_v = p.normal.cross(p.basis_u);
  p.covariance = Eigen::Vector3d(1e-5, 1e-5, 1e-5).asDiagonal();
  p.centroid = -d * p.normal + p.basis_u * (0.5 * (u_min + u_max));
  p.u_min = u_min;
  p.u_max = u_max;
  p.z_min = -0.4;
  p.z_max = 2.0;
  p.inliers = 500;
  return p;
}

// A desk's or sofa's face can be long and, seen tilted, tall; it never rises above the sensor,
// a wall in range always does (the VLP-16's upward beams hit it there).
TEST(PlaneMapper, AVerticalPlaneThatStaysBelowTheSensorIsFurniture) {
  SGraph g;
  ASSERT_TRUE(g.Init({}));
  PlaneMapper m;
  PlaneAssociationConfig config;
  config.sensor_height_m = 0.3;  // Spot: the VLP-16 0.3 m above the base
  ASSERT_TRUE(m.Init(64, config));
  const std::uint32_t k0 = *g.AddKeyframe(0, Pose(0, 0, 0));
  ExtractedPlane desk = Wall(Eigen::Vector3d(-1, 0, 0), 1.5, -1.5, 1.5);  // 3 m long
  desk.z_min = -0.5;
  desk.z_max = 0.35;  // 0.85 m tall (above min_wall_height_m), top 5 cm above the sensor
  ExtractedPlane wall = Wall(Eigen::Vector3d(-1, 0, 0), 4.0, -2.0, 2.0);
  wall.z_min = -0.5;
  wall.z_max = 0.45;  // what the +1 to +3 degree beams see of a wall 4 m away over clutter
  std::vector<ExtractedPlane> planes{desk, wall};
  ASSERT_TRUE(m.Associate(g, k0, planes));
  EXPECT_EQ(m.stats().furniture, 1u);
  EXPECT_EQ(m.stats().created, 1u);
  EXPECT_NEAR(std::fabs(g.plane(0).d), 4.0, 1e-6);
  config.min_rise_above_sensor_m = std::numeric_limits<double>::quiet_NaN();
  EXPECT_FALSE(m.Init(64, config));
}

TEST(PlaneMapper, AssociatesBySideAndExtentNotJustByLine) {
  SGraph g;
  ASSERT_TRUE(g.Init({}));
  PlaneMapper m;
  ASSERT_TRUE(m.Init(64, {}));
  const std::uint32_t k0 = *g.AddKeyframe(0, Pose(0, 0, 0));
  // A wall 2 m ahead (x = 2, seen facing -x), two collinear pieces 3 m apart along it, a
  // furniture face, and the floor.
  const Eigen::Vector3d facing(-1, 0, 0);
  std::vector<ExtractedPlane> planes{Wall(facing, 2.0, -1.0, 1.0), Wall(facing, 2.0, 4.0, 6.0),
                                     Wall(facing, 1.0, 0.0, 0.3),
                                     Wall(Eigen::Vector3d::UnitZ(), 0.5, -1, 1)};
  ASSERT_TRUE(m.Associate(g, k0, planes));
  EXPECT_EQ(g.plane_slots(), 3u);  // two wall pieces and the floor
  EXPECT_EQ(m.stats().furniture, 1u);
  // One metre on, the same wall is 1 m away and its first piece extends: it associates.
  const std::uint32_t k1 = *g.AddKeyframe(1, Pose(1, 0, 0));
  ASSERT_TRUE(g.AddRelativePose(k0, k1, Pose(1, 0, 0), Matrix6d::Identity() * 1e4,
                                RelativePoseKind::kOdometry));
  std::vector<ExtractedPlane> again{Wall(facing, 1.0, -2.0, 0.5),
                                    Wall(Eigen::Vector3d::UnitZ(), 0.5, -1, 1)};
  ASSERT_TRUE(m.Associate(g, k1, again));
  EXPECT_EQ(g.plane_slots(), 3u);
  EXPECT_EQ(m.stats().associated, 2u);
  EXPECT_EQ(g.plane(0).observations, 2u);
  EXPECT_EQ(g.plane(2).observations, 2u);  // the floor: horizontal planes associate too
  // The other face of that wall (seen from beyond it, facing +x) is never the same landmark.
  const std::uint32_t k2 = *g.AddKeyframe(2, Pose(3, 0, 0));
  ASSERT_TRUE(g.AddRelativePose(k1, k2, Pose(2, 0, 0), Matrix6d::Identity() * 1e4,
                                RelativePoseKind::kOdometry));
  std::vector<ExtractedPlane> behind{Wall(Eigen::Vector3d::UnitX(), 0.88, -1.0, 1.0)};
  ASSERT_TRUE(m.Associate(g, k2, behind));
  EXPECT_EQ(g.plane_slots(), 4u);
  // Its extent is what room detection sees.
  BoundedVector<MapWall> walls(16);
  BoundedVector<std::uint32_t> ids(16);
  m.MapWalls(g, 2, walls, ids);
  ASSERT_EQ(walls.size(), 1u);
  EXPECT_EQ(ids[0], 0u);
  EXPECT_NEAR(std::fabs(walls[0].d), 2.0, 1e-6);
  EXPECT_NEAR(std::min(walls[0].a.y(), walls[0].b.y()), -1.0, 1e-6);
  EXPECT_NEAR(std::max(walls[0].a.y(), walls[0].b.y()), 2.0, 1e-6);  // the union of both sightings
}

// The floor applies where the wall was seen: a patch 4 m along the wall from the keyframe keeps
// a precise offset there, and its offset at the keyframe carries the angle's floor times 4 m.
TEST(PlaneMapper, TheCovarianceFloorAppliesWhereTheWallWasSeen) {
  const double floor_m = 0.01;
  ExtractedPlane near = Wall(Eigen::Vector3d(-1, 0, 0), 2.0, -0.5, 0.5);  // centroid at the foot point
  ExtractedPlane far = Wall(Eigen::Vector3d(-1, 0, 0), 2.0, 3.5, 4.5);    // 4 m along the wall
  near.covariance = far.covariance = Eigen::Vector3d(1e-8, 1e-8, 1e-8).asDiagonal();
  const Eigen::Matrix3d c_near = PlaneObservationCovariance(near, floor_m);
  EXPECT_NEAR(c_near(2, 2), floor_m * floor_m, 1e-6);
  EXPECT_NEAR(c_near(0, 0), floor_m * floor_m, 1e-6);
  const Eigen::Matrix3d c_far = PlaneObservationCovariance(far, floor_m);
  const double lever = far.basis_u.dot(far.centroid);
  ASSERT_NEAR(std::fabs(lever), 4.0, 1e-9);
  // At the origin: the floor plus the angle's floor over the lever.
  EXPECT_NEAR(c_far(2, 2), floor_m * floor_m * (1 + lever * lever), 1e-6);
  // At the centroid (d + alpha * lever): just the floor.
  const Eigen::Vector3d at_centroid(lever, 0, 1);
  EXPECT_NEAR(at_centroid.dot(c_far * at_centroid), floor_m * floor_m, 1e-6);
  // A fit less precise than the floor keeps its own figures.
  far.covariance = Eigen::Vector3d(1e-2, 1e-2, 1e-2).asDiagonal();
  EXPECT_TRUE(PlaneObservationCovariance(far, floor_m).isApprox(far.covariance, 1e-9));
}

TEST(LoopCloser, InformationKeepsTheHessiansShape) {
  Matrix6d H = Matrix6d::Identity();
  H.diagonal() << 400, 400, 4, 1000, 1000, 1000;  // weak along z: a corridor-like degeneracy
  const Matrix6d info = InformationFromHessian(H, 0.02);
  EXPECT_NEAR(1.0 / std::sqrt(info(0, 0)), 0.02, 1e-4);
  EXPECT_GT(1.0 / std::sqrt(info(2, 2)), 0.15);  // stays weak
  Matrix6d bad = H;
  bad(0, 0) = std::nan("");
  EXPECT_TRUE(InformationFromHessian(bad, 0.02).isApprox(Matrix6d::Identity() / (0.02 * 0.02)));
}

TEST(LocalMapper, WalksARoomWithBiasedOdometry) {
  const LocalMapperConfig config = SmallConfig(64, 256);
  LocalMapper mapper;
  ASSERT_TRUE(mapper.Init(config));
  const Walk walk;
  std::vector<float> times(20000, 0.1f);  // every point taken at the end of the sweep
  double worst_odometry = 0;
  for (std::size_t i = 0; i < walk.truth.size(); ++i) {
    const double t = 10.0 + static_cast<double>(i);
    // The odometry frame starts at the first true pose's odometry reading.
    ASSERT_TRUE(mapper.AddOdometry(t - 0.15, walk.odometry[i]));
    ASSERT_TRUE(mapper.AddOdometry(t + 0.05, walk.odometry[i]));
    const auto points = ScanAt(walk.truth[i], config, static_cast<std::uint32_t>(i + 1));
    auto outcome = mapper.AddScan({points, times, t - 0.1, t});
    ASSERT_TRUE(outcome);
    EXPECT_EQ(*outcome, ScanOutcome::kKeyframe);
    worst_odometry = std::max(
        worst_odometry, (walk.odometry[i].translation() - walk.truth[i].translation()).norm());
  }
  ASSERT_TRUE(mapper.Finish());
  const SGraph& g = mapper.graph();
  ASSERT_EQ(g.stats().keyframes, walk.truth.size());
  // The map frame is the first odometry pose (= the first true pose here).
  double worst = 0;
  for (std::uint32_t k = 0; k < g.keyframe_slots(); ++k) {
    const auto i = static_cast<std::size_t>(g.keyframe_stamp(k) - 10.0 + 0.5);
    worst =
        std::max(worst, (g.keyframe_pose(k).translation() - walk.truth[i].translation()).norm());
  }
  EXPECT_GT(worst_odometry, 0.5);
  EXPECT_LT(worst, 0.05);
  EXPECT_GT(mapper.stats().scan_match_accepted, 25u);
  // A closed room seen whole from every keyframe: its fitness is low, and the limit its floor.
  EXPECT_DOUBLE_EQ(mapper.stats().scan_match_fitness_limit_m2, config.scan_match_max_fitness_m2);
  EXPECT_EQ(mapper.stats().scan_match_above_floor, 0u);
  // Four walls, the floor and the ceiling; one four-wall room at the room's centre.
  std::size_t walls = 0, floors = 0;
  for (std::uint32_t p = 0; p < g.plane_slots(); ++p) {
    const MapPlane plane = g.plane(p);
    if (plane.observations < 3) continue;
    walls += plane.plane_class == PlaneClass::kWall ? 1u : 0u;
    floors += plane.plane_class == PlaneClass::kFloor ? 1u : 0u;
  }
  EXPECT_EQ(walls, 4u);
  EXPECT_EQ(floors, 1u);
  ASSERT_EQ(g.stats().rooms, 1u);
  EXPECT_EQ(g.room(0).shape, RoomShape::kFourWall);
  EXPECT_LT((g.room(0).centre - Eigen::Vector2d(5, 4)).norm(), 0.05);
  EXPECT_TRUE(g.has_floor());
}

// A foot slips on one step: the encoders report 45 % of it (0.5 m short, twice
// max_correction_m). The match from the odometry's guess is refused; the one from the pace of
// the last match is accepted and the map stays on the truth. With the motion seed off, the
// walk ends tens of centimetres off (in the benchmark's buildings such a step left robots'
// own maps 20-30 cm off: docs/results.md).
double WorstAfterASlip(double motion_seed_max_age_s, LocalMapperStats& stats) {
  LocalMapperConfig config = SmallConfig(64, 256);
  config.motion_seed_max_age_s = motion_seed_max_age_s;
  config.track_scans = false;  // keyframes only: the pace seed is their slip remedy
  LocalMapper mapper;
  EXPECT_TRUE(mapper.Init(config));
  // Short and sparse: the test runs under qemu-aarch64 too.
  const Walk walk(12);
  std::vector<Eigen::Isometry3d> odometry = walk.odometry;
  constexpr std::size_t kSlip = 8;
  const Eigen::Isometry3d slipped_step = [&] {
    Eigen::Isometry3d step = walk.odometry[kSlip - 1].inverse() * walk.odometry[kSlip];
    step.translation() *= 0.45;
    return step;
  }();
  odometry[kSlip] = odometry[kSlip - 1] * slipped_step;
  for (std::size_t i = kSlip + 1; i < odometry.size(); ++i)
    odometry[i] = odometry[i - 1] * (walk.odometry[i - 1].inverse() * walk.odometry[i]);
  constexpr std::size_t kPoints = 8000;
  std::vector<float> times(kPoints, 0.1f);
  for (std::size_t i = 0; i < walk.truth.size(); ++i) {
    const double t = 10.0 + static_cast<double>(i);
    EXPECT_TRUE(mapper.AddOdometry(t - 0.15, odometry[i]));
    EXPECT_TRUE(mapper.AddOdometry(t + 0.05, odometry[i]));
    const auto points = ScanAt(walk.truth[i], config, static_cast<std::uint32_t>(i + 1), kPoints);
    EXPECT_TRUE(mapper.AddScan({points, times, t - 0.1, t}));
  }
  EXPECT_TRUE(mapper.Finish());
  const SGraph& g = mapper.graph();
  double worst = 0;
  for (std::uint32_t k = 0; k < g.keyframe_slots(); ++k) {
    const auto i = static_cast<std::size_t>(g.keyframe_stamp(k) - 10.0 + 0.5);
    worst = std::max(worst, (g.keyframe_pose(k).translation() - walk.truth[i].translation()).norm());
  }
  stats = mapper.stats();
  return worst;
}

// A sensor or building whose every fitness is above the configured floor: the first matches
// are refused, the gate learns the robot's own fitnesses from them, and every later match is
// accepted at the robot's own bound, so the map holds as it does with a floor that fits.
TEST(LocalMapper, AFitnessFloorBelowEveryMatchIsWidenedByTheRobotsOwnMatches) {
  LocalMapperConfig config = SmallConfig(64, 256);
  config.scan_match_max_fitness_m2 = 1e-6;  // below any real fit at 0.2 m map sampling
  config.scan_match_fitness_window = 20;
  config.scan_match_fitness_outlier_z = 3.5;  // on (the default is off)
  LocalMapper mapper;
  ASSERT_TRUE(mapper.Init(config));
  const Walk walk;
  WalkSteps(mapper, walk, config, 0, walk.truth.size());
  const LocalMapperStats& s = mapper.stats();
  const FitnessGateConfig gate = config.scan_match_fitness_gate();
  EXPECT_EQ(s.scan_match_rejected_fitness, gate.min_samples);  // until the gate has its figures
  EXPECT_EQ(s.scan_match_accepted, walk.truth.size() - 1 - gate.min_samples);
  EXPECT_EQ(s.scan_match_above_floor, s.scan_match_accepted);
  EXPECT_GT(s.scan_match_fitness_limit_m2, config.scan_match_max_fitness_m2);
  // With outlier_z 0 the floor is all there is, and nothing is ever matched.
  config.scan_match_fitness_outlier_z = 0;
  LocalMapper fixed;
  ASSERT_TRUE(fixed.Init(config));
  WalkSteps(fixed, walk, config, 0, walk.truth.size());
  EXPECT_EQ(fixed.stats().scan_match_accepted, 0u);
}

TEST(LocalMapper, AFootSlipIsMatchedFromTheLastMatchsPace) {
  LocalMapperStats with{}, without{};
  const double worst_with = WorstAfterASlip(LocalMapperConfig{}.motion_seed_max_age_s, with);
  const double worst_without = WorstAfterASlip(0.0, without);
  EXPECT_LT(worst_with, 0.05);
  EXPECT_GT(worst_without, 0.15);
  EXPECT_GE(with.scan_match_motion_seeded, 1u);
  EXPECT_EQ(without.scan_match_motion_seeded, 0u);
  // The slipped step: refused from the odometry's guess alone, accepted from the pace.
  const auto refused = [](const LocalMapperStats& s) {
    return s.scan_match_rejected_diverged + s.scan_match_rejected_fitness +
           s.scan_match_rejected_failed + s.scan_match_rejected_overlap;
  };
  EXPECT_GE(refused(without), 1u);
  EXPECT_EQ(with.scan_match_accepted, without.scan_match_accepted + refused(without) - refused(with));
  EXPECT_LT(refused(with), refused(without));
}

// Sweeps at 10 Hz while the robot walks 6 m across the room at 1 m/s, its encoders reporting
// 45 % of the motion for one second (a foot slipping): 0.55 m short by the next keyframe, far
// beyond max_correction_m. Scan tracking registers every sweep, each only 5.5 cm off, and the
// map stays on the truth; keyframes alone (the pace seed off too) end decimetres off.
double WorstAfterASlipAt10Hz(bool track_scans, LocalMapperStats& stats) {
  LocalMapperConfig config = SmallConfig(32, 256);
  config.track_scans = track_scans;
  config.motion_seed_max_age_s = 0;
  LocalMapper mapper;
  EXPECT_TRUE(mapper.Init(config));
  auto truth_at = [](double t) {
    Eigen::Isometry3d T = Pose(2.0 + std::clamp(t, 0.0, 6.0), 4.0 + 0.3 * std::sin(0.5 * t), 0.1);
    T.translation().z() = 0.5;
    return T;
  };
  auto reported = [](double t) { return t < 2.0 ? t : t < 3.0 ? 2.0 + 0.45 * (t - 2.0) : t - 0.55; };
  constexpr std::size_t kPoints = 6000;
  std::vector<float> times(kPoints, 0.1f);
  double next_odometry = 0.0;
  double worst = 0;
  for (int k = 1; k <= 60; ++k) {
    const double t = 0.1 * k;
    for (; next_odometry <= t + 0.05; next_odometry += 0.02) {
      // The encoders integrate the reported motion; the heading and the sway are right.
      Eigen::Isometry3d T_odom = truth_at(reported(next_odometry));
      T_odom.linear() = truth_at(next_odometry).linear();
      T_odom.translation().y() = truth_at(next_odometry).translation().y();
      EXPECT_TRUE(mapper.AddOdometry(next_odometry, truth_at(0).inverse() * T_odom));
    }
    const auto points = ScanAt(truth_at(t), config, static_cast<std::uint32_t>(k), kPoints);
    EXPECT_TRUE(mapper.AddScan({points, times, t - 0.1, t}));
  }
  EXPECT_TRUE(mapper.Finish());
  const SGraph& g = mapper.graph();
  for (std::uint32_t k = 0; k < g.keyframe_slots(); ++k) {
    const Eigen::Isometry3d truth = truth_at(0).inverse() * truth_at(g.keyframe_stamp(k));
    worst = std::max(worst, (g.keyframe_pose(k).translation() - truth.translation()).norm());
  }
  stats = mapper.stats();
  return worst;
}

TEST(LocalMapper, AFootSlipBetweenKeyframesIsTrackedSweepBySweep) {
  LocalMapperStats tracked{}, keyframes_only{};
  EXPECT_LT(WorstAfterASlipAt10Hz(true, tracked), 0.05);
  EXPECT_GT(WorstAfterASlipAt10Hz(false, keyframes_only), 0.15);
  EXPECT_GT(tracked.scans_tracked, 50u);
  EXPECT_EQ(keyframes_only.scans_tracked, 0u);
  // The slip gate saw the encoders disagree with the matches it was given.
  EXPECT_GE(tracked.odometry_slips, 1u);
}

// A restarted node rebuilds its mapper from the journaled keyframe scans alone (the sweeps
// between them are not kept). Each keyframe carries the motion scan tracking gave it; replayed
// with it, the rebuilt map is the live one: the same keyframes at the same poses.
TEST(LocalMapper, KeyframesReplayedWithTheirTrackedMotionRebuildTheLiveMap) {
  LocalMapperConfig config = SmallConfig(32, 256);
  LocalMapper live, rebuilt;
  ASSERT_TRUE(live.Init(config));
  ASSERT_TRUE(rebuilt.Init(config));
  auto truth_at = [](double t) {
    Eigen::Isometry3d T = Pose(2.0 + t, 4.0 + 0.3 * std::sin(0.5 * t), 0.1 + 0.05 * t);
    T.translation().z() = 0.5;
    return T;
  };
  constexpr std::size_t kPoints = 6000;
  std::vector<float> times(kPoints, 0.1f);
  std::vector<std::pair<double, Eigen::Isometry3d>> odometry;
  for (double t = 0; t <= 4.2; t += 0.02) {
    Eigen::Isometry3d T = truth_at(0).inverse() * truth_at(t);
    T.translation() *= 1.04;  // the encoders' scale error
    odometry.emplace_back(t, T);
  }
  std::size_t fed = 0;
  std::vector<std::pair<std::vector<Eigen::Vector3f>, LocalMapper::KeyframeMotion>> journal;
  std::vector<double> journal_end;
  for (int k = 1; k <= 40; ++k) {
    const double t = 0.1 * k;
    for (; fed < odometry.size() && odometry[fed].first <= t + 0.05; ++fed)
      ASSERT_TRUE(live.AddOdometry(odometry[fed].first, odometry[fed].second));
    auto points = ScanAt(truth_at(t), config, static_cast<std::uint32_t>(k), kPoints);
    auto outcome = live.AddScan({points, times, t - 0.1, t});
    ASSERT_TRUE(outcome);
    if (*outcome == ScanOutcome::kKeyframe) {
      journal.emplace_back(std::move(points), live.last_keyframe_motion());
      journal_end.push_back(t);
    }
  }
  ASSERT_GE(journal.size(), 3u);
  fed = 0;
  for (std::size_t i = 0; i < journal.size(); ++i) {
    const double t = journal_end[i];
    for (; fed < odometry.size() && odometry[fed].first <= t + 0.05; ++fed)
      ASSERT_TRUE(rebuilt.AddOdometry(odometry[fed].first, odometry[fed].second));
    auto outcome = rebuilt.ReplayKeyframe({journal[i].first, times, t - 0.1, t}, journal[i].second);
    ASSERT_TRUE(outcome);
    EXPECT_EQ(*outcome, ScanOutcome::kKeyframe);
  }
  const SGraph& a = live.graph();
  const SGraph& b = rebuilt.graph();
  ASSERT_EQ(a.keyframe_slots(), b.keyframe_slots());
  for (std::uint32_t k = 0; k < a.keyframe_slots(); ++k) {
    EXPECT_DOUBLE_EQ(a.keyframe_stamp(k), b.keyframe_stamp(k));
    EXPECT_LT((a.keyframe_pose(k).translation() - b.keyframe_pose(k).translation()).norm(), 1e-6);
  }
  LocalMapper::KeyframeMotion bad;
  bad.T_last_new.linear()(0, 0) = 2;
  EXPECT_FALSE(rebuilt.ReplayKeyframe({journal[0].first, times, 9.9, 10.0}, bad));
}

// Four laps of the room with a keyframe store for a third of them: loop closures every few
// keyframes once the path is 10 m long, so that soon every keyframe the graph could sparsify
// carries one. The first version then wrote the next keyframe past the graph's and the mapper's
// per-keyframe arrays.
TEST(LocalMapper, PatrolWithLoopsEverywhereStaysWithinTheGraphsCapacity) {
  LocalMapperConfig config = SmallConfig(20, 256);
  config.graph.local_window_keyframes = 8;
  config.full_solve_lag_keyframes = 3;  // below half the window
  LocalMapper mapper;
  ASSERT_TRUE(mapper.Init(config));
  const Walk walk(60);
  std::vector<float> times(20000, 0.1f);
  for (std::size_t i = 0; i < walk.truth.size(); ++i) {
    auto outcome = FeedStep(mapper, config, walk, i, times);
    ASSERT_TRUE(outcome) << "keyframe " << i << ": " << outcome.error().detail;
    ASSERT_EQ(*outcome, ScanOutcome::kKeyframe);
    ASSERT_LE(mapper.graph().keyframe_slots(), config.graph.max_keyframes + 1);
    ASSERT_LE(mapper.graph().stats().keyframes, config.graph.max_keyframes);
  }
  ASSERT_TRUE(mapper.Finish());
  const SGraph& g = mapper.graph();
  const SGraphStats s = g.stats();
  EXPECT_EQ(s.keyframes, config.graph.max_keyframes);
  EXPECT_EQ(s.sparsified, walk.truth.size() - config.graph.max_keyframes);
  EXPECT_EQ(s.rejected_keyframes, 0u);
  EXPECT_EQ(s.sparsify_dropped, 0u);
  EXPECT_EQ(mapper.stats().keyframes_refused, 0u);
  EXPECT_EQ(mapper.stats().chain_factors_refused, 0u);
  EXPECT_GE(mapper.stats().loop_closures, 5u);
  EXPECT_GT(s.sparsified_with_loops, 0u);
  EXPECT_GT(s.sparsify_carried, 0u);
  // The survivors are where they belong; the odometry alone is far off by the last lap.
  double worst = 0, worst_odometry = 0;
  for (std::uint32_t k = 0; k < g.keyframe_slots(); ++k) {
    if (!g.keyframe_active(k)) continue;
    const auto i = static_cast<std::size_t>(g.keyframe_stamp(k) - 10.0 + 0.5);
    worst =
        std::max(worst, (g.keyframe_pose(k).translation() - walk.truth[i].translation()).norm());
    worst_odometry = std::max(
        worst_odometry, (walk.odometry[i].translation() - walk.truth[i].translation()).norm());
  }
  EXPECT_GT(worst_odometry, 0.5);
  EXPECT_LT(worst, 0.05);
  std::printf(
      "loops %llu, loop victims %zu, carried %zu, merged %zu; worst %.3f m (odometry %.3f)\n",
      static_cast<unsigned long long>(mapper.stats().loop_closures), s.sparsified_with_loops,
      s.sparsify_carried, s.sparsify_merged, worst, worst_odometry);
}

// Three laps of the room with loop closures every few keyframes, the full solve run on the spot
// and in the background (full_solve_lag_keyframes, a worker thread running each job as the
// node's does): the same map, within rounding of the local solves' time limits.
struct PatrolResult {
  std::vector<Eigen::Vector3d> positions;
  double worst_m = 0;
  LocalMapperStats stats;
};

PatrolResult Patrol(std::size_t lag, bool worker) {
  LocalMapperConfig config = SmallConfig(64, 256);
  config.full_solve_lag_keyframes = lag;
  LocalMapper mapper;
  EXPECT_TRUE(mapper.Init(config));
  const Walk walk(45);
  std::vector<float> times(20000, 0.1f);
  std::jthread runner;
  std::uint64_t begun = 0;
  for (std::size_t i = 0; i < walk.truth.size(); ++i) {
    EXPECT_TRUE(FeedStep(mapper, config, walk, i, times));
    // One thread per job begun, as the node's solver thread takes each offer once; the previous
    // job was applied before this one began, so its thread has finished.
    if (worker && mapper.stats().full_solves_begun != begun) {
      begun = mapper.stats().full_solves_begun;
      if (SGraphSolveJob* job = mapper.background_solve()) {
        if (runner.joinable()) runner.join();
        runner = std::jthread([job] {
          if (job->TryClaim()) job->Run();
        });
      }
    }
  }
  if (runner.joinable()) runner.join();
  EXPECT_TRUE(mapper.Finish());
  PatrolResult result;
  const SGraph& g = mapper.graph();
  for (std::uint32_t k = 0; k < g.keyframe_slots(); ++k) {
    const auto i = static_cast<std::size_t>(g.keyframe_stamp(k) - 10.0 + 0.5);
    result.positions.push_back(g.keyframe_pose(k).translation());
    result.worst_m = std::max(result.worst_m,
                              (g.keyframe_pose(k).translation() - walk.truth[i].translation()).norm());
  }
  result.stats = mapper.stats();
  return result;
}

TEST(LocalMapper, TheFullSolveInTheBackgroundMakesTheSameMap) {
  const PatrolResult on_the_spot = Patrol(0, false);
  const PatrolResult background = Patrol(5, true);
  const PatrolResult no_worker = Patrol(5, false);  // the mapper runs each job at its keyframe
  EXPECT_LT(on_the_spot.worst_m, 0.05);
  EXPECT_LT(background.worst_m, 0.05);
  EXPECT_GE(background.stats.loop_closures, 3u);
  EXPECT_GT(background.stats.full_solves_background, 0u);
  EXPECT_EQ(on_the_spot.stats.full_solves_background, 0u);
  // Without a worker the mapper ran every job itself at its keyframe.
  EXPECT_GT(no_worker.stats.full_solves_waited, 0u);
  EXPECT_LT(background.stats.full_solves_waited, background.stats.full_solves_begun);
  ASSERT_EQ(background.positions.size(), no_worker.positions.size());
  for (std::size_t k = 0; k < background.positions.size(); ++k) {
    EXPECT_LT((background.positions[k] - no_worker.positions[k]).norm(), 1e-6) << k;
    EXPECT_LT((background.positions[k] - on_the_spot.positions[k]).norm(), 0.02) << k;
  }
}

// Three laps of 15 places with a cloud store of about 15 clouds: a place's older clouds go,
// every place keeps one (the ring the store replaced kept the last N keyframes' instead).
TEST(LocalMapper, AFullCloudStoreKeepsACloudOfEveryPlace) {
  LocalMapperConfig config = SmallConfig(64, 256);
  config.cloud_store_points = 100000;
  LocalMapper mapper;
  ASSERT_TRUE(mapper.Init(config));
  const Walk walk(45);
  std::vector<float> times(20000, 0.1f);
  for (std::size_t i = 0; i < walk.truth.size(); ++i) ASSERT_TRUE(FeedStep(mapper, config, walk, i, times));
  ASSERT_TRUE(mapper.Finish());
  const KeyframeCloudStoreStats& st = mapper.clouds().stats();
  const double cell_m = mapper.cloud_cover().cell_m();
  const SGraph& g = mapper.graph();
  std::printf("store: %zu clouds of %zu keyframes, %zu points (%zu capacity); evicted %llu covered, %llu uncovered; "
              "cell %.1f m, %llu coarsenings, %llu compactions\n",
              mapper.clouds().stored_clouds(), static_cast<std::size_t>(g.stats().keyframes),
              mapper.clouds().used_points(), mapper.clouds().capacity_points(),
              static_cast<unsigned long long>(st.evicted_covered),
              static_cast<unsigned long long>(st.evicted_uncovered), cell_m,
              static_cast<unsigned long long>(mapper.cloud_cover().coarsenings()),
              static_cast<unsigned long long>(st.compactions));
  EXPECT_GT(st.evicted_covered, 0u);
  EXPECT_EQ(st.evicted_uncovered, 0u);
  EXPECT_LT(mapper.clouds().stored_clouds(), walk.truth.size());
  // Every place of the walk has a stored cloud taken within a cell of it.
  for (std::size_t i = 0; i < walk.truth.size(); ++i) {
    double nearest = 1e9;
    for (std::uint32_t k = 0; k < g.keyframe_slots(); ++k) {
      if (mapper.keyframe_cloud(k).empty()) continue;
      nearest = std::min(nearest, (g.keyframe_pose(k).translation() - walk.truth[i].translation()).norm());
    }
    EXPECT_LE(nearest, std::sqrt(3.0) * cell_m) << "place " << i;
  }
  // The local map's keyframes are never evicted.
  std::vector<std::uint32_t> recent(config.local_map_keyframes);
  const std::size_t n = g.RecentKeyframes(recent);
  for (std::size_t j = 0; j < n; ++j) EXPECT_FALSE(mapper.keyframe_cloud(recent[j]).empty()) << recent[j];
}

TEST(LocalMapper, BadScansAreCountedAndTheScanPathDoesNotAllocate) {
  const LocalMapperConfig config = SmallConfig(32, 128);
  LocalMapper mapper;
  auto init = mapper.Init(config);
  ASSERT_TRUE(init) << init.error().detail;
  const auto points = ScanAt(Pose(5, 4, 0) * Eigen::Translation3d(0, 0, 0.5), config, 1);
  std::vector<float> times(points.size(), 0.1f);
  // Before any odometry: counted, not a keyframe.
  EXPECT_EQ(*mapper.AddScan({points, times, 0.9, 1.0}), ScanOutcome::kNoOdometry);
  // Points and times of different lengths.
  EXPECT_FALSE(mapper.AddScan({points, std::span(times).first(10), 0.9, 1.0}));
  ASSERT_TRUE(mapper.AddOdometry(0.5, Eigen::Isometry3d::Identity()));
  ASSERT_TRUE(mapper.AddOdometry(1.05, Eigen::Isometry3d::Identity()));
  EXPECT_EQ(*mapper.AddScan({points, times, 0.9, 1.0}), ScanOutcome::kKeyframe);
  // Standing still: every further scan is not a keyframe, and that path allocates nothing.
  test::AllocationScope scope;
  for (int i = 0; i < 50; ++i) {
    const double t = 1.1 + 0.1 * i;
    ASSERT_TRUE(mapper.AddOdometry(t + 0.05, Eigen::Isometry3d::Identity()));
    auto outcome = mapper.AddScan({points, times, t - 0.1, t});
    ASSERT_TRUE(outcome);
    EXPECT_EQ(*outcome, ScanOutcome::kNotKeyframe);
  }
  EXPECT_EQ(scope.allocations(), 0u);
  EXPECT_EQ(mapper.stats().scans_tracked, 50u);  // each of them registered (scan tracking)
  EXPECT_EQ(mapper.stats().no_odometry, 1u);
  EXPECT_EQ(mapper.stats().bad_scans, 1u);
  EXPECT_EQ(mapper.stats().scan_points_beyond_capacity, 0u);
  // A keyframe scan beyond max_scan_points: the excess is left out of the keyframe, counted.
  ASSERT_GE(points.size(), 300u);
  LocalMapperConfig small = config;
  small.max_scan_points = points.size() - 100;
  LocalMapper cut;
  ASSERT_TRUE(cut.Init(small));
  ASSERT_TRUE(cut.AddOdometry(0.5, Eigen::Isometry3d::Identity()));
  ASSERT_TRUE(cut.AddOdometry(1.05, Eigen::Isometry3d::Identity()));
  EXPECT_EQ(*cut.AddScan({points, times, 0.9, 1.0}), ScanOutcome::kKeyframe);
  EXPECT_EQ(cut.stats().scan_points_beyond_capacity, 100u);
  LocalMapperConfig bad = config;
  bad.keyframe_spacing_m = -1;
  EXPECT_FALSE(LocalMapper().Init(bad));
  bad = config;
  bad.T_base_lidar.linear()(0, 0) = 2;
  EXPECT_FALSE(LocalMapper().Init(bad));
}

}  // namespace
}  // namespace msgraphs::core
