// SPDX-License-Identifier: MIT
#include "furniture_sets.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace msgraphs::sim::building {
namespace {

// How many items a room of `area_m2` gets at full amount: one per `per_m2`, at least `floor`.
int Count(double amount, double area_m2, double per_m2, int at_least = 1) {
  if (amount <= 0) return 0;
  return std::max(at_least, static_cast<int>(std::lround(amount * area_m2 / per_m2)));
}

// Centimetre sizes, like real catalogues.
double Size(Random& rng, double lo, double hi) { return SnapCm(rng.Uniform(lo, hi)); }

void Chairs(RoomLayout& r, Random& rng, int n) {
  for (int k = 0; k < n; ++k) r.FreeSomewhere(rng, 0.5, 0.5, 0.9, Material::kFabric, 4);
}

void Office(RoomLayout& r, double amount, double ceiling, Random& rng) {
  const int n = Count(amount, r.area(), 7.0);
  for (int k = 0; k < n; ++k) {
    switch (rng.Index(6)) {
      case 0:
      case 1:
        r.AgainstSomeWall(rng, Size(rng, 1.4, 1.8), Size(rng, 0.7, 0.8), 0.75, Material::kWood);
        break;
      case 2:
        r.AgainstSomeWall(rng, Size(rng, 0.8, 2.4), Size(rng, 0.35, 0.45),
                          std::min(2.1, ceiling - 0.3), Material::kWood);
        break;
      case 3:
        r.AgainstSomeWall(rng, 0.8, 0.5, 1.2, Material::kMetal);
        break;
      case 4:
        r.FreeSomewhere(rng, 0.5, 0.5, 0.9, Material::kFabric, 4);
        break;
      default:
        if (r.area() > 16) {
          r.Round(r.At(rng.Uniform(1.5, r.extent_u() - 1.5), rng.Uniform(1.5, r.extent_v() - 1.5)),
                  Size(rng, 0.45, 0.6), 0.74, Material::kWood, 0.8);
        } else {
          r.Round(r.At(rng.Uniform(0.5, r.extent_u() - 0.5), rng.Uniform(0.5, r.extent_v() - 0.5)),
                  0.25, 1.1, Material::kFabric);
        }
    }
  }
}

void Classroom(RoomLayout& r, double amount, Random& rng) {
  if (amount <= 0) return;
  // Rows of pupils' desks facing the u = 0 end, a teacher's desk there, shelves at the back.
  r.AgainstSomeWall(rng, 1.6, 0.7, 0.75, Material::kWood);
  const double desk_w = 1.2, desk_d = 0.6, aisle = amount > 0.8 ? 0.9 : 1.1;
  for (double a = 2.6; a + desk_d < r.extent_u() - 1.4; a += desk_d + aisle) {
    for (double b = 1.4; b + desk_w < r.extent_v() - 1.4; b += desk_w + aisle) {
      if (rng.Chance(amount))
        r.Free(r.At(a + 0.5 * desk_d, b + 0.5 * desk_w), r.yaw_u(), desk_d, desk_w, 0.75,
               Material::kWood, 0.05);
    }
  }
  r.AgainstSomeWall(rng, 2.4, 0.4, 1.8, Material::kWood);
}

void Meeting(RoomLayout& r, double amount, Random& rng) {
  if (amount <= 0) return;
  const double length = SnapCm(std::min(4.0, r.extent_u() - 3.2)),
               width = SnapCm(std::min(1.4, r.extent_v() - 3.2));
  if (length > 1.2 && width > 0.8) {
    r.Free(r.At(0.5 * r.extent_u(), 0.5 * r.extent_v()), r.yaw_u(), length, width, 0.75,
           Material::kWood, 0.9);
  }
  Chairs(r, rng, Count(amount, r.area(), 6.0));
  r.AgainstSomeWall(rng, 1.8, 0.1, 1.9, Material::kPainted);  // whiteboard
}

void Patient(RoomLayout& r, double amount, Random& rng) {
  if (amount <= 0) return;
  r.AgainstSomeWall(rng, 1.0, 2.1, 0.6, Material::kFabric, 12);  // bed, head to the wall
  r.AgainstSomeWall(rng, 0.5, 0.45, 0.7, Material::kWood);       // bedside table
  if (amount > 0.5) r.AgainstSomeWall(rng, 1.0, 0.6, 2.0, Material::kWood);  // wardrobe
  if (amount > 0.8) Chairs(r, rng, 1);
}

void Bath(RoomLayout& r, double amount, Random& rng) {
  if (amount <= 0) return;
  r.AgainstSomeWall(rng, 0.4, 0.65, 0.45, Material::kPainted);  // toilet
  r.AgainstSomeWall(rng, 0.6, 0.45, 0.85, Material::kPainted);  // wash basin
  if (amount > 0.5 && r.extent_u() > 2.3)
    r.AgainstSomeWall(rng, 1.7, 0.75, 0.55, Material::kPainted);  // bath
}

void Living(RoomLayout& r, double amount, Random& rng) {
  const int n = Count(amount, r.area(), 5.0);
  for (int k = 0; k < n; ++k) {
    switch (rng.Index(5)) {
      case 0:
        r.AgainstSomeWall(rng, Size(rng, 1.8, 2.2), 0.9, 0.8, Material::kFabric);
        break;  // sofa
      case 1:
        r.AgainstSomeWall(rng, 1.6, 0.4, 0.5, Material::kWood);
        break;  // TV board
      case 2:
        r.AgainstSomeWall(rng, Size(rng, 0.8, 1.2), 0.35, 1.8, Material::kWood);
        break;  // shelf
      case 3:
        r.FreeSomewhere(rng, 1.0, 0.6, 0.45, Material::kWood, 4);
        break;  // low table
      default:
        r.FreeSomewhere(rng, 0.8, 0.8, 0.8, Material::kFabric, 4);  // armchair
    }
  }
}

void Bedroom(RoomLayout& r, double amount, Random& rng) {
  if (amount <= 0) return;
  r.AgainstSomeWall(rng, r.area() > 10 ? 1.6 : 1.0, 2.0, 0.5, Material::kFabric, 12);
  r.AgainstSomeWall(rng, SnapCm(std::min(2.0, r.edge_length(0) - 0.6)), 0.6, 2.0, Material::kWood);
  if (amount > 0.5) r.AgainstSomeWall(rng, 0.45, 0.4, 0.5, Material::kWood);
  if (amount > 0.8) r.AgainstSomeWall(rng, 1.2, 0.6, 0.75, Material::kWood);
}

void Kitchen(RoomLayout& r, double amount, Random& rng) {
  if (amount <= 0) return;
  r.AgainstSomeWall(rng, Size(rng, 2.0, 3.6), 0.6, 0.9, Material::kPainted, 12);  // counter
  r.AgainstSomeWall(rng, 0.7, 0.7, 1.8, Material::kMetal);                        // fridge
  if (amount > 0.5) r.FreeSomewhere(rng, 1.2, 0.8, 0.75, Material::kWood, 6);     // table
  if (amount > 0.8) Chairs(r, rng, 2);
}

void Storage(RoomLayout& r, double amount, double ceiling, Random& rng) {
  const int n = Count(amount, r.area(), 4.0);
  for (int k = 0; k < n; ++k) {
    r.AgainstSomeWall(rng, Size(rng, 1.0, 2.4), Size(rng, 0.4, 0.6), std::min(2.2, ceiling - 0.3),
                      Material::kMetal);
  }
}

void Circulation(RoomLayout& r, double amount, Random& rng) {
  // Corridors keep a clear lane: only shallow items, and only in wide ones.
  if (r.extent_v() < 2.2 && r.area() < 30) return;
  const double depth_max = std::min(0.5, r.extent_v() - 1.7);
  if (depth_max < 0.3) return;
  const int n = Count(amount, r.area(), 16.0, 0);
  for (int k = 0; k < n; ++k) {
    switch (rng.Index(3)) {
      case 0:
        r.AgainstSomeWall(rng, Size(rng, 1.2, 1.8), std::min(0.45, depth_max), 0.45,
                          Material::kWood);
        break;
      case 1:
        r.AgainstSomeWall(rng, 0.8, std::min(0.4, depth_max), 1.2, Material::kMetal);
        break;
      default: {
        // A plant in a corner-ish spot: against a wall as a 0.4 m square pot.
        r.AgainstSomeWall(rng, 0.4, 0.4, 1.0, Material::kFabric);
      }
    }
  }
}

void NurseStation(RoomLayout& r, double amount, double ceiling, Random& rng) {
  if (amount <= 0) return;
  r.AgainstSomeWall(rng, Size(rng, 2.4, 3.6), 0.7, 1.1, Material::kWood, 12);
  Storage(r, amount * 0.5, ceiling, rng);
  Chairs(r, rng, Count(amount, r.area(), 10.0));
}

void Bare(RoomLayout& r, double amount, Random& rng) {
  const int n = Count(amount, r.area(), 14.0, 0);
  for (int k = 0; k < n; ++k) {
    switch (rng.Index(5)) {
      case 0:
        r.FreeSomewhere(rng, 1.2, 1.0, Size(rng, 0.15, 1.2), Material::kWood);
        break;  // pallet
      case 1:
        r.FreeSomewhere(rng, Size(rng, 1.0, 3.0), Size(rng, 0.5, 1.2), Size(rng, 0.3, 1.5),
                        Material::kConcrete);
        break;
      case 2:
        r.FreeSomewhere(rng, Size(rng, 2.0, 4.0), Size(rng, 0.3, 0.6), Size(rng, 0.2, 0.6),
                        Material::kMetal);
        break;
      case 3: {
        for (int t = 0; t < 4; ++t) {
          if (r.Round(r.At(rng.Uniform(0, r.extent_u()), rng.Uniform(0, r.extent_v())), 0.3, 0.9,
                      Material::kMetal, 0.6))
            break;
        }
        break;
      }
      default:
        r.AgainstSomeWall(rng, Size(rng, 1.0, 3.0), Size(rng, 0.6, 1.2), Size(rng, 0.5, 2.0),
                          Material::kWood);
    }
  }
}

}  // namespace

