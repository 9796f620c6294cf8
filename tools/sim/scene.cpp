// SPDX-License-Identifier: MIT
#include "scene.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace msgraphs::sim {
namespace {
constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kEps = 1e-9;
}  // namespace

Scene::Scene(const World& world, int level, double cell_size_m) : cell_(cell_size_m) {
  const Level* lv = world.FindLevel(level);
  floor_z_ = lv != nullptr ? lv->floor_z_m : 0.0;
  if (lv != nullptr && lv->ceiling_height_m) ceiling_z_ = floor_z_ + *lv->ceiling_height_m;

  // Walls: solid pieces between doors at full height, lintels above doors. Pieces at the
  // wall's true ends grow by half the thickness so that corners close.
  for (std::size_t wall_index = 0; wall_index < world.walls.size(); ++wall_index) {
    const Wall& w = world.walls[wall_index];
    if (w.level != level) continue;
    const Eigen::Vector2d dir = w.direction();
    const double yaw_c = dir.x(), yaw_s = dir.y();
    const double length = w.length();
    std::vector<Door> doors = w.doors;
    std::sort(doors.begin(), doors.end(),
              [](const Door& a, const Door& b) { return a.offset_m < b.offset_m; });
    auto add_piece = [&](double a, double b, double z0, double z1) {
      if (b - a < 1e-6 || z1 - z0 < 1e-6) return;
      const Eigen::Vector2d centre = w.start + dir * (0.5 * (a + b));
      boxes_.push_back({centre, yaw_c, yaw_s, 0.5 * (b - a), 0.5 * w.thickness_m, floor_z_ + z0,
                        floor_z_ + z1, w.material, static_cast<std::int32_t>(wall_index)});
    };
    double cursor = -0.5 * w.thickness_m;
    for (const Door& d : doors) {
      add_piece(cursor, d.offset_m, 0.0, w.height_m);
      add_piece(d.offset_m, d.offset_m + d.width_m, d.height_m, w.height_m);
      cursor = d.offset_m + d.width_m;
    }
    add_piece(cursor, length + 0.5 * w.thickness_m, 0.0, w.height_m);
  }
  for (const Box& b : world.boxes) {
    if (b.level != level) continue;
    boxes_.push_back({b.centre, std::cos(b.yaw_rad), std::sin(b.yaw_rad), 0.5 * b.size_m.x(),
                      0.5 * b.size_m.y(), floor_z_, floor_z_ + b.size_m.z(), b.material});
  }
  for (const Cylinder& c : world.cylinders) {
    if (c.level != level) continue;
    cylinders_.push_back({c.centre, c.radius_m, floor_z_, floor_z_ + c.height_m, c.material});
  }

  // Grid over everything, with a margin.
  Eigen::Vector2d lo(kInf, kInf), hi(-kInf, -kInf);
  auto grow = [&](const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
    lo = lo.cwiseMin(a);
    hi = hi.cwiseMax(b);
  };
  std::vector<std::pair<Eigen::Vector2d, Eigen::Vector2d>> bounds;
  for (const BoxPrimitive& b : boxes_) {
    const double ex = std::fabs(b.c) * b.hx + std::fabs(b.s) * b.hy;
    const double ey = std::fabs(b.s) * b.hx + std::fabs(b.c) * b.hy;
    bounds.emplace_back(b.centre - Eigen::Vector2d(ex, ey), b.centre + Eigen::Vector2d(ex, ey));
  }
  for (const CylinderPrimitive& c : cylinders_) {
    bounds.emplace_back(c.centre - Eigen::Vector2d(c.radius, c.radius),
                        c.centre + Eigen::Vector2d(c.radius, c.radius));
  }
  for (const auto& [a, b] : bounds) grow(a, b);
  for (const Room& r : world.rooms) {
    for (const auto& p : r.polygon) grow(p, p);
  }
  if (!(lo.x() < hi.x())) {
    lo = {-1, -1};
    hi = {1, 1};
  }
  origin_ = lo - Eigen::Vector2d(cell_, cell_);
  nx_ = static_cast<int>(std::ceil((hi.x() - origin_.x()) / cell_)) + 1;
  ny_ = static_cast<int>(std::ceil((hi.y() - origin_.y()) / cell_)) + 1;
  building_.assign(static_cast<std::size_t>(nx_ * ny_), {});
  for (std::uint32_t id = 0; id < bounds.size(); ++id)
    Insert(id, bounds[id].first, bounds[id].second);
  cell_start_.assign(building_.size() + 1, 0);
  for (std::size_t k = 0; k < building_.size(); ++k) {
    cell_start_[k + 1] = cell_start_[k] + static_cast<std::uint32_t>(building_[k].size());
  }
  cells_.reserve(cell_start_.back());
  for (const auto& list : building_) cells_.insert(cells_.end(), list.begin(), list.end());
  building_.clear();
  building_.shrink_to_fit();
}

