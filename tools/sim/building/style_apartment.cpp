// SPDX-License-Identifier: MIT
// An apartment block: flats along a corridor, each a small hallway at its entrance, a bath,
// a WC or a closet (down to 2 x 2 m) and a kitchen at the front, a living room and bedrooms
// behind; sometimes an open kitchen makes the living room L-shaped. Identical flats repeat
// one layout (same rooms, doors and furniture).
#include <algorithm>
#include <cmath>

#include "style_common.hpp"

namespace msgraphs::sim::building {
namespace {

struct UnitRoom {
  std::vector<Rect> parts;  // x: along the strip from the flat's start, y: depth from the front
  RoomUse use;
};

struct Unit {
  std::vector<UnitRoom> rooms;
  int entrance = 0;
  std::vector<std::pair<int, int>> doors;  // rooms joined (BFS tree from the entrance)
};

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

// Widths of pieces of at least `min_m` summing to `total`, drawn from `sizes`.
std::vector<double> Split(Random& rng,
                          double total,
                          double min_m,
                          const std::vector<double>& sizes) {
  std::vector<double> out;
  double rest = total;
  while (rest > 1e-6) {
    double piece = sizes[static_cast<std::size_t>(rng.Index(static_cast<int>(sizes.size())))];
    if (rest - piece < min_m) piece = rest;
    out.push_back(SnapCm(piece));
    rest = SnapCm(rest - piece);
  }
  return out;
}

// A flat `width` wide and `depth` deep whose front faces the corridor over [f_lo, f_hi].
Unit DrawUnit(Random& rng, double width, double depth, double f_lo, double f_hi) {
  static constexpr double kFront[] = {2.0, 2.2, 2.4, 2.6, 3.0};
  static constexpr double kHall[] = {2.0, 2.2, 2.4};
  Unit u;
  const double df = Pick(rng, kFront);
  // Front: hallway, wet rooms and the kitchen.
  const double hall = Pick(rng, kHall);
  std::vector<double> front = Split(rng, width - hall, 2.0, {2.0, 2.2, 2.4, 2.6});
  // The hallway goes where it faces the corridor.
  std::vector<int> spots;
  for (std::size_t i = 0; i <= front.size(); ++i) spots.push_back(static_cast<int>(i));
  for (std::size_t i = spots.size() - 1; i > 0; --i)
    std::swap(spots[i], spots[static_cast<std::size_t>(rng.Index(static_cast<int>(i + 1)))]);
  int at = spots[0];
  for (int s : spots) {
    double x = 0;
    for (int i = 0; i < s; ++i) x += front[static_cast<std::size_t>(i)];
    if (x >= f_lo - 1e-6 && x + hall <= f_hi + 1e-6) {
      at = s;
      break;
    }
  }
  front.insert(front.begin() + at, hall);
  double x = 0;
  bool kitchen = false;
  for (std::size_t i = 0; i < front.size(); ++i) {
    RoomUse use = RoomUse::kHallway;
    if (static_cast<int>(i) == at) {
      u.entrance = static_cast<int>(u.rooms.size());
    } else if (front[i] >= 2.6 && !kitchen) {
      use = RoomUse::kKitchen;
      kitchen = true;
    } else {
      const double p = rng.Uniform();
      use = p < 0.45 ? RoomUse::kBath : p < 0.8 ? RoomUse::kWc : RoomUse::kStorage;
    }
    // The last piece ends exactly at the flat's side (its width need not be on the cm grid).
    const double x1 = i + 1 == front.size() ? width : SnapCm(x + front[i]);
    u.rooms.push_back({{Rect{x, 0, x1, df}}, use});
    x = x1;
  }
  // Back: a living room and bedrooms.
  const int back_rooms = width < 6.6 ? 1 : width < 9.6 ? 2 : 3;
  std::vector<double> back;
  for (int k = 0; k < back_rooms; ++k) back.push_back(width / back_rooms);
  if (back_rooms > 1) {
    const double shift = SnapCm(rng.Uniform(-0.6, 0.6));
    back[0] = SnapCm(back[0] + shift);
    back[1] = SnapCm(back[1] - shift);
  }
  const int living = rng.Index(back_rooms);
  x = 0;
  const std::size_t first_back = u.rooms.size();
  for (int k = 0; k < back_rooms; ++k) {
    const double x1 = k + 1 == back_rooms ? width : SnapCm(x + back[static_cast<std::size_t>(k)]);
    u.rooms.push_back(
        {{Rect{SnapCm(x), df, x1, depth}}, k == living ? RoomUse::kLiving : RoomUse::kBedroom});
    x = x1;
  }
  // An open kitchen: the kitchen joins the living room behind it when flush with one of its
  // sides (the union is then an L).
  if (rng.Chance(0.35)) {
    for (std::size_t i = 0; i < first_back; ++i) {
      if (u.rooms[i].use != RoomUse::kKitchen) continue;
      UnitRoom& liv = u.rooms[first_back + static_cast<std::size_t>(living)];
      const Rect& kr = u.rooms[i].parts[0];
      const Rect& lr = liv.parts[0];
      const bool flush = std::fabs(kr.x0 - lr.x0) < 1e-6 || std::fabs(kr.x1 - lr.x1) < 1e-6;
      if (flush && kr.x0 >= lr.x0 - 1e-6 && kr.x1 <= lr.x1 + 1e-6 &&
          kr.width() < lr.width() - 1.0) {
        liv.parts.push_back(kr);
        u.rooms.erase(u.rooms.begin() + static_cast<std::ptrdiff_t>(i));
        if (u.entrance > static_cast<int>(i)) --u.entrance;
      }
      break;
    }
  }
  // Doors: a tree from the hallway over rooms sharing at least 1.3 m of wall.
  const std::size_t n = u.rooms.size();
  std::vector<bool> seen(n, false);
  std::vector<int> queue{u.entrance};
  seen[static_cast<std::size_t>(u.entrance)] = true;
  for (std::size_t q = 0; q < queue.size(); ++q) {
    const auto r = static_cast<std::size_t>(queue[q]);
    for (std::size_t o = 0; o < n; ++o) {
      if (seen[o]) continue;
      double shared = 0;
      for (const Rect& a : u.rooms[r].parts) {
        for (const Rect& b : u.rooms[o].parts) shared = std::max(shared, Shared(a, b));
      }
      if (shared < 1.3) continue;
      seen[o] = true;
      queue.push_back(static_cast<int>(o));
      u.doors.emplace_back(static_cast<int>(r), static_cast<int>(o));
    }
  }
  return u;
}

}  // namespace

bool BuildApartment(const Choices& c, Random& rng, Plan& plan, std::string& error) {
  static constexpr double kCorridor[] = {1.5, 1.6, 1.8};
  static constexpr double kUnit[] = {6.6, 7.2, 8.0, 9.0};
  plan.name = "apartment block";
  plan.walls.exterior_thickness_m = SnapCm(rng.Uniform(0.25, 0.35));
  plan.walls.interior_thickness_m = 0.1;
  plan.ceiling_m = c.ceiling_m;
  plan.corridor = c.corridor;

  CorridorSpec spec;
  spec.shape = c.corridor;
  spec.width_m = Pick(rng, kCorridor);
  const double depth = SnapCm(rng.Uniform(6.5, 9.0));
  spec.depth_s_m = spec.depth_n_m = spec.depth_e_m = spec.depth_w_m = depth;
  const double k = c.scale;
  auto len = [&](double lo, double hi) { return SnapCm(std::max(lo, rng.Uniform(lo, hi) * k)); };
  switch (c.corridor) {
    case CorridorShape::kL:
      spec.length_m = len(depth + 7, 20);
      spec.arm_m = len(depth + 7, 16);
      break;
    case CorridorShape::kT:
      spec.length_m = len(2 * depth + spec.width_m + 14, 32);
      spec.branch_at_m = SnapCm(rng.Uniform(depth + 7, spec.length_m - spec.width_m - depth - 7));
      spec.arm_m = len(depth + 7, 14);
      break;
    default:
      spec.shape = CorridorShape::kStraight;
      plan.corridor = CorridorShape::kStraight;
      spec.length_m = len(12, 28);
  }
  const CorridorLayout layout = LayoutCorridors(spec);
  PlanBuilder b(plan, Affine2());
  AddCorridors(b, layout, rng, 0.2);
  const double identical = c.identical_rows() ? Pick(rng, kUnit) : 0.0;
  for (const Strip& s : layout.strips) {
    int first = -1, count = 0;
    std::vector<std::pair<double, double>> cuts;
    if (identical > 0) cuts = CutIdentical(s, identical, 6.0, first, count);
    if (cuts.empty()) {
      cuts = CutStrip(s, rng, 6.6, 9.6, 2.6);
      first = -1;
    }
    Unit original;
    std::vector<int> original_rooms, original_doors;
    double original_a0 = 0;
    std::vector<int> groups;
    for (std::size_t u = 0; u < cuts.size(); ++u) {
      const auto [a0, a1] = cuts[u];
      const bool identical_unit =
          first >= 0 && static_cast<int>(u) >= first && static_cast<int>(u) < first + count;
      const bool copy = identical_unit && !original_rooms.empty();
      const Unit unit = copy ? original : DrawUnit(rng, a1 - a0, s.depth(), s.f0 - a0, s.f1 - a0);
      std::vector<int> ids, door_ids;
      for (const UnitRoom& r : unit.rooms) {
        std::vector<Rect> parts;
        for (const Rect& p : r.parts) parts.push_back(s.Piece(a0 + p.x0, a0 + p.x1, p.y0, p.y1));
        ids.push_back(b.Room(r.use, parts));
      }
      Connection entrance = DrawDoor(rng, DoorKind::kSingle);
      entrance.width_m = std::max(entrance.width_m, 0.9);
      door_ids.push_back(b.Connect(ids[static_cast<std::size_t>(unit.entrance)], -1, entrance));
      for (const auto& [x, y] : unit.doors) {
        Connection d = DrawDoor(rng, DoorKind::kSingle);
        d.width_m = std::min(d.width_m, 0.9);
        door_ids.push_back(
            b.Connect(ids[static_cast<std::size_t>(x)], ids[static_cast<std::size_t>(y)], d));
      }
      if (!identical_unit) continue;
      if (!copy) {
        original = unit;
        original_rooms = ids;
        original_doors = door_ids;
        original_a0 = a0;
        for (int id : ids) {
          plan.identical_groups.push_back({id});
          groups.push_back(static_cast<int>(plan.identical_groups.size()) - 1);
          plan.rooms[static_cast<std::size_t>(id)].identical_group = groups.back();
        }
        continue;
      }
      const Affine2 shift =
          Affine2::Translation(b.T().linear * (s.AxisStep() * (a0 - original_a0)));
      for (std::size_t i = 0; i < ids.size(); ++i) {
        PlanRoom& room = plan.rooms[static_cast<std::size_t>(ids[i])];
        room.copy_of = original_rooms[i];
        room.copy_map = shift;
        room.identical_group = groups[i];
        plan.identical_groups[static_cast<std::size_t>(groups[i])].push_back(ids[i]);
      }
      for (std::size_t i = 0; i < door_ids.size(); ++i) {
        Connection& d = plan.connections[static_cast<std::size_t>(door_ids[i])];
        d = plan.connections[static_cast<std::size_t>(original_doors[i])];
        d.a = plan.connections[static_cast<std::size_t>(original_doors[i])].a -
              original_rooms.front() + ids.front();
        if (d.b >= 0) d.b = d.b - original_rooms.front() + ids.front();
        d.follows = original_doors[i];
        d.follow_map = shift;
      }
    }
  }
  (void)error;
  return true;
}

}  // namespace msgraphs::sim::building
