// SPDX-License-Identifier: MIT
#include "msgraphs/core/perception/room_segmentation.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

namespace msgraphs::core {
namespace {
constexpr float kInf = 1e20f;
}  // namespace

Status RoomSegmentationConfig::Validate() const {
  if (!(door_cut_clearance_m > 0.05f) || !(min_region_area_m2 >= 0) || !(close_openings_up_to_m >= 0)) return Error{Errc::kInvalidConfig, "rooms: door cut clearance > 0.05 m"};
  return Ok();
}

Status RoomDetectionConfig::Validate() const {
  if (!(wall_search_m > 0) || !(min_width_m > 0) || !(angle_tolerance_deg > 0 && angle_tolerance_deg < 45) ||
      !(max_centre_outside_m >= 0)) {
    return Error{Errc::kInvalidConfig, "rooms: search and width must be > 0, angle tolerance 0..45 degrees"};
  }
  return Ok();
}

Status RoomSegmenter::Init(int width, int height, std::size_t max_regions, std::size_t max_walls) {
  if (width < 1 || height < 1 || max_regions == 0 || max_regions > 65000) {
    return Error{Errc::kInvalidConfig, "rooms: grid size and 1..65000 regions"};
  }
  width_ = width;
  height_ = height;
  const auto n = static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
  dist2_.assign(n, 0.0f);
  labels_.assign(n, 0);
  queue_.assign(n, 0);
  const auto m = static_cast<std::size_t>(std::max(width, height)) + 1;
  f_.assign(m, 0.0f);
  d_.assign(m, 0.0f);
  z_.assign(m + 1, 0.0f);
  v_.assign(m, 0);
  max_regions_ = max_regions;
  max_walls_ = max_walls;
  support_.assign(max_walls * (max_regions + 1), 0);
  keep_.assign(65536, 0);
  blocked_.assign(n, 0);
  return Ok();
}

float RoomSegmenter::clearance(int x, int y) const { return std::sqrt(dist2_[Index(x, y)]) * resolution_; }

// Felzenszwalb-Huttenlocher exact 1-D squared distance transform of f_[0, n) into d_.
void RoomSegmenter::DistanceTransform1D(int n) {
  int k = 0;
  v_[0] = 0;
  z_[0] = -kInf;
  z_[1] = kInf;
  for (int q = 1; q < n; ++q) {
    const auto uq = static_cast<std::size_t>(q);
    float s = 0;
    for (;;) {
      const int p = v_[static_cast<std::size_t>(k)];
      const auto up = static_cast<std::size_t>(p);
      s = ((f_[uq] + static_cast<float>(q * q)) - (f_[up] + static_cast<float>(p * p))) / static_cast<float>(2 * q - 2 * p);
      if (s > z_[static_cast<std::size_t>(k)] || k == 0) break;
      --k;
    }
    if (s <= z_[static_cast<std::size_t>(k)] && k == 0) {
      v_[0] = q;
      z_[0] = -kInf;
      z_[1] = kInf;
      continue;
    }
    ++k;
    v_[static_cast<std::size_t>(k)] = q;
    z_[static_cast<std::size_t>(k)] = s;
    z_[static_cast<std::size_t>(k) + 1] = kInf;
  }
  k = 0;
  for (int q = 0; q < n; ++q) {
    while (z_[static_cast<std::size_t>(k) + 1] < static_cast<float>(q)) ++k;
    const int p = v_[static_cast<std::size_t>(k)];
    d_[static_cast<std::size_t>(q)] = static_cast<float>((q - p) * (q - p)) + f_[static_cast<std::size_t>(p)];
  }
}

void RoomSegmenter::CloseOpenings(const FreeSpaceGrid& grid, std::span<const MapWall> walls, float max_gap_m) {
  std::fill(blocked_.begin(), blocked_.end(), 0);
  const double step = 0.5 * static_cast<double>(grid.resolution());
  auto block = [&](const Eigen::Vector2d& p, const Eigen::Vector2d& q) {
    const double length = (q - p).norm();
    for (double s = 0; s <= length; s += step) {
      int x = 0, y = 0;
      if (grid.ToCell(p + (q - p) * (length > 0 ? s / length : 0.0), x, y)) blocked_[Index(x, y)] = 1;
    }
  };
  // A wall's extent spans its doorways when the wall continues above them (a lintel is part of
  // the same plane): where that line crosses free space at walking height is an opening.
  for (const MapWall& w : walls) {
    if (w.a.allFinite() && w.b.allFinite()) block(w.a, w.b);
  }
  if (!(max_gap_m > 0.0f)) return;
  const double cos5 = std::cos(5.0 * std::numbers::pi / 180.0);
  for (std::size_t i = 0; i < walls.size(); ++i) {
    for (std::size_t j = i + 1; j < walls.size(); ++j) {
      const MapWall& a = walls[i];
      const MapWall& b = walls[j];
      if (a.normal.dot(b.normal) < cos5 || std::fabs(a.d - b.d) > 0.15) continue;  // not one line, one side
      const Eigen::Vector2d dir(-a.normal.y(), a.normal.x());
      double a0 = dir.dot(a.a), a1 = dir.dot(a.b), b0 = dir.dot(b.a), b1 = dir.dot(b.b);
      if (a0 > a1) std::swap(a0, a1);
      if (b0 > b1) std::swap(b0, b1);
      double from = 0, to = 0;
      if (a1 <= b0) {
        from = a1;
        to = b0;
      } else if (b1 <= a0) {
        from = b1;
        to = a0;
      } else {
        continue;  // overlapping pieces: no opening between them
      }
      if (to - from < 0.3 || to - from > static_cast<double>(max_gap_m)) continue;
      // Close the gap along the (averaged) line.
      const Eigen::Vector2d foot = -0.5 * (a.d + b.d) * a.normal;
      block(foot + (from - dir.dot(foot)) * dir, foot + (to - dir.dot(foot)) * dir);
    }
  }
}

Status RoomSegmenter::Segment(const FreeSpaceGrid& grid, const RoomSegmentationConfig& config,
                              BoundedVector<RoomRegion>& regions, std::span<const MapWall> walls) {
  regions.clear();
  if (Status s = config.Validate(); !s) return s;
  if (grid.width() != width_ || grid.height() != height_) return Error{Errc::kInvalidArgument, "rooms: grid size differs from Init"};
  resolution_ = grid.resolution();
  CloseOpenings(grid, walls, config.close_openings_up_to_m);
  // Distance transform: sites are the cells that are not free, and closed openings.
  for (int y = 0; y < height_; ++y) {
    for (int x = 0; x < width_; ++x) {
      const bool free = grid.state(x, y) == FreeSpaceGrid::Cell::kFree && blocked_[Index(x, y)] == 0;
      dist2_[Index(x, y)] = free ? kInf : 0.0f;
    }
  }
  for (int x = 0; x < width_; ++x) {
    for (int y = 0; y < height_; ++y) f_[static_cast<std::size_t>(y)] = dist2_[Index(x, y)];
    DistanceTransform1D(height_);
    for (int y = 0; y < height_; ++y) dist2_[Index(x, y)] = d_[static_cast<std::size_t>(y)];
  }
  for (int y = 0; y < height_; ++y) {
    for (int x = 0; x < width_; ++x) f_[static_cast<std::size_t>(x)] = dist2_[Index(x, y)];
    DistanceTransform1D(width_);
    for (int x = 0; x < width_; ++x) dist2_[Index(x, y)] = d_[static_cast<std::size_t>(x)];
  }
  // Cores: free cells farther than the cut clearance from any obstacle; 4-connected components.
  const float cut_cells = config.door_cut_clearance_m / resolution_;
  const float cut2 = cut_cells * cut_cells;
  std::fill(labels_.begin(), labels_.end(), 0);
  std::uint16_t next = 0;
  bool overflow = false;
  auto push_neighbours = [&](std::uint32_t k, std::size_t& tail, auto&& accept) {
    const int x = static_cast<int>(k % static_cast<std::uint32_t>(width_)), y = static_cast<int>(k / static_cast<std::uint32_t>(width_));
    const int nx[4] = {x + 1, x - 1, x, x}, ny[4] = {y, y, y + 1, y - 1};
    for (int i = 0; i < 4; ++i) {
      if (nx[i] < 0 || ny[i] < 0 || nx[i] >= width_ || ny[i] >= height_) continue;
      const std::size_t u = Index(nx[i], ny[i]);
      if (labels_[u] != 0 || !accept(u)) continue;
      labels_[u] = labels_[k];
      queue_[tail++] = static_cast<std::uint32_t>(u);
    }
  };
  for (std::size_t seed = 0; seed < labels_.size(); ++seed) {
    if (labels_[seed] != 0 || dist2_[seed] <= cut2 || dist2_[seed] >= kInf) continue;
    if (next == std::numeric_limits<std::uint16_t>::max()) {
      overflow = true;
      break;
    }
    labels_[seed] = ++next;
    std::size_t head = 0, tail = 0;
    queue_[tail++] = static_cast<std::uint32_t>(seed);
    while (head < tail) {
      push_neighbours(queue_[head++], tail, [&](std::size_t u) { return dist2_[u] > cut2 && dist2_[u] < kInf; });
    }
  }
  // Grow the cores back over the cut free cells, breadth first, so each takes the nearest core.
  std::size_t head = 0, tail = 0;
  for (std::size_t k = 0; k < labels_.size(); ++k) {
    if (labels_[k] != 0) queue_[tail++] = static_cast<std::uint32_t>(k);
  }
  while (head < tail) {
    push_neighbours(queue_[head++], tail, [&](std::size_t u) { return dist2_[u] > 0.0f; });
  }
  // Regions, small ones dropped (their cells unlabelled).
  const double cell_area = static_cast<double>(resolution_) * static_cast<double>(resolution_);
  const std::size_t labels = static_cast<std::size_t>(next) + 1;
  if (labels > max_regions_ + 1) overflow = true;
  const std::size_t counted = std::min(labels, max_regions_ + 1);
  // Cells and centroid sums accumulate in the region list itself (label l at index l - 1).
  for (std::size_t l = 1; l < counted; ++l) {
    RoomRegion r;
    r.label = static_cast<std::uint16_t>(l);
    if (!regions.try_push_back(r)) {
      overflow = true;
      break;
    }
  }
  for (int y = 0; y < height_; ++y) {
    for (int x = 0; x < width_; ++x) {
      const std::uint16_t l = labels_[Index(x, y)];
      if (l == 0 || l > regions.size()) continue;
      RoomRegion& r = regions[static_cast<std::size_t>(l) - 1];
      ++r.cells;
      r.centroid += grid.CellCentre(x, y);
    }
  }
  // Compact: keep regions above the minimum area; unlabel the others.
  std::size_t kept = 0;
  for (std::size_t i = 0; i < regions.size(); ++i) {
    RoomRegion r = regions[i];
    r.area_m2 = static_cast<double>(r.cells) * cell_area;
    if (r.cells > 0) r.centroid /= static_cast<double>(r.cells);
    if (r.area_m2 >= static_cast<double>(config.min_region_area_m2)) regions[kept++] = r;
  }
  regions.resize_down(kept);
  std::fill(keep_.begin(), keep_.end(), 0);
  for (std::size_t i = 0; i < regions.size(); ++i) keep_[regions[i].label] = 1;
  for (std::size_t k = 0; k < labels_.size(); ++k) {
    if (keep_[labels_[k]] == 0) labels_[k] = 0;
  }
  if (overflow) return Error{Errc::kCapacityExceeded, "rooms: more regions than capacity"};
  return Ok();
}

Status RoomSegmenter::DetectRooms(const FreeSpaceGrid& grid, std::span<const RoomRegion> regions,
                                  std::span<const MapWall> walls, const RoomDetectionConfig& config,
                                  BoundedVector<DetectedRoom>& rooms) {
  rooms.clear();
  if (Status s = config.Validate(); !s) return s;
  if (walls.size() > max_walls_) return Error{Errc::kCapacityExceeded, "rooms: more walls than Init allowed"};
  if (regions.size() > max_regions_) return Error{Errc::kCapacityExceeded, "rooms: more regions than Init allowed"};
  // Support: for each wall, walk inwards from points along it and count region cells met.
  const std::size_t stride = regions.size();
  std::fill(support_.begin(), support_.begin() + static_cast<std::ptrdiff_t>(walls.size() * stride), 0u);
  auto region_index = [&](std::uint16_t label) -> int {
    for (std::size_t i = 0; i < regions.size(); ++i) {
      if (regions[i].label == label) return static_cast<int>(i);
    }
    return -1;
  };
  const double step = static_cast<double>(resolution_);
  for (std::size_t w = 0; w < walls.size(); ++w) {
    const MapWall& wall = walls[w];
    if (!wall.normal.allFinite() || !wall.a.allFinite() || !wall.b.allFinite()) continue;
    // Sampled a cell apart, never more often than the grid's diagonal holds cells: the rest of
    // a longer wall lies outside the grid (this also bounds the walk for any extent given).
    const double length_cells = (wall.b - wall.a).norm() / step;
    const double diagonal_cells = std::hypot(static_cast<double>(grid.width()), static_cast<double>(grid.height()));
    const int along = std::max(1, static_cast<int>(std::min(length_cells, diagonal_cells)));
    const int depth = static_cast<int>(static_cast<double>(config.wall_search_m) / step);
    for (int i = 0; i <= along; ++i) {
      const Eigen::Vector2d on = wall.a + (wall.b - wall.a) * (static_cast<double>(i) / along);
      std::uint16_t last = 0;
      for (int j = 1; j <= depth; ++j) {
        int x = 0, y = 0;
        if (!grid.ToCell(on + wall.normal * (j * step), x, y)) break;
        const std::uint16_t l = labels_[Index(x, y)];
        if (grid.state(x, y) == FreeSpaceGrid::Cell::kOccupied && j > 3) break;  // another wall
        if (l == 0 || l == last) continue;
        last = l;
        const int r = region_index(l);
        if (r >= 0) support_[w * stride + static_cast<std::size_t>(r)] += 1;
      }
    }
  }
  const double tolerance = static_cast<double>(config.angle_tolerance_deg) * std::numbers::pi / 180.0;
  for (std::size_t r = 0; r < regions.size(); ++r) {
    // Orientation: weighted circular mean of the wall normals' angles times four.
    double s4 = 0, c4 = 0;
    std::size_t total = 0;
    for (std::size_t w = 0; w < walls.size(); ++w) {
      const std::uint32_t support = support_[w * stride + r];
      if (support < config.min_support_cells) continue;
      const double a = std::atan2(walls[w].normal.y(), walls[w].normal.x());
      s4 += support * std::sin(4 * a);
      c4 += support * std::cos(4 * a);
      total += support;
    }
    if (total == 0) continue;
    double yaw = std::atan2(s4, c4) / 4.0;  // in (-pi/4, pi/4]
    if (yaw >= std::numbers::pi / 4) yaw -= std::numbers::pi / 2;
    const Eigen::Vector2d ex(std::cos(yaw), std::sin(yaw)), ey(-std::sin(yaw), std::cos(yaw));
    // The best-supported wall facing +x, -x, +y, -y of the room frame.
    std::array<std::int32_t, 4> best{-1, -1, -1, -1};
    std::array<std::uint32_t, 4> best_support{0, 0, 0, 0};
    const Eigen::Vector2d axes[4] = {ex, -ex, ey, -ey};
    for (std::size_t w = 0; w < walls.size(); ++w) {
      const std::uint32_t support = support_[w * stride + r];
      if (support < config.min_support_cells) continue;
      for (int k = 0; k < 4; ++k) {
        if (walls[w].normal.dot(axes[k]) < std::cos(tolerance)) continue;
        if (support > best_support[static_cast<std::size_t>(k)]) {
          best_support[static_cast<std::size_t>(k)] = support;
          best[static_cast<std::size_t>(k)] = static_cast<std::int32_t>(w);
        }
      }
    }
    const Eigen::Vector2d c = regions[r].centroid;
    // Position of a wall along an axis: its line's foot point nearest the region centroid.
    auto position = [&](std::int32_t w, const Eigen::Vector2d& axis) {
      const MapWall& m = walls[static_cast<std::size_t>(w)];
      const Eigen::Vector2d foot = c - (m.normal.dot(c) + m.d) * m.normal;
      return foot.dot(axis);
    };
    auto pair = [&](int low, int high, const Eigen::Vector2d& axis, double& mid, double& width) {
      if (best[static_cast<std::size_t>(low)] < 0 || best[static_cast<std::size_t>(high)] < 0) return false;
      const double lo = position(best[static_cast<std::size_t>(low)], axis);
      const double hi = position(best[static_cast<std::size_t>(high)], axis);
      const double cc = c.dot(axis);
      width = hi - lo;
      mid = 0.5 * (lo + hi);
      return width >= static_cast<double>(config.min_width_m) && lo < cc && cc < hi;
    };
    double mx = 0, wx = 0, my = 0, wy = 0;
    const bool has_x = pair(0, 1, ex, mx, wx);
    const bool has_y = pair(2, 3, ey, my, wy);
    if (!has_x && !has_y) continue;
    DetectedRoom room;
    room.region = regions[r].label;
    room.support_cells = total;
    if (has_x && has_y) {
      room.kind = RoomKind::kRoom;
      room.centre = mx * ex + my * ey;
      room.yaw_rad = yaw;
      room.size_x_m = wx;
      room.size_y_m = wy;
      room.walls = best;
    } else {
      room.kind = RoomKind::kCorridor;
      // Across the corridor from its walls, along it from the region (the walls say nothing).
      const Eigen::Vector2d across = has_x ? ex : ey;
      const Eigen::Vector2d lengthwise = has_x ? ey : ex;
      const double mid = has_x ? mx : my;
      room.centre = mid * across + c.dot(lengthwise) * lengthwise;
      // For a corridor the x axis points across it, so the yaw keeps its quarter turn.
      room.yaw_rad = has_x ? yaw : yaw + std::numbers::pi / 2;
      room.size_x_m = has_x ? wx : wy;
      room.size_y_m = 0;
      room.walls = has_x ? std::array<std::int32_t, 4>{best[0], best[1], -1, -1}
                         : std::array<std::int32_t, 4>{best[2], best[3], -1, -1};
    }
    // The centre must lie in (or next to) its region.
    int x = 0, y = 0;
    bool inside = false;
    if (grid.ToCell(room.centre, x, y)) {
      const int reach = static_cast<int>(static_cast<double>(config.max_centre_outside_m) / step);
      for (int dy = -reach; dy <= reach && !inside; ++dy) {
        for (int dx = -reach; dx <= reach && !inside; ++dx) {
          const int xx = x + dx, yy = y + dy;
          if (xx < 0 || yy < 0 || xx >= width_ || yy >= height_) continue;
          inside = labels_[Index(xx, yy)] == room.region && dx * dx + dy * dy <= reach * reach;
        }
      }
    }
    if (!inside) continue;
    if (!rooms.try_push_back(room)) return Error{Errc::kCapacityExceeded, "rooms: output full"};
  }
  return Ok();
}

}  // namespace msgraphs::core
