// SPDX-License-Identifier: MIT
#include "mission.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <queue>
#include <set>

#include "random.hpp"

namespace msgraphs::sim {
namespace {

constexpr double kCell = 0.1;  // planning grid resolution, metres

// Clearance of every grid cell from obstacles in the robot's height band.
class NavGrid {
 public:
  NavGrid(const World& world, const Scene& scene, int level, double body_top_m) {
    Eigen::Vector2d lo(1e9, 1e9), hi(-1e9, -1e9);
    for (const Room& r : world.rooms) {
      if (r.level != level) continue;
      for (const auto& p : r.polygon) {
        lo = lo.cwiseMin(p);
        hi = hi.cwiseMax(p);
      }
    }
    origin_ = lo;
    nx_ = static_cast<int>(std::ceil((hi.x() - lo.x()) / kCell)) + 1;
    ny_ = static_cast<int>(std::ceil((hi.y() - lo.y()) / kCell)) + 1;
    clearance_.assign(static_cast<std::size_t>(nx_ * ny_), 0.0);
    room_.assign(clearance_.size(), -1);
    const double z0 = scene.floor_z() + 0.05, z1 = scene.floor_z() + body_top_m;
    for (int y = 0; y < ny_; ++y) {
      for (int x = 0; x < nx_; ++x) {
        const Eigen::Vector2d p = Centre(x, y);
        const auto k = Index(x, y);
        for (std::size_t r = 0; r < world.rooms.size(); ++r) {
          if (world.rooms[r].level == level && world.rooms[r].Contains(p)) {
            room_[k] = static_cast<int>(r);
            break;
          }
        }
        // Outside every room is not walkable (outdoors, inside walls).
        clearance_[k] = room_[k] < 0 ? 0.0 : std::min(scene.FootprintDistance(p, z0, z1, 2.0), 2.0);
      }
    }
  }

  Eigen::Vector2d Centre(int x, int y) const { return origin_ + Eigen::Vector2d((x + 0.5) * kCell, (y + 0.5) * kCell); }
  std::size_t Index(int x, int y) const { return static_cast<std::size_t>(y * nx_ + x); }
  bool Cell(const Eigen::Vector2d& p, int& x, int& y) const {
    x = static_cast<int>(std::floor((p.x() - origin_.x()) / kCell));
    y = static_cast<int>(std::floor((p.y() - origin_.y()) / kCell));
    return x >= 0 && y >= 0 && x < nx_ && y < ny_;
  }
  double Clearance(const Eigen::Vector2d& p) const {
    int x = 0, y = 0;
    return Cell(p, x, y) ? clearance_[Index(x, y)] : 0.0;
  }
  int RoomOf(int x, int y) const { return room_[Index(x, y)]; }
  int nx() const { return nx_; }
  int ny() const { return ny_; }

  bool SegmentClear(const Eigen::Vector2d& a, const Eigen::Vector2d& b, double clearance) const {
    const double length = (b - a).norm();
    const int steps = std::max(1, static_cast<int>(length / (0.5 * kCell)));
    for (int i = 0; i <= steps; ++i) {
      if (Clearance(a + (b - a) * (static_cast<double>(i) / steps)) < clearance) return false;
    }
    return true;
  }

  // A* on 8-connected cells with clearance >= `clearance`; returns a shortened polyline.
  std::vector<Eigen::Vector2d> Plan(const Eigen::Vector2d& from, const Eigen::Vector2d& to, double clearance) const {
    int sx = 0, sy = 0, gx = 0, gy = 0;
    if (!Cell(from, sx, sy) || !Cell(to, gx, gy)) return {};
    const std::size_t n = clearance_.size();
    std::vector<double> g(n, std::numeric_limits<double>::infinity());
    std::vector<std::int64_t> parent(n, -1);
    using Item = std::pair<double, std::size_t>;
    std::priority_queue<Item, std::vector<Item>, std::greater<>> open;
    const std::size_t start = Index(sx, sy), goal = Index(gx, gy);
    g[start] = 0;
    open.push({0, start});
    while (!open.empty()) {
      const auto [f, k] = open.top();
      open.pop();
      if (k == goal) break;
      const int x = static_cast<int>(k % static_cast<std::size_t>(nx_)), y = static_cast<int>(k / static_cast<std::size_t>(nx_));
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
          if (dx == 0 && dy == 0) continue;
          const int ux = x + dx, uy = y + dy;
          if (ux < 0 || uy < 0 || ux >= nx_ || uy >= ny_) continue;
          const std::size_t u = Index(ux, uy);
          if (clearance_[u] < clearance && u != goal) continue;
          // Prefer the middle of free space: a small penalty near obstacles.
          const double step = (dx != 0 && dy != 0 ? std::numbers::sqrt2 : 1.0) * kCell *
                              (1.0 + 0.5 * std::max(0.0, 1.0 - clearance_[u]));
          if (g[k] + step < g[u]) {
            g[u] = g[k] + step;
            parent[u] = static_cast<std::int64_t>(k);
            open.push({g[u] + std::hypot(ux - gx, uy - gy) * kCell, u});
          }
        }
      }
    }
    if (parent[goal] < 0 && goal != start) return {};
    std::vector<Eigen::Vector2d> cells;
    for (std::int64_t k = static_cast<std::int64_t>(goal); k >= 0; k = parent[static_cast<std::size_t>(k)]) {
      const auto u = static_cast<std::size_t>(k);
      cells.push_back(Centre(static_cast<int>(u % static_cast<std::size_t>(nx_)), static_cast<int>(u / static_cast<std::size_t>(nx_))));
      if (u == start) break;
    }
    std::reverse(cells.begin(), cells.end());
    cells.front() = from;
    cells.back() = to;
    // Shorten by line of sight.
    std::vector<Eigen::Vector2d> path{cells.front()};
    std::size_t i = 0;
    while (i + 1 < cells.size()) {
      std::size_t j = cells.size() - 1;
      while (j > i + 1 && !SegmentClear(cells[i], cells[j], clearance)) --j;
      path.push_back(cells[j]);
      i = j;
    }
    return path;
  }