void Scene::Insert(std::uint32_t id, const Eigen::Vector2d& lo, const Eigen::Vector2d& hi) {
  const int x0 = std::max(0, static_cast<int>(std::floor((lo.x() - origin_.x()) / cell_)));
  const int y0 = std::max(0, static_cast<int>(std::floor((lo.y() - origin_.y()) / cell_)));
  const int x1 = std::min(nx_ - 1, static_cast<int>(std::floor((hi.x() - origin_.x()) / cell_)));
  const int y1 = std::min(ny_ - 1, static_cast<int>(std::floor((hi.y() - origin_.y()) / cell_)));
  for (int y = y0; y <= y1; ++y) {
    for (int x = x0; x <= x1; ++x) building_[static_cast<std::size_t>(y * nx_ + x)].push_back(id);
  }
}

Scene::Scratch Scene::MakeScratch() const {
  Scratch s;
  s.stamp.assign(primitives(), 0);
  return s;
}

bool Scene::TestPrimitive(std::uint32_t id,
                          const Eigen::Vector3d& o,
                          const Eigen::Vector3d& d,
                          Hit& best) const {
  if (id < boxes_.size()) {
    const BoxPrimitive& b = boxes_[id];
    // Into the box frame (yaw only).
    const double px = o.x() - b.centre.x(), py = o.y() - b.centre.y();
    const double lx = b.c * px + b.s * py, ly = -b.s * px + b.c * py;
    const double dx = b.c * d.x() + b.s * d.y(), dy = -b.s * d.x() + b.c * d.y();
    double t_in = -kInf, t_out = kInf;
    int axis = -1;
    double sign = 0;
    auto slab = [&](double p, double v, double lo, double hi, int a) {
      if (std::fabs(v) < kEps) return p >= lo && p <= hi;
      double t0 = (lo - p) / v, t1 = (hi - p) / v;
      double s0 = -1;
      if (t0 > t1) {
        std::swap(t0, t1);
        s0 = 1;
      }
      if (t0 > t_in) {
        t_in = t0;
        axis = a;
        sign = s0;
      }
      t_out = std::min(t_out, t1);
      return t_in <= t_out;
    };
    if (!slab(lx, dx, -b.hx, b.hx, 0) || !slab(ly, dy, -b.hy, b.hy, 1) ||
        !slab(o.z(), d.z(), b.z0, b.z1, 2))
      return false;
    if (t_in <= 1e-6 || t_in >= best.range_m) return false;
    best.range_m = t_in;
    best.material = b.material;
    if (axis == 0) best.normal = Eigen::Vector3d(sign * b.c, sign * b.s, 0);
    if (axis == 1) best.normal = Eigen::Vector3d(-sign * b.s, sign * b.c, 0);
    if (axis == 2) best.normal = Eigen::Vector3d(0, 0, sign);
    // A wall piece's +-y faces are the wall's two faces (its y axis is the wall's normal()); the
    // ray enters through the face whose outward normal is sign * normal().
    best.wall = axis == 1 ? b.wall : -1;
    best.face = static_cast<std::int8_t>(axis == 1 && b.wall >= 0 ? (sign > 0 ? 1 : -1) : 0);
    return true;
  }
  const CylinderPrimitive& c = cylinders_[id - boxes_.size()];
  bool hit = false;
  const double px = o.x() - c.centre.x(), py = o.y() - c.centre.y();
  const double a = d.x() * d.x() + d.y() * d.y();
  if (a > kEps) {
    const double bq = px * d.x() + py * d.y();
    const double cq = px * px + py * py - c.radius * c.radius;
    const double disc = bq * bq - a * cq;
    if (disc >= 0) {
      const double t = (-bq - std::sqrt(disc)) / a;
      const double z = o.z() + t * d.z();
      if (t > 1e-6 && t < best.range_m && z >= c.z0 && z <= c.z1) {
        best.range_m = t;
        best.material = c.material;
        best.normal = Eigen::Vector3d(px + t * d.x(), py + t * d.y(), 0).normalized();
        best.wall = -1;
        best.face = 0;
        hit = true;
      }
    }
  }
  if (d.z() < -kEps && o.z() > c.z1) {  // the top disc
    const double t = (c.z1 - o.z()) / d.z();
    const double x = px + t * d.x(), y = py + t * d.y();
    if (t > 1e-6 && t < best.range_m && x * x + y * y <= c.radius * c.radius) {
      best.range_m = t;
      best.material = c.material;
      best.normal = {0, 0, 1};
      best.wall = -1;
      best.face = 0;
      hit = true;
    }
  }
  return hit;
}

