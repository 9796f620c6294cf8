// SPDX-License-Identifier: MIT
#include "msgraphs/core/perception/free_space_grid.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>

namespace msgraphs::core {

Status FreeSpaceGridConfig::Validate() const {
  if (!(resolution_m >= 0.02f && resolution_m <= 1.0f) || width < 8 || height < 8 || width > 8192 || height > 8192 ||
      !origin_m.allFinite() || !(obstacle_max_height_m > obstacle_min_height_m) || !(max_range_m > 0)) {
    return Error{Errc::kInvalidConfig, "free space grid: resolution 0.02..1 m, 8..8192 cells per side, heights ordered"};
  }
  return Ok();
}

Status FreeSpaceGrid::Init(const FreeSpaceGridConfig& config) {
  if (Status s = config.Validate(); !s) return s;
  config_ = config;
  const auto n = static_cast<std::size_t>(config.width) * static_cast<std::size_t>(config.height);
  free_.assign(n, 0);
  occupied_.assign(n, 0);
  clear_low_.assign(n, 0);
  outside_ = 0;
  return Ok();
}

void FreeSpaceGrid::Clear() {
  std::fill(free_.begin(), free_.end(), 0);
  std::fill(occupied_.begin(), occupied_.end(), 0);
  std::fill(clear_low_.begin(), clear_low_.end(), 0);
  outside_ = 0;
}

bool FreeSpaceGrid::ToCell(const Eigen::Vector2d& p, int& x, int& y) const {
  const double fx = (p.x() - static_cast<double>(config_.origin_m.x())) / static_cast<double>(config_.resolution_m);
  const double fy = (p.y() - static_cast<double>(config_.origin_m.y())) / static_cast<double>(config_.resolution_m);
  if (!(fx >= 0 && fy >= 0 && fx < config_.width && fy < config_.height)) return false;
  x = static_cast<int>(fx);
  y = static_cast<int>(fy);
  return true;
}

Eigen::Vector2d FreeSpaceGrid::CellCentre(int x, int y) const {
  const double r = static_cast<double>(config_.resolution_m);
  return {static_cast<double>(config_.origin_m.x()) + (x + 0.5) * r, static_cast<double>(config_.origin_m.y()) + (y + 0.5) * r};
}

FreeSpaceGrid::Cell FreeSpaceGrid::state(int x, int y) const {
  if (x < 0 || y < 0 || x >= config_.width || y >= config_.height) return Cell::kUnknown;
  const auto k = static_cast<std::size_t>(y) * static_cast<std::size_t>(config_.width) + static_cast<std::size_t>(x);
  const unsigned f = free_[k], o = occupied_[k];
  // A wall cell is crossed by grazing rays now and then; a few hits on it outweigh them.
  if (o > 0 && 4 * o >= f) return Cell::kOccupied;
  if (f >= 2) return Cell::kFree;
  return Cell::kUnknown;
}

bool FreeSpaceGrid::ever_occupied(int x, int y) const {
  if (x < 0 || y < 0 || x >= config_.width || y >= config_.height) return false;
  return occupied_[static_cast<std::size_t>(y) * static_cast<std::size_t>(config_.width) + static_cast<std::size_t>(x)] > 0;
}

bool FreeSpaceGrid::clear_below_sensor(int x, int y, unsigned min_rays) const {
  if (x < 0 || y < 0 || x >= config_.width || y >= config_.height) return false;
  return clear_low_[static_cast<std::size_t>(y) * static_cast<std::size_t>(config_.width) + static_cast<std::size_t>(x)] >=
         min_rays;
}

void FreeSpaceGrid::Ray(int x0, int y0, int x1, int y1, bool mark_end_free, bool descending) {
  const int dx = std::abs(x1 - x0), dy = -std::abs(y1 - y0);
  const int sx = x0 < x1 ? 1 : -1, sy = y0 < y1 ? 1 : -1;
  int err = dx + dy;
  for (;;) {
    const bool end = x0 == x1 && y0 == y1;
    if (end && !mark_end_free) break;
    const std::size_t k = static_cast<std::size_t>(y0) * static_cast<std::size_t>(config_.width) + static_cast<std::size_t>(x0);
    if (free_[k] < 0xFFFF) ++free_[k];
    if (descending && clear_low_[k] < 0xFFFF) ++clear_low_[k];
    if (end) break;
    const int e2 = 2 * err;
    if (e2 >= dy) {
      err += dy;
      x0 += sx;
    }
    if (e2 <= dx) {
      err += dx;
      y0 += sy;
    }
  }
}

void FreeSpaceGrid::Integrate(const Eigen::Vector3f& sensor, std::span<const Eigen::Vector3f> points, float floor_z) {
  int sx = 0, sy = 0;
  if (!sensor.allFinite() || !ToCell(sensor.head<2>().cast<double>(), sx, sy)) {
    outside_ += points.size();
    return;
  }
  const float max_range2 = config_.max_range_m * config_.max_range_m;
  for (const Eigen::Vector3f& p : points) {
    if (!p.allFinite() || (p - sensor).head<2>().squaredNorm() > max_range2) continue;
    int x = 0, y = 0;
    if (!ToCell(p.head<2>().cast<double>(), x, y)) {
      ++outside_;
      continue;
    }
    const float h = p.z() - floor_z;
    if (h >= config_.obstacle_min_height_m && h <= config_.obstacle_max_height_m) {
      Ray(sx, sy, x, y, false, p.z() < sensor.z());
      auto& o = occupied_[static_cast<std::size_t>(y) * static_cast<std::size_t>(config_.width) + static_cast<std::size_t>(x)];
      if (o < 0xFFFF) ++o;
    } else {
      // A floor hit is free itself.
      Ray(sx, sy, x, y, h < config_.obstacle_min_height_m, p.z() < sensor.z());
    }
  }
}

}  // namespace msgraphs::core