void PlaceRacks(RoomLayout& r, double amount, double ceiling_m, Random& rng) {
  if (amount <= 0) return;
  const double perimeter = Size(rng, 2.0, 3.0);
  const double depth = 2.0 + 0.2 * rng.Index(3);  // two racks back to back
  const double aisle = amount > 0.8   ? Size(rng, 1.8, 2.4)
                       : amount > 0.5 ? Size(rng, 2.4, 3.2)
                                      : Size(rng, 3.0, 4.0);
  const double height = std::min(ceiling_m - 0.6, 2.5 + 0.5 * rng.Index(6));
  const double bay = 2.7;
  const int bays_per_run = 3 + rng.Index(4);
  const double cross_aisle = 2.5;
  for (double b = perimeter + 0.5 * depth; b + 0.5 * depth <= r.extent_v() - perimeter;
       b += depth + aisle) {
    if (!rng.Chance(0.35 + 0.65 * amount)) continue;
    for (double a = perimeter; a + bay <= r.extent_u() - perimeter;) {
      int bays = 0;
      while (bays < bays_per_run && a + (bays + 1) * bay <= r.extent_u() - perimeter) ++bays;
      const double length = bays * bay;
      if (!r.Free(r.At(a + 0.5 * length, b), r.yaw_u(), length, depth, height, Material::kMetal,
                  0.05)) {
        // Blocked somewhere (a door zone, an inner corner): the bays that fit.
        for (int k = 0; k < bays; ++k) {
          r.Free(r.At(a + (k + 0.5) * bay, b), r.yaw_u(), bay, depth, height, Material::kMetal,
                 0.05);
        }
      }
      a += length + cross_aisle;
    }
  }
  // Pallets waiting near the walls.
  const int pallets = Count(amount, r.area(), 120.0);
  for (int k = 0; k < pallets; ++k)
    r.FreeSomewhere(rng, 1.2, 1.0, Size(rng, 0.15, 1.4), Material::kWood);
}

