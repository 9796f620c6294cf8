// SPDX-License-Identifier: MIT
// Clearance of a room's floor for a walking robot: obstacle footprints (wall pieces beside
// doors, furniture, columns) rasterised on a grid, a Euclidean distance transform, then a
// flood fill. The estimate is conservative: a cell's value is at most its true distance to
// the nearest footprint, and at most 2 half cell diagonals below it.
#pragma once

#include <vector>

#include "geometry.hpp"
#include "world.hpp"

namespace msgraphs::sim::building {

class ClearanceGrid {
 public:
  /// Covers [lo, hi] with square cells of `cell_m`. Allocates.
  ClearanceGrid(const Vec2& lo, const Vec2& hi, double cell_m);

  void AddRectangle(const Vec2& centre, double yaw_rad, double half_x_m, double half_y_m);
  void AddCircle(const Vec2& centre, double radius_m);
  /// Every solid piece of the wall in the robot's height band (doors are open below their
  /// height, which is at least 1 m), grown by half its thickness at its ends like the scene.
  void AddWall(const Wall& wall);
  void AddBox(const Box& box) {
    AddRectangle(box.centre, box.yaw_rad, 0.5 * box.size_m.x(), 0.5 * box.size_m.y());
  }
  void AddCylinder(const Cylinder& c) { AddCircle(c.centre, c.radius_m); }
  /// Distance transform; call after the last Add.
  void Compute();

  int nx() const { return nx_; }
  int ny() const { return ny_; }
  Vec2 Centre(int i, int j) const { return lo_ + Vec2((i + 0.5) * cell_, (j + 0.5) * cell_); }
  bool CellOf(const Vec2& p, int& i, int& j) const;
  /// Conservative clearance (m) of cell (i, j).
  double Clearance(int i, int j) const { return clearance_[Index(i, j)]; }

 private:
  std::size_t Index(int i, int j) const {
    return static_cast<std::size_t>(j) * static_cast<std::size_t>(nx_) +
           static_cast<std::size_t>(i);
  }
  template <typename Inside>
  void Mark(const Vec2& lo, const Vec2& hi, Inside&& inside);

  Vec2 lo_;
  double cell_;
  int nx_ = 0, ny_ = 0;
  std::vector<char> occupied_;
  std::vector<double> clearance_;
};

/// What a robot can do in a room, from a ClearanceGrid that holds everything around it.
struct RoomWalk {
  bool mouths_connected = false;  ///< every door's mouth reaches every other through the room
  bool no_pockets = false;        ///< all the room's free floor is one region with the mouths
  int free_cells = 0;             ///< cells a robot can stand on with room to spare
};

/// `mouths`: points just inside the room in front of each of its doors. `pass_m`: clearance a
/// robot needs to pass; `stand_m`: clearance counted as free floor.
RoomWalk WalkRoom(const ClearanceGrid& grid,
                  const Polygon& room,
                  const std::vector<Vec2>& mouths,
                  double pass_m,
                  double stand_m);

}  // namespace msgraphs::sim::building
