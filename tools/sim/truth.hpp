// SPDX-License-Identifier: MIT
// Ground truth and pictures: TUM trajectories of each robot's base frame in the world frame
// (stamped by the robot's own clock), true start poses, the world's true walls (both faces as
// planes) and rooms (centre, orientation, size, polygon), and a top-down SVG.
#pragma once

#include <string>

#include "clocks.hpp"
#include "mission.hpp"
#include "world.hpp"

namespace msgraphs::sim {

bool WriteTum(const Trajectory& trajectory, const RobotClocks& clocks, double rate_hz, const std::string& path);
bool WriteStartPose(const RobotPlan& plan, double base_z_m, const std::string& path);
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