  // Free cells of a room with at least `clearance`.
  std::vector<Eigen::Vector2d> FreeCells(int room, double clearance) const {
    std::vector<Eigen::Vector2d> out;
    for (int y = 0; y < ny_; ++y) {
      for (int x = 0; x < nx_; ++x) {
        if (room_[Index(x, y)] == room && clearance_[Index(x, y)] >= clearance) out.push_back(Centre(x, y));
      }
    }
    return out;
  }

 private:
  Eigen::Vector2d origin_;
  int nx_ = 0, ny_ = 0;
  std::vector<double> clearance_;
  std::vector<int> room_;
};

// Follows a polyline like Spot: turn in place when far off heading, otherwise walk and steer,
// with speed, turn-rate and acceleration limits. Appends to `traj` until the end or `t_end`.
void Follow(const std::vector<Eigen::Vector2d>& path, const MissionConfig& c, PlanarPose& pose, double& speed,
            Trajectory& traj, double t_end) {
  const double dt = traj.dt_s();
  std::size_t target = 1;
  while (target < path.size() && traj.duration_s() < t_end) {
    const Eigen::Vector2d to = path[target] - Eigen::Vector2d(pose.x, pose.y);
    const double dist = to.norm();
    const bool last = target + 1 == path.size();
    if (dist < (last ? 0.05 : 0.25)) {
      ++target;
      continue;
    }
    const double heading_error = std::remainder(std::atan2(to.y(), to.x()) - pose.yaw, 2 * std::numbers::pi);
    double wanted_speed = 0.0;
    if (std::fabs(heading_error) < 0.6) {
      wanted_speed = c.max_speed_mps * std::cos(heading_error);
      if (last) wanted_speed = std::min(wanted_speed, std::sqrt(2 * c.max_accel_mps2 * dist));
    }
    speed += std::clamp(wanted_speed - speed, -c.max_accel_mps2 * dt, c.max_accel_mps2 * dt);
    const double turn = std::clamp(2.0 * heading_error, -c.max_turn_rate_rps, c.max_turn_rate_rps);
    pose.yaw = std::remainder(pose.yaw + turn * dt, 2 * std::numbers::pi);
    pose.x += speed * std::cos(pose.yaw) * dt;
    pose.y += speed * std::sin(pose.yaw) * dt;
    traj.Append(pose);
  }
}

}  // namespace

