// SPDX-License-Identifier: MIT
// What a generated building contains, for benchmarks that need specific cases and for the
// summary written next to the world (building.txt). Room ids are the world's.
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "options.hpp"
#include "world.hpp"

namespace msgraphs::sim::building {

struct BuildingFeatures {
  std::uint64_t seed = 0;
  Style style = Style::kOffice;
  CorridorShape corridor = CorridorShape::kNone;
  Symmetry symmetry = Symmetry::kNone;  ///< what the building really has (after placement)
  Clutter clutter = Clutter::kNone;
  double rotation_deg = 0;
  std::vector<double> wing_angles_deg;  ///< the turn at each joint between wings
  double ceiling_m = 0, wall_height_min_m = 0, wall_height_max_m = 0;
  std::string largest_room, smallest_room;  ///< by area; sizes: minimum-area rectangle
  double largest_width_m = 0, largest_length_m = 0, smallest_width_m = 0, smallest_length_m = 0;
  int rooms = 0, walls = 0, doors = 0, boxes = 0, cylinders = 0;
  int l_shaped_rooms = 0;        ///< six corners, all right angles
  int doors_without_lintel = 0;  ///< openings up to the ceiling
  double door_width_min_m = 0, door_width_max_m = 0;
  double footprint_width_m = 0, footprint_length_m = 0;  ///< in the building's own frame
  /// Rooms that are copies of each other (same size, doors and furniture), the original first.
  std::vector<std::vector<std::string>> identical_groups;
  /// (room, its mirror image) across the building's axis.
  std::vector<std::pair<std::string, std::string>> mirror_pairs;
  int attempts = 1;                   ///< layouts drawn until one passed every check
  std::vector<std::string> rejected;  ///< why each earlier layout was drawn again
};

/// Fills the counts and sizes that follow from the world itself.
void MeasureWorld(const World& world, BuildingFeatures& f);

/// The summary as text ("msgraphs-building 1", then one "key value..." line each).
std::string WriteFeatures(const BuildingFeatures& f);

}  // namespace msgraphs::sim::building
