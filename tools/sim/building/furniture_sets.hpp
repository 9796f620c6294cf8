// SPDX-License-Identifier: MIT
// What stands in a room of each use: desks and shelves in offices, beds in patient rooms and
// bedrooms, counters in kitchens, rack rows in warehouse halls, desk islands in open-plan
// offices, pallets and stacks on construction floors. Sizes are common furniture sizes.
#pragma once

#include "plan.hpp"
#include "room_layout.hpp"

namespace msgraphs::sim::building {

/// Furnishes `room` for `use`. `amount` 0..1 scales how much is placed (0: nothing, 1: dense);
/// `ceiling_m` bounds tall items.
void FurnishRoom(RoomLayout& room, RoomUse use, double amount, double ceiling_m, Random& rng);

/// Rows of back-to-back pallet racks along the hall's long axis with aisles between them and
/// cross aisles every few bays.
void PlaceRacks(RoomLayout& room, double amount, double ceiling_m, Random& rng);
/// Islands of four desks on a grid with aisles.
void PlaceDeskIslands(RoomLayout& room, double amount, Random& rng);
/// A grid of columns `spacing_m` apart, clear of the walls.
void PlaceColumns(
    RoomLayout& room, double spacing_m, double radius_m, double ceiling_m, bool square);

}  // namespace msgraphs::sim::building
