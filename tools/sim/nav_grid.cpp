// SPDX-License-Identifier: MIT
#include "nav_grid.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>
#include <queue>

namespace msgraphs::sim {

NavGrid::NavGrid(const World& world, const Scene& scene, int level, double body_top_m) {
  Eigen::Vector2d lo(1e9, 1e9), hi(-1e9, -1e9);
  for (const Room& r : world.rooms) {
    if (r.level != level) continue;
    for (const auto& p : r.polygon) {
      lo = lo.cwiseMin(p);
      hi = hi.cwiseMax(p);
    }
  }
  origin_ = lo;
  nx_ = static_cast<int>(std::ceil((hi.x() - lo.x()) / kCellM)) + 1;
  ny_ = static_cast<int>(std::ceil((hi.y() - lo.y()) / kCellM)) + 1;
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

bool NavGrid::Cell(const Eigen::Vector2d& p, int& x, int& y) const {
  x = static_cast<int>(std::floor((p.x() - origin_.x()) / kCellM));
  y = static_cast<int>(std::floor((p.y() - origin_.y()) / kCellM));
  return x >= 0 && y >= 0 && x < nx_ && y < ny_;
}

double NavGrid::Clearance(const Eigen::Vector2d& p) const {
  int x = 0, y = 0;
  return Cell(p, x, y) ? clearance_[Index(x, y)] : 0.0;
}

int NavGrid::RoomAt(const Eigen::Vector2d& p) const {
  int x = 0, y = 0;
  return Cell(p, x, y) ? room_[Index(x, y)] : -1;
}

bool NavGrid::SegmentClear(const Eigen::Vector2d& a,
                           const Eigen::Vector2d& b,
                           double clearance,
                           const RoomExclusion& excluded) const {
  const double length = (b - a).norm();
  const int steps = std::max(1, static_cast<int>(length / (0.5 * kCellM)));
  for (int i = 0; i <= steps; ++i) {
    const Eigen::Vector2d p = a + (b - a) * (static_cast<double>(i) / steps);
    if (Clearance(p) < clearance) return false;
    if (excluded.Has(RoomAt(p))) return false;
  }
  return true;
}

std::vector<Eigen::Vector2d> NavGrid::Plan(const Eigen::Vector2d& from,
                                           const Eigen::Vector2d& to,
                                           double clearance,
                                           const RoomExclusion& excluded) const {
  int sx = 0, sy = 0, gx = 0, gy = 0;
  if (!Cell(from, sx, sy) || !Cell(to, gx, gy)) return {};
  const std::size_t n = clearance_.size();
  std::vector<double> g(n, std::numeric_limits<double>::infinity());
  std::vector<std::int64_t> parent(n, -1);
  using Item = std::pair<double, std::size_t>;
  std::priority_queue<Item, std::vector<Item>, std::greater<>> open;
  const std::size_t start = Index(sx, sy), goal = Index(gx, gy);
  const auto nxu = static_cast<std::size_t>(nx_);
  g[start] = 0;
  open.push({0, start});
  while (!open.empty()) {
    const auto [f, k] = open.top();
    open.pop();
    if (k == goal) break;
    const int x = static_cast<int>(k % nxu), y = static_cast<int>(k / nxu);
    for (int dy = -1; dy <= 1; ++dy) {
      for (int dx = -1; dx <= 1; ++dx) {
        if (dx == 0 && dy == 0) continue;
        const int ux = x + dx, uy = y + dy;
        if (ux < 0 || uy < 0 || ux >= nx_ || uy >= ny_) continue;
        const std::size_t u = Index(ux, uy);
        if (u != goal && (clearance_[u] < clearance || excluded.Has(room_[u]))) continue;
        // Prefer the middle of free space: a small penalty near obstacles.
        const double step = (dx != 0 && dy != 0 ? std::numbers::sqrt2 : 1.0) * kCellM *
                            (1.0 + 0.5 * std::max(0.0, 1.0 - clearance_[u]));
        if (g[k] + step < g[u]) {
          g[u] = g[k] + step;
          parent[u] = static_cast<std::int64_t>(k);
          open.push({g[u] + std::hypot(ux - gx, uy - gy) * kCellM, u});
        }
      }
    }
  }
  if (parent[goal] < 0 && goal != start) return {};
  std::vector<Eigen::Vector2d> cells;
  for (auto k = static_cast<std::int64_t>(goal); k >= 0; k = parent[static_cast<std::size_t>(k)]) {
    const auto u = static_cast<std::size_t>(k);
    cells.push_back(Centre(static_cast<int>(u % nxu), static_cast<int>(u / nxu)));
    if (u == start) break;
  }
  std::reverse(cells.begin(), cells.end());
  cells.front() = from;
  cells.back() = to;
  // Shorten by line of sight (also around the excluded room).
  std::vector<Eigen::Vector2d> path{cells.front()};
  std::size_t i = 0;
  while (i + 1 < cells.size()) {
    std::size_t j = cells.size() - 1;
    while (j > i + 1 && !SegmentClear(cells[i], cells[j], clearance, excluded)) --j;
    path.push_back(cells[j]);
    i = j;
  }
  return path;
}

std::vector<bool> NavGrid::ReachableRooms(const Eigen::Vector2d& from,
                                          double clearance,
                                          const RoomExclusion& excluded,
                                          std::size_t rooms) const {
  std::vector<bool> out(rooms, false);
  int sx = 0, sy = 0;
  if (!Cell(from, sx, sy)) return out;
  std::vector<bool> seen(clearance_.size(), false);
  std::vector<std::size_t> stack{Index(sx, sy)};
  seen[stack.back()] = true;
  const auto nxu = static_cast<std::size_t>(nx_);
  while (!stack.empty()) {
    const std::size_t k = stack.back();
    stack.pop_back();
    if (room_[k] >= 0 && static_cast<std::size_t>(room_[k]) < rooms)
      out[static_cast<std::size_t>(room_[k])] = true;
    const int x = static_cast<int>(k % nxu), y = static_cast<int>(k / nxu);
    for (int dy = -1; dy <= 1; ++dy) {
      for (int dx = -1; dx <= 1; ++dx) {
        const int ux = x + dx, uy = y + dy;
        if (ux < 0 || uy < 0 || ux >= nx_ || uy >= ny_) continue;
        const std::size_t u = Index(ux, uy);
        if (seen[u] || clearance_[u] < clearance || excluded.Has(room_[u])) continue;
        seen[u] = true;
        stack.push_back(u);
      }
    }
  }
  return out;
}

std::vector<Eigen::Vector2d> NavGrid::FreeCells(int room, double clearance) const {
  std::vector<Eigen::Vector2d> out;
  for (int y = 0; y < ny_; ++y) {
    for (int x = 0; x < nx_; ++x) {
      if (room_[Index(x, y)] == room && clearance_[Index(x, y)] >= clearance)
        out.push_back(Centre(x, y));
    }
  }
  return out;
}

}  // namespace msgraphs::sim
