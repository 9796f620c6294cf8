// SPDX-License-Identifier: MIT
// Buildings of several wings: straight double-loaded wings off a central block, meeting at
// 30, 45, 60 or 90 degrees through triangular lobbies, or a wing and its mirror image.
#include "style_common.hpp"

namespace msgraphs::sim::building {

bool BuildMultiWing(const Choices& c, Random& rng, Plan& plan, std::string& error) {
  static constexpr double kCorridor[] = {1.8, 2.0, 2.2, 2.4};
  static constexpr double kRow[] = {3.6, 4.0, 4.5};
  plan.name = "multi-wing building";
  plan.walls.exterior_thickness_m = SnapCm(rng.Uniform(0.25, 0.35));
  plan.walls.interior_thickness_m = 0.12;
  plan.ceiling_m = c.ceiling_m;
  RoomRecipe recipe;
  recipe.min_width_m = 3.0;
  recipe.max_width_m = 6.0;
  recipe.use = [](Random& r, double width, double depth) {
    if (width < 3.2) return RoomUse::kStorage;
    if (width >= 4.5 && depth >= 5 && r.Chance(0.2)) return RoomUse::kMeeting;
    return RoomUse::kOffice;
  };
  CorridorSpec spec;
  spec.width_m = Pick(rng, kCorridor);
  spec.depth_s_m = SnapCm(rng.Uniform(4.5, 6.5));
  spec.depth_n_m = SnapCm(rng.Uniform(4.5, 6.5));
  CorridorSpec hub = spec;
  hub.length_m = SnapCm(std::max(12.0, rng.Uniform(14, 26) * c.scale));
  const double identical = c.identical_rows() ? Pick(rng, kRow) : 0.0;
  BuildWingedPlan(c, rng, plan, hub, spec, 10, 20, recipe, identical);
  (void)error;
  return true;
}

}  // namespace msgraphs::sim::building
