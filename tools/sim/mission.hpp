// SPDX-License-Identifier: MIT
// Missions: Spot-like robots walking waypoint paths through a level of the building. Paths are
// planned on a clearance grid (A*, then shortened by line of sight) and followed by a
// unicycle controller with Spot's limits (about 1 m/s, turning in place when the heading is
// far off), so trajectories have realistic speed changes and turns.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "scene.hpp"
#include "trajectory.hpp"
#include "world.hpp"

namespace msgraphs::sim {

struct MissionConfig {
  int robots = 3;
  double duration_s = 300.0;
  std::uint64_t seed = 1;
  int level = 0;
  double max_speed_mps = 1.0;
  double max_turn_rate_rps = 0.8;
  double max_accel_mps2 = 0.5;
  double robot_radius_m = 0.35;   ///< clearance kept from walls and clutter
  double base_height_m = 0.5;     ///< Spot's body above the floor while walking
  int shared_rooms = 2;           ///< rooms every robot visits (each pair shares at least these)
};

struct RobotPlan {
  int id = 0;
  PlanarPose start;
  std::string start_room;
  std::vector<std::string> rooms_visited;  ///< in order, start room first
  Trajectory trajectory;
};

struct Mission {
  MissionConfig config;
  std::vector<std::string> shared_rooms;
  std::vector<RobotPlan> robots;
};

std::optional<Mission> PlanMission(const World& world, const Scene& scene, const MissionConfig& config,
                                   std::string& error);

}  // namespace msgraphs::sim
