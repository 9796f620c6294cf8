// SPDX-License-Identifier: MIT
// A local mapper that mapped one box room (synthetic_clouds.hpp), for the tests of what is built
// from a robot's map: room descriptors, place clouds.
#pragma once

#include <gtest/gtest.h>

#include <cstdint>
#include <vector>

#include "msgraphs/core/slam/local_mapper.hpp"
#include "synthetic_clouds.hpp"

namespace msgraphs::test {

using core::LocalMapper;
using core::LocalMapperConfig;

inline constexpr double kSx = 10.0, kSy = 8.0;  // the room, corner at the world origin

// The room seen by a mapper driven along its middle.
inline void MapTheRoom(double ceiling_m, LocalMapper& mapper) {
  LocalMapperConfig config;
  config.max_scan_points = 25000;
  config.cloud_store_points = 32 * 6000;
  config.graph.max_keyframes = 32;
  config.graph.max_factors = 32 * 64;
  config.grid.width = config.grid.height = 256;
  config.grid.origin_m = Eigen::Vector2f(-7.8f, -12.8f);  // the map frame starts at (2, 4)
  const Status init = mapper.Init(config);
  ASSERT_TRUE(init) << init.error().detail;
  // Perfect odometry along the room's middle, a keyframe a metre; the map frame is the first
  // base pose (2, 4, 0.5 m above the floor).
  const Eigen::Isometry3d T_world_first = [] {
    Eigen::Isometry3d T = test::PlanarPose(2.0, 4.0, 0.0);
    T.translation().z() = 0.5;
    return T;
  }();
  std::vector<float> times(20000, 0.1f);
  for (int i = 0; i < 7; ++i) {
    Eigen::Isometry3d T_world_base = T_world_first;
    T_world_base.translation().x() += i;
    const Eigen::Isometry3d odometry = T_world_first.inverse() * T_world_base;
    const double t = 10.0 + i;
    ASSERT_TRUE(mapper.AddOdometry(t - 0.15, odometry));
    ASSERT_TRUE(mapper.AddOdometry(t + 0.05, odometry));
    const auto points = test::BoxRoom(kSx, kSy, ceiling_m, 20000, 0.01, static_cast<std::uint32_t>(i + 1),
                                      (T_world_base * config.T_base_lidar).inverse());
    ASSERT_TRUE(mapper.AddScan({points, times, t - 0.1, t}));
  }
  ASSERT_TRUE(mapper.Finish());
}

}  // namespace msgraphs::test
