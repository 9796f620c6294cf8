// SPDX-License-Identifier: MIT
// Synthetic S-Graph worlds with known truth, shared by the graph tests: a rectangular room, a
// robot walking laps of an ellipse in it with drifting odometry, noisy plane measurements.
#pragma once

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <array>
#include <cmath>
#include <numbers>
#include <random>
#include <vector>

#include "msgraphs/core/geometry/se3.hpp"
#include "msgraphs/core/graph/s_graph.hpp"

namespace msgraphs::core::sgraph_test {

struct TruePlane {
  Eigen::Vector3d n;
  double d;
};

// A rectangular room (size_x x size_y, rotated by yaw about its centre), walls facing inwards,
// and its floor 0.5 m below the base frame.
struct Room {
  Eigen::Vector2d centre{3.0, -2.0};
  double yaw = 0.5;
  double size_x = 8.0, size_y = 6.0;
  std::vector<TruePlane> walls() const {
    std::vector<TruePlane> out;
    const Eigen::Matrix3d R = RotZ(yaw);
    const Eigen::Vector3d c(centre.x(), centre.y(), 0);
    const Eigen::Vector3d ex = R.col(0), ey = R.col(1);
    // Low x (faces +x), high x (faces -x), low y, high y.
    for (auto [n, half] :
         {std::pair{ex, size_x / 2}, std::pair{Eigen::Vector3d(-ex), size_x / 2},
          std::pair{ey, size_y / 2}, std::pair{Eigen::Vector3d(-ey), size_y / 2}}) {
      const Eigen::Vector3d on_wall = c - n * half;
      out.push_back({n, -n.dot(on_wall)});
    }
    return out;
  }
};

inline PlaneMeasurement Measure(const TruePlane& p,
                                const Eigen::Isometry3d& T,
                                std::mt19937& rng,
                                double sigma) {
  std::normal_distribution<double> noise(0.0, sigma);
  PlaneMeasurement z;
  z.normal = (T.linear().transpose() * p.n + Eigen::Vector3d(noise(rng), noise(rng), noise(rng)))
                 .normalized();
  z.d = p.d + p.n.dot(T.translation()) + noise(rng);
  z.basis_u = z.normal.unitOrthogonal();
  z.basis_v = z.normal.cross(z.basis_u);
  z.covariance = Eigen::Matrix3d::Identity() * sigma * sigma;
  return z;
}

inline Matrix6d OdometryInformation() {
  Matrix6d info = Matrix6d::Zero();
  info.diagonal() << 1 / (0.03 * 0.03), 1 / (0.03 * 0.03), 1 / (0.03 * 0.03), 1 / (0.005 * 0.005),
      1 / (0.005 * 0.005), 1 / (0.005 * 0.005);
  return info;
}

// A loop closure's information: 2 cm, 0.23 degrees.
inline Matrix6d LoopInformation() {
  Matrix6d info = Matrix6d::Zero();
  info.diagonal() << Eigen::Vector3d::Constant(1 / (0.02 * 0.02)),
      Eigen::Vector3d::Constant(1 / (0.004 * 0.004));
  return info;
}

// A robot walking laps of an ellipse inside the room, with drifting odometry (scale +3 %,
// yaw +0.17 degrees per step: about Spot's 1 degree per 10 m, exaggerated threefold).
struct Walk {
  std::vector<Eigen::Isometry3d> truth, odometry;
  explicit Walk(const Room& room, int steps) {
    Eigen::Isometry3d odo = Eigen::Isometry3d::Identity();
    for (int i = 0; i < steps; ++i) {
      const double a = 2 * std::numbers::pi * i / 24.0;
      Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
      T.linear() = RotZ(room.yaw + a + std::numbers::pi / 2);
      T.translation() = Eigen::Vector3d(room.centre.x(), room.centre.y(), 0) +
                        RotZ(room.yaw) * Eigen::Vector3d(2.5 * std::cos(a), 1.8 * std::sin(a), 0);
      if (i > 0) {
        Eigen::Isometry3d delta = truth.back().inverse() * T;
        delta.translation() *= 1.03;
        delta.linear() = RotZ(0.003) * delta.linear();
        odo = odo * delta;
      } else {
        odo = T;
      }
      truth.push_back(T);
      odometry.push_back(odo);
    }
  }
};

// Keyframe i of the walk, guessed from the previous estimate and the odometry, joined to the
// previous keyframe by the odometry factor; its id goes to the back of `ids`.
inline void AddWalkStep(SGraph& g,
                        const Walk& walk,
                        std::size_t i,
                        std::vector<std::uint32_t>& ids) {
  const Eigen::Isometry3d guess =
      i == 0 ? walk.truth[0]
             : g.keyframe_pose(ids.back()) * (walk.odometry[i - 1].inverse() * walk.odometry[i]);
  auto id = g.AddKeyframe(static_cast<double>(i), guess);
  ASSERT_TRUE(id);
  if (i > 0) {
    ASSERT_TRUE(g.AddRelativePose(ids.back(), *id,
                                  walk.odometry[i - 1].inverse() * walk.odometry[i],
                                  OdometryInformation(), RelativePoseKind::kOdometry));
  }
  ids.push_back(*id);
}

inline double MaxPositionError(const SGraph& g,
                               const std::vector<std::uint32_t>& ids,
                               const std::vector<Eigen::Isometry3d>& truth) {
  double worst = 0;
  for (std::size_t i = 0; i < ids.size(); ++i) {
    if (!g.keyframe_active(ids[i])) continue;
    worst =
        std::max(worst, (g.keyframe_pose(ids[i]).translation() - truth[i].translation()).norm());
  }
  return worst;
}

// A row of 6 m rooms along x, each with its own four walls and a room node, walked one way at
// 0.6 m a keyframe with odometry 2 % long (10 keyframes a room).
struct RoomRow {
  SGraph graph;
  std::mt19937 rng{11};
  std::vector<std::uint32_t> ids;
  std::vector<Eigen::Isometry3d> truth;
  std::vector<std::array<std::int32_t, 4>> walls;
  std::uint32_t floor = 0;

