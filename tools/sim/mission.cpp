// SPDX-License-Identifier: MIT
#include "mission.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <numbers>
#include <set>
#include <sstream>
#include <tuple>

#include "nav_grid.hpp"
#include "random.hpp"
#include "room_visits.hpp"
#include "walker.hpp"

namespace msgraphs::sim {
namespace {

constexpr double kDegToRad = std::numbers::pi / 180.0;

struct RoomInfo {
  int world_index = 0;
  std::vector<Eigen::Vector2d> free;
  std::vector<Entrance> entrances;
  double area_m2 = 0;
  /// A robot can look into it from outside and walk on elsewhere without passing through it:
  /// it has an opening, and every other room stays reachable when it is closed off.
  bool peekable = false;
};

VisitKind DrawKind(const VisitKinds& w, bool allow_peek, Random& rng) {
  const double peek = allow_peek ? w.peek : 0.0;
  const double total = peek + w.partial + w.full;
  if (!(total > 0)) return VisitKind::kFull;
  const double u = rng.Uniform(0, total);
  if (u < peek) return VisitKind::kPeek;
  return u < peek + w.partial ? VisitKind::kPartial : VisitKind::kFull;
}

// One robot walking its visits.
class RobotWalk {
 public:
  RobotWalk(const World& world,
            const NavGrid& grid,
            const std::vector<RoomInfo>& rooms,
            const MissionConfig& config,
            Walker& walker,
            Random& rng)
      : world_(world), grid_(grid), rooms_(rooms), config_(config), walker_(walker), rng_(rng) {}

  // Walks one visit of rooms_[k]; false when nothing could be planned (nothing moved).
  // visit.points counts the points reached (the mission can end on the way).
  bool Do(std::size_t k, VisitKind kind, RoomExclusion avoid, Visit& visit) {
    const RoomInfo& room = rooms_[k];
    visit.room = world_.rooms[static_cast<std::size_t>(room.world_index)].id;
    visit.kind = kind;
    visit.start_s = walker_.now_s();
    visit.points = 0;
    bool moved = false;
    switch (kind) {
      case VisitKind::kPeek:
        moved = Peek(room, avoid, visit.points);
        break;
      case VisitKind::kPartial: {
        const Entrance* e = NearestEntrance(room.entrances, walker_.position());
        std::vector<Eigen::Vector2d> near;
        if (e != nullptr) {
          near = CellsNear(room.free, *e, config_.partial_reach_m, 0.6);
          if (near.empty()) near = CellsNear(room.free, *e, config_.partial_reach_m, 0.0);
        }
        if (near.empty()) near = room.free;
        const int count = 1 + rng_.Index(2);
        for (int i = 0; i < count; ++i) {
          const auto& goal =
              near[static_cast<std::size_t>(rng_.Index(static_cast<int>(near.size())))];
          moved = WalkTo(goal, avoid, visit.points) || moved;
        }
        break;
      }
      case VisitKind::kFull: {
        const int count = std::clamp(
            static_cast<int>(std::lround(room.area_m2 / config_.full_m2_per_point)), 3, 6);
        for (const auto& goal : CoverPoints(room.free, count, walker_.position()))
          moved = WalkTo(goal, avoid, visit.points) || moved;
        break;
      }
      case VisitKind::kStart:
        break;
    }
    visit.end_s = walker_.now_s();
    return moved;
  }

 private:
  // False when there is no path; `reached` counts the goal if the robot got there in time.
  bool WalkTo(const Eigen::Vector2d& goal, const RoomExclusion& avoid, int& reached) {
    const auto path = grid_.Plan(walker_.position(), goal, config_.robot_radius_m, avoid);
    if (path.size() < 2) return false;
    if (walker_.Follow(path)) ++reached;
    return true;
  }

