// SPDX-License-Identifier: MIT
// Office or school floors: a double-loaded corridor of any shape with rows of offices (or
// classrooms), meeting rooms, store rooms, and now and then an open-plan hall of desks.
#include <cmath>

#include "style_common.hpp"

namespace msgraphs::sim::building {
namespace {

// Sizes of the corridor shapes: main length X, other arms Y (metres, before scaling).
void SizeCorridors(
    const Choices& c, Random& rng, CorridorSpec& s, double depth_lo, double depth_hi) {
  auto depth = [&]() { return SnapCm(rng.Uniform(depth_lo, depth_hi)); };
  s.shape = c.corridor;
  s.depth_s_m = depth();
  s.depth_n_m = depth();
  s.depth_e_m = depth();
  s.depth_w_m = depth();
  s.depth_in_m = SnapCm(rng.Uniform(4.0, std::min(6.0, depth_hi)));
  const double w = s.width_m, k = c.scale;
  auto len = [&](double lo, double hi) { return SnapCm(std::max(lo, rng.Uniform(lo, hi) * k)); };
  switch (c.corridor) {
    case CorridorShape::kNone:
    case CorridorShape::kStraight:
      s.length_m = len(20, 56);
      break;
    case CorridorShape::kL:
      s.length_m = len(std::max(16.0, s.depth_w_m + 6), 40);
      s.arm_m = len(s.depth_n_m + 7, 30);
      break;
    case CorridorShape::kT:
      s.length_m = len(s.depth_w_m + s.depth_e_m + w + 14, 56);
      s.branch_at_m = SnapCm(rng.Uniform(s.depth_w_m + 6, s.length_m - w - s.depth_e_m - 6));
      s.arm_m = len(s.depth_n_m + 7, 26);
      break;
    case CorridorShape::kU:
      s.length_m = len(2 * w + 2 * s.depth_in_m + 6, 40);
      s.arm_m = len(s.depth_n_m + 7, 20);
      break;
    case CorridorShape::kLoop:
      s.length_m = len(22, 40);
      s.arm_m = SnapCm(2 * w + rng.Uniform(8.5, 15.0));
      break;
  }
  s.split = s.length_m > 30 && rng.Chance(0.5);
}

}  // namespace

bool BuildOffice(const Choices& c, Random& rng, Plan& plan, std::string& error) {
  static constexpr double kOfficeCorridor[] = {1.8, 2.0, 2.2, 2.4, 2.6};
  static constexpr double kSchoolCorridor[] = {2.4, 2.8, 3.0, 3.2};
  static constexpr double kOfficeRow[] = {3.6, 4.0, 4.5, 5.0};
  static constexpr double kSchoolRow[] = {7.2, 8.0, 8.4};
  const bool school = rng.Chance(0.3);
  plan.name = school ? "school" : "office";
  plan.walls.exterior_thickness_m = SnapCm(rng.Uniform(0.25, 0.35));
  static constexpr double kInterior[] = {0.10, 0.12, 0.15};
  plan.walls.interior_thickness_m = Pick(rng, kInterior);
  plan.walls.interior_material = rng.Chance(0.15) ? Material::kGlass : Material::kPainted;
  plan.ceiling_m = c.ceiling_m;

  RoomRecipe recipe;
  recipe.min_width_m = school ? 6.5 : 3.0;
  recipe.max_width_m = school ? 9.0 : 6.0;
  recipe.door = school ? DoorKind::kDouble : DoorKind::kSingle;
  recipe.use = [school](Random& r, double width, double depth) {
    if (width < 2.8) return RoomUse::kStorage;
    if (school)
      return r.Chance(0.8) ? RoomUse::kClassroom
                           : (r.Chance(0.5) ? RoomUse::kStorage : RoomUse::kMeeting);
    if (width >= 4.5 && depth >= 5 && r.Chance(0.2)) return RoomUse::kMeeting;
    return r.Chance(0.1) ? RoomUse::kStorage : RoomUse::kOffice;
  };
  const double identical =
      c.identical_rows() ? (school ? Pick(rng, kSchoolRow) : Pick(rng, kOfficeRow)) : 0.0;

  CorridorSpec spec;
  spec.width_m = school ? Pick(rng, kSchoolCorridor) : Pick(rng, kOfficeCorridor);
  SizeCorridors(c, rng, spec, school ? 7.0 : 4.5, school ? 8.5 : 7.0);
  if (c.mirrored_wings()) {
    CorridorSpec hub = spec;
    hub.length_m = SnapCm(std::max(12.0, rng.Uniform(14, 28) * c.scale));
    BuildWingedPlan(c, rng, plan, hub, spec, 12, 24, recipe, identical);
    return true;
  }
  const CorridorLayout layout = LayoutCorridors(spec);
  PlanBuilder b(plan, Affine2());
  AddCorridors(b, layout, rng, 0.4);
  plan.corridor = c.corridor;
  // The longest strip carries the identical row for sure, the others half the time.
  std::size_t longest = 0;
  for (std::size_t i = 1; i < layout.strips.size(); ++i) {
    if (layout.strips[i].f1 - layout.strips[i].f0 >
        layout.strips[longest].f1 - layout.strips[longest].f0)
      longest = i;
  }
  for (std::size_t i = 0; i < layout.strips.size(); ++i) {
    const Strip& s = layout.strips[i];
    const double length = s.a1() - s.a0();
    const bool row = identical > 0 && (i == longest || rng.Chance(0.5));
    const bool hall = !row && length >= 12 && s.depth() >= 6 && rng.Chance(s.core ? 0.45 : 0.15);
    if (hall) {
      // One open-plan office (or, in a loop's core, a lobby or meeting area), two doors.
      const RoomUse use = s.core && rng.Chance(0.4) ? RoomUse::kLobby : RoomUse::kOpenPlan;
      const int r = b.Room(use, s.rect);
      plan.rooms[static_cast<std::size_t>(r)].column_spacing_m =
          length > 20 && rng.Chance(0.5) ? 7.2 : 0.0;
      b.Connect(r, -1, DrawDoor(rng, DoorKind::kDouble, 0.3));
      b.Connect(r, -1, DrawDoor(rng, DoorKind::kDouble, 0.3));
      continue;
    }
    FillStrip(b, s, recipe, rng, row ? identical : 0.0);
  }
  (void)error;
  return true;
}

}  // namespace msgraphs::sim::building
