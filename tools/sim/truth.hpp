// SPDX-License-Identifier: MIT
// Ground truth and pictures: TUM trajectories of each robot's base frame in the world frame
// (full 6-DOF with the gait, stamped by the robot's own clock, at any rate), true start poses, the
// world's true walls (both faces as planes) and rooms (centre, orientation, size, polygon), and a
// top-down SVG.
#pragma once

#include <string>

#include "clocks.hpp"
#include "mission.hpp"
#include "world.hpp"

namespace msgraphs::sim {

bool WriteTum(const Trajectory& trajectory,
              const RobotClocks& clocks,
              double rate_hz,
              const std::string& path);
/// The true T_world_base at the robot's start (its trajectory's t = 0), yaw and start room.
bool WriteStartPose(const RobotPlan& plan, const std::string& path);
bool WriteWallsCsv(const World& world, const std::string& path);
bool WriteRoomsCsv(const World& world, const std::string& path);
bool WriteSvg(const World& world, const Mission* mission, int level, const std::string& path);

/// The minimum-area rectangle around a room: orientation in [0, 90) degrees, width <= length.
struct RoomRectangle {
  double orientation_deg = 0, width_m = 0, length_m = 0;
  Eigen::Vector2d centre{0, 0};
};
RoomRectangle MinAreaRectangle(const Room& room);

}  // namespace msgraphs::sim