  // Stands in (or just outside) the doorway without entering, looks in, turning left and
  // right, for a few seconds. False when no doorway could be reached; `reached` counts the
  // stand point if the robot got there in time.
  bool Peek(const RoomInfo& room, RoomExclusion avoid, int& reached) {
    avoid.b = avoid.a;
    avoid.a = room.world_index;  // never through the room it only looks into
    // Entrances nearest first: the first one with a stand point the robot can reach.
    std::vector<const Entrance*> order;
    for (const Entrance& e : room.entrances) order.push_back(&e);
    const Eigen::Vector2d from = walker_.position();
    std::sort(order.begin(), order.end(), [&](const Entrance* a, const Entrance* b) {
      return (a->centre - from).squaredNorm() < (b->centre - from).squaredNorm();
    });
    for (const Entrance* e : order) {
      Eigen::Vector2d stand;
      if (!PeekStandPoint(grid_, room.world_index, *e, config_.robot_radius_m,
                          config_.peek_stand_min_m, config_.peek_stand_max_m, rng_, stand))
        continue;
      const auto path = grid_.Plan(from, stand, config_.robot_radius_m, avoid);
      if (path.size() < 2) continue;
      if (!walker_.Follow(path)) return true;
      ++reached;
      const double in = std::atan2(e->inward.y(), e->inward.x());
      const double look_s = rng_.Uniform(config_.peek_look_min_s, config_.peek_look_max_s);
      const double sweep =
          rng_.Uniform(config_.peek_sweep_min_deg, config_.peek_sweep_max_deg) * kDegToRad;
      const double first = rng_.Chance(0.5) ? sweep : -sweep;  // left or right first
      for (const double yaw : {in, in + first, in - first, in}) {
        walker_.TurnTo(yaw);
        walker_.Hold(0.25 * look_s);
      }
      return true;
    }
    return false;
  }