  explicit RoomRow(const SGraphConfig& config) { EXPECT_TRUE(graph.Init(config)); }

  static Eigen::Isometry3d TruePose(std::size_t k) {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear() = RotZ(0.05 * std::sin(0.4 * static_cast<double>(k)));
    T.translation() << 0.3 + 0.6 * static_cast<double>(k), 0.5 * std::sin(0.3 * static_cast<double>(k)), 0;
    return T;
  }

  std::array<TruePlane, 4> RoomWalls(std::size_t room) const {
    const double x0 = 6.0 * static_cast<double>(room);
    return {TruePlane{Eigen::Vector3d::UnitX(), -x0}, TruePlane{-Eigen::Vector3d::UnitX(), x0 + 6},
            TruePlane{Eigen::Vector3d::UnitY(), 2.5}, TruePlane{-Eigen::Vector3d::UnitY(), 2.5}};
  }

  void Step() {
    const std::size_t k = ids.size();
    const Eigen::Isometry3d T = TruePose(k);
    truth.push_back(T);
    Eigen::Isometry3d delta = k == 0 ? T : TruePose(k - 1).inverse() * T;
    delta.translation() *= 1.02;  // drifting odometry
    const Eigen::Isometry3d guess = k == 0 ? T : graph.keyframe_pose(ids.back()) * delta;
    const std::uint32_t id = *graph.AddKeyframe(static_cast<double>(k), guess);
    if (k == 0) floor = *graph.AddPlane(Eigen::Vector3d::UnitZ(), 0.5, PlaneClass::kFloor);
    if (k > 0) {
      ASSERT_TRUE(graph.AddRelativePose(ids.back(), id, delta, OdometryInformation(),
                                        RelativePoseKind::kOdometry));
    }
    ids.push_back(id);
    const std::size_t room = static_cast<std::size_t>(T.translation().x() / 6.0);
    const auto truth_walls = RoomWalls(room);
    std::array<PlaneMeasurement, 4> z;
    for (std::size_t i = 0; i < 4; ++i) z[i] = Measure(truth_walls[i], T, rng, 0.005);
    if (walls.size() <= room) {
      // A new room's walls start where the keyframe's estimate puts them, as the mapper does.
      const Eigen::Isometry3d T_est = graph.keyframe_pose(id);
      std::array<std::int32_t, 4> w{};
      for (std::size_t i = 0; i < 4; ++i) {
        const Eigen::Vector3d n = T_est.linear() * z[i].normal;
        w[i] = static_cast<std::int32_t>(
            *graph.AddPlane(n, z[i].d - n.dot(T_est.translation()), PlaneClass::kWall));
      }
      walls.push_back(w);
    }
    for (std::size_t i = 0; i < 4; ++i)
      ASSERT_TRUE(graph.AddPlaneObservation(id, static_cast<std::uint32_t>(walls[room][i]), z[i]));
    ASSERT_TRUE(graph.AddPlaneObservation(
        id, floor, Measure(TruePlane{Eigen::Vector3d::UnitZ(), 0.5}, T, rng, 0.005)));
    if (k % 10 == 5) {  // the room is found half way through it
      MapRoom r;
      r.centre = Eigen::Vector2d(6.0 * static_cast<double>(room) + 3, 0);
      r.walls = walls[room];
      ASSERT_TRUE(graph.AddRoom(r));
    }
  }
};

}  // namespace msgraphs::core::sgraph_test
