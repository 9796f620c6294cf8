// SPDX-License-Identifier: MIT
// The front end's synthetic world for core tests: a 10 x 8 x 3 m box room, scans of it from a
// lidar on a legged robot's base, a walk round it with biased odometry, and the mapper sized for
// it (slam_test.cpp, relocalise_test.cpp).
#pragma once

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cstdint>
#include <numbers>
#include <span>
#include <vector>

#include "msgraphs/core/geometry/se3.hpp"
#include "msgraphs/core/slam/local_mapper.hpp"
#include "synthetic_clouds.hpp"

namespace msgraphs::core {

inline Eigen::Isometry3d Pose(double x, double y, double yaw) { return test::PlanarPose(x, y, yaw); }

constexpr double kSx = 10.0, kSy = 8.0, kSz = 3.0;

// A scan of the box room taken by a lidar 0.8 m above the floor at T_world_base.
inline std::vector<Eigen::Vector3f> ScanAt(const Eigen::Isometry3d& T_world_base,
                                    const LocalMapperConfig& config,
                                    std::uint32_t seed, std::size_t points = 20000) {
  const Eigen::Isometry3d T_lidar_world = (T_world_base * config.T_base_lidar).inverse();
  return test::BoxRoom(kSx, kSy, kSz, points, 0.01, seed, T_lidar_world);
}

// The true path (base at 0.5 m) inside the room and odometry with 5 % scale error and yaw drift.
// With `rock_deg`, the base rocks like a trotting legged robot's: pitch +-rock_deg alternating
// from step to step and roll at two thirds of it (level at the start, as a robot stands).
struct Walk {
  std::vector<Eigen::Isometry3d> truth, odometry;
  explicit Walk(int steps = 30, double rock_deg = 0.0) {  // 15 a lap
    Eigen::Isometry3d odo = Eigen::Isometry3d::Identity();
    for (int i = 0; i < steps; ++i) {
      const double a = 2 * std::numbers::pi * i / 15.0;
      Eigen::Isometry3d T =
          Pose(5 + 2.5 * std::cos(a), 4 + 2.0 * std::sin(a), a + std::numbers::pi / 2);
      T.translation().z() = 0.5;
      if (i > 0 && rock_deg > 0) {
        const double rock = rock_deg * std::numbers::pi / 180.0;
        T.linear() = T.linear() *
                     Eigen::AngleAxisd((i % 2 ? 1 : -1) * rock, Eigen::Vector3d::UnitY()) *
                     Eigen::AngleAxisd(0.67 * rock * std::sin(0.9 * i), Eigen::Vector3d::UnitX());
      }
      if (i == 0) {
        odo = T;
      } else {
        Eigen::Isometry3d delta = truth.back().inverse() * T;
        delta.translation() *= 1.05;
        delta.linear() = RotZ(0.01) * delta.linear();
        odo = odo * delta;
      }
      truth.push_back(T);
      odometry.push_back(odo);
    }
  }
};

// A mapper sized for the synthetic room: 20,000-point scans, a small grid around the room.
inline LocalMapperConfig SmallConfig(std::size_t keyframes, int grid_cells) {
  LocalMapperConfig config;
  config.max_scan_points = 25000;
  config.cloud_store_points = keyframes * 6000;
  config.graph.max_keyframes = keyframes;
  config.graph.max_factors = keyframes * 64;
  config.grid.width = config.grid.height = grid_cells;
  // Grid centred on the room (10 x 8 m, corner at the origin).
  config.grid.origin_m = Eigen::Vector2f(5.0f, 4.0f) -
                         Eigen::Vector2f::Constant(0.05f * static_cast<float>(grid_cells));
  return config;
}

// Step i of a walk (one keyframe a second): its odometry around the sweep, then the sweep.
inline auto FeedStep(LocalMapper& mapper, const LocalMapperConfig& config, const Walk& walk, std::size_t i,
              std::span<const float> times) {
  const double t = 10.0 + static_cast<double>(i);
  EXPECT_TRUE(mapper.AddOdometry(t - 0.15, walk.odometry[i]));
  EXPECT_TRUE(mapper.AddOdometry(t + 0.05, walk.odometry[i]));
  const auto points = ScanAt(walk.truth[i], config, static_cast<std::uint32_t>(i + 1));
  return mapper.AddScan({points, times, t - 0.1, t});
}


/// A scan of some world from T_world_base: (pose, config, seed, points).
using ScanFn = std::vector<Eigen::Vector3f> (*)(const Eigen::Isometry3d&, const LocalMapperConfig&,
                                                std::uint32_t, std::size_t);

// Steps [first, last) of the walk, one scan a second from t = 10 s, odometry bracketing each.
inline void WalkSteps(LocalMapper& mapper, const Walk& walk, const LocalMapperConfig& config,
                      std::size_t first, std::size_t last, ScanFn scan = ScanAt) {
  for (std::size_t i = first; i < last; ++i) {
    const double t = 10.0 + static_cast<double>(i);
    ASSERT_TRUE(mapper.AddOdometry(t - 0.15, walk.odometry[i]));
    ASSERT_TRUE(mapper.AddOdometry(t + 0.05, walk.odometry[i]));
    const auto points = scan(walk.truth[i], config, static_cast<std::uint32_t>(i + 1), 20000);
    const std::vector<float> times(points.size(), 0.1f);  // every point at the sweep's end
    ASSERT_TRUE(mapper.AddScan({points, times, t - 0.1, t}));
  }
}

}  // namespace msgraphs::core
