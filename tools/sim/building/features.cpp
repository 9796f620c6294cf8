// SPDX-License-Identifier: MIT
#include "features.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "truth.hpp"

namespace msgraphs::sim::building {
namespace {

bool LShaped(const Room& r) {
  if (r.polygon.size() != 6) return false;
  for (std::size_t i = 0; i < 6; ++i) {
    const Eigen::Vector2d a = (r.polygon[(i + 1) % 6] - r.polygon[i]).normalized();
    const Eigen::Vector2d b = (r.polygon[(i + 2) % 6] - r.polygon[(i + 1) % 6]).normalized();
    if (std::fabs(a.dot(b)) > 1e-6) return false;
  }
  return true;
}

std::string Fixed(double v, int decimals) {
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), "%.*f", decimals, v == 0.0 ? 0.0 : v);
  return buffer;
}

}  // namespace

void MeasureWorld(const World& world, BuildingFeatures& f) {
  f.rooms = static_cast<int>(world.rooms.size());
  f.walls = static_cast<int>(world.walls.size());
  f.boxes = static_cast<int>(world.boxes.size());
  f.cylinders = static_cast<int>(world.cylinders.size());
  f.ceiling_m = world.levels.empty() || !world.levels[0].ceiling_height_m
                    ? 0.0
                    : *world.levels[0].ceiling_height_m;
  f.doors = 0;
  f.doors_without_lintel = 0;
  f.door_width_min_m = 1e9;
  f.door_width_max_m = 0;
  f.wall_height_min_m = 1e9;
  f.wall_height_max_m = 0;
  for (const Wall& w : world.walls) {
    f.wall_height_min_m = std::min(f.wall_height_min_m, w.height_m);
    f.wall_height_max_m = std::max(f.wall_height_max_m, w.height_m);
    for (const Door& d : w.doors) {
      ++f.doors;
      f.doors_without_lintel += d.height_m >= w.height_m ? 1 : 0;
      f.door_width_min_m = std::min(f.door_width_min_m, d.width_m);
      f.door_width_max_m = std::max(f.door_width_max_m, d.width_m);
    }
  }
  if (f.doors == 0) f.door_width_min_m = 0;
  if (world.walls.empty()) f.wall_height_min_m = 0;
  f.l_shaped_rooms = 0;
  const Room* largest = nullptr;
  const Room* smallest = nullptr;
  for (const Room& r : world.rooms) {
    f.l_shaped_rooms += LShaped(r) ? 1 : 0;
    if (largest == nullptr || r.Area() > largest->Area()) largest = &r;
    if (smallest == nullptr || r.Area() < smallest->Area()) smallest = &r;
  }
  if (largest != nullptr) {
    const RoomRectangle a = MinAreaRectangle(*largest), b = MinAreaRectangle(*smallest);
    f.largest_room = largest->id;
    f.largest_width_m = a.width_m;
    f.largest_length_m = a.length_m;
    f.smallest_room = smallest->id;
    f.smallest_width_m = b.width_m;
    f.smallest_length_m = b.length_m;
  }
}

std::string WriteFeatures(const BuildingFeatures& f) {
  std::string out = "msgraphs-building 1\n";
  auto line = [&](const std::string& key, const std::string& value) {
    out += key + " " + value + "\n";
  };
  line("seed", std::to_string(f.seed));
  line("style", ToString(f.style));
  line("corridor", ToString(f.corridor));
  line("symmetry", ToString(f.symmetry));
  line("clutter", ToString(f.clutter));
  line("rotation_deg", Fixed(f.rotation_deg, 1));
  std::string angles;
  for (double a : f.wing_angles_deg) angles += (angles.empty() ? "" : " ") + Fixed(a, 0);
  line("wing_angles_deg", angles.empty() ? "none" : angles);
  line("ceiling_m", Fixed(f.ceiling_m, 2));
  line("wall_height_m", Fixed(f.wall_height_min_m, 2) + " " + Fixed(f.wall_height_max_m, 2));
  line("footprint_m", Fixed(f.footprint_width_m, 2) + " " + Fixed(f.footprint_length_m, 2));
  line("rooms", std::to_string(f.rooms));
  line("walls", std::to_string(f.walls));
  line("doors", std::to_string(f.doors));
  line("doors_without_lintel", std::to_string(f.doors_without_lintel));
  line("door_width_m", Fixed(f.door_width_min_m, 2) + " " + Fixed(f.door_width_max_m, 2));
  line("largest_room",
       f.largest_room + " " + Fixed(f.largest_width_m, 2) + " " + Fixed(f.largest_length_m, 2));
  line("smallest_room",
       f.smallest_room + " " + Fixed(f.smallest_width_m, 2) + " " + Fixed(f.smallest_length_m, 2));
  line("l_shaped_rooms", std::to_string(f.l_shaped_rooms));
  line("boxes", std::to_string(f.boxes));
  line("cylinders", std::to_string(f.cylinders));
  for (const auto& g : f.identical_groups) {
    std::string ids;
    for (const auto& id : g) ids += (ids.empty() ? "" : " ") + id;
    line("identical", ids);
  }
  for (const auto& [a, b] : f.mirror_pairs) line("mirror", a + " " + b);
  line("attempts", std::to_string(f.attempts));
  for (const auto& why : f.rejected) line("rejected", why);
  return out;
}

}  // namespace msgraphs::sim::building
