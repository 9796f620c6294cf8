// SPDX-License-Identifier: MIT
#include "room_visits.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace msgraphs::sim {

std::vector<Entrance> FindEntrances(const NavGrid& grid, int room, double clearance) {
  // Boundary links: a walkable cell of the room beside a walkable cell of another room.
  struct Link {
    Eigen::Vector2d inside, outside;
  };
  std::vector<Link> links;
  const std::vector<Eigen::Vector2d> cells = grid.FreeCells(room, clearance);
  const double h = NavGrid::kCellM;
  for (const Eigen::Vector2d& c : cells) {
    for (int dy = -1; dy <= 1; ++dy) {
      for (int dx = -1; dx <= 1; ++dx) {
        if ((dx == 0) == (dy == 0)) continue;  // 4-neighbours: clean boundary directions
        const Eigen::Vector2d n = c + Eigen::Vector2d(dx * h, dy * h);
        const int other = grid.RoomAt(n);
        if (other >= 0 && other != room && grid.Clearance(n) >= clearance) links.push_back({c, n});
      }
    }
  }
  // Group links into openings: links closer than two cells belong to the same one.
  std::vector<int> group(links.size(), -1);
  int groups = 0;
  for (std::size_t i = 0; i < links.size(); ++i) {
    if (group[i] >= 0) continue;
    std::vector<std::size_t> stack{i};
    group[i] = groups;
    while (!stack.empty()) {
      const std::size_t k = stack.back();
      stack.pop_back();
      for (std::size_t j = 0; j < links.size(); ++j) {
        if (group[j] < 0 && (links[j].inside - links[k].inside).norm() < 2.01 * h) {
          group[j] = groups;
          stack.push_back(j);
        }
      }
    }
    ++groups;
  }
  std::vector<Entrance> out;
  for (int g = 0; g < groups; ++g) {
    Eigen::Vector2d centre = Eigen::Vector2d::Zero(), inward = Eigen::Vector2d::Zero();
    Eigen::Vector2d lo(1e18, 1e18), hi(-1e18, -1e18);
    int n = 0;
    for (std::size_t i = 0; i < links.size(); ++i) {
      if (group[i] != g) continue;
      centre += 0.5 * (links[i].inside + links[i].outside);
      inward += links[i].inside - links[i].outside;
      lo = lo.cwiseMin(links[i].inside);
      hi = hi.cwiseMax(links[i].inside);
      ++n;
    }
    if (n == 0 || inward.norm() < 1e-9) continue;
    Entrance e;
    e.centre = centre / n;
    e.inward = inward.normalized();
    // Extent across the opening: the links' spread perpendicular to the inward direction.
    const Eigen::Vector2d across(-e.inward.y(), e.inward.x());
    double a0 = 1e18, a1 = -1e18;
    for (std::size_t i = 0; i < links.size(); ++i) {
      if (group[i] != g) continue;
      a0 = std::min(a0, across.dot(links[i].inside));
      a1 = std::max(a1, across.dot(links[i].inside));
    }
    e.width_m = a1 - a0 + h;
    out.push_back(e);
  }
  return out;
}

const Entrance* NearestEntrance(const std::vector<Entrance>& entrances,
                                const Eigen::Vector2d& from) {
  const Entrance* best = nullptr;
  double best_d = std::numeric_limits<double>::infinity();
  for (const Entrance& e : entrances) {
    const double d = (e.centre - 0.5 * e.inward - from).norm();
    if (d < best_d) {
      best_d = d;
      best = &e;
    }
  }
  return best;
}

bool PeekStandPoint(const NavGrid& grid,
                    int room,
                    const Entrance& entrance,
                    double clearance,
                    double min_m,
                    double max_m,
                    Random& rng,
                    Eigen::Vector2d& out) {
  // The drawn distance, else the nearest usable one: closer down to min_m, then further out.
  const double wanted = rng.Uniform(min_m, max_m);
  std::vector<double> candidates{wanted};
  for (double d = wanted - 0.05; d >= min_m; d -= 0.05) candidates.push_back(d);
  for (double d = wanted + 0.05; d <= max_m + 1.0; d += 0.05) candidates.push_back(d);
  for (const double d : candidates) {
    const Eigen::Vector2d p = entrance.centre - entrance.inward * d;
    const int r = grid.RoomAt(p);
    if (r >= 0 && r != room && grid.Clearance(p) >= clearance) {
      out = p;
      return true;
    }
  }
  return false;
}

std::vector<Eigen::Vector2d> CellsNear(const std::vector<Eigen::Vector2d>& cells,
                                       const Entrance& entrance,
                                       double reach_m,
                                       double min_inside_m) {
  std::vector<Eigen::Vector2d> out;
  for (const Eigen::Vector2d& c : cells) {
    const double inside = (c - entrance.centre).dot(entrance.inward);
    if (inside >= min_inside_m && (c - entrance.centre).norm() <= reach_m) out.push_back(c);
  }
  return out;
}

std::vector<Eigen::Vector2d> CoverPoints(const std::vector<Eigen::Vector2d>& cells,
                                         int count,
                                         const Eigen::Vector2d& from) {
  std::vector<Eigen::Vector2d> chosen;
  if (cells.empty() || count < 1) return chosen;
  std::vector<double> distance(cells.size(), std::numeric_limits<double>::infinity());
  // Start from the free cell nearest the robot: it walks in and then out to the far parts.
  std::size_t next = 0;
  for (std::size_t i = 1; i < cells.size(); ++i) {
    if ((cells[i] - from).squaredNorm() < (cells[next] - from).squaredNorm()) next = i;
  }
  for (int k = 0; k < count; ++k) {
    chosen.push_back(cells[next]);
    std::size_t far = 0;
    for (std::size_t i = 0; i < cells.size(); ++i) {
      distance[i] = std::min(distance[i], (cells[i] - cells[next]).norm());
      if (distance[i] > distance[far]) far = i;
    }
    if (distance[far] < 0.5) break;  // the room is covered
    next = far;
  }
  // Walking order: nearest next.
  std::vector<Eigen::Vector2d> order;
  Eigen::Vector2d at = from;
  while (!chosen.empty()) {
    std::size_t best = 0;
    for (std::size_t i = 1; i < chosen.size(); ++i) {
      if ((chosen[i] - at).squaredNorm() < (chosen[best] - at).squaredNorm()) best = i;
    }
    at = chosen[best];
    order.push_back(at);
    chosen.erase(chosen.begin() + static_cast<std::ptrdiff_t>(best));
  }
  return order;
}

}  // namespace msgraphs::sim
