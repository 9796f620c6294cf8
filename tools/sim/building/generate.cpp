// SPDX-License-Identifier: MIT
#include "generate.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <set>

#include "choices.hpp"
#include "doors.hpp"
#include "furnish.hpp"
#include "styles.hpp"
#include "symmetry.hpp"
#include "walls.hpp"
#include "world_writer.hpp"

namespace msgraphs::sim::building {
namespace {

constexpr std::uint64_t kLayoutStream = 0x6C61796F;  // "layo"
constexpr int kMaxAttempts = 12;
constexpr double kShrinkPerAttempt = 0.9;

double Quantised(double v) { return std::round(v * 1e4) / 1e4; }  // 0.1 mm
Vec2 Quantised(const Vec2& p) { return {Quantised(p.x()), Quantised(p.y())}; }

double Amount(Clutter c) {
  switch (c) {
    case Clutter::kNone:
      return 0.0;
    case Clutter::kSparse:
      return 0.35;
    case Clutter::kMedium:
      return 0.7;
    case Clutter::kDense:
      return 1.0;
  }
  return 0.0;
}

bool SegmentsCross(const Vec2& a, const Vec2& b, const Vec2& c, const Vec2& d) {
  const double eps = 1e-9;
  const double d1 = Cross(b - a, c - a), d2 = Cross(b - a, d - a);
  const double d3 = Cross(d - c, a - c), d4 = Cross(d - c, b - c);
  return ((d1 > eps && d2 < -eps) || (d1 < -eps && d2 > eps)) &&
         ((d3 > eps && d4 < -eps) || (d3 < -eps && d4 > eps));
}

// Distance from p to a polygon's outline.
double OutlineDistance(const Polygon& poly, const Vec2& p) {
  double best = 1e18;
  for (std::size_t i = 0; i < poly.size(); ++i)
    best = std::min(best, SegmentDistance(p, poly[i], poly[(i + 1) % poly.size()]));
  return best;
}

// Rooms overlap when outlines cross or a corner of one lies well inside the other (rooms
// that only share walls do neither).
bool RoomsOverlap(const Plan& plan) {
  const auto& rooms = plan.rooms;
  std::vector<std::pair<Vec2, Vec2>> box;
  for (const PlanRoom& r : rooms) {
    Vec2 lo(1e18, 1e18), hi(-1e18, -1e18);
    for (const Vec2& p : r.polygon) {
      lo = lo.cwiseMin(p);
      hi = hi.cwiseMax(p);
    }
    box.emplace_back(lo, hi);
  }
  for (std::size_t a = 0; a < rooms.size(); ++a) {
    for (std::size_t b = a + 1; b < rooms.size(); ++b) {
      if ((box[a].first.array() > box[b].second.array() - 1e-6).any() ||
          (box[b].first.array() > box[a].second.array() - 1e-6).any()) {
        continue;
      }
      const Polygon& A = rooms[a].polygon;
      const Polygon& B = rooms[b].polygon;
      for (std::size_t i = 0; i < A.size(); ++i) {
        for (std::size_t j = 0; j < B.size(); ++j) {
          if (SegmentsCross(A[i], A[(i + 1) % A.size()], B[j], B[(j + 1) % B.size()])) return true;
        }
      }
      for (const Vec2& p : A) {
        if (Inside(B, p) && OutlineDistance(B, p) > 1e-6) return true;
      }
      for (const Vec2& p : B) {
        if (Inside(A, p) && OutlineDistance(A, p) > 1e-6) return true;
      }
      // Identical outlines, or one inside the other touching: test a point inside each.
      const Vec2 ca = (A[0] + A[1] + A[2]) / 3.0;
      if (Inside(A, ca) && Inside(B, ca) && OutlineDistance(B, ca) > 1e-6) return true;
    }
  }
  return false;
}

// Drops room r from the copies (identical groups, mirror pairs): its doors or furniture could
// not be where the original's are.
void Uncopy(Plan& plan, int r) {
  PlanRoom& room = plan.rooms[static_cast<std::size_t>(r)];
  room.copy_of = -1;
  if (room.identical_group >= 0) {
    auto& g = plan.identical_groups[static_cast<std::size_t>(room.identical_group)];
    g.erase(std::remove(g.begin(), g.end(), r), g.end());
    room.identical_group = -1;
  }
  plan.mirror_pairs.erase(std::remove_if(plan.mirror_pairs.begin(), plan.mirror_pairs.end(),
                                         [&](const auto& p) { return p.second == r; }),
                          plan.mirror_pairs.end());
}

std::string RoomId(int index) { return "R" + std::to_string(index + 1); }

World ToWorld(const Plan& plan,
              const std::vector<PlanWall>& walls,
              const std::vector<Item>& items,
              double rotation_deg,
              const Vec2& centre,
              const std::string& name) {
  // Rotate about the footprint's centre, which goes to the origin.
  const Affine2 G =
      Affine2::Rotation(rotation_deg * std::numbers::pi / 180.0) * Affine2::Translation(-centre);
  World w;
  w.name = name;
  w.levels.push_back({0, 0.0, plan.ceiling_m});
  for (const PlanWall& pw : walls) {
    Wall wall = pw.wall;
    wall.start = Quantised(G(wall.start));
    wall.end = Quantised(G(wall.end));
    w.walls.push_back(std::move(wall));
  }
  for (std::size_t r = 0; r < plan.rooms.size(); ++r) {
    Room room;
    room.id = RoomId(static_cast<int>(r));
    room.name = ToString(plan.rooms[r].use);
    for (const Vec2& p : plan.rooms[r].polygon) room.polygon.push_back(Quantised(G(p)));
    w.rooms.push_back(std::move(room));
  }
  for (const Item& item : items) {
    if (item.round) {
      w.cylinders.push_back({Quantised(G(item.centre)), Quantised(0.5 * item.size_x_m),
                             Quantised(item.height_m), 0, item.material});
      continue;
    }
    // Yaw in degrees on the file's 1e-4 degree grid, in [0, 180) (a box is symmetric).
    double deg = G.MapAngle(item.yaw_rad) * 180.0 / std::numbers::pi;
    deg = std::fmod(std::fmod(deg, 180.0) + 180.0, 180.0);
    deg = std::round(deg * 1e4) / 1e4;
    if (deg >= 180.0) deg -= 180.0;
    w.boxes.push_back(
        {Quantised(G(item.centre)),
         deg * (std::numbers::pi / 180.0),
         {Quantised(item.size_x_m), Quantised(item.size_y_m), Quantised(item.height_m)},
         0,
         item.material});
  }
  return w;
}

}  // namespace

World GenerateBuilding(std::uint64_t seed,
                       const BuildingOptions& options,
                       BuildingFeatures* features) {
  const Choices base = Resolve(seed, options);
  World world;
  std::vector<std::string> rejected;  // why earlier attempts were drawn again
  for (int attempt = 0; attempt < kMaxAttempts; ++attempt) {
    Choices c = base;
    c.scale = std::pow(kShrinkPerAttempt, attempt);
    Random rng = Random::Stream(seed, kLayoutStream, static_cast<std::uint64_t>(attempt));
    Plan plan;
    std::string error;
    auto reject = [&](const std::string& why) { rejected.push_back(why); };
    if (!BuildStyle(c, rng, plan, error) || plan.broken) {
      reject("layout: " +
             (error.empty() ? std::string("a room is not one simple polygon") : error));
      continue;
    }
    if (static_cast<int>(plan.rooms.size()) > kMaxRooms || plan.rooms.empty()) {
      reject(std::to_string(plan.rooms.size()) + " rooms");
      continue;
    }
    Vec2 lo(1e18, 1e18), hi(-1e18, -1e18);
    for (const PlanRoom& r : plan.rooms) {
      for (const Vec2& p : r.polygon) {
        lo = lo.cwiseMin(p);
        hi = hi.cwiseMax(p);
      }
    }
    if ((hi - lo).maxCoeff() > kMaxFootprint_m) {
      reject("footprint " + std::to_string(static_cast<int>((hi - lo).maxCoeff())) + " m");
      continue;
    }
    if (RoomsOverlap(plan)) {
      reject("wings overlap");
      continue;
    }
    std::vector<PlanWall> walls;
    if (!BuildWalls(plan, walls, error)) {
      reject("walls: " + error);
      continue;
    }
    DoorPlacer placer(plan, walls);
    placer.PlaceAll();
    if (!placer.ConnectAll(error)) {
      reject("doors: " + error);
      continue;
    }
    for (int c_index : placer.displaced())
      Uncopy(plan, plan.connections[static_cast<std::size_t>(c_index)].a);
    for (int c_index : placer.failed()) {
      const Connection& con = plan.connections[static_cast<std::size_t>(c_index)];
      Uncopy(plan, con.a);
      if (con.b >= 0) Uncopy(plan, con.b);
    }
    // A copy whose original lost its copy status keeps its own geometry but not the claim.
    FurnishReport report;
    const auto room_items = Furnish(plan, walls, placer.doors(), Amount(c.clutter), seed, report);
    if (!report.unwalkable_rooms.empty()) {
      const PlanRoom& r = plan.rooms[static_cast<std::size_t>(report.unwalkable_rooms.front())];
      reject(std::string("unwalkable ") + ToString(r.use));
      continue;
    }
    KeepVerifiedCopies(plan, placer.doors(), room_items);
    std::vector<Item> items;
    for (const auto& list : room_items) items.insert(items.end(), list.begin(), list.end());

    const Vec2 centre(SnapCm(0.5 * (lo.x() + hi.x())), SnapCm(0.5 * (lo.y() + hi.y())));
    const std::string name = std::string("Generated ") + ToString(c.style) + " building (" +
                             plan.name + "), seed " + std::to_string(seed);
    world = ToWorld(plan, walls, items, c.rotation_deg, centre, name);
    ParseError parse_error;
    if (!ParseWorld(WriteWorld(world), parse_error)) {
      reject("invalid world: " + parse_error.reason);
      continue;
    }

    if (features != nullptr) {
      BuildingFeatures& f = *features;
      f = BuildingFeatures{};
      f.seed = seed;
      f.style = c.style;
      f.corridor = plan.corridor;
      f.clutter = c.clutter;
      f.rotation_deg = c.rotation_deg;
      f.wing_angles_deg = plan.wing_angles_deg;
      f.footprint_width_m = std::min(hi.x() - lo.x(), hi.y() - lo.y());
      f.footprint_length_m = std::max(hi.x() - lo.x(), hi.y() - lo.y());
      for (const auto& g : plan.identical_groups) {
        if (g.size() < 2) continue;
        std::vector<std::string> ids;
        for (int r : g) ids.push_back(RoomId(r));
        f.identical_groups.push_back(std::move(ids));
      }
      for (const auto& [a, b] : plan.mirror_pairs)
        f.mirror_pairs.emplace_back(RoomId(a), RoomId(b));
      const bool rows = !f.identical_groups.empty(), mirror = !f.mirror_pairs.empty();
      f.symmetry = rows && mirror ? Symmetry::kBoth
                   : rows         ? Symmetry::kIdenticalRow
                   : mirror       ? Symmetry::kMirroredWings
                                  : Symmetry::kNone;
      f.attempts = attempt + 1;
      f.rejected = rejected;
      MeasureWorld(world, f);
    }
    return world;
  }
  // Every attempt failed (no seed in seeds 1..300 gets here): the plainest building, and
  // failing that two rooms and a door.
  BuildingOptions plain;
  plain.style = Style::kOffice;
  plain.corridor = CorridorShape::kStraight;
  plain.symmetry = Symmetry::kNone;
  plain.clutter = Clutter::kNone;
  plain.rotation_deg = options.rotation_deg;
  if (!(options.style == plain.style && options.corridor == plain.corridor &&
        options.clutter == plain.clutter && options.symmetry == plain.symmetry)) {
    return GenerateBuilding(seed, plain, features);
  }
  world = World{};
  world.name = "Generated fallback building (two rooms), seed " + std::to_string(seed);
  world.levels.push_back({0, 0.0, 3.0});
  auto wall = [&](const char* id, double x1, double y1, double x2, double y2, double t) {
    world.walls.push_back({id, {x1, y1}, {x2, y2}, t, 3.0, 0, Material::kPainted, {}});
  };
  wall("e1", -6, -3, 6, -3, 0.3);
  wall("e2", 6, -3, 6, 3, 0.3);
  wall("e3", 6, 3, -6, 3, 0.3);
  wall("e4", -6, 3, -6, -3, 0.3);
  wall("i1", 0, -3, 0, 3, 0.12);
  world.walls.back().doors.push_back({2.5, 1.0, 2.1});
  world.rooms.push_back({"R1", "office", 0, {{-6, -3}, {0, -3}, {0, 3}, {-6, 3}}});
  world.rooms.push_back({"R2", "office", 0, {{0, -3}, {6, -3}, {6, 3}, {0, 3}}});
  if (features != nullptr) {
    *features = BuildingFeatures{};
    features->seed = seed;
    features->attempts = 2 * kMaxAttempts;
    features->rejected = rejected;
    features->footprint_width_m = 6;
    features->footprint_length_m = 12;
    MeasureWorld(world, *features);
  }
  return world;
}

}  // namespace msgraphs::sim::building
