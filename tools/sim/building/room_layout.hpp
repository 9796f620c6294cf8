// SPDX-License-Identifier: MIT
// Furniture placement inside one room: items against a wall (back to the wall's face) or
// free-standing, never overlapping each other, outside the room or in front of a door.
#pragma once

#include <vector>

#include "geometry.hpp"
#include "random.hpp"
#include "world.hpp"

namespace msgraphs::sim::building {

struct Item {
  bool round = false;
  Vec2 centre = Vec2::Zero();
  double yaw_rad = 0;
  double size_x_m = 1, size_y_m = 1;  ///< round: the diameter twice
  double height_m = 1;
  Material material = Material::kWood;
};

/// A keep-out in front of a door: the door's span widened, from the wall into the room.
struct DoorZone {
  Vec2 centre;     ///< on the wall's centre line
  Vec2 into_room;  ///< unit
  double width_m;
  double wall_thickness_m;
};

class RoomLayout {
 public:
  /// `face_offset_m`: distance from a wall's centre line to where furniture may start.
  RoomLayout(const Polygon& room, const std::vector<DoorZone>& doors, double face_offset_m);

  /// The room's frame: its longest edge's direction u, v = u turned left, and the extent of
  /// the room along them from `origin` (the minimum corner in that frame).
  const Vec2& u() const { return u_; }
  const Vec2& v() const { return v_; }
  const Vec2& origin() const { return origin_; }
  double extent_u() const { return extent_u_; }
  double extent_v() const { return extent_v_; }
  Vec2 At(double a, double b) const { return origin_ + u_ * a + v_ * b; }
  double yaw_u() const;
  double area() const { return area_; }
  const Polygon& polygon() const { return room_; }
  double face_offset() const { return face_; }
  int edges() const { return static_cast<int>(room_.size()); }
  double edge_length(int e) const;

  /// An item with its back against edge `e`, its centre `along` metres from the edge's start
  /// (width along the wall, depth into the room). True when it fits and was added.
  bool AgainstWall(
      int e, double along, double width_m, double depth_m, double height_m, Material m);
  /// Against a random edge at a random place; `tries` attempts.
  bool AgainstSomeWall(
      Random& rng, double width_m, double depth_m, double height_m, Material m, int tries = 8);
  bool Free(const Vec2& centre,
            double yaw_rad,
            double size_x_m,
            double size_y_m,
            double height_m,
            Material m,
            double gap_m = 0.05);
  bool Round(const Vec2& centre, double radius_m, double height_m, Material m, double gap_m = 0.05);
  /// A random free spot for a free-standing item.
  bool FreeSomewhere(
      Random& rng, double size_x_m, double size_y_m, double height_m, Material m, int tries = 8);

  const std::vector<Item>& items() const { return items_; }
  void PopItem() { items_.pop_back(); }

 private:
  bool Fits(const Item& item, double gap_m) const;

  Polygon room_;
  std::vector<DoorZone> doors_;
  double face_;
  Vec2 u_, v_, origin_;
  double extent_u_ = 0, extent_v_ = 0, area_ = 0;
  std::vector<Item> items_;
};

/// The four corners of an item's footprint (a round item: its bounding square).
std::vector<Vec2> Corners(const Item& item, double grow_m = 0.0);

}  // namespace msgraphs::sim::building
