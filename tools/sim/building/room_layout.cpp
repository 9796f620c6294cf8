// SPDX-License-Identifier: MIT
#include "room_layout.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace msgraphs::sim::building {
namespace {

// Keep-out in front of a door: 0.45 m beyond each jamb, 1.3 m deep past the wall's face, so a
// robot can step through and turn.
constexpr double kZoneSide_m = 0.45;
constexpr double kZoneDepth_m = 1.3;

bool SeparatedOnAxis(const std::vector<Vec2>& a, const std::vector<Vec2>& b, const Vec2& axis) {
  double a0 = 1e18, a1 = -1e18, b0 = 1e18, b1 = -1e18;
  for (const Vec2& p : a) {
    a0 = std::min(a0, p.dot(axis));
    a1 = std::max(a1, p.dot(axis));
  }
  for (const Vec2& p : b) {
    b0 = std::min(b0, p.dot(axis));
    b1 = std::max(b1, p.dot(axis));
  }
  return a1 <= b0 || b1 <= a0;
}

// Convex quadrilaterals overlap unless an edge normal separates them.
bool Overlap(const std::vector<Vec2>& a, const std::vector<Vec2>& b) {
  for (const auto* poly : {&a, &b}) {
    for (std::size_t i = 0; i < poly->size(); ++i) {
      const Vec2 e = (*poly)[(i + 1) % poly->size()] - (*poly)[i];
      if (SeparatedOnAxis(a, b, Vec2(-e.y(), e.x()))) return false;
    }
  }
  return true;
}

std::vector<Vec2> ZoneCorners(const DoorZone& z) {
  const Vec2 along(-z.into_room.y(), z.into_room.x());
  const double half = 0.5 * z.width_m + kZoneSide_m;
  const double depth = 0.5 * z.wall_thickness_m + kZoneDepth_m;
  return {z.centre - along * half, z.centre + along * half,
          z.centre + along * half + z.into_room * depth,
          z.centre - along * half + z.into_room * depth};
}

}  // namespace

std::vector<Vec2> Corners(const Item& item, double grow_m) {
  const Vec2 ax(std::cos(item.yaw_rad), std::sin(item.yaw_rad)), ay(-ax.y(), ax.x());
  const double hx = 0.5 * item.size_x_m + grow_m, hy = 0.5 * item.size_y_m + grow_m;
  return {item.centre - ax * hx - ay * hy, item.centre + ax * hx - ay * hy,
          item.centre + ax * hx + ay * hy, item.centre - ax * hx + ay * hy};
}

RoomLayout::RoomLayout(const Polygon& room,
                       const std::vector<DoorZone>& doors,
                       double face_offset_m)
    : room_(room), doors_(doors), face_(face_offset_m) {
  int longest = 0;
  for (int e = 1; e < edges(); ++e) {
    if (edge_length(e) > edge_length(longest) + 1e-9) longest = e;
  }
  u_ = (room_[static_cast<std::size_t>(longest + 1) % room_.size()] -
        room_[static_cast<std::size_t>(longest)])
           .normalized();
  v_ = Vec2(-u_.y(), u_.x());
  double a0 = 1e18, a1 = -1e18, b0 = 1e18, b1 = -1e18;
  for (const Vec2& p : room_) {
    a0 = std::min(a0, p.dot(u_));
    a1 = std::max(a1, p.dot(u_));
    b0 = std::min(b0, p.dot(v_));
    b1 = std::max(b1, p.dot(v_));
  }
  origin_ = u_ * a0 + v_ * b0;
  extent_u_ = a1 - a0;
  extent_v_ = b1 - b0;
  area_ = std::fabs(SignedArea(room_));
}

double RoomLayout::yaw_u() const { return std::atan2(u_.y(), u_.x()); }

double RoomLayout::edge_length(int e) const {
  return (room_[static_cast<std::size_t>(e + 1) % room_.size()] -
          room_[static_cast<std::size_t>(e)])
      .norm();
}