std::optional<Hit> Scene::Cast(const Eigen::Vector3d& o,
                               const Eigen::Vector3d& d,
                               double max_range,
                               Scratch& scratch) const {
  Hit best;
  best.range_m = max_range;
  bool any = false;
  // Floor and ceiling first: they bound how far the grid walk needs to go.
  if (d.z() < -kEps) {
    const double t = (floor_z_ - o.z()) / d.z();
    if (t > 0 && t < best.range_m) {
      best = {t, {0, 0, 1}, Material::kConcrete, -1, 0};
      any = true;
    }
  } else if (d.z() > kEps && ceiling_z_) {
    const double t = (*ceiling_z_ - o.z()) / d.z();
    if (t > 0 && t < best.range_m) {
      best = {t, {0, 0, -1}, Material::kPainted, -1, 0};
      any = true;
    }
  }

  if (++scratch.ray == 0) {  // stamp wrapped: clear
    std::fill(scratch.stamp.begin(), scratch.stamp.end(), 0);
    scratch.ray = 1;
  }
  // 2-D DDA over the grid.
  const double gx = (o.x() - origin_.x()) / cell_, gy = (o.y() - origin_.y()) / cell_;
  int cx = static_cast<int>(std::floor(gx)), cy = static_cast<int>(std::floor(gy));
  const int step_x = d.x() > 0 ? 1 : -1, step_y = d.y() > 0 ? 1 : -1;
  const double inv_dx = std::fabs(d.x()) > kEps ? 1.0 / std::fabs(d.x()) : kInf;
  const double inv_dy = std::fabs(d.y()) > kEps ? 1.0 / std::fabs(d.y()) : kInf;
  // A ray without an x (or y) component never crosses an x (or y) cell boundary. Setting that
  // explicitly avoids 0 * inf = NaN when the origin lies exactly on a boundary.
  double t_next_x =
      inv_dx == kInf ? kInf : ((d.x() > 0 ? (cx + 1 - gx) : (gx - cx)) * cell_) * inv_dx;
  double t_next_y =
      inv_dy == kInf ? kInf : ((d.y() > 0 ? (cy + 1 - gy) : (gy - cy)) * cell_) * inv_dy;
  const double t_dx = cell_ * inv_dx, t_dy = cell_ * inv_dy;
  double t_cell_start = 0.0;
  for (int guard = 0; guard < 100000; ++guard) {
    if (cx < 0 || cy < 0 || cx >= nx_ || cy >= ny_) break;  // left the building's grid
    const auto k = static_cast<std::size_t>(cy * nx_ + cx);
    for (std::uint32_t i = cell_start_[k]; i < cell_start_[k + 1]; ++i) {
      const std::uint32_t id = cells_[i];
      if (scratch.stamp[id] == scratch.ray) continue;
      scratch.stamp[id] = scratch.ray;
      any |= TestPrimitive(id, o, d, best);
    }
    const double t_cell_end = std::min(t_next_x, t_next_y);
    if (best.range_m <= t_cell_end || t_cell_start >= best.range_m) break;
    t_cell_start = t_cell_end;
    if (t_next_x < t_next_y) {
      cx += step_x;
      t_next_x += t_dx;
    } else {
      cy += step_y;
      t_next_y += t_dy;
    }
  }
  if (!any) return std::nullopt;
  if (best.normal.dot(d) > 0) best.normal = -best.normal;
  return best;
}

