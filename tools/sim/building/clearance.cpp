// SPDX-License-Identifier: MIT
#include "clearance.hpp"

#include <algorithm>
#include <cmath>
#include <deque>
#include <limits>

namespace msgraphs::sim::building {
namespace {

// Squared distance transform of one row (Felzenszwalb and Huttenlocher 2012): f holds 0 at
// obstacles and a large value elsewhere; d receives min_q (p - q)^2 + f(q).
void Transform1d(const std::vector<double>& f,
                 std::vector<double>& d,
                 std::vector<int>& v,
                 std::vector<double>& z) {
  const int n = static_cast<int>(f.size());
  auto at = [](auto& a, int i) -> auto& { return a[static_cast<std::size_t>(i)]; };
  auto meet = [&](int q, int p) {  // where the parabolas rooted at q and p intersect
    return ((at(f, q) + q * q) - (at(f, p) + p * p)) / (2.0 * (q - p));
  };
  int k = 0;
  at(v, 0) = 0;
  at(z, 0) = -std::numeric_limits<double>::infinity();
  at(z, 1) = std::numeric_limits<double>::infinity();
  for (int q = 1; q < n; ++q) {
    double s = meet(q, at(v, k));
    while (s <= at(z, k)) {
      --k;
      s = meet(q, at(v, k));
    }
    ++k;
    at(v, k) = q;
    at(z, k) = s;
    at(z, k + 1) = std::numeric_limits<double>::infinity();
  }
  k = 0;
  for (int q = 0; q < n; ++q) {
    while (at(z, k + 1) < q) ++k;
    const int p = at(v, k);
    at(d, q) = (q - p) * (q - p) + at(f, p);
  }
}

}  // namespace

ClearanceGrid::ClearanceGrid(const Vec2& lo, const Vec2& hi, double cell_m)
    : lo_(lo), cell_(cell_m) {
  nx_ = std::max(1, static_cast<int>(std::ceil((hi.x() - lo.x()) / cell_)));
  ny_ = std::max(1, static_cast<int>(std::ceil((hi.y() - lo.y()) / cell_)));
  occupied_.assign(static_cast<std::size_t>(nx_) * static_cast<std::size_t>(ny_), 0);
}

bool ClearanceGrid::CellOf(const Vec2& p, int& i, int& j) const {
  i = static_cast<int>(std::floor((p.x() - lo_.x()) / cell_));
  j = static_cast<int>(std::floor((p.y() - lo_.y()) / cell_));
  return i >= 0 && j >= 0 && i < nx_ && j < ny_;
}

template <typename Inside>
void ClearanceGrid::Mark(const Vec2& lo, const Vec2& hi, Inside&& inside) {
  // A cell is an obstacle when its centre is within half a diagonal of the footprint: every
  // footprint point then lies in an obstacle cell, which makes the estimate conservative.
  const double grow = 0.5 * std::sqrt(2.0) * cell_;
  int i0 = 0, j0 = 0, i1 = 0, j1 = 0;
  CellOf(lo - Vec2(grow, grow), i0, j0);
  CellOf(hi + Vec2(grow, grow), i1, j1);
  i0 = std::max(i0, 0);
  j0 = std::max(j0, 0);
  i1 = std::min(i1, nx_ - 1);
  j1 = std::min(j1, ny_ - 1);
  for (int j = j0; j <= j1; ++j) {
    for (int i = i0; i <= i1; ++i) {
      if (inside(Centre(i, j), grow)) occupied_[Index(i, j)] = 1;
    }
  }
}

void ClearanceGrid::AddRectangle(const Vec2& centre, double yaw_rad, double hx, double hy) {
  const double c = std::cos(yaw_rad), s = std::sin(yaw_rad);
  const double ex = std::fabs(c) * hx + std::fabs(s) * hy,
               ey = std::fabs(s) * hx + std::fabs(c) * hy;
  Mark(centre - Vec2(ex, ey), centre + Vec2(ex, ey), [&](const Vec2& p, double grow) {
    const Vec2 q = p - centre;
    const double lx = std::fabs(c * q.x() + s * q.y()) - hx,
                 ly = std::fabs(-s * q.x() + c * q.y()) - hy;
    return std::hypot(std::max(lx, 0.0), std::max(ly, 0.0)) <= grow;
  });
}

void ClearanceGrid::AddCircle(const Vec2& centre, double radius_m) {
  Mark(centre - Vec2(radius_m, radius_m), centre + Vec2(radius_m, radius_m),
       [&](const Vec2& p, double grow) { return (p - centre).norm() <= radius_m + grow; });
}

void ClearanceGrid::AddWall(const Wall& w) {
  const Vec2 d = w.direction();
  const double yaw = std::atan2(d.y(), d.x());
  std::vector<Door> doors = w.doors;
  std::sort(doors.begin(), doors.end(),
            [](const Door& a, const Door& b) { return a.offset_m < b.offset_m; });
  auto piece = [&](double a, double b) {
    if (b - a > 1e-6)
      AddRectangle(w.start + d * (0.5 * (a + b)), yaw, 0.5 * (b - a), 0.5 * w.thickness_m);
  };
  double cursor = -0.5 * w.thickness_m;
  for (const Door& door : doors) {
    piece(cursor, door.offset_m);
    cursor = door.offset_m + door.width_m;
  }
  piece(cursor, w.length() + 0.5 * w.thickness_m);
}

void ClearanceGrid::Compute() {
  const double big = 1e12;
  const std::size_t n = occupied_.size();
  std::vector<double> g(n);
  for (std::size_t k = 0; k < n; ++k) g[k] = occupied_[k] != 0 ? 0.0 : big;
  const int m = std::max(nx_, ny_);
  std::vector<double> f(static_cast<std::size_t>(m)), d(static_cast<std::size_t>(m)),
      z(static_cast<std::size_t>(m) + 1);
  std::vector<int> v(static_cast<std::size_t>(m));
  f.resize(static_cast<std::size_t>(ny_));
  d.resize(static_cast<std::size_t>(ny_));
  for (int i = 0; i < nx_; ++i) {
    for (int j = 0; j < ny_; ++j) f[static_cast<std::size_t>(j)] = g[Index(i, j)];
    Transform1d(f, d, v, z);
    for (int j = 0; j < ny_; ++j) g[Index(i, j)] = d[static_cast<std::size_t>(j)];
  }
  f.resize(static_cast<std::size_t>(nx_));
  d.resize(static_cast<std::size_t>(nx_));
  for (int j = 0; j < ny_; ++j) {
    for (int i = 0; i < nx_; ++i) f[static_cast<std::size_t>(i)] = g[Index(i, j)];
    Transform1d(f, d, v, z);
    for (int i = 0; i < nx_; ++i) g[Index(i, j)] = d[static_cast<std::size_t>(i)];
  }
  // Distance between cell centres, less half a diagonal (see Mark) for the footprint itself.
  clearance_.resize(n);
  const double grow = 0.5 * std::sqrt(2.0) * cell_;
  for (std::size_t k = 0; k < n; ++k) {
    clearance_[k] = g[k] >= big ? 1e9 : std::max(0.0, std::sqrt(g[k]) * cell_ - grow);
  }
}

RoomWalk WalkRoom(const ClearanceGrid& grid,
                  const Polygon& room,
                  const std::vector<Vec2>& mouths,
                  double pass_m,
                  double stand_m) {
  RoomWalk walk;
  const int nx = grid.nx(), ny = grid.ny();
  std::vector<char> in_room(static_cast<std::size_t>(nx) * static_cast<std::size_t>(ny), 0);
  auto index = [&](int i, int j) {
    return static_cast<std::size_t>(j) * static_cast<std::size_t>(nx) + static_cast<std::size_t>(i);
  };
  // Row by row: cell centres between pairs of outline crossings are inside (even-odd rule,
  // the same half-open test as Inside()).
  std::vector<double> crossings;
  for (int j = 0; j < ny; ++j) {
    const double y = grid.Centre(0, j).y();
    crossings.clear();
    for (std::size_t k = 0, l = room.size() - 1; k < room.size(); l = k++) {
      const Vec2& a = room[k];
      const Vec2& b = room[l];
      if ((a.y() > y) != (b.y() > y))
        crossings.push_back((b.x() - a.x()) * (y - a.y()) / (b.y() - a.y()) + a.x());
    }
    std::sort(crossings.begin(), crossings.end());
    for (std::size_t k = 0; k + 1 < crossings.size(); k += 2) {
      for (int i = 0; i < nx; ++i) {
        const double x = grid.Centre(i, j).x();
        if (x > crossings[k] && x < crossings[k + 1]) in_room[index(i, j)] = 1;
      }
    }
  }
  std::vector<char> reached(in_room.size(), 0);
  std::deque<std::pair<int, int>> queue;
  // A mouth stands for the roomiest cell within 0.15 m of it (the estimate's own error is of
  // that order).
  auto mouth_cell = [&](const Vec2& p, int& bi, int& bj) {
    double best = -1;
    for (double dy = -0.15; dy <= 0.151; dy += 0.05) {
      for (double dx = -0.15; dx <= 0.151; dx += 0.05) {
        int i = 0, j = 0;
        if (!grid.CellOf(p + Vec2(dx, dy), i, j) || !in_room[index(i, j)]) continue;
        if (grid.Clearance(i, j) > best) {
          best = grid.Clearance(i, j);
          bi = i;
          bj = j;
        }
      }
    }
    return best >= pass_m;
  };
  auto seed = [&](const Vec2& p) {
    int i = 0, j = 0;
    if (!mouth_cell(p, i, j)) return false;
    if (!reached[index(i, j)]) {
      reached[index(i, j)] = 1;
      queue.emplace_back(i, j);
    }
    return true;
  };
  auto fill = [&]() {
    while (!queue.empty()) {
      const auto [i, j] = queue.front();
      queue.pop_front();
      for (int dj = -1; dj <= 1; ++dj) {
        for (int di = -1; di <= 1; ++di) {
          const int u = i + di, w = j + dj;
          if (u < 0 || w < 0 || u >= nx || w >= ny) continue;
          const std::size_t k = index(u, w);
          if (reached[k] || !in_room[k] || grid.Clearance(u, w) < pass_m) continue;
          reached[k] = 1;
          queue.emplace_back(u, w);
        }
      }
    }
  };
  // The region of the first mouth (or of the roomiest cell when the room has no door).
  bool ok = true;
  if (!mouths.empty()) {
    ok = seed(mouths.front());
  } else {
    double best = -1;
    int bi = 0, bj = 0;
    for (int j = 0; j < ny; ++j) {
      for (int i = 0; i < nx; ++i) {
        if (in_room[index(i, j)] && grid.Clearance(i, j) > best) {
          best = grid.Clearance(i, j);
          bi = i;
          bj = j;
        }
      }
    }
    ok = best >= pass_m;
    if (ok) {
      reached[index(bi, bj)] = 1;
      queue.emplace_back(bi, bj);
    }
  }
  fill();
  walk.mouths_connected = ok;
  for (std::size_t m = 1; m < mouths.size() && walk.mouths_connected; ++m) {
    int i = 0, j = 0;
    walk.mouths_connected = mouth_cell(mouths[m], i, j) && reached[index(i, j)] != 0;
  }
  walk.no_pockets = ok;
  for (int j = 0; j < ny; ++j) {
    for (int i = 0; i < nx; ++i) {
      const std::size_t k = index(i, j);
      if (!in_room[k]) continue;
      const double c = grid.Clearance(i, j);
      if (c >= pass_m + 0.01 && !reached[k]) walk.no_pockets = false;
      if (reached[k] && c >= stand_m) ++walk.free_cells;
    }
  }
  return walk;
}

}  // namespace msgraphs::sim::building
