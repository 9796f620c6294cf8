// SPDX-License-Identifier: MIT
// Distilled rooms for the collaborative tests: a rectangular room and its four walls, as one
// robot would send them.
#pragma once

#include <Eigen/Geometry>
#include <cmath>
#include <cstdint>
#include <utility>

#include "msgraphs/core/graph/distilled_graph.hpp"

namespace msgraphs::test {

// A 6 x 4 m room centred at (cx, cy), rotated by yaw, in one robot's map: four walls and the room.
inline void AddRoom(core::DistilledGraph& g,
                    std::uint32_t first_wall,
                    std::uint32_t room_id,
                    const Eigen::Isometry3d& T_map_room,
                    std::uint32_t version) {
  const double hx = 3, hy = 2;
  const Eigen::Vector3d ex = T_map_room.linear().col(0), ey = T_map_room.linear().col(1);
  const Eigen::Vector3d c = T_map_room.translation();
  const std::pair<Eigen::Vector3d, double> faces[4] = {{ex, hx}, {-ex, hx}, {ey, hy}, {-ey, hy}};
  core::DistilledRoom room;
  room.id = room_id;
  room.version = version;
  room.centre = c.head<2>();
  room.yaw_rad = std::atan2(ex.y(), ex.x());
  room.size_x_m = 2 * hx;
  room.size_y_m = 2 * hy;
  for (int i = 0; i < 4; ++i) {
    core::DistilledWall w;
    w.id = first_wall + static_cast<std::uint32_t>(i);
    w.version = version;
    w.normal = faces[i].first;
    w.d = -w.normal.dot(c - w.normal * faces[i].second);
    w.covariance = Eigen::Vector3d(1e-4, 1e-4, 4e-4).asDiagonal();
    w.a = (c - w.normal * faces[i].second).head<2>();
    w.b = w.a + Eigen::Vector2d(1, 0);
    g.walls.push_back(w);
    room.walls[static_cast<std::size_t>(i)] = static_cast<std::int32_t>(w.id);
  }
  g.rooms.push_back(room);
}

}  // namespace msgraphs::test
