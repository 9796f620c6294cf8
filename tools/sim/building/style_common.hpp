// SPDX-License-Identifier: MIT
// Pieces the corridor styles share: corridor rooms with openings between them, strips filled
// with rooms (optionally a row of identical ones, optionally with an en-suite bathroom at the
// door), straight wings joined at an angle by a triangular lobby, and mirror images of wings.
#pragma once

#include <functional>
#include <vector>

#include "block.hpp"
#include "styles.hpp"

namespace msgraphs::sim::building {

/// Adds the layout's corridor rooms and the openings between them; returns their indices.
std::vector<int> AddCorridors(PlanBuilder& b,
                              const CorridorLayout& layout,
                              Random& rng,
                              double no_lintel_chance);

struct RoomRecipe {
  double min_width_m = 3.0, max_width_m = 6.0;
  DoorKind door = DoorKind::kSingle;
  double no_lintel_chance = 0.0;
  /// En-suite bathroom in the room's front corner (0: none): along the front, and deep.
  double bath_along_m = 0, bath_depth_m = 0;
  /// The room's use from its size (width along the corridor, depth).
  std::function<RoomUse(Random&, double, double)> use;
};

/// Fills a strip with rooms facing its corridor. `identical_width_m` > 0: a row of identical
/// rooms that wide (same size, door and furniture), where at least two fit.
void FillStrip(PlanBuilder& b,
               const Strip& s,
               const RoomRecipe& recipe,
               Random& rng,
               double identical_width_m);

/// A straight double-loaded block placed in the building.
struct Wing {
  Affine2 T;  ///< block frame -> building frame
  double length_m = 0, y_lo = 0, y_hi = 0, corridor_w = 0;
  int west_corridor = -1, east_corridor = -1;
  /// The same block seen from its other end (rotated half a turn about its corridor's middle).
  Wing Reversed() const;
};

/// Adds a straight block at T.
Wing AddStraightWing(PlanBuilder& b,
                     const CorridorSpec& spec,
                     const RoomRecipe& recipe,
                     Random& rng,
                     double identical_width_m);
/// Where a wing of extent [y_lo, y_hi] goes to continue `a` past its east end, turned by
/// `angle_rad` (positive: to the left).
Affine2 AttachEast(const Wing& a, double y_lo, double y_hi, double angle_rad);
/// Joins wing b (attached by AttachEast with `angle_rad`) to a: an opening between their
/// corridors, or a triangular lobby between them when turned. Returns the lobby (-1: none)
/// and the connection that reaches into a.
struct Joint {
  int lobby = -1;
  int door_into_a = -1;
};
Joint JoinWings(Plan& plan, const Wing& a, const Wing& b, double angle_rad, Random& rng);

/// A hub (straight block centred on x = 0) with wings: with mirrored wings, one wing at the
/// east end and its mirror image about x = 0 at the west end; otherwise a chain of 1 to 3
/// wings, each turned at its joint. Corridor and room sizes from `hub` and `wing`.
void BuildWingedPlan(const Choices& c,
                     Random& rng,
                     Plan& plan,
                     const CorridorSpec& hub,
                     const CorridorSpec& wing,
                     double wing_length_lo_m,
                     double wing_length_hi_m,
                     const RoomRecipe& recipe,
                     double identical_width_m);

/// Appends the mirror images (about `mirror`) of rooms [first_room, end_room) and of the doors
/// among them and to their corridors, recording them as mirror pairs and copies.
void MirrorRooms(Plan& plan,
                 int first_room,
                 int end_room,
                 int first_connection,
                 int end_connection,
                 const Affine2& mirror);

/// Draws from a small set (the generator's sizes are catalogue values).
template <typename T, std::size_t N>
T Pick(Random& rng, const T (&values)[N]) {
  return values[rng.Index(static_cast<int>(N))];
}

}  // namespace msgraphs::sim::building