  const World& world_;
  const NavGrid& grid_;
  const std::vector<RoomInfo>& rooms_;
  const MissionConfig& config_;
  Walker& walker_;
  Random& rng_;
};

double DrawDelay(const MissionConfig& config, int robot) {
  const StartDelays& d = config.start_delays;
  switch (d.mode) {
    case StartDelays::Mode::kNone:
      return 0.0;
    case StartDelays::Mode::kRandom: {
      Random r =
          Random::Stream(config.seed, 0x64656C61, static_cast<std::uint64_t>(robot));  // "dela"
      // Whole milliseconds: the value is written to mission.txt and read back by tools.
      return std::floor(r.Uniform(0, std::min(d.random_max_s, config.duration_s / 3.0)) * 1e3) /
             1e3;
    }
    case StartDelays::Mode::kExplicit: {
      const auto it = d.explicit_s.find(robot);
      return it == d.explicit_s.end() ? 0.0 : it->second;
    }
  }
  return 0.0;
}

}  // namespace

const char* ToString(VisitKind kind) {
  switch (kind) {
    case VisitKind::kStart:
      return "start";
    case VisitKind::kPeek:
      return "peek";
    case VisitKind::kPartial:
      return "partial";
    case VisitKind::kFull:
      return "full";
  }
  return "?";
}

std::optional<VisitKinds> VisitKinds::Parse(const std::string& text, std::string& error) {
  VisitKinds k{0, 0, 0};
  std::stringstream in(text);
  std::string item;
  while (std::getline(in, item, ',')) {
    const auto eq = item.find('=');
    char* end = nullptr;
    const double w = eq == std::string::npos ? -1 : std::strtod(item.c_str() + eq + 1, &end);
    const std::string name = item.substr(0, eq);
    if (eq == std::string::npos || end == nullptr || *end != '\0' || !(w >= 0) ||
        !std::isfinite(w) || (name != "peek" && name != "partial" && name != "full")) {
      error = "--visit-kinds takes peek=W,partial=W,full=W with weights >= 0, not '" + item + "'";
      return std::nullopt;
    }
    (name == "peek" ? k.peek : name == "partial" ? k.partial : k.full) = w;
  }
  if (!(k.peek + k.partial + k.full > 0)) {
    error = "--visit-kinds needs a weight above 0";
    return std::nullopt;
  }
  return k;
}

std::optional<StartDelays> StartDelays::Parse(const std::string& text, std::string& error) {
  StartDelays d;
  if (text == "none") return d;
  if (text == "random") {
    d.mode = Mode::kRandom;
    return d;
  }
  d.mode = Mode::kExplicit;
  std::stringstream in(text);
  std::string item;
  while (std::getline(in, item, ',')) {
    char* end = nullptr;
    const long robot = std::strtol(item.c_str(), &end, 10);
    double delay = -1;
    if (end != item.c_str() && *end == '=') {
      const char* v = end + 1;
      delay = std::strtod(v, &end);
      if (end == v || *end != '\0') delay = -1;
    }
    if (robot < 1 || robot > 10 || !(delay >= 0) || !std::isfinite(delay)) {
      error = "--start-delays takes random, none or ROBOT=SECONDS,..., not '" + item + "'";
      return std::nullopt;
    }
    d.explicit_s[static_cast<int>(robot)] = delay;
  }
  return d;
}

std::optional<Mission> PlanMission(const World& world,
                                   const Scene& scene,
                                   const MissionConfig& config,
                                   std::string& error) {
  if (config.robots < 1 || config.robots > 10) {
    error = "robots must be 1..10";
    return std::nullopt;
  }
  if (!(config.duration_s > 0) || config.duration_s > 3600) {
    error = "duration must be in (0, 3600] s";
    return std::nullopt;
  }
  if (config.people.count < 0 || config.people.count > 50) {
    error = "people must be 0..50";
    return std::nullopt;
  }
  for (const auto& [robot, delay] : config.start_delays.explicit_s) {
    if (robot > config.robots) {
      error = "a start delay for robot " + std::to_string(robot) + " of " +
              std::to_string(config.robots);
      return std::nullopt;
    }
  }
  const NavGrid grid(world, scene, config.level, 1.0);
  std::vector<RoomInfo> rooms;
  std::vector<int> room_index(world.rooms.size(), -1);  // world room -> rooms
  for (std::size_t r = 0; r < world.rooms.size(); ++r) {
    if (world.rooms[r].level != config.level) continue;
    RoomInfo info;
    info.world_index = static_cast<int>(r);
    info.free = grid.FreeCells(static_cast<int>(r), config.robot_radius_m + 0.2);
    if (info.free.size() < 4) continue;  // too cluttered or too small to walk into
    info.entrances = FindEntrances(grid, static_cast<int>(r), config.robot_radius_m);
    info.area_m2 = world.rooms[r].Area();
    room_index[r] = static_cast<int>(rooms.size());
    rooms.push_back(std::move(info));
  }
  for (RoomInfo& info : rooms) {
    if (info.entrances.empty()) continue;
    const RoomInfo& other = rooms[&info == &rooms[0] && rooms.size() > 1 ? 1 : 0];
    const auto reach = grid.ReachableRooms(other.free[other.free.size() / 2], config.robot_radius_m,
                                           {info.world_index, -1}, world.rooms.size());
    info.peekable = true;
    for (const RoomInfo& r : rooms) {
      if (&r != &info && !reach[static_cast<std::size_t>(r.world_index)]) info.peekable = false;
    }
  }
  if (config.shared_rooms < 0 ||
      static_cast<int>(rooms.size()) < std::max(2, config.shared_rooms)) {
    error = "fewer walkable rooms than the mission needs";
    return std::nullopt;
  }
  // Every walkable room must be reachable from the first one.
  for (std::size_t i = 1; i < rooms.size(); ++i) {
    if (grid.Plan(rooms[0].free[rooms[0].free.size() / 2], rooms[i].free[rooms[i].free.size() / 2],
                  config.robot_radius_m)
            .empty()) {
      error = "room '" + world.rooms[static_cast<std::size_t>(rooms[i].world_index)].id +
              "' is not reachable (doors too narrow?)";
      return std::nullopt;
    }
  }

  Random rng = Random::Stream(config.seed, 0x6D697373);  // "miss"
  Mission mission;
  mission.config = config;
  const int n_rooms = static_cast<int>(rooms.size());
  std::vector<int> order(rooms.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = static_cast<int>(i);
  for (std::size_t i = order.size() - 1; i > 0; --i)
    std::swap(order[i], order[static_cast<std::size_t>(rng.Index(static_cast<int>(i + 1)))]);
  const std::vector<int> shared(order.begin(), order.begin() + config.shared_rooms);
  for (int s : shared)
    mission.shared_rooms.push_back(
        world.rooms[static_cast<std::size_t>(rooms[static_cast<std::size_t>(s)].world_index)].id);
  const WalkerLimits limits{config.max_speed_mps, config.max_turn_rate_rps, config.max_accel_mps2};

  for (int id = 0; id < config.robots; ++id) {
    RobotPlan plan;
    plan.id = id + 1;
    plan.start_delay_s = DrawDelay(config, plan.id);
    const double walk_s = config.duration_s - plan.start_delay_s;
    if (!(walk_s >= 1.0)) {
      error = "robot " + std::to_string(plan.id) + " starts " + std::to_string(plan.start_delay_s) +
              " s into a " + std::to_string(config.duration_s) + " s mission (needs 1 s at least)";
      return std::nullopt;
    }
    plan.trajectory = Trajectory(0.01, scene.floor_z() + config.base_height_m);
    plan.trajectory.set_start_s(plan.start_delay_s);
    // Different start rooms where possible; start anywhere free, facing anywhere.
    const int start_room = order[static_cast<std::size_t>((config.shared_rooms + id) % n_rooms)];
    const auto& start_cells = rooms[static_cast<std::size_t>(start_room)].free;
    const Eigen::Vector2d p =
        start_cells[static_cast<std::size_t>(rng.Index(static_cast<int>(start_cells.size())))];
    plan.start = {p.x(), p.y(), rng.Uniform(-std::numbers::pi, std::numbers::pi)};
    plan.start_room = world
                          .rooms[static_cast<std::size_t>(
                              rooms[static_cast<std::size_t>(start_room)].world_index)]
                          .id;
    plan.rooms_visited.push_back(plan.start_room);
    plan.visits.push_back(
        {plan.start_room, VisitKind::kStart, plan.start_delay_s, plan.start_delay_s, 1});

    // The visit list: the shared rooms first (entered, in a random order: visits can be long,
    // and each pair must share them), two random rooms of any kind, then random rooms and kinds
    // until the mission ends.
    std::vector<std::pair<int, VisitKind>> visits;
    for (int s : shared) {
      // Drawn all the same, so that the random stream does not depend on the shared kind.
      const VisitKind drawn = DrawKind(config.visit_kinds, false, rng);
      visits.push_back({s, config.shared_visit_partial ? VisitKind::kPartial : drawn});
    }
    for (std::size_t i = visits.size(); i > 1; --i)
      std::swap(visits[i - 1], visits[static_cast<std::size_t>(rng.Index(static_cast<int>(i)))]);
    for (int k = 0; k < 2; ++k) {
      const int room = rng.Index(n_rooms);
      visits.push_back({room, DrawKind(config.visit_kinds, true, rng)});
    }

    plan.trajectory.Append(plan.start);
    Walker walker(plan.trajectory, limits, walk_s);
    RobotWalk walk(world, grid, rooms, config, walker, rng);
    walker.Hold(config.start_stand_s);
    int current = start_room;
    int last_peek = -1;  // world index of the room looked into last: the next visit avoids it
    std::size_t next_visit = 0;
    int stuck = 0;
    while (!walker.done() && stuck < 50) {
      int room = 0;
      VisitKind kind = VisitKind::kFull;
      if (next_visit < visits.size()) {
        std::tie(room, kind) = visits[next_visit++];
      } else {
        room = rng.Index(n_rooms);
        kind = DrawKind(config.visit_kinds, true, rng);
        // Not the room it is in, nor (where there is a choice) the one it just looked into.
        if ((room == current && n_rooms > 1) ||
            (rooms[static_cast<std::size_t>(room)].world_index == last_peek && n_rooms > 2))
          continue;
      }
      const RoomInfo& info = rooms[static_cast<std::size_t>(room)];
      // A robot looks into a room from outside only: not the one it stands in, nor one it could
      // not walk on from without passing through it (a hallway everything opens onto).
      if (kind == VisitKind::kPeek && (room == current || !info.peekable))
        kind = DrawKind(config.visit_kinds, false, rng);
      RoomExclusion avoid;
      if (last_peek != info.world_index) avoid.a = last_peek;
      Visit visit;
      if (!walk.Do(static_cast<std::size_t>(room), kind, avoid, visit)) {
        ++stuck;
        continue;
      }
      stuck = 0;
      last_peek = -1;
      visit.start_s += plan.start_delay_s;
      visit.end_s += plan.start_delay_s;
      plan.visits.push_back(visit);
      if (kind == VisitKind::kPeek) {
        last_peek = info.world_index;
        const int here = grid.RoomAt(walker.position());
        current = here >= 0 && room_index[static_cast<std::size_t>(here)] >= 0
                      ? room_index[static_cast<std::size_t>(here)]
                      : current;
        continue;
      }
      // Entered on purpose (unless the mission ended before the robot got in).
      const bool inside = grid.RoomAt(walker.position()) == info.world_index;
      if (room != current && inside) plan.rooms_visited.push_back(visit.room);
      if (inside) current = room;
    }
    // Stand still for the rest of the mission if the plan ran out early.
    while (plan.trajectory.duration_s() < walk_s)
      plan.trajectory.Append(plan.trajectory.samples().back());
    plan.gait = GaitParams::Draw(config.gait, config.seed, plan.id);
    plan.trajectory.SetGait(plan.gait);
    mission.robots.push_back(std::move(plan));
  }
  // Each pair must share at least `shared_rooms` rooms they actually entered.
  for (std::size_t a = 0; a < mission.robots.size(); ++a) {
    for (std::size_t b = a + 1; b < mission.robots.size(); ++b) {
      const std::set<std::string> ra(mission.robots[a].rooms_visited.begin(),
                                     mission.robots[a].rooms_visited.end());
      int common = 0;
      for (const auto& r : std::set<std::string>(mission.robots[b].rooms_visited.begin(),
                                                 mission.robots[b].rooms_visited.end()))
        common += static_cast<int>(ra.count(r));
      if (common < config.shared_rooms) {
        auto entered = [&](const RobotPlan& r) {
          std::string list;
          for (const auto& room : r.rooms_visited) list += " " + room;
          return list;
        };
        error = "robots " + std::to_string(a + 1) + " and " + std::to_string(b + 1) +
                " share only " + std::to_string(common) + " of the " +
                std::to_string(config.shared_rooms) +
                " rooms asked for (mission too short for this building?); they entered" +
                entered(mission.robots[a]) + ";" + entered(mission.robots[b]);
        return std::nullopt;
      }
    }
  }
  std::vector<std::vector<Eigen::Vector2d>> free;
  std::vector<int> world_rooms;
  for (const RoomInfo& r : rooms) {
    world_rooms.push_back(r.world_index);
    free.push_back(r.free);
  }
  mission.people =
      PlanPeople(world, grid, world_rooms, free, config.people, config.duration_s, config.seed);
  return mission;
}

}  // namespace msgraphs::sim