std::optional<Mission> PlanMission(const World& world, const Scene& scene, const MissionConfig& config,
                                   std::string& error) {
  if (config.robots < 1 || config.robots > 10) {
    error = "robots must be 1..10";
    return std::nullopt;
  }
  if (!(config.duration_s > 0) || config.duration_s > 3600) {
    error = "duration must be in (0, 3600] s";
    return std::nullopt;
  }
  const NavGrid grid(world, scene, config.level, 1.0);
  std::vector<int> rooms;
  std::vector<std::vector<Eigen::Vector2d>> free;
  for (std::size_t r = 0; r < world.rooms.size(); ++r) {
    if (world.rooms[r].level != config.level) continue;
    auto cells = grid.FreeCells(static_cast<int>(r), config.robot_radius_m + 0.2);
    if (cells.size() < 4) continue;  // too cluttered or too small to walk into
    rooms.push_back(static_cast<int>(r));
    free.push_back(std::move(cells));
  }
  if (config.shared_rooms < 0 || static_cast<int>(rooms.size()) < std::max(2, config.shared_rooms)) {
    error = "fewer walkable rooms than the mission needs";
    return std::nullopt;
  }
  // Every walkable room must be reachable from the first one.
  for (std::size_t i = 1; i < rooms.size(); ++i) {
    if (grid.Plan(free[0][free[0].size() / 2], free[i][free[i].size() / 2], config.robot_radius_m).empty()) {
      error = "room '" + world.rooms[static_cast<std::size_t>(rooms[i])].id + "' is not reachable (doors too narrow?)";
      return std::nullopt;
    }
  }

  Random rng = Random::Stream(config.seed, 0x6D697373);  // "miss"
  Mission mission;
  mission.config = config;
  std::vector<int> order(rooms.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = static_cast<int>(i);
  for (std::size_t i = order.size() - 1; i > 0; --i) std::swap(order[i], order[static_cast<std::size_t>(rng.Index(static_cast<int>(i + 1)))]);
  std::vector<int> shared(order.begin(), order.begin() + config.shared_rooms);
  for (int s : shared) mission.shared_rooms.push_back(world.rooms[static_cast<std::size_t>(rooms[static_cast<std::size_t>(s)])].id);

  for (int id = 0; id < config.robots; ++id) {
    RobotPlan plan;
    plan.id = id + 1;
    plan.trajectory = Trajectory(0.01, scene.floor_z() + config.base_height_m);
    // Different start rooms where possible; start anywhere free, facing anywhere.
    const int start_room = order[static_cast<std::size_t>((config.shared_rooms + id) % static_cast<int>(order.size()))];
    const auto& start_cells = free[static_cast<std::size_t>(start_room)];
    const Eigen::Vector2d p = start_cells[static_cast<std::size_t>(rng.Index(static_cast<int>(start_cells.size())))];
    plan.start = {p.x(), p.y(), rng.Uniform(-std::numbers::pi, std::numbers::pi)};
    plan.start_room = world.rooms[static_cast<std::size_t>(rooms[static_cast<std::size_t>(start_room)])].id;
    plan.rooms_visited.push_back(plan.start_room);

    // The visit list: the shared rooms in a random order among a few others, then random rooms.
    std::vector<int> visits = shared;
    for (int k = 0; k < 2; ++k) visits.push_back(rng.Index(static_cast<int>(rooms.size())));
    for (std::size_t i = visits.size() - 1; i > 0; --i) std::swap(visits[i], visits[static_cast<std::size_t>(rng.Index(static_cast<int>(i + 1)))]);

    PlanarPose pose = plan.start;
    double speed = 0.0;
    plan.trajectory.Append(pose);
    int current = start_room;
    std::size_t next_visit = 0;
    int stuck = 0;
    while (plan.trajectory.duration_s() < config.duration_s && stuck < 50) {
      int room = 0;
      if (next_visit < visits.size()) {
        room = visits[next_visit++];
      } else {
        room = rng.Index(static_cast<int>(rooms.size()));
        if (room == current && rooms.size() > 1) continue;
      }
      // Two points in the room: walk in, look around, move on.
      bool moved = false;
      for (int k = 0; k < 2; ++k) {
        const auto& cells = free[static_cast<std::size_t>(room)];
        const Eigen::Vector2d goal = cells[static_cast<std::size_t>(rng.Index(static_cast<int>(cells.size())))];
        const auto path = grid.Plan({pose.x, pose.y}, goal, config.robot_radius_m);
        if (path.size() < 2) continue;
        Follow(path, config, pose, speed, plan.trajectory, config.duration_s);
        moved = true;
      }
      if (!moved) {
        ++stuck;
        continue;
      }
      stuck = 0;
      if (room != current) plan.rooms_visited.push_back(world.rooms[static_cast<std::size_t>(rooms[static_cast<std::size_t>(room)])].id);
      current = room;
    }
    // Stand still for the rest of the mission if the plan ran out early.
    while (plan.trajectory.duration_s() < config.duration_s) plan.trajectory.Append(pose);
    mission.robots.push_back(std::move(plan));
  }
  // Each pair must share at least `shared_rooms` rooms they actually reached.
  for (std::size_t a = 0; a < mission.robots.size(); ++a) {
    for (std::size_t b = a + 1; b < mission.robots.size(); ++b) {
      std::set<std::string> ra(mission.robots[a].rooms_visited.begin(), mission.robots[a].rooms_visited.end());
      int common = 0;
      for (const auto& r : std::set<std::string>(mission.robots[b].rooms_visited.begin(), mission.robots[b].rooms_visited.end())) {
        common += static_cast<int>(ra.count(r));
      }
      if (common < config.shared_rooms) {
        error = "robots " + std::to_string(a + 1) + " and " + std::to_string(b + 1) + " share only " +
                std::to_string(common) + " rooms (mission too short for this building?)";
        return std::nullopt;
      }
    }
  }
  return mission;
}

}  // namespace msgraphs::sim
