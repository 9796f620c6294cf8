// SPDX-License-Identifier: MIT
// A hospital ward: rows of identical patient rooms, each with an en-suite bathroom beside its
// bed-wide door, along wide corridors; a nurse station; often two mirrored wings off a hub.
#include <cmath>

#include "style_common.hpp"

namespace msgraphs::sim::building {

bool BuildHospital(const Choices& c, Random& rng, Plan& plan, std::string& error) {
  static constexpr double kCorridor[] = {2.4, 2.6, 2.8, 3.0};
  static constexpr double kRoom[] = {4.0, 4.2, 4.5, 4.8};
  static constexpr double kBath[] = {2.0, 2.2, 2.4};
  plan.name = "hospital";
  plan.walls.exterior_thickness_m = SnapCm(rng.Uniform(0.25, 0.35));
  plan.walls.interior_thickness_m = 0.12;
  plan.ceiling_m = c.ceiling_m;

  RoomRecipe recipe;
  recipe.min_width_m = 4.0;
  recipe.max_width_m = 4.8;
  recipe.door = DoorKind::kBed;
  static constexpr double kBathAlong[] = {2.0, 2.2};
  recipe.bath_along_m = Pick(rng, kBathAlong);
  recipe.bath_depth_m = Pick(rng, kBath);
  recipe.use = [](Random& r, double width, double) {
    if (width < 4.0) return r.Chance(0.5) ? RoomUse::kStorage : RoomUse::kOffice;
    const double p = r.Uniform();
    return p < 0.8 ? RoomUse::kPatient : p < 0.9 ? RoomUse::kNurseStation : RoomUse::kStorage;
  };
  const double identical = c.identical_rows() ? Pick(rng, kRoom) : 0.0;

  CorridorSpec spec;
  spec.width_m = Pick(rng, kCorridor);
  auto depth = [&]() { return SnapCm(rng.Uniform(5.5, 6.5)); };
  spec.depth_s_m = depth();
  spec.depth_n_m = depth();
  spec.depth_e_m = depth();
  spec.depth_w_m = depth();
  spec.depth_in_m = SnapCm(rng.Uniform(4.5, 6.0));
  const double k = c.scale;
  auto len = [&](double lo, double hi) { return SnapCm(std::max(lo, rng.Uniform(lo, hi) * k)); };
  if (c.mirrored_wings()) {
    CorridorSpec hub = spec;
    hub.length_m = len(8, 14);
    BuildWingedPlan(c, rng, plan, hub, spec, 10, 16, recipe, identical);
    return true;
  }
  spec.shape = c.corridor;
  switch (c.corridor) {
    case CorridorShape::kNone:
    case CorridorShape::kStraight:
      spec.length_m = len(16, 36);
      break;
    case CorridorShape::kL:
      spec.length_m = len(spec.depth_w_m + 6, 28);
      spec.arm_m = len(spec.depth_n_m + 7, 22);
      break;
    case CorridorShape::kT:
      spec.length_m = len(spec.depth_w_m + spec.depth_e_m + spec.width_m + 14, 40);
      spec.branch_at_m = SnapCm(
          rng.Uniform(spec.depth_w_m + 6, spec.length_m - spec.width_m - spec.depth_e_m - 6));
      spec.arm_m = len(spec.depth_n_m + 7, 18);
      break;
    case CorridorShape::kU:
      spec.length_m = len(2 * spec.width_m + 2 * spec.depth_in_m + 6, 36);
      spec.arm_m = len(spec.depth_n_m + 7, 16);
      break;
    case CorridorShape::kLoop:
      spec.length_m = len(20, 34);
      spec.arm_m = SnapCm(2 * spec.width_m + rng.Uniform(9.0, 12.0));
      break;
  }
  spec.split = spec.length_m > 30 && rng.Chance(0.5);
  const CorridorLayout layout = LayoutCorridors(spec);
  PlanBuilder b(plan, Affine2());
  AddCorridors(b, layout, rng, 0.3);
  plan.corridor = c.corridor;
  bool station = false;
  for (const Strip& s : layout.strips) {
    if (s.core && !station && s.a1() - s.a0() >= 8) {
      // The nurse station in the middle of the ward, open to the corridor by two wide doors.
      const int r = b.Room(RoomUse::kNurseStation, s.rect);
      b.Connect(r, -1, DrawDoor(rng, DoorKind::kWide, 0.5));
      b.Connect(r, -1, DrawDoor(rng, DoorKind::kDouble));
      station = true;
      continue;
    }
    FillStrip(b, s, recipe, rng, identical);
  }
  (void)error;
  return true;
}

}  // namespace msgraphs::sim::building
