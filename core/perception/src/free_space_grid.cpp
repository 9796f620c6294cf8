// SPDX-License-Identifier: MIT
#include "msgraphs/core/perception/free_space_grid.hpp"
#include "msgraphs/base/snapshot_archive.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>

namespace msgraphs::core {
namespace {

// The sector of a ray's line direction, (dx, dy) != 0: floor(angle / pi * 8) of its angle folded
// into [0, pi] (pi itself in the last sector), by comparing slopes with the sector bounds'
// tangents: one per ray and per point of every keyframe, where atan2 cost a millisecond.
int Sector(int dx, int dy) {
  static_assert(FreeSpaceGrid::kDirectionSectors == 8, "the bounds below are for 8 sectors");
  constexpr double kTan22 = 0.41421356237309503;  // tan(pi / 8)
  constexpr double kTan67 = 2.4142135623730949;   // tan(3 pi / 8)
  if (dy < 0) {
    dx = -dx;
    dy = -dy;
  }
  const double x = std::abs(dx), y = dy;
  if (dx > 0) return y < kTan22 * x ? 0 : y < x ? 1 : y < kTan67 * x ? 2 : 3;
  if (dx == 0) return 4;
  return y <= kTan22 * x ? 7 : y <= x ? 6 : y <= kTan67 * x ? 5 : 4;
}

}  // namespace

Status FreeSpaceGridConfig::Validate() const {
  if (!(resolution_m >= 0.02f && resolution_m <= 1.0f) || width < 8 || height < 8 || width > 8192 || height > 8192 ||
      !origin_m.allFinite() || !(obstacle_max_height_m > obstacle_min_height_m) || !(max_range_m > 0) ||
      follow_step_cells < 1) {
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
  low_directions_.assign(n, 0);
  outside_ = 0;
  moves_ = 0;
  origin0_m_ = config.origin_m;
  moved_cells_.setZero();
  return Ok();
}

void FreeSpaceGrid::Clear() {
  std::fill(free_.begin(), free_.end(), 0);
  std::fill(occupied_.begin(), occupied_.end(), 0);
  std::fill(clear_low_.begin(), clear_low_.end(), 0);
  std::fill(low_directions_.begin(), low_directions_.end(), std::uint8_t{0});
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

std::uint8_t FreeSpaceGrid::clear_directions(int x, int y) const {
  if (x < 0 || y < 0 || x >= config_.width || y >= config_.height) return 0;
  return low_directions_[static_cast<std::size_t>(y) * static_cast<std::size_t>(config_.width) + static_cast<std::size_t>(x)];
}

bool FreeSpaceGrid::clear_across(int x, int y) const {
  const unsigned mask = clear_directions(x, y);
  // Two sectors with one between them, either way round the half turn: rays at least one
  // sector's width apart.
  for (int i = 0; i < kDirectionSectors; ++i) {
    if ((mask & (1u << i)) == 0) continue;
    for (int j = i + 2; j < kDirectionSectors; ++j) {
      if ((mask & (1u << j)) != 0 && kDirectionSectors - (j - i) >= 2) return true;
    }
  }
  return false;
}

void FreeSpaceGrid::Ray(int x0, int y0, int x1, int y1, bool mark_end_free, bool descending) {
  const unsigned sector_bit = descending && (x1 != x0 || y1 != y0) ? 1u << Sector(x1 - x0, y1 - y0) : 0u;
  const int dx = std::abs(x1 - x0), dy = -std::abs(y1 - y0);
  const int sx = x0 < x1 ? 1 : -1, sy = y0 < y1 ? 1 : -1;
  int err = dx + dy;
  for (;;) {
    const bool end = x0 == x1 && y0 == y1;
    if (end && !mark_end_free) break;
    const std::size_t k = static_cast<std::size_t>(y0) * static_cast<std::size_t>(config_.width) + static_cast<std::size_t>(x0);
    if (free_[k] < 0xFFFF) ++free_[k];
    if (descending && clear_low_[k] < 0xFFFF) ++clear_low_[k];
    low_directions_[k] = static_cast<std::uint8_t>(low_directions_[k] | sector_bit);
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

template <typename T>
void FreeSpaceGrid::Shift(std::vector<T>& cells, int dx, int dy) const {
  // new(x, y) = old(x + dx, y + dy), zero where that is outside. Rows are visited in the order
  // that reads each source row before it is overwritten.
  const int w = config_.width, h = config_.height;
  const int keep = std::max(0, w - std::abs(dx));
  for (int i = 0; i < h; ++i) {
    const int y = dy >= 0 ? i : h - 1 - i;
    T* row = cells.data() + static_cast<std::size_t>(y) * static_cast<std::size_t>(w);
    const int src_y = y + dy;
    if (src_y < 0 || src_y >= h || keep == 0) {
      std::fill(row, row + w, T{0});
      continue;
    }
    const T* src = cells.data() + static_cast<std::size_t>(src_y) * static_cast<std::size_t>(w);
    std::memmove(row + std::max(0, -dx), src + std::max(0, dx), static_cast<std::size_t>(keep) * sizeof(T));
    if (dx > 0) std::fill(row + keep, row + w, T{0});
    if (dx < 0) std::fill(row, row - dx, T{0});
  }
}

bool FreeSpaceGrid::Follow(const Eigen::Vector2f& sensor_m) {
  if (!sensor_m.allFinite()) return false;
  const float r = config_.resolution_m;
  const float margin_m =
      std::min(config_.max_range_m, 0.25f * r * static_cast<float>(std::min(config_.width, config_.height)));
  const Eigen::Vector2f low = sensor_m - config_.origin_m;
  const Eigen::Vector2f high = Eigen::Vector2f(r * static_cast<float>(config_.width), r * static_cast<float>(config_.height)) - low;
  if (low.minCoeff() >= margin_m && high.minCoeff() >= margin_m) return false;
  // The shift that centres the sensor, rounded to whole steps (a far jump clears the grid).
  const auto steps = [&](float offset_m, int cells) {
    const double shift_cells = static_cast<double>(offset_m / r) - 0.5 * cells;
    const int step = config_.follow_step_cells;
    const double s = std::round(shift_cells / step) * step;
    return static_cast<int>(std::clamp(s, -4.0 * cells, 4.0 * cells));
  };
  const int dx = steps(low.x(), config_.width), dy = steps(low.y(), config_.height);
  if (dx == 0 && dy == 0) return false;
  Shift(free_, dx, dy);
  Shift(occupied_, dx, dy);
  Shift(clear_low_, dx, dy);
  Shift(low_directions_, dx, dy);
  moved_cells_ += Eigen::Vector2i(dx, dy);  // summed in cells: no rounding drift over many moves
  config_.origin_m = origin0_m_ + moved_cells_.cast<float>() * r;
  ++moves_;
  return true;
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


template <class Archive>
void FreeSpaceGrid::Io(Archive& ar) {
  IoSameSize(ar, free_.size());
  if (ar.failed()) return;
  ar(free_.data(), free_.size());
  ar(occupied_.data(), occupied_.size());
  ar(clear_low_.data(), clear_low_.size());
  ar(low_directions_.data(), low_directions_.size());
  ar(outside_);
  ar(moves_);
  // Where the window has moved to, in whole cells from the configured origin (the config's,
  // not the snapshot's): the origin follows from it as Follow computes it.
  ar(moved_cells_.data(), 2);
  if constexpr (Archive::kLoading) {
    // Follow moves at most four widths a step; a mission's worth is far below this bound,
    // which keeps the sums in int.
    constexpr int kMaxMovedCells = 1 << 24;
    const auto out = [](int v) { return v < -kMaxMovedCells || v > kMaxMovedCells; };
    if (out(moved_cells_.x()) || out(moved_cells_.y())) {
      ar.Fail();
      moved_cells_.setZero();
    }
    config_.origin_m = origin0_m_ + moved_cells_.cast<float>() * config_.resolution_m;
  }
}

void FreeSpaceGrid::Save(SnapshotWriter& w) const { const_cast<FreeSpaceGrid*>(this)->Io(w); }
void FreeSpaceGrid::Load(SnapshotReader& r) { Io(r); }

}  // namespace msgraphs::core
