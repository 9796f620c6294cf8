// SPDX-License-Identifier: MIT
// Where a robot goes when it visits a room, by the kind of visit:
//   peek:    it stops in a doorway (or just outside it) without entering, looks in for a few
//            seconds (turning left and right) and leaves;
//   partial: it walks to a point or two near the entrance it came through;
//   full:    it walks several points spread over the whole room (farthest-point sampling of the
//            room's free cells), so every part of the room is seen from close.
// Entrances come from the planning grid (walkable cells of the room next to walkable cells of
// another room), so doors and doorless openings alike are found, at any angle.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "nav_grid.hpp"
#include "random.hpp"

namespace msgraphs::sim {

struct Entrance {
  Eigen::Vector2d centre;  ///< on the room's boundary, in the middle of the opening
  Eigen::Vector2d inward;  ///< unit, into the room
  double width_m = 0;      ///< walkable width of the opening (at the robot's clearance)
};

/// Every opening through which a robot with `clearance` walks into `room` (allocates).
std::vector<Entrance> FindEntrances(const NavGrid& grid, int room, double clearance);

/// The entrance whose outside is nearest to `from`, or nullptr when the room has none.
const Entrance* NearestEntrance(const std::vector<Entrance>& entrances,
                                const Eigen::Vector2d& from);

/// A point outside `room` in front of `entrance`, between `min_m` and `max_m` from the boundary
/// (drawn), where the robot has `clearance`; false when there is none.
bool PeekStandPoint(const NavGrid& grid,
                    int room,
                    const Entrance& entrance,
                    double clearance,
                    double min_m,
                    double max_m,
                    Random& rng,
                    Eigen::Vector2d& out);

/// Free cells of the room within `reach_m` of the entrance, at least `min_inside_m` inside it.
std::vector<Eigen::Vector2d> CellsNear(const std::vector<Eigen::Vector2d>& cells,
                                       const Entrance& entrance,
                                       double reach_m,
                                       double min_inside_m);

/// `count` cells spread over `cells` (farthest-point sampling from the cell nearest `from`),
/// in a walking order (nearest next, from `from`).
std::vector<Eigen::Vector2d> CoverPoints(const std::vector<Eigen::Vector2d>& cells,
                                         int count,
                                         const Eigen::Vector2d& from);

}  // namespace msgraphs::sim