bool RoomLayout::Fits(const Item& item, double gap_m) const {
  const auto corners = Corners(item);
  for (const Vec2& c : corners) {
    if (!Inside(room_, c)) return false;
  }
  // Clear of every wall's face (the back of a wall item touches it, hence the tolerance), and
  // no reflex corner of the room poking into the footprint.
  const auto past_face = Corners(item, face_ - 1e-6);
  for (std::size_t i = 0; i < room_.size(); ++i) {
    const Vec2& a = room_[i];
    const Vec2& b = room_[(i + 1) % room_.size()];
    for (const Vec2& c : corners) {
      if (SegmentDistance(c, a, b) < face_ - 1e-6) return false;
    }
    if (Inside(past_face, a)) return false;
  }
  for (const DoorZone& z : doors_) {
    if (Overlap(Corners(item), ZoneCorners(z))) return false;
  }
  const auto grown = Corners(item, gap_m);
  for (const Item& other : items_) {
    if (Overlap(grown, Corners(other))) return false;
  }
  return true;
}

bool RoomLayout::AgainstWall(
    int e, double along, double width_m, double depth_m, double height_m, Material m) {
  const Vec2& a = room_[static_cast<std::size_t>(e)];
  const Vec2& b = room_[static_cast<std::size_t>(e + 1) % room_.size()];
  const Vec2 d = (b - a).normalized(), in(-d.y(), d.x());
  Item item;
  item.centre = a + d * along + in * (face_ + 0.5 * depth_m + 1e-4);
  item.yaw_rad = std::atan2(d.y(), d.x());
  item.size_x_m = width_m;
  item.size_y_m = depth_m;
  item.height_m = height_m;
  item.material = m;
  if (!Fits(item, 0.05)) return false;
  items_.push_back(item);
  return true;
}

bool RoomLayout::AgainstSomeWall(
    Random& rng, double width_m, double depth_m, double height_m, Material m, int tries) {
  for (int t = 0; t < tries; ++t) {
    const int e = rng.Index(edges());
    const double length = edge_length(e);
    if (length < width_m + 2 * face_) continue;
    const double along = rng.Uniform(face_ + 0.5 * width_m, length - face_ - 0.5 * width_m);
    if (AgainstWall(e, along, width_m, depth_m, height_m, m)) return true;
  }
  return false;
}

bool RoomLayout::Free(const Vec2& centre,
                      double yaw_rad,
                      double size_x_m,
                      double size_y_m,
                      double height_m,
                      Material m,
                      double gap_m) {
  Item item;
  item.centre = centre;
  item.yaw_rad = yaw_rad;
  item.size_x_m = size_x_m;
  item.size_y_m = size_y_m;
  item.height_m = height_m;
  item.material = m;
  if (!Fits(item, gap_m)) return false;
  items_.push_back(item);
  return true;
}

bool RoomLayout::Round(
    const Vec2& centre, double radius_m, double height_m, Material m, double gap_m) {
  Item item;
  item.round = true;
  item.centre = centre;
  item.size_x_m = item.size_y_m = 2 * radius_m;
  item.height_m = height_m;
  item.material = m;
  if (!Fits(item, gap_m)) return false;
  items_.push_back(item);
  return true;
}

bool RoomLayout::FreeSomewhere(
    Random& rng, double size_x_m, double size_y_m, double height_m, Material m, int tries) {
  for (int t = 0; t < tries; ++t) {
    const Vec2 c = At(rng.Uniform(0, extent_u_), rng.Uniform(0, extent_v_));
    // Mostly square to the room, sometimes askew (a dropped pallet).
    const double yaw = yaw_u() + (rng.Chance(0.7) ? 0.5 * std::numbers::pi * rng.Index(2)
                                                  : rng.Uniform(0, std::numbers::pi));
    if (Free(c, yaw, size_x_m, size_y_m, height_m, m, 0.6)) return true;
  }
  return false;
}

}  // namespace msgraphs::sim::building
