// SPDX-License-Identifier: MIT
// Furniture and columns for every room of a plan, each room kept walkable: every door's mouth
// reaches every other and all free floor through passages a robot fits (ClearanceGrid), or
// the items placed last are taken out again. Copies of a room (identical rooms, mirrored
// wings) get the original's furniture mapped like the room.
#pragma once

#include <cstdint>
#include <vector>

#include "doors.hpp"
#include "room_layout.hpp"

namespace msgraphs::sim::building {

/// Clearance a robot needs to pass (the planner's 0.35 m radius and a 5 cm margin) and the
/// clearance counted as free floor (the planner's 0.35 + 0.2 m).
inline constexpr double kPassClearance_m = 0.40;
inline constexpr double kStandClearance_m = 0.55;

struct FurnishReport {
  std::vector<int> broken_copies;     ///< copies whose mapped furniture did not fit
  std::vector<int> unwalkable_rooms;  ///< rooms a robot cannot cross even when empty
  int removed_items = 0;              ///< placed, then taken out to keep a room walkable
};

/// Furnishes `plan`'s rooms; `amount` 0..1 (clutter). The items of each room.
std::vector<std::vector<Item>> Furnish(const Plan& plan,
                                       const std::vector<PlanWall>& walls,
                                       const std::vector<PlacedDoor>& doors,
                                       double amount,
                                       std::uint64_t seed,
                                       FurnishReport& report);

}  // namespace msgraphs::sim::building