double Scene::DistanceToSurface(const Eigen::Vector3d& p, double search_radius) const {
  double best = std::fabs(p.z() - floor_z_);
  if (ceiling_z_) best = std::min(best, std::fabs(p.z() - *ceiling_z_));
  ForEachPrimitiveNear(p.head<2>(), search_radius, [&](std::uint32_t id) {
    if (id < boxes_.size()) {
      const BoxPrimitive& b = boxes_[id];
      const double px = p.x() - b.centre.x(), py = p.y() - b.centre.y();
      const Eigen::Vector3d local(b.c * px + b.s * py, -b.s * px + b.c * py,
                                  p.z() - 0.5 * (b.z0 + b.z1));
      const Eigen::Vector3d half(b.hx, b.hy, 0.5 * (b.z1 - b.z0));
      const Eigen::Vector3d q = local.cwiseAbs() - half;
      const double outside = q.cwiseMax(0.0).norm();
      const double inside = std::min(0.0, q.maxCoeff());
      best = std::min(best, std::fabs(outside + inside));
    } else {
      const CylinderPrimitive& c = cylinders_[id - boxes_.size()];
      const double r = std::hypot(p.x() - c.centre.x(), p.y() - c.centre.y()) - c.radius;
      const double h = std::max(c.z0 - p.z(), p.z() - c.z1);
      const double outside = std::hypot(std::max(r, 0.0), std::max(h, 0.0));
      const double inside = std::min(0.0, std::max(r, h));
      best = std::min(best, std::fabs(outside + inside));
    }
  });
  return best;
}

double Scene::FootprintDistance(const Eigen::Vector2d& p,
                                double z_lo,
                                double z_hi,
                                double search_radius) const {
  double best = kInf;
  ForEachPrimitiveNear(p, search_radius, [&](std::uint32_t id) {
    if (id < boxes_.size()) {
      const BoxPrimitive& b = boxes_[id];
      if (b.z1 < z_lo || b.z0 > z_hi) return;
      const double px = p.x() - b.centre.x(), py = p.y() - b.centre.y();
      const double qx = std::fabs(b.c * px + b.s * py) - b.hx,
                   qy = std::fabs(-b.s * px + b.c * py) - b.hy;
      best = std::min(best, std::hypot(std::max(qx, 0.0), std::max(qy, 0.0)));
    } else {
      const CylinderPrimitive& c = cylinders_[id - boxes_.size()];
      if (c.z1 < z_lo || c.z0 > z_hi) return;
      best = std::min(
          best, std::max(0.0, std::hypot(p.x() - c.centre.x(), p.y() - c.centre.y()) - c.radius));
    }
  });
  return best > search_radius ? kInf : best;
}

}  // namespace msgraphs::sim
