// SPDX-License-Identifier: MIT
// Hubs with wings: mirrored pairs or chains of straight wings turned at their joints.
#include <algorithm>
#include <cmath>
#include <numbers>

#include "style_common.hpp"

namespace msgraphs::sim::building {

void BuildWingedPlan(const Choices& c,
                     Random& rng,
                     Plan& plan,
                     const CorridorSpec& hub_spec,
                     const CorridorSpec& wing_spec,
                     double wing_length_lo_m,
                     double wing_length_hi_m,
                     const RoomRecipe& recipe,
                     double identical_width_m) {
  static constexpr double kAngles[] = {30.0, 45.0, 60.0, 90.0};
  plan.corridor = CorridorShape::kStraight;
  auto draw_angle = [&]() { return c.wing_angle_forced ? c.wing_angle_deg : Pick(rng, kAngles); };
  // With identical rows, every block is long enough for at least two of them per strip.
  const double row_m = identical_width_m > 0 ? SnapCm(2 * identical_width_m + 1.0) : 0.0;
  CorridorSpec hub_block = hub_spec;
  hub_block.length_m = std::max(hub_spec.length_m, row_m);
  PlanBuilder hub_builder(plan, Affine2::Translation({-0.5 * hub_block.length_m, 0}));
  const Wing hub = AddStraightWing(hub_builder, hub_block, recipe, rng, identical_width_m);
  auto add_wing = [&](const Wing& from, double angle_deg) {
    CorridorSpec s = wing_spec;
    s.length_m =
        SnapCm(std::max({8.0, row_m, rng.Uniform(wing_length_lo_m, wing_length_hi_m) * c.scale}));
    s.split = false;
    const double y_lo = -s.depth_s_m, y_hi = s.width_m + s.depth_n_m;
    PlanBuilder b(plan, AttachEast(from, y_lo, y_hi, angle_deg * std::numbers::pi / 180.0));
    return AddStraightWing(b, s, recipe, rng, identical_width_m);
  };
  auto join = [&](const Wing& a, const Wing& b, double angle_deg) {
    plan.wing_angles_deg.push_back(std::fabs(angle_deg));
    return JoinWings(plan, a, b, angle_deg * std::numbers::pi / 180.0, rng);
  };

  if (c.mirrored_wings()) {
    // The east wing turns left; its mirror image about x = 0 leaves the west end turning right
    // (seen along its corridor), i.e. both wings bend the same way: a chevron or a U.
    const double angle = draw_angle();
    const int rooms0 = static_cast<int>(plan.rooms.size()),
              doors0 = static_cast<int>(plan.connections.size());
    const Wing east = add_wing(hub, angle);
    const Joint joint = join(hub, east, angle);
    const int rooms1 = static_cast<int>(plan.rooms.size()),
              doors1 = static_cast<int>(plan.connections.size());
    plan.mirror_axis_point = Vec2::Zero();
    plan.mirror_axis_direction = Vec2(0, 1);
    const Affine2 mirror = Affine2::Reflection(plan.mirror_axis_point, plan.mirror_axis_direction);
    MirrorRooms(plan, rooms0, rooms1, doors0, doors1, mirror);
    plan.wing_angles_deg.push_back(angle);
    // The mirrored joint's door into the hub's west end, where the original's went, mirrored.
    Connection door = plan.connections[static_cast<std::size_t>(joint.door_into_a)];
    door.a = rooms1 + (door.a - rooms0);
    door.b = hub.west_corridor;
    door.follows = joint.door_into_a;
    door.follow_map = mirror;
    plan.connections.push_back(door);
    return;
  }
  auto signed_angle = [&]() { return draw_angle() * (rng.Chance(0.5) ? 1.0 : -1.0); };
  const int wings = 1 + rng.Index(3);
  const double a1 = signed_angle();
  const Wing east = add_wing(hub, a1);
  join(hub, east, a1);
  if (wings >= 2) {
    const double a2 = signed_angle();
    const Wing further = add_wing(east, a2);
    join(east, further, a2);
  }
  if (wings == 3) {
    const Wing from = hub.Reversed();
    const double a3 = signed_angle();
    const Wing west = add_wing(from, a3);
    join(from, west, a3);
  }
}

}  // namespace msgraphs::sim::building
