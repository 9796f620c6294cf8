// SPDX-License-Identifier: MIT
// The distilled S-Graph a robot shares (paper section V): its origin (the map frame itself),
// walls with their covariances, rooms with their walls, and the floor; every element carries
// the version it last changed in, so a receiver can be sent only what changed. Fixed capacity
// per graph (Init); plain data, no Ceres.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>

#include "msgraphs/base/bounded_vector.hpp"
#include "msgraphs/core/graph/s_graph.hpp"

namespace msgraphs::core {

struct DistilledWall {
  std::uint32_t id = 0;
  std::uint32_t version = 0;
  Eigen::Vector3d normal = Eigen::Vector3d::UnitX();  ///< unit, map frame, facing the observed side
  double d = 0;
  /// Over (alpha, beta, delta_d) along WallBasis(normal): the plane's own uncertainty.
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Identity();
  Eigen::Vector2d a = Eigen::Vector2d::Zero(), b = Eigen::Vector2d::Zero();  ///< extent (xy ends)
};

struct DistilledRoom {
  std::uint32_t id = 0;
  std::uint32_t version = 0;
  RoomShape shape = RoomShape::kFourWall;
  Eigen::Vector2d centre = Eigen::Vector2d::Zero();
  double yaw_rad = 0;                 ///< room frame x axis: the normal of walls[0]
  double size_x_m = 0, size_y_m = 0;  ///< wall to wall; a corridor's size_y is 0
  std::array<std::int32_t, 4> walls{-1, -1, -1,
                                    -1};  ///< DistilledWall ids (low x, high x, low y, high y)
};

struct DistilledGraph {
  std::uint16_t robot = 0;
  std::uint32_t version = 0;
  BoundedVector<DistilledWall> walls;
  BoundedVector<DistilledRoom> rooms;
  bool has_floor = false;
  Eigen::Vector2d floor_centre = Eigen::Vector2d::Zero();
  double floor_z_m = 0;  ///< the floor's height in this robot's map frame (room frames sit on it)

  void Init(std::size_t max_walls, std::size_t max_rooms) {
    walls.Init(max_walls);
    rooms.Init(max_rooms);
    Clear();
  }
  /// Empty, capacities kept: no allocation.
  void Clear() {
    walls.clear();
    rooms.clear();
    robot = 0;
    has_floor = false;
    floor_centre.setZero();
    floor_z_m = 0;
    version = 0;
  }
  /// Element by element into this graph's capacities (sized alike: no allocation; beyond
  /// them, false and the rest left out).
  bool CopyFrom(const DistilledGraph& other) {
    Clear();
    robot = other.robot;
    version = other.version;
    has_floor = other.has_floor;
    floor_centre = other.floor_centre;
    floor_z_m = other.floor_z_m;
    bool all = true;
    for (const DistilledWall& w : other.walls) all = walls.try_push_back(w) && all;
    for (const DistilledRoom& r : other.rooms) all = rooms.try_push_back(r) && all;
    return all;
  }
  const DistilledWall* FindWall(std::uint32_t id) const {
    for (const DistilledWall& w : walls) {
      if (w.id == id) return &w;
    }
    return nullptr;
  }
  const DistilledRoom* FindRoom(std::uint32_t id) const {
    for (const DistilledRoom& r : rooms) {
      if (r.id == id) return &r;
    }
    return nullptr;
  }
};

/// The basis the wall covariance refers to (the same rule as the S-Graph's planes): u horizontal
/// along the wall, v = n x u.
inline void WallBasis(const Eigen::Vector3d& normal, Eigen::Vector3d& u, Eigen::Vector3d& v) {
  const Eigen::Vector3d up =
      std::abs(normal.z()) < 0.9 ? Eigen::Vector3d::UnitZ() : Eigen::Vector3d::UnitX();
  u = up.cross(normal).normalized();
  v = normal.cross(u);
}

}  // namespace msgraphs::core
