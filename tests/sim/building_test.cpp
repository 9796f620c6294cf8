// SPDX-License-Identifier: MIT
// The building generator: deterministic, always valid and connected, covering every feature
// the benchmark needs across a seed range, honouring forced options, with identical rooms and
// mirrored wings that really are copies (checked on the written world, not on the generator's
// word), and missions planned in every style.
#include <gtest/gtest.h>

#include <chrono>
#include <cstdio>
#include <map>
#include <set>

#include "building/generate.hpp"
#include "building_checks.hpp"
#include "mission.hpp"
#include "scene.hpp"
#include "truth.hpp"
#include "world_writer.hpp"

namespace msgraphs::sim {
namespace {

using building::BuildingFeatures;
using building::BuildingOptions;
using building::GenerateBuilding;

constexpr std::uint64_t kSeeds = 300;

struct Generated {
  World world;
  BuildingFeatures features;
};

const Room* Find(const World& w, const std::string& id) {
  for (const Room& r : w.rooms) {
    if (r.id == id) return &r;
  }
  return nullptr;
}

int Index(const World& w, const Room* r) { return static_cast<int>(r - w.rooms.data()); }

// Does `q` hold the points of `p` mapped by `map` (same count, each within tol)?
template <typename Map>
bool SamePoints(const std::vector<Eigen::Vector2d>& p,
                const std::vector<Eigen::Vector2d>& q,
                Map map,
                double tol) {
  if (p.size() != q.size()) return false;
  for (const auto& a : p) {
    const Eigen::Vector2d m = map(a);
    if (std::none_of(q.begin(), q.end(),
                     [&](const Eigen::Vector2d& b) { return (b - m).norm() < tol; }))
      return false;
  }
  return true;
}

struct Thing {
  Eigen::Vector2d centre;
  double yaw_deg;  // modulo 180 (boxes are symmetric); -1 for cylinders
  Eigen::Vector3d size;
  Material material;
};

std::vector<Thing> ThingsIn(const World& w, const Room& r) {
  std::vector<Thing> out;
  for (const Box& b : w.boxes) {
    if (r.Contains(b.centre)) {
      out.push_back({b.centre, std::fmod(b.yaw_rad * 180.0 / std::numbers::pi + 360.0, 180.0),
                     b.size_m, b.material});
    }
  }
  for (const Cylinder& c : w.cylinders) {
    if (r.Contains(c.centre))
      out.push_back({c.centre, -1, {c.radius_m, c.radius_m, c.height_m}, c.material});
  }
  return out;
}

// The other room's furniture is this room's mapped by (point map, yaw map).
template <typename Map, typename YawMap>
bool SameThings(const std::vector<Thing>& a, const std::vector<Thing>& b, Map map, YawMap yaw_map) {
  if (a.size() != b.size()) return false;
  for (const Thing& t : a) {
    const Eigen::Vector2d c = map(t.centre);
    const bool found = std::any_of(b.begin(), b.end(), [&](const Thing& u) {
      if ((u.centre - c).norm() > 2e-3 || (u.size - t.size).norm() > 1e-6 ||
          u.material != t.material)
        return false;
      if (t.yaw_deg < 0) return u.yaw_deg < 0;
      const double d = std::fabs(std::remainder(u.yaw_deg - yaw_map(t.yaw_deg), 180.0));
      return d < 1e-2 || (std::fabs(t.size.x() - t.size.y()) < 1e-9 && std::fabs(d - 90) < 1e-2);
    });
    if (!found) return false;
  }
  return true;
}

// Door centres on a room's outline (either side of the door).
std::vector<Eigen::Vector2d> DoorsOf(const World& w, int room) {
  std::vector<Eigen::Vector2d> out;
  for (const auto& j : test::DoorJoins(w)) {
    if (j.a == room || j.b == room) {
      out.push_back(j.wall->start +
                    j.wall->direction() * (j.door->offset_m + 0.5 * j.door->width_m));
    }
  }
  return out;
}

TEST(BuildingGenerator, SameSeedSameBytesAndSeedsDiffer) {
  std::set<std::string> distinct;
  for (std::uint64_t seed = 1; seed <= 20; ++seed) {
    BuildingFeatures f1, f2;
    const std::string a = WriteWorld(GenerateBuilding(seed, {}, &f1));
    const std::string b = WriteWorld(GenerateBuilding(seed, {}, &f2));
    ASSERT_EQ(a, b) << "seed " << seed;
    EXPECT_EQ(building::WriteFeatures(f1), building::WriteFeatures(f2));
    distinct.insert(a);
  }
  EXPECT_EQ(distinct.size(), 20u);
  // Forcing one choice leaves the others where the seed put them.
  BuildingFeatures plain, turned;
  GenerateBuilding(11, {}, &plain);
  BuildingOptions o;
  o.rotation_deg = 12.5;
  GenerateBuilding(11, o, &turned);
  EXPECT_EQ(plain.style, turned.style);
  EXPECT_EQ(plain.rooms, turned.rooms);
  EXPECT_EQ(turned.rotation_deg, 12.5);
}

void CheckValidConnectedAndBounded(const Generated& g) {
  {
    const World& w = g.world;
    const std::uint64_t seed = g.features.seed;
    ParseError error;
    EXPECT_TRUE(ParseWorld(WriteWorld(w), error).has_value())
        << "seed " << seed << ": line " << error.line << ": " << error.reason;
    EXPECT_GE(w.rooms.size(), 2u) << seed;
    EXPECT_LE(w.rooms.size(), static_cast<std::size_t>(building::kMaxRooms)) << seed;
    EXPECT_TRUE(test::DoorsConnectEveryRoom(w)) << "seed " << seed;
    EXPECT_EQ(test::OverlapSamples(w, 0.5), 0) << "seed " << seed;
    const Eigen::Vector2d extent = test::Extent(w, g.features.rotation_deg);
    EXPECT_LE(extent.maxCoeff(), building::kMaxFootprint_m + 1e-6) << seed;
    // Every point is within 100 m of the building's centre (the origin).
    for (const Room& r : w.rooms) {
      for (const auto& p : r.polygon) EXPECT_LT(p.norm(), 100.0) << seed;
    }
    for (const Cylinder& c : w.cylinders) EXPECT_NE(w.RoomAt(c.centre, 0), nullptr) << seed;
    // Every door joins two rooms (none leads outside), and nothing stands in a doorway.
    for (const auto& j : test::DoorJoins(w)) {
      EXPECT_TRUE(j.a >= 0 && j.b >= 0 && j.a != j.b) << "seed " << seed << " wall " << j.wall->id;
      const Eigen::Vector2d c =
          j.wall->start + j.wall->direction() * (j.door->offset_m + 0.5 * j.door->width_m);
      for (const Box& b : w.boxes) EXPECT_GT((b.centre - c).norm(), 0.5) << "seed " << seed;
    }
  }
}

void CountFeatures(const Generated& g, std::map<std::string, int>& seen, std::set<int>& styles) {
  {
    const World& w = g.world;
    const BuildingFeatures& f = g.features;
    styles.insert(static_cast<int>(f.style));
    const double ceiling = *w.levels[0].ceiling_height_m;
    if (ceiling == 6.0) ++seen["6 m ceiling"];
    if (ceiling == 2.3) ++seen["2.3 m ceiling"];
    bool axis_aligned = false;
    std::set<long> angles;
    for (const Wall& wall : w.walls) {
      const double a = test::WallAngleDeg(wall);
      axis_aligned |= std::fabs(std::remainder(a, 90.0)) < 0.05;
      angles.insert(std::lround(a * 100));
      for (const Door& d : wall.doors) {
        if (d.height_m == wall.height_m) ++seen["door without lintel"];
        if (d.height_m < wall.height_m) ++seen["door with lintel"];
        if (d.width_m <= 0.8) ++seen["0.8 m door"];
        if (d.width_m >= 2.4) ++seen["2.4 m+ opening"];
      }
    }
    if (!axis_aligned) ++seen["rotation not a multiple of 90"];
    for (long a : angles) {
      for (long b : angles) {
        const double d = std::fabs(std::remainder(static_cast<double>(a - b) / 100.0, 180.0));
        if (std::fabs(d - 45.0) < 0.02) ++seen["45 degree wing"];
        if (std::fabs(d - 30.0) < 0.02) ++seen["30 degree wing"];
      }
    }
    for (const Room& r : w.rooms) {
      const RoomRectangle rect = MinAreaRectangle(r);
      if (std::fabs(rect.width_m - 2.0) < 0.01 && std::fabs(rect.length_m - 2.0) < 0.01)
        ++seen["2 x 2 room"];
      if (rect.width_m > 29.99 && rect.length_m > 39.99) ++seen["30 x 40 hall"];
      bool right_angles = r.polygon.size() == 6;
      for (std::size_t i = 0; right_angles && i < 6; ++i) {
        const auto a = (r.polygon[(i + 1) % 6] - r.polygon[i]).normalized(),
                   b = (r.polygon[(i + 2) % 6] - r.polygon[(i + 1) % 6]).normalized();
        right_angles = std::fabs(a.dot(b)) < 1e-3;
      }
      if (right_angles) ++seen["L-shaped room"];
      const auto things = ThingsIn(w, r);
      const auto metal = std::count_if(things.begin(), things.end(), [](const Thing& t) {
        return t.material == Material::kMetal && t.size.x() >= 2.7;
      });
      if (r.name == "hall" && metal >= 4) ++seen["hall with rack rows"];
      if (r.name == "open_plan" && things.size() >= 4) ++seen["open-plan hall with desks"];
    }
    // A corridor with doors into rooms on both of its sides.
    for (std::size_t c = 0; c < w.rooms.size(); ++c) {
      if (w.rooms[c].name != "corridor") continue;
      std::vector<Eigen::Vector2d> out;
      for (const auto& j : test::DoorJoins(w)) {
        const int other = j.a == static_cast<int>(c) ? j.b : j.b == static_cast<int>(c) ? j.a : -1;
        if (other < 0 || w.rooms[static_cast<std::size_t>(other)].name == "corridor") continue;
        out.push_back((j.a == static_cast<int>(c) ? -1.0 : 1.0) * j.wall->normal());
      }
      bool both = false;
      for (const auto& a : out) {
        for (const auto& b : out) both |= a.dot(b) < -0.999;
      }
      if (both) ++seen["double-loaded corridor"];
    }
    // Corridors joined in a ring: the doors between corridor rooms close a cycle.
    {
      int corridor_rooms = 0, corridor_doors = 0;
      for (const Room& r : w.rooms) corridor_rooms += r.name == "corridor" ? 1 : 0;
      for (const auto& j : test::DoorJoins(w)) {
        if (j.a >= 0 && j.b >= 0 && w.rooms[static_cast<std::size_t>(j.a)].name == "corridor" &&
            w.rooms[static_cast<std::size_t>(j.b)].name == "corridor") {
          ++corridor_doors;
        }
      }
      if (corridor_rooms >= 2 && corridor_doors >= corridor_rooms &&
          f.corridor == building::CorridorShape::kLoop)
        ++seen["loop corridor"];
    }
    if (f.corridor == building::CorridorShape::kL) ++seen["L corridor"];
    if (f.corridor == building::CorridorShape::kT) ++seen["T corridor"];
    if (f.corridor == building::CorridorShape::kU) ++seen["U corridor"];
    if (!f.mirror_pairs.empty()) ++seen["mirrored wing"];
    if (!f.identical_groups.empty()) ++seen["identical-room row"];
    if (w.boxes.empty() && w.cylinders.empty()) ++seen["no clutter"];
    if (f.clutter == building::Clutter::kDense && w.boxes.size() + w.cylinders.size() > 40)
      ++seen["dense clutter"];
  }
}

void ExpectEveryFeature(std::map<std::string, int>& seen, const std::set<int>& styles) {
  for (const char* feature : {"6 m ceiling",
                              "2.3 m ceiling",
                              "door without lintel",
                              "door with lintel",
                              "0.8 m door",
                              "2.4 m+ opening",
                              "rotation not a multiple of 90",
                              "45 degree wing",
                              "30 degree wing",
                              "2 x 2 room",
                              "30 x 40 hall",
                              "L-shaped room",
                              "hall with rack rows",
                              "open-plan hall with desks",
                              "double-loaded corridor",
                              "loop corridor",
                              "L corridor",
                              "T corridor",
                              "U corridor",
                              "mirrored wing",
                              "identical-room row",
                              "no clutter",
                              "dense clutter"}) {
    EXPECT_GT(seen[feature], 0) << feature << " never appears in seeds 1.." << kSeeds;
  }
  EXPECT_EQ(styles.size(), static_cast<std::size_t>(building::kStyleCount));
}

// Identical rooms are translated copies with the same doors and furniture.
void CheckIdentical(const Generated& g, int& groups, int& copies) {
  {
    const World& w = g.world;
    for (const auto& group : g.features.identical_groups) {
      ASSERT_GE(group.size(), 2u);
      const Room* original = Find(w, group[0]);
      ASSERT_NE(original, nullptr);
      const auto things = ThingsIn(w, *original);
      const auto doors = DoorsOf(w, Index(w, original));
      ++groups;
      for (std::size_t k = 1; k < group.size(); ++k) {
        const Room* copy = Find(w, group[k]);
        ASSERT_NE(copy, nullptr);
        const Eigen::Vector2d shift = copy->Centroid() - original->Centroid();
        auto map = [&](const Eigen::Vector2d& p) { return Eigen::Vector2d(p + shift); };
        const std::string where =
            "seed " + std::to_string(g.features.seed) + " " + group[0] + " / " + group[k];
        EXPECT_TRUE(SamePoints(original->polygon, copy->polygon, map, 2e-3)) << where;
        EXPECT_TRUE(SamePoints(doors, DoorsOf(w, Index(w, copy)), map, 2e-3)) << where << ": doors";
        EXPECT_TRUE(SameThings(things, ThingsIn(w, *copy), map, [](double y) { return y; }))
            << where << ": furniture";
        ++copies;
      }
    }
  }
}

// Mirrored wings are mirror images about one axis (outlines, doors, furniture).
void CheckMirrored(const Generated& g, int& buildings) {
  {
    const World& w = g.world;
    const auto& pairs = g.features.mirror_pairs;
    if (pairs.empty()) return;
    ++buildings;
    // The axis: the perpendicular bisector of the first pair whose centroids differ.
    Eigen::Vector2d m(0, 0), n(1, 0);
    for (const auto& [a, b] : pairs) {
      const Eigen::Vector2d ca = Find(w, a)->Centroid(), cb = Find(w, b)->Centroid();
      if ((cb - ca).norm() > 0.5) {
        m = 0.5 * (ca + cb);
        n = (cb - ca).normalized();
        break;
      }
    }
    auto reflect = [&](const Eigen::Vector2d& p) {
      return Eigen::Vector2d(p - 2.0 * (p - m).dot(n) * n);
    };
    const double axis_deg =
        std::atan2(n.x(), -n.y()) * 180.0 / std::numbers::pi;  // the axis direction
    for (const auto& [a, b] : pairs) {
      const Room* ra = Find(w, a);
      const Room* rb = Find(w, b);
      const std::string where = "seed " + std::to_string(g.features.seed) + " " + a + " / " + b;
      EXPECT_TRUE(SamePoints(ra->polygon, rb->polygon, reflect, 2e-3)) << where;
      EXPECT_TRUE(SamePoints(DoorsOf(w, Index(w, ra)), DoorsOf(w, Index(w, rb)), reflect, 2e-3))
          << where << ": doors";
      EXPECT_TRUE(SameThings(ThingsIn(w, *ra), ThingsIn(w, *rb), reflect,
                             [&](double y) { return 2 * axis_deg - y; }))
          << where << ": furniture";
    }
  }
}

// Seeds 1..300 (generated once: ctest runs each test case in its own process).
// The bytes of three buildings, as written on the machine that recorded them (FNV-1a 64 of the
// world file). Another machine, compiler or C library must give the same: that is the
// generator's promise. A deliberate change of the generator changes them: record the new
// values (msgraphs_sim --building N --world-out b.world, then hash b.world) in that commit.
TEST(BuildingGenerator, WrittenBytesMatchTheRecordedDigests) {
  const std::pair<std::uint64_t, std::uint64_t> recorded[] = {
      {1, 0x8dd50d937308e360ull}, {2, 0x3daabb48f3e9120cull}, {3, 0x08c8aa7c35bcbeeeull}};
  for (const auto& [seed, digest] : recorded) {
    std::uint64_t h = 0xcbf29ce484222325ull;
    for (const char c : WriteWorld(GenerateBuilding(seed, {}))) {
      h = (h ^ static_cast<unsigned char>(c)) * 0x100000001b3ull;
    }
    EXPECT_EQ(h, digest) << "seed " << seed;
  }
}

TEST(BuildingGenerator, SeedRangeIsValidCoversEveryFeatureAndKeepsItsSymmetries) {
  std::map<std::string, int> seen;
  std::set<int> styles;
  int groups = 0, copies = 0, mirrored = 0;
  const auto t0 = std::chrono::steady_clock::now();
  for (std::uint64_t seed = 1; seed <= kSeeds; ++seed) {
    Generated g;
    g.world = GenerateBuilding(seed, {}, &g.features);
    CheckValidConnectedAndBounded(g);
    CountFeatures(g, seen, styles);
    CheckIdentical(g, groups, copies);
    CheckMirrored(g, mirrored);
  }
  ExpectEveryFeature(seen, styles);
  EXPECT_GT(groups, 20);
  EXPECT_GT(copies, 60);
  EXPECT_GT(mirrored, 10);
  std::printf("%llu buildings in %.2f s: %d identical groups (%d copies), %d with mirrored wings\n",
              static_cast<unsigned long long>(kSeeds),
              std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), groups,
              copies, mirrored);
}

TEST(BuildingGenerator, ForcedOptionsAreHonoured) {
  using namespace building;
  for (int s = 0; s < kStyleCount; ++s) {
    BuildingOptions o;
    o.style = static_cast<Style>(s);
    o.rotation_deg = 33.3;
    o.clutter = Clutter::kNone;
    o.ceiling_m = 4.2;
    BuildingFeatures f;
    const World w = GenerateBuilding(5, o, &f);
    EXPECT_EQ(f.style, *o.style);
    EXPECT_EQ(f.clutter, Clutter::kNone);
    EXPECT_TRUE(w.boxes.empty() && w.cylinders.empty()) << ToString(*o.style);
    EXPECT_EQ(*w.levels[0].ceiling_height_m, 4.2);
    for (const Wall& wall : w.walls) EXPECT_EQ(wall.height_m, 4.2);
    // Walls run along the building's axes (its main block), turned by 33.3 degrees.
    int along = 0;
    for (const Wall& wall : w.walls)
      along += std::fabs(std::remainder(test::WallAngleDeg(wall) - 33.3, 90.0)) < 0.01 ? 1 : 0;
    EXPECT_GT(along, static_cast<int>(w.walls.size()) / 4) << ToString(*o.style);
  }
  for (CorridorShape shape : {CorridorShape::kStraight, CorridorShape::kL, CorridorShape::kT,
                              CorridorShape::kU, CorridorShape::kLoop}) {
    BuildingOptions o;
    o.style = Style::kOffice;
    o.corridor = shape;
    BuildingFeatures f;
    GenerateBuilding(9, o, &f);
    EXPECT_EQ(f.corridor, shape);
  }
  BuildingOptions mirrored;
  mirrored.symmetry = Symmetry::kBoth;
  mirrored.wing_angle_deg = 45;
  mirrored.style = Style::kHospital;
  BuildingFeatures f;
  GenerateBuilding(3, mirrored, &f);
  EXPECT_EQ(f.symmetry, Symmetry::kBoth);
  EXPECT_FALSE(f.mirror_pairs.empty());
  EXPECT_FALSE(f.identical_groups.empty());
  ASSERT_FALSE(f.wing_angles_deg.empty());
  EXPECT_EQ(f.wing_angles_deg[0], 45);
  // Combinations that cannot be built are refused with a reason.
  BuildingOptions bad;
  bad.style = Style::kWarehouse;
  bad.symmetry = Symmetry::kMirroredWings;
  EXPECT_NE(CheckOptions(bad), "");
  bad = {};
  bad.ceiling_m = 7;
  EXPECT_NE(CheckOptions(bad), "");
  bad = {};
  bad.wing_angle_deg = 50;
  EXPECT_NE(CheckOptions(bad), "");
  std::string error;
  BuildingOptions parsed;
  EXPECT_FALSE(SetOption("--style", "castle", parsed, error));
  EXPECT_NE(error.find("castle"), std::string::npos);
  EXPECT_TRUE(SetOption("--corridor", "loop", parsed, error));
  EXPECT_EQ(parsed.corridor, CorridorShape::kLoop);
}

TEST(BuildingGenerator, FeatureSummaryDescribesTheWorld) {
  BuildingFeatures f;
  const World w = GenerateBuilding(7, {}, &f);
  const std::string text = building::WriteFeatures(f);
  EXPECT_EQ(text.rfind("msgraphs-building 1\nseed 7\n", 0), 0u);
  EXPECT_NE(text.find("rooms " + std::to_string(w.rooms.size()) + "\n"), std::string::npos);
  EXPECT_NE(text.find(std::string("style ") + building::ToString(f.style) + "\n"),
            std::string::npos);
  int doors = 0;
  for (const Wall& wall : w.walls) doors += static_cast<int>(wall.doors.size());
  EXPECT_EQ(f.doors, doors);
}

// A 2-robot, 120 s mission plans in a building of every style (and every pair of robots
// shares the two rooms the planner asks for).
TEST(BuildingMissions, EveryStylePlansATwoRobotMission) {
  for (int s = 0; s < building::kStyleCount; ++s) {
    BuildingOptions o;
    o.style = static_cast<building::Style>(s);
    const World w = GenerateBuilding(100 + static_cast<std::uint64_t>(s), o);
    const Scene scene(w, 0);
    MissionConfig config;
    config.robots = 2;
    config.duration_s = 120;
    config.seed = 3;
    std::string error;
    const auto mission = PlanMission(w, scene, config, error);
    ASSERT_TRUE(mission.has_value()) << building::ToString(*o.style) << ": " << error;
    for (const RobotPlan& r : mission->robots)
      EXPECT_GT(r.trajectory.PathLength(120), 20.0) << building::ToString(*o.style);
  }
}

}  // namespace
}  // namespace msgraphs::sim
