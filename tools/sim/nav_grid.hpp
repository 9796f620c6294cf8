// SPDX-License-Identifier: MIT
// The planning grid of one level: every 0.1 m cell's clearance from obstacles in the body's
// height band and the room it lies in. A* on it (8-connected, a small penalty near obstacles,
// shortened by line of sight) plans the robots' and the simulated people's paths; a room can be
// excluded so that a path goes around it (a robot that only looks into a room from its door).
#pragma once

#include <Eigen/Core>
#include <vector>

#include "scene.hpp"
#include "world.hpp"

namespace msgraphs::sim {

/// Up to two rooms (indices into World::rooms, -1: none) a path must not pass through.
struct RoomExclusion {
  int a = -1, b = -1;
  bool Has(int room) const { return room >= 0 && (room == a || room == b); }
};

class NavGrid {
 public:
  static constexpr double kCellM = 0.1;  ///< grid resolution

  /// Clearance from everything between 5 cm above the floor and body_top_m (allocates).
  NavGrid(const World& world, const Scene& scene, int level, double body_top_m);

  Eigen::Vector2d Centre(int x, int y) const {
    return origin_ + Eigen::Vector2d((x + 0.5) * kCellM, (y + 0.5) * kCellM);
  }
  bool Cell(const Eigen::Vector2d& p, int& x, int& y) const;
  double Clearance(const Eigen::Vector2d& p) const;
  /// Index into World::rooms of the room containing p, -1 outside every room of the level.
  int RoomAt(const Eigen::Vector2d& p) const;

  /// True when every point of a-b has `clearance` and lies outside the excluded rooms.
  bool SegmentClear(const Eigen::Vector2d& a,
                    const Eigen::Vector2d& b,
                    double clearance,
                    const RoomExclusion& excluded = {}) const;

  /// A* from `from` to `to` through cells with at least `clearance`, never through a cell of an
  /// excluded room (the goal cell excepted); a polyline shortened by line of sight, or empty
  /// when there is no path.
  std::vector<Eigen::Vector2d> Plan(const Eigen::Vector2d& from,
                                    const Eigen::Vector2d& to,
                                    double clearance,
                                    const RoomExclusion& excluded = {}) const;

  /// Per room (index into World::rooms): whether a cell of it with `clearance` can be reached
  /// from `from` without passing through an excluded room (a flood fill; allocates).
  std::vector<bool> ReachableRooms(const Eigen::Vector2d& from,
                                   double clearance,
                                   const RoomExclusion& excluded,
                                   std::size_t rooms) const;

  /// Centres of the cells of `room` (index into World::rooms) with at least `clearance`.
  std::vector<Eigen::Vector2d> FreeCells(int room, double clearance) const;

 private:
  std::size_t Index(int x, int y) const { return static_cast<std::size_t>(y * nx_ + x); }

  Eigen::Vector2d origin_;
  int nx_ = 0, ny_ = 0;
  std::vector<double> clearance_;
  std::vector<int> room_;
};

}  // namespace msgraphs::sim
