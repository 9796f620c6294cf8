// SPDX-License-Identifier: MIT
// Checks of generated buildings that look only at the world (not at the generator's own
// bookkeeping): which rooms each door joins, overlaps, the footprint in the building's frame.
#pragma once

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <numbers>
#include <numeric>
#include <vector>

#include "world.hpp"

namespace msgraphs::sim::test {

struct DoorJoin {
  int a = -1, b = -1;
  const Wall* wall = nullptr;
  const Door* door = nullptr;
};

/// The rooms on either side of every door (found 0.2 m past the wall's faces).
inline std::vector<DoorJoin> DoorJoins(const World& w) {
  std::vector<DoorJoin> out;
  auto index = [&](const Eigen::Vector2d& p) {
    const Room* r = w.RoomAt(p, 0);
    return r == nullptr ? -1 : static_cast<int>(r - w.rooms.data());
  };
  for (const Wall& wall : w.walls) {
    for (const Door& d : wall.doors) {
      const Eigen::Vector2d c = wall.start + wall.direction() * (d.offset_m + 0.5 * d.width_m);
      const Eigen::Vector2d n = wall.normal() * (0.5 * wall.thickness_m + 0.2);
      out.push_back({index(c + n), index(c - n), &wall, &d});
    }
  }
  return out;
}

/// Whether every room is reached from the first one through doors.
inline bool DoorsConnectEveryRoom(const World& w) {
  std::vector<int> parent(w.rooms.size());
  std::iota(parent.begin(), parent.end(), 0);
  auto find = [&](int x) {
    while (parent[static_cast<std::size_t>(x)] != x) x = parent[static_cast<std::size_t>(x)];
    return x;
  };
  for (const DoorJoin& j : DoorJoins(w)) {
    if (j.a >= 0 && j.b >= 0) parent[static_cast<std::size_t>(find(j.a))] = find(j.b);
  }
  for (std::size_t r = 0; r < w.rooms.size(); ++r) {
    if (find(static_cast<int>(r)) != find(0)) return false;
  }
  return true;
}

/// Points on a fine grid (offset so that none falls on a wall line) lying in two rooms.
inline int OverlapSamples(const World& w, double step_m = 0.25) {
  Eigen::Vector2d lo(1e18, 1e18), hi(-1e18, -1e18);
  for (const Room& r : w.rooms) {
    for (const auto& p : r.polygon) {
      lo = lo.cwiseMin(p);
      hi = hi.cwiseMax(p);
    }
  }
  int overlaps = 0;
  for (double y = lo.y() + 0.0731; y < hi.y(); y += step_m) {
    for (double x = lo.x() + 0.0917; x < hi.x(); x += step_m) {
      int in = 0;
      for (const Room& r : w.rooms) in += r.Contains({x, y}) ? 1 : 0;
      overlaps += in > 1 ? 1 : 0;
    }
  }
  return overlaps;
}

/// Extent of the rooms along and across `angle_deg` (the building's own frame).
inline Eigen::Vector2d Extent(const World& w, double angle_deg) {
  const Eigen::Rotation2Dd R(-angle_deg * std::numbers::pi / 180.0);
  Eigen::Vector2d lo(1e18, 1e18), hi(-1e18, -1e18);
  for (const Room& r : w.rooms) {
    for (const auto& p : r.polygon) {
      const Eigen::Vector2d q = R * p;
      lo = lo.cwiseMin(q);
      hi = hi.cwiseMax(q);
    }
  }
  return hi - lo;
}

/// Direction of a wall modulo 180 degrees.
inline double WallAngleDeg(const Wall& wall) {
  const Eigen::Vector2d d = wall.direction();
  double a = std::atan2(d.y(), d.x()) * 180.0 / std::numbers::pi;
  return std::fmod(std::fmod(a, 180.0) + 180.0, 180.0);
}

}  // namespace msgraphs::sim::test
