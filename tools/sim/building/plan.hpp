// SPDX-License-Identifier: MIT
// A building while it is generated, in the building frame (before the whole building is
// rotated): rooms as polygons, the doors wanted between them, and structural items. Styles
// fill a Plan; walls, doors and furniture are derived from it (walls.hpp, doors.hpp,
// furnish.hpp).
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "geometry.hpp"
#include "options.hpp"
#include "world.hpp"

namespace msgraphs::sim::building {

enum class RoomUse : std::uint8_t {
  kCorridor,
  kOffice,
  kClassroom,
  kMeeting,
  kOpenPlan,
  kPatient,
  kBath,
  kNurseStation,
  kHall,
  kStorage,
  kLobby,
  kLiving,
  kBedroom,
  kKitchen,
  kWc,
  kHallway,
  kBare,
};
const char* ToString(RoomUse use);

struct PlanRoom {
  RoomUse use = RoomUse::kOffice;
  Polygon polygon;  ///< Normalised(): counter-clockwise, lowest-left vertex first
  /// This room is `copy_of` mapped by `copy_map` (translated: identical rooms; mirrored:
  /// a mirrored wing). Its doors and furniture are the original's, mapped the same way.
  int copy_of = -1;
  Affine2 copy_map;
  int identical_group = -1;  ///< index into Plan::identical_groups
  /// Structural columns on a grid this far apart (0: none), e.g. in halls.
  double column_spacing_m = 0;
  double column_radius_m = 0.25;
  bool square_columns = false;
};

/// A door wanted between rooms a and b; b = -1: the corridor next to a with the longest wall
/// in common (strip rooms do not know which corridor piece they face).
struct Connection {
  int a = -1, b = -1;
  double width_m = 0.9;
  bool lintel = true;          ///< false: the opening reaches the ceiling
  double door_height_m = 2.1;  ///< with a lintel
  double position = 0.5;       ///< where along the free part of the shared wall, 0..1
  /// Place the door where connection `follows` was placed, mapped by `follow_map`
  /// (identical rooms, mirrored wings).
  int follows = -1;
  Affine2 follow_map;
};

struct WallStyle {
  double exterior_thickness_m = 0.3;
  double interior_thickness_m = 0.12;
  Material exterior_material = Material::kPainted;
  Material interior_material = Material::kPainted;
};

struct Plan {
  std::string name;
  std::vector<PlanRoom> rooms;
  std::vector<Connection> connections;
  std::vector<std::vector<int>> identical_groups;  ///< room indices, the original first
  std::vector<std::pair<int, int>> mirror_pairs;   ///< (room, its mirror image)
  Vec2 mirror_axis_point = Vec2::Zero(), mirror_axis_direction = Vec2(0, 1);
  WallStyle walls;
  double ceiling_m = 3.0;
  // What the style built (for the feature summary).
  CorridorShape corridor = CorridorShape::kNone;
  std::vector<double> wing_angles_deg;  ///< turn at each wing joint
  bool broken = false;                  ///< a layout step failed: draw the attempt again
};

}  // namespace msgraphs::sim::building
