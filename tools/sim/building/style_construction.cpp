// SPDX-License-Identifier: MIT
// A construction site floor: a rectangular or L-shaped shell split into large bare concrete
// rooms and halls, wide openings mostly without lintels, columns, pallets and stacks.
#include <algorithm>
#include <cmath>

#include "style_common.hpp"

namespace msgraphs::sim::building {
namespace {

// Splits r in two across its longer side (mostly) until rooms are small enough or too narrow
// to split again; cut positions on a 0.5 m grid.
void Split(const Rect& r, Random& rng, double min_side, double stop_area, std::vector<Rect>& out) {
  const bool can_x = r.width() >= 2 * min_side, can_y = r.height() >= 2 * min_side;
  if ((!can_x && !can_y) || (r.width() * r.height() < stop_area && rng.Chance(0.7))) {
    out.push_back(r);
    return;
  }
  bool along_x = can_x && (!can_y || (r.width() >= r.height() ? rng.Chance(0.8) : rng.Chance(0.2)));
  const double lo = along_x ? r.x0 : r.y0, len = along_x ? r.width() : r.height();
  double cut = std::round((lo + len * rng.Uniform(0.35, 0.65)) * 2.0) / 2.0;
  cut = std::clamp(cut, lo + min_side, lo + len - min_side);
  if (along_x) {
    Split({r.x0, r.y0, cut, r.y1}, rng, min_side, stop_area, out);
    Split({cut, r.y0, r.x1, r.y1}, rng, min_side, stop_area, out);
  } else {
    Split({r.x0, r.y0, r.x1, cut}, rng, min_side, stop_area, out);
    Split({r.x0, cut, r.x1, r.y1}, rng, min_side, stop_area, out);
  }
}

// Length of the edge two rectangles share (0: none).
double Shared(const Rect& a, const Rect& b) {
  auto overlap = [](double a0, double a1, double b0, double b1) {
    return std::min(a1, b1) - std::max(a0, b0);
  };
  if (std::fabs(a.x1 - b.x0) < 1e-6 || std::fabs(b.x1 - a.x0) < 1e-6)
    return std::max(0.0, overlap(a.y0, a.y1, b.y0, b.y1));
  if (std::fabs(a.y1 - b.y0) < 1e-6 || std::fabs(b.y1 - a.y0) < 1e-6)
    return std::max(0.0, overlap(a.x0, a.x1, b.x0, b.x1));
  return 0;
}

}  // namespace

bool BuildConstruction(const Choices& c, Random& rng, Plan& plan, std::string& error) {
  plan.name = "construction site";
  static constexpr double kThickness[] = {0.2, 0.25, 0.3};
  static constexpr double kMinSide[] = {5.0, 6.0, 7.5};
  static constexpr double kColumnSpacing[] = {5.0, 6.0, 7.5};
  const double t = Pick(rng, kThickness);
  plan.walls.exterior_thickness_m = 0.3;
  plan.walls.interior_thickness_m = t;
  plan.walls.exterior_material = plan.walls.interior_material = Material::kConcrete;
  plan.ceiling_m = c.ceiling_m;
  plan.corridor = CorridorShape::kNone;

  const double k = c.scale;
  const double W = std::round(std::max(20.0, rng.Uniform(24, 60) * k) * 2) / 2;
  const double H = std::round(std::max(15.0, rng.Uniform(16, 40) * k) * 2) / 2;
  // The shell: a rectangle, or an L (one corner left out), as two rectangles.
  std::vector<Rect> shell;
  if (rng.Chance(0.4)) {
    const double cx = std::round(W * rng.Uniform(0.45, 0.65) * 2) / 2,
                 cy = std::round(H * rng.Uniform(0.45, 0.65) * 2) / 2;
    shell = {{0, 0, W, cy}, {0, cy, cx, H}};
  } else {
    shell = {{0, 0, W, H}};
  }
  const double min_side = Pick(rng, kMinSide);
  const double stop_area = rng.Uniform(80, 260);
  std::vector<Rect> rooms;
  for (const Rect& r : shell) Split(r, rng, min_side, stop_area, rooms);
  PlanBuilder b(plan, Affine2());
  std::vector<int> ids;
  for (const Rect& r : rooms) {
    const int id = b.Room(RoomUse::kBare, r);
    PlanRoom& room = plan.rooms[static_cast<std::size_t>(id)];
    if (r.width() * r.height() >= 50 && rng.Chance(0.7)) {
      room.column_spacing_m = Pick(rng, kColumnSpacing);
      room.square_columns = rng.Chance(0.3);
      room.column_radius_m = room.square_columns ? 0.2 : SnapCm(rng.Uniform(0.2, 0.3));
    }
    ids.push_back(id);
  }
  // Openings: a random spanning tree over rooms sharing at least 3 m of wall, then a few more.
  const std::size_t n = rooms.size();
  std::vector<bool> in_tree(n, false);
  in_tree[0] = true;
  for (std::size_t added = 1; added < n;) {
    std::vector<std::pair<std::size_t, std::size_t>> frontier;
    for (std::size_t a = 0; a < n; ++a) {
      for (std::size_t z = 0; z < n; ++z) {
        if (in_tree[a] && !in_tree[z] && Shared(rooms[a], rooms[z]) >= 3.0)
          frontier.emplace_back(a, z);
      }
    }
    if (frontier.empty()) break;  // the door placer's ConnectAll takes over
    const auto [a, z] =
        frontier[static_cast<std::size_t>(rng.Index(static_cast<int>(frontier.size())))];
    b.Connect(ids[a], ids[z], DrawDoor(rng, DoorKind::kWide, 0.7));
    in_tree[z] = true;
    ++added;
  }
  for (std::size_t a = 0; a < n; ++a) {
    for (std::size_t z = a + 1; z < n; ++z) {
      if (Shared(rooms[a], rooms[z]) >= 4.0 && rng.Chance(0.25))
        b.Connect(ids[a], ids[z], DrawDoor(rng, DoorKind::kWide, 0.7));
    }
  }
  (void)error;
  return true;
}

}  // namespace msgraphs::sim::building
