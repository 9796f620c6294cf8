// SPDX-License-Identifier: MIT
#include "style_common.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>

namespace msgraphs::sim::building {

std::vector<int> AddCorridors(PlanBuilder& b,
                              const CorridorLayout& layout,
                              Random& rng,
                              double no_lintel_chance) {
  std::vector<int> ids;
  for (const auto& rects : layout.corridors) ids.push_back(b.Room(RoomUse::kCorridor, rects));
  for (const auto& [i, j] : layout.joints) {
    b.Connect(ids[static_cast<std::size_t>(i)], ids[static_cast<std::size_t>(j)],
              DrawDoor(rng, DoorKind::kOpening, no_lintel_chance));
  }
  return ids;
}

void FillStrip(PlanBuilder& b,
               const Strip& s,
               const RoomRecipe& recipe,
               Random& rng,
               double identical_width_m) {
  int first = -1, count = 0;
  std::vector<std::pair<double, double>> cuts;
  if (identical_width_m > 0)
    cuts = CutIdentical(s, identical_width_m, recipe.min_width_m, first, count);
  if (cuts.empty()) {
    cuts = CutStrip(s, rng, recipe.min_width_m, recipe.max_width_m);
    first = -1;
  }
  Plan& plan = b.plan();
  const double depth = s.depth();
  // The first identical room is the original; the others copy it, shifted along the strip.
  struct Original {
    int room = -1, bath = -1, door = -1, bath_door = -1;
    double a0 = 0;
    RoomUse use = RoomUse::kOffice;
    Connection door_spec, bath_spec;
  } original;
  int group = -1, bath_group = -1;
  for (std::size_t k = 0; k < cuts.size(); ++k) {
    const auto [a0, a1] = cuts[k];
    const bool identical =
        first >= 0 && static_cast<int>(k) >= first && static_cast<int>(k) < first + count;
    const bool copy = identical && original.room >= 0;
    const RoomUse use = copy ? original.use : recipe.use(rng, a1 - a0, depth);
    const Connection door =
        copy ? original.door_spec : DrawDoor(rng, recipe.door, recipe.no_lintel_chance);
    Connection bath_door = copy ? original.bath_spec : DrawDoor(rng, DoorKind::kSingle);
    bath_door.width_m = std::min(bath_door.width_m, 0.9);
    const double ba = recipe.bath_along_m, bd = recipe.bath_depth_m;
    // (copies decide as their original did: widths on the 1 cm grid may differ by rounding)
    const bool bath = copy ? original.bath >= 0
                           : ba > 0 && use == RoomUse::kPatient && a1 - a0 >= ba + 2.0 - 1e-6 &&
                                 depth >= bd + 2.5 - 1e-6;
    int room = -1, bath_room = -1;
    if (bath) {
      room = b.Room(use, {s.Piece(a0 + ba, a1, 0, bd), s.Piece(a0, a1, bd, depth)});
      bath_room = b.Room(RoomUse::kBath, s.Piece(a0, a0 + ba, 0, bd));
    } else {
      room = b.Room(use, s.Piece(a0, a1, 0, depth));
    }
    const int c = b.Connect(room, -1, door);
    const int cb = bath ? b.Connect(bath_room, room, bath_door) : -1;
    if (!identical) continue;
    if (!copy) {
      original = {room, bath_room, c, cb, a0, use, door, bath_door};
      plan.identical_groups.push_back({room});
      group = static_cast<int>(plan.identical_groups.size()) - 1;
      plan.rooms[static_cast<std::size_t>(room)].identical_group = group;
      if (bath) {
        plan.identical_groups.push_back({bath_room});
        bath_group = static_cast<int>(plan.identical_groups.size()) - 1;
        plan.rooms[static_cast<std::size_t>(bath_room)].identical_group = bath_group;
      }
      continue;
    }
    const Affine2 shift = Affine2::Translation(b.T().linear * (s.AxisStep() * (a0 - original.a0)));
    auto mark = [&](int r, int of, int g, int conn, int conn_of) {
      PlanRoom& pr = plan.rooms[static_cast<std::size_t>(r)];
      pr.copy_of = of;
      pr.copy_map = shift;
      pr.identical_group = g;
      plan.identical_groups[static_cast<std::size_t>(g)].push_back(r);
      plan.connections[static_cast<std::size_t>(conn)].follows = conn_of;
      plan.connections[static_cast<std::size_t>(conn)].follow_map = shift;
    };
    mark(room, original.room, group, c, original.door);
    if (bath && original.bath >= 0)
      mark(bath_room, original.bath, bath_group, cb, original.bath_door);
  }
}

Wing Wing::Reversed() const {
  Wing r = *this;
  Affine2 half_turn;
  half_turn.linear = -Eigen::Matrix2d::Identity();
  half_turn.offset = Vec2(length_m, corridor_w);
  r.T = T * half_turn;
  r.y_lo = corridor_w - y_hi;
  r.y_hi = corridor_w - y_lo;
  r.west_corridor = east_corridor;
  r.east_corridor = west_corridor;
  return r;
}

Wing AddStraightWing(PlanBuilder& b,
                     const CorridorSpec& spec,
                     const RoomRecipe& recipe,
                     Random& rng,
                     double identical_width_m) {
  CorridorSpec s = spec;
  s.shape = CorridorShape::kStraight;
  const CorridorLayout layout = LayoutCorridors(s);
  const auto corridors = AddCorridors(b, layout, rng, 0.5);
  for (const Strip& strip : layout.strips) FillStrip(b, strip, recipe, rng, identical_width_m);
  Wing w;
  w.T = b.T();
  w.length_m = s.length_m;
  w.y_lo = layout.y_lo;
  w.y_hi = layout.y_hi;
  w.corridor_w = s.width_m;
  w.west_corridor = corridors[static_cast<std::size_t>(layout.west_end)];
  w.east_corridor = corridors[static_cast<std::size_t>(layout.east_end)];
  return w;
}

Affine2 AttachEast(const Wing& a, double y_lo, double y_hi, double angle_rad) {
  if (angle_rad == 0) return a.T * Affine2::Translation({a.length_m, 0});
  // Turning left pivots about the north-east corner, right about the south-east one, so the
  // wings touch there and open a wedge on the other side.
  const double pivot_a = angle_rad > 0 ? a.y_hi : a.y_lo, pivot_b = angle_rad > 0 ? y_hi : y_lo;
  return a.T * Affine2::Translation({a.length_m, pivot_a}) * Affine2::Rotation(angle_rad) *
         Affine2::Translation({0, -pivot_b});
}

Joint JoinWings(Plan& plan, const Wing& a, const Wing& b, double angle_rad, Random& rng) {
  PlanBuilder builder(plan, Affine2());
  Joint joint;
  if (angle_rad == 0) {
    joint.door_into_a =
        builder.Connect(b.west_corridor, a.east_corridor, DrawDoor(rng, DoorKind::kOpening, 0.5));
    return joint;
  }
  // The wedge between the wings is a lobby: from the pivot to 1.5 m past the far side of the
  // corridors (into the end rooms there), so that the corridors open well inside it.
  const double L = a.length_m, w = a.corridor_w;
  constexpr double kPast_m = 1.5;
  Polygon lobby;
  if (angle_rad > 0) {
    const double ea = std::min(kPast_m, -a.y_lo), eb = std::min(kPast_m, -b.y_lo);
    lobby = {a.T({L, -ea}), b.T({0, -eb}), a.T({L, a.y_hi})};
  } else {
    const double ea = std::min(kPast_m, a.y_hi - w), eb = std::min(kPast_m, b.y_hi - b.corridor_w);
    lobby = {a.T({L, w + ea}), a.T({L, a.y_lo}), b.T({0, b.corridor_w + eb})};
  }
  joint.lobby = builder.RoomPolygon(RoomUse::kLobby, lobby);
  joint.door_into_a =
      builder.Connect(joint.lobby, a.east_corridor, DrawDoor(rng, DoorKind::kOpening, 0.5));
  builder.Connect(joint.lobby, b.west_corridor, DrawDoor(rng, DoorKind::kOpening, 0.5));
  return joint;
}

void MirrorRooms(Plan& plan,
                 int first_room,
                 int end_room,
                 int first_connection,
                 int end_connection,
                 const Affine2& mirror) {
  std::map<int, int> image;  // room -> its mirror image
  std::map<int, int> group_image;
  for (int r = first_room; r < end_room; ++r) {
    PlanRoom copy = plan.rooms[static_cast<std::size_t>(r)];
    copy.polygon = Transformed(copy.polygon, mirror);
    copy.copy_of = r;
    copy.copy_map = mirror;
    if (copy.identical_group >= 0) {
      auto it = group_image.find(copy.identical_group);
      if (it == group_image.end()) {
        plan.identical_groups.emplace_back();
        it = group_image
                 .emplace(copy.identical_group, static_cast<int>(plan.identical_groups.size()) - 1)
                 .first;
      }
      copy.identical_group = it->second;
    }
    const int index = static_cast<int>(plan.rooms.size());
    if (copy.identical_group >= 0)
      plan.identical_groups[static_cast<std::size_t>(copy.identical_group)].push_back(index);
    plan.rooms.push_back(std::move(copy));
    image[r] = index;
    plan.mirror_pairs.emplace_back(r, index);
  }
  for (int c = first_connection; c < end_connection; ++c) {
    Connection m = plan.connections[static_cast<std::size_t>(c)];
    const auto a = image.find(m.a);
    if (a == image.end()) continue;
    m.a = a->second;
    if (m.b >= 0) {
      const auto b = image.find(m.b);
      if (b == image.end()) continue;  // doors out of the mirrored part are the caller's
      m.b = b->second;
    }
    m.follows = c;
    m.follow_map = mirror;
    plan.connections.push_back(m);
  }
}

}  // namespace msgraphs::sim::building
