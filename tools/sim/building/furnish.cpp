// SPDX-License-Identifier: MIT
#include "furnish.hpp"

#include <algorithm>
#include <cmath>

#include "clearance.hpp"
#include "furniture_sets.hpp"

namespace msgraphs::sim::building {
namespace {

constexpr std::uint64_t kFurnishStream = 0x6675726E;  // "furn"
constexpr double kCell_m = 0.1;
constexpr double kMouthDepth_m = 0.5;  // past the wall's face

struct RoomDoors {
  std::vector<DoorZone> zones;
  std::vector<Vec2> mouths;
};

RoomDoors DoorsOf(int room,
                  const std::vector<PlanWall>& walls,
                  const std::vector<PlacedDoor>& doors) {
  RoomDoors out;
  for (const PlacedDoor& d : doors) {
    if (d.a != room && d.b != room) continue;
    const Vec2 in = d.a == room ? d.into_a : Vec2(-d.into_a);
    const double t = walls[static_cast<std::size_t>(d.wall)].wall.thickness_m;
    out.zones.push_back({d.centre, in, d.width_m, t});
    out.mouths.push_back(d.centre + in * (0.5 * t + kMouthDepth_m));
  }
  return out;
}

void Bounds(const std::vector<Vec2>& points, Vec2& lo, Vec2& hi) {
  for (const Vec2& p : points) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
}

void AddItem(ClearanceGrid& grid, const Item& item) {
  if (item.round) {
    grid.AddCircle(item.centre, 0.5 * item.size_x_m);
  } else {
    grid.AddRectangle(item.centre, item.yaw_rad, 0.5 * item.size_x_m, 0.5 * item.size_y_m);
  }
}

struct Check {
  bool ok = false;
  bool roomy = false;  // some floor a planner could count as free
};

Check WalkCheck(const Polygon& room,
                const RoomDoors& doors,
                const std::vector<PlanWall>& walls,
                const std::vector<Item>& placed,
                const std::vector<Item>& items) {
  // Footprints farther than this outside the room cannot bring a cell in it below the
  // clearances tested (0.55 m at most).
  constexpr double kMargin_m = 0.7;
  Vec2 lo(1e18, 1e18), hi(-1e18, -1e18);
  Bounds(room, lo, hi);
  lo -= Vec2(kMargin_m, kMargin_m);
  hi += Vec2(kMargin_m, kMargin_m);
  ClearanceGrid grid(lo, hi, kCell_m);
  auto near = [&](const std::vector<Vec2>& pts, double grow) {
    Vec2 a(1e18, 1e18), b(-1e18, -1e18);
    Bounds(pts, a, b);
    return a.x() - grow <= hi.x() && b.x() + grow >= lo.x() && a.y() - grow <= hi.y() &&
           b.y() + grow >= lo.y();
  };
  for (const PlanWall& w : walls) {
    if (near({w.wall.start, w.wall.end}, w.wall.thickness_m)) grid.AddWall(w.wall);
  }
  for (const auto* list : {&placed, &items}) {
    for (const Item& item : *list) {
      if (near(Corners(item), 0.0)) AddItem(grid, item);
    }
  }
  grid.Compute();
  const RoomWalk walk = WalkRoom(grid, room, doors.mouths, kPassClearance_m, kStandClearance_m);
  Check check;
  check.ok = walk.mouths_connected && walk.no_pockets;
  // A cell at pass + 1 cm could truly have the planner's 0.55 m (the estimate is up to 0.14 m
  // low): such a room counts as walkable for the planner.
  for (int j = 0; j < grid.ny() && !check.roomy; ++j) {
    for (int i = 0; i < grid.nx() && !check.roomy; ++i) {
      check.roomy =
          grid.Clearance(i, j) >= kPassClearance_m + 0.01 && Inside(room, grid.Centre(i, j));
    }
  }
  return check;
}

// Right angles only, and every edge at least 1.9 m long.
bool Rectilinear(const Polygon& p) {
  for (std::size_t i = 0; i < p.size(); ++i) {
    const Vec2 a = p[(i + 1) % p.size()] - p[i], b = p[(i + 2) % p.size()] - p[(i + 1) % p.size()];
    if (a.norm() < 1.9 || std::fabs(a.normalized().dot(b.normalized())) > 1e-6) return false;
  }
  return true;
}

Item Mapped(const Item& item, const Affine2& T) {
  Item out = item;
  out.centre = T(item.centre);
  out.yaw_rad = T.MapAngle(item.yaw_rad);
  return out;
}

}  // namespace

std::vector<std::vector<Item>> Furnish(const Plan& plan,
                                       const std::vector<PlanWall>& walls,
                                       const std::vector<PlacedDoor>& doors,
                                       double amount,
                                       std::uint64_t seed,
                                       FurnishReport& report) {
  const std::size_t n = plan.rooms.size();
  std::vector<std::vector<Item>> per_room(n);
  std::vector<Item> placed;
  const double face =
      0.5 * std::max(plan.walls.exterior_thickness_m, plan.walls.interior_thickness_m) + 0.03;

  auto furnish_original = [&](std::size_t r) {
    const PlanRoom& room = plan.rooms[r];
    const RoomDoors rd = DoorsOf(static_cast<int>(r), walls, doors);
    RoomLayout layout(room.polygon, rd.zones, face);
    Random rng = Random::Stream(seed, kFurnishStream, r);
    FurnishRoom(layout, room.use, amount, plan.ceiling_m, rng);
    // Columns where the furniture leaves room for them (rack rows stay whole).
    if (room.column_spacing_m > 0 && amount > 0) {
      PlaceColumns(layout, room.column_spacing_m, room.column_radius_m, plan.ceiling_m,
                   room.square_columns);
    }
    std::vector<Item> items = layout.items();
    // An empty room with right-angled corners and no part narrower than 1.9 m is walkable by
    // construction; everything else is checked.
    if (items.empty() && Rectilinear(room.polygon)) return items;
    if (WalkCheck(room.polygon, rd, walls, placed, items).ok) return items;
    // Keep the longest walkable prefix of the items (placed in order of importance).
    std::size_t lo = 0, hi = items.size();  // prefix lo passes (or is empty), hi fails
    const auto prefix = [&](std::size_t k) {
      return std::vector<Item>(items.begin(), items.begin() + static_cast<std::ptrdiff_t>(k));
    };
    const Check empty = WalkCheck(room.polygon, rd, walls, placed, {});
    if (!empty.ok) {
      if (empty.roomy) report.unwalkable_rooms.push_back(static_cast<int>(r));
      report.removed_items += static_cast<int>(items.size());
      return std::vector<Item>{};
    }
    while (hi - lo > 1) {
      const std::size_t mid = (lo + hi) / 2;
      (WalkCheck(room.polygon, rd, walls, placed, prefix(mid)).ok ? lo : hi) = mid;
    }
    report.removed_items += static_cast<int>(items.size() - lo);
    return prefix(lo);
  };

  // Originals in room order, then copies (their originals are furnished by then).
  for (int pass = 0; pass < 2; ++pass) {
    for (std::size_t r = 0; r < n; ++r) {
      const PlanRoom& room = plan.rooms[r];
      if ((room.copy_of >= 0) != (pass == 1)) continue;
      std::vector<Item> items;
      if (room.copy_of >= 0) {
        for (const Item& item : per_room[static_cast<std::size_t>(room.copy_of)])
          items.push_back(Mapped(item, room.copy_map));
        const RoomDoors rd = DoorsOf(static_cast<int>(r), walls, doors);
        if (!WalkCheck(room.polygon, rd, walls, placed, items).ok) {
          report.broken_copies.push_back(static_cast<int>(r));
          items = furnish_original(r);
        }
      } else {
        items = furnish_original(r);
      }
      placed.insert(placed.end(), items.begin(), items.end());
      per_room[r] = std::move(items);
    }
  }
  return per_room;
}

}  // namespace msgraphs::sim::building
