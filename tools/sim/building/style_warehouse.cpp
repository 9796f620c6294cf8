// SPDX-License-Identifier: MIT
// A warehouse: one to three large halls side by side (up to 30 x 40 m) with rows of pallet
// racks and columns, wide openings between them, and a strip of offices along a corridor.
#include <cmath>

#include "style_common.hpp"

namespace msgraphs::sim::building {

bool BuildWarehouse(const Choices& c, Random& rng, Plan& plan, std::string& error) {
  static constexpr double kHallWidth[] = {12, 15, 18, 20, 24, 30};
  static constexpr double kHallDepth[] = {20, 24, 30, 36, 40};
  static constexpr double kCorridor[] = {1.8, 2.0, 2.4};
  plan.name = "warehouse";
  plan.walls.exterior_thickness_m = 0.3;
  plan.walls.interior_thickness_m = 0.2;
  plan.walls.exterior_material = Material::kConcrete;
  plan.walls.interior_material = rng.Chance(0.5) ? Material::kConcrete : Material::kPainted;
  plan.ceiling_m = c.ceiling_m;
  plan.corridor = CorridorShape::kStraight;

  // Halls along x at 0 <= y <= depth; the office strip below them, y < 0.
  const int halls = 1 + rng.Index(3);
  const bool big = rng.Chance(0.15);  // the largest hall the generator makes: 30 x 40 m
  std::vector<Rect> hall_rects;
  double x = 0;
  for (int h = 0; h < halls; ++h) {
    double width = Pick(rng, kHallWidth), depth = Pick(rng, kHallDepth);
    if (h == 0 && big) {
      width = 30;
      depth = 40;
    }
    if (c.scale < 1.0 && !(h == 0 && big)) {
      width = SnapCm(std::max(12.0, width * c.scale));
      depth = SnapCm(std::max(20.0, depth * c.scale));
    }
    hall_rects.push_back({x, 0, x + width, depth});
    x += width;
  }
  const double total = x;
  PlanBuilder b(plan, Affine2());
  std::vector<int> hall_ids;
  for (std::size_t h = 0; h < hall_rects.size(); ++h) {
    const Rect& r = hall_rects[h];
    int id = -1;
    // An annex makes the first hall L-shaped now and then (a loading bay behind it).
    if (h == 0 && rng.Chance(0.3)) {
      const double annex_w = SnapCm(rng.Uniform(0.35, 0.6) * r.width()),
                   annex_d = SnapCm(rng.Uniform(6, 10));
      id = b.Room(RoomUse::kHall, {r, Rect{r.x0, r.y1, r.x0 + annex_w, r.y1 + annex_d}});
    } else {
      id = b.Room(RoomUse::kHall, r);
    }
    PlanRoom& room = plan.rooms[static_cast<std::size_t>(id)];
    if (rng.Chance(0.7)) {
      static constexpr double kSpacing[] = {8.0, 9.0, 10.0, 12.0};
      room.column_spacing_m = Pick(rng, kSpacing);
      room.square_columns = rng.Chance(0.5);
      room.column_radius_m = room.square_columns ? 0.2 : 0.25;
    }
    hall_ids.push_back(id);
    if (h > 0) {
      b.Connect(hall_ids[h - 1], id, DrawDoor(rng, DoorKind::kWide, 0.6));
      if (rng.Chance(0.4)) b.Connect(hall_ids[h - 1], id, DrawDoor(rng, DoorKind::kWide, 0.6));
    }
  }
  // Offices: a corridor along the halls' south side over part of their length, one row below.
  const double w = Pick(rng, kCorridor);
  const double strip_len = SnapCm(std::max(std::min(12.0, total), rng.Uniform(0.4, 1.0) * total));
  const double depth = SnapCm(rng.Uniform(4.0, 6.0));
  const int corridor = b.Room(RoomUse::kCorridor, Rect{0, -w, strip_len, 0});
  for (std::size_t h = 0; h < hall_rects.size(); ++h) {
    if (hall_rects[h].x0 < strip_len - 3.0)
      b.Connect(hall_ids[h], corridor, DrawDoor(rng, DoorKind::kWide, 0.5));
  }
  const Strip offices{{0, -w - depth, strip_len, -w}, 2, 0, strip_len};
  RoomRecipe recipe;
  recipe.min_width_m = 3.0;
  recipe.max_width_m = 5.0;
  recipe.use = [](Random& r, double width, double) {
    if (width < 3.2) return r.Chance(0.5) ? RoomUse::kWc : RoomUse::kStorage;
    return r.Chance(0.7) ? RoomUse::kOffice
                         : (r.Chance(0.5) ? RoomUse::kMeeting : RoomUse::kStorage);
  };
  FillStrip(b, offices, recipe, rng, 0.0);
  (void)error;
  return true;
}

}  // namespace msgraphs::sim::building