void PlaceDeskIslands(RoomLayout& r, double amount, Random& rng) {
  if (amount <= 0) return;
  const double w = 3.2, d = 1.6, aisle = amount > 0.8 ? 1.8 : 2.4, edge = 1.8;
  for (double b = edge + 0.5 * d; b + 0.5 * d <= r.extent_v() - edge; b += d + aisle) {
    for (double a = edge + 0.5 * w; a + 0.5 * w <= r.extent_u() - edge; a += w + aisle) {
      if (rng.Chance(0.3 + 0.7 * amount))
        r.Free(r.At(a, b), r.yaw_u(), w, d, 0.75, Material::kWood, 0.05);
    }
  }
  for (int k = 0; k < Count(amount, r.area(), 40.0); ++k)
    r.AgainstSomeWall(rng, 0.4, 0.4, 1.2, Material::kFabric);
}

void PlaceColumns(RoomLayout& r, double spacing_m, double radius_m, double ceiling_m, bool square) {
  // Columns keep 1.2 m from walls, so that no column pinches a passage shut.
  const double clear = radius_m + 1.2;
  const int nu = static_cast<int>(std::floor(r.extent_u() / spacing_m));
  const int nv = static_cast<int>(std::floor(r.extent_v() / spacing_m));
  const double u0 = 0.5 * (r.extent_u() - (nu - 1) * spacing_m),
               v0 = 0.5 * (r.extent_v() - (nv - 1) * spacing_m);
  for (int j = 0; j < nv; ++j) {
    for (int i = 0; i < nu; ++i) {
      const Vec2 c = r.At(u0 + i * spacing_m, v0 + j * spacing_m);
      const Polygon& poly = r.polygon();
      bool near_wall = !Inside(poly, c);
      for (std::size_t e = 0; e < poly.size() && !near_wall; ++e) {
        near_wall = SegmentDistance(c, poly[e], poly[(e + 1) % poly.size()]) < clear;
      }
      if (near_wall) continue;
      if (square) {
        r.Free(c, r.yaw_u(), 2 * radius_m, 2 * radius_m, ceiling_m, Material::kConcrete, 0.6);
      } else {
        r.Round(c, radius_m, ceiling_m, Material::kConcrete, 0.6);
      }
    }
  }
}

void FurnishRoom(RoomLayout& r, RoomUse use, double amount, double ceiling_m, Random& rng) {
  switch (use) {
    case RoomUse::kOffice:
      Office(r, amount, ceiling_m, rng);
      break;
    case RoomUse::kClassroom:
      Classroom(r, amount, rng);
      break;
    case RoomUse::kMeeting:
      Meeting(r, amount, rng);
      break;
    case RoomUse::kOpenPlan:
      PlaceDeskIslands(r, amount, rng);
      break;
    case RoomUse::kPatient:
      Patient(r, amount, rng);
      break;
    case RoomUse::kBath:
    case RoomUse::kWc:
      Bath(r, amount, rng);
      break;
    case RoomUse::kNurseStation:
      NurseStation(r, amount, ceiling_m, rng);
      break;
    case RoomUse::kHall:
      PlaceRacks(r, amount, ceiling_m, rng);
      break;
    case RoomUse::kStorage:
      Storage(r, amount, ceiling_m, rng);
      break;
    case RoomUse::kLiving:
      Living(r, amount, rng);
      break;
    case RoomUse::kBedroom:
      Bedroom(r, amount, rng);
      break;
    case RoomUse::kKitchen:
      Kitchen(r, amount, rng);
      break;
    case RoomUse::kBare:
      Bare(r, amount, rng);
      break;
    case RoomUse::kCorridor:
    case RoomUse::kLobby:
    case RoomUse::kHallway:
      Circulation(r, amount, rng);
      break;
  }
}

}  // namespace msgraphs::sim::building
