// SPDX-License-Identifier: MIT
#include "msgraphs/core/collab/free_space_summary.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace msgraphs::core {
namespace {
// Chamfer 3-4 distance: 3 units a cell along an axis, 4 diagonally (within 6 % of Euclidean).
constexpr std::uint16_t kAxis = 3, kDiagonal = 4;
constexpr std::uint16_t kFar = std::numeric_limits<std::uint16_t>::max();
}  // namespace

Status FreeSpaceSummaryConfig::Validate() const {
  if (!(cell_m >= 0.1f && cell_m <= 2.0f) || max_cells < 16 || max_cells > (std::size_t{1} << 24) ||
      !(min_free_share > 0.0f && min_free_share <= 1.0f) || max_openings > 65535 ||
      !(min_opening_m > 0) || !(opening_front_m > 0) || !(opening_behind_m > 0)) {
    return Error{Errc::kInvalidConfig,
                 "free-space summary: cell 0.1..2 m, 16..2^24 cells, free share in (0, 1], "
                 "at most 65535 openings, opening sizes positive"};
  }
  return Ok();
}

Status FreeSpaceSummary::Init(const FreeSpaceSummaryConfig& config) {
  if (auto s = config.Validate(); !s) return s;
  config_ = config;
  cell_m_ = config.cell_m;
  cells_.assign(config.max_cells, 0);
  clearance_.assign(config.max_cells, 0);
  openings_.assign(config.max_openings, Opening{});
  opening_count_ = 0;
  width_ = height_ = 0;
  free_cells_ = 0;
  cropped_ = 0;
  return Ok();
}

Status FreeSpaceSummary::Reset(const Eigen::Vector2d& origin_m, float cell_m, int width,
                               int height) {
  if (!origin_m.allFinite() || !(cell_m >= 0.05f && cell_m <= 4.0f) || width < 1 || height < 1)
    return Error{Errc::kMalformed, "free-space summary: cell size or grid size out of range"};
  if (static_cast<std::size_t>(width) * static_cast<std::size_t>(height) > cells_.size())
    return Error{Errc::kCapacityExceeded, "free-space summary: grid larger than max_cells"};
  origin_m_ = origin_m;
  cell_m_ = cell_m;
  width_ = width;
  height_ = height;
  std::fill_n(cells_.begin(), cells(), std::uint8_t{0});
  free_cells_ = 0;
  opening_count_ = 0;
  return Ok();
}

bool FreeSpaceSummary::add_opening(const Opening& o) {
  if (opening_count_ == openings_.size()) return false;
  openings_[opening_count_++] = o;
  return true;
}

bool FreeSpaceSummary::NearOpening(const Eigen::Vector2d& p, double margin_m) const {
  for (std::size_t i = 0; i < opening_count_; ++i) {
    const Eigen::Vector2d ab = openings_[i].b - openings_[i].a;
    const double t = std::clamp(ab.dot(p - openings_[i].a) / std::max(1e-12, ab.squaredNorm()), 0.0, 1.0);
    if ((openings_[i].a + t * ab - p).norm() <= margin_m) return true;
  }
  return false;
}

namespace {

// A fine cell of a wall seen edge-on: it returned points in the obstacle band, the descending
// rays through it ran one way only (within a sector or two side by side), and the returns line
// up along those rays (another cell one or two steps along them returned points too): the rays
// grazed a surface that runs their way. A wall copy that rays crossed, one way but across it,
// has its returns across the rays instead, and is seen through.
bool SeenEdgeOn(const FreeSpaceGrid& grid, int x, int y) {
  if (!grid.ever_occupied(x, y) || grid.clear_across(x, y)) return false;
  const unsigned mask = grid.clear_directions(x, y);
  if (mask == 0) return false;  // no descending ray crossed it: not free anyway
  int sector = 0;
  while ((mask & (1u << sector)) == 0) ++sector;
  // The middle of the set sectors: one, or two side by side (the last and the first are side
  // by side across the half turn).
  double sectors = sector + 0.5;
  if (sector == 0 && (mask & (1u << (FreeSpaceGrid::kDirectionSectors - 1))) != 0) {
    sectors = 0.0;
  } else if ((mask & (1u << (sector + 1))) != 0) {
    sectors = sector + 1.0;
  }
  constexpr double kPi = 3.14159265358979323846;
  const double angle = sectors * kPi / FreeSpaceGrid::kDirectionSectors;
  const double ux = std::cos(angle), uy = std::sin(angle);
  for (const double step : {1.0, 2.0, -1.0, -2.0}) {
    const int nx = x + static_cast<int>(std::lround(step * ux)), ny = y + static_cast<int>(std::lround(step * uy));
    if ((nx != x || ny != y) && grid.ever_occupied(nx, ny)) return true;
  }
  return false;
}

}  // namespace

Status FreeSpaceSummary::Build(const FreeSpaceGrid& grid, std::span<const DistilledWall> walls) {
  // The bounding box of the known fine cells.
  int x0 = grid.width(), y0 = grid.height(), x1 = -1, y1 = -1;
  for (int y = 0; y < grid.height(); ++y) {
    for (int x = 0; x < grid.width(); ++x) {
      if (grid.state(x, y) == FreeSpaceGrid::Cell::kUnknown) continue;
      x0 = std::min(x0, x);
      x1 = std::max(x1, x);
      y0 = std::min(y0, y);
      y1 = std::max(y1, y);
    }
  }
  width_ = height_ = 0;
  free_cells_ = 0;
  opening_count_ = 0;
  if (x1 < 0) return Error{Errc::kDegenerate, "free-space summary: the grid knows no cell"};
  const float fine = grid.resolution();
  const int ratio = std::max(1, static_cast<int>(std::lround(config_.cell_m / fine)));
  cell_m_ = fine * static_cast<float>(ratio);
  int cx0 = x0 / ratio, cy0 = y0 / ratio;
  int w = x1 / ratio - cx0 + 1, h = y1 / ratio - cy0 + 1;
  // Too large for the store: keep the part around the map origin (where the robot started),
  // and say so.
  const auto max_cells = static_cast<double>(cells_.size());
  if (static_cast<double>(w) * h > max_cells) {
    ++cropped_;
    const double shrink = std::sqrt(max_cells / (static_cast<double>(w) * h));
    const int nw = std::max(1, static_cast<int>(w * shrink)), nh = std::max(1, static_cast<int>(h * shrink));
    int ox = 0, oy = 0;
    const bool inside = grid.ToCell(Eigen::Vector2d::Zero(), ox, oy);
    const int ocx = inside ? ox / ratio : cx0 + w / 2, ocy = inside ? oy / ratio : cy0 + h / 2;
    cx0 = std::clamp(ocx - nw / 2, cx0, cx0 + w - nw);
    cy0 = std::clamp(ocy - nh / 2, cy0, cy0 + h - nh);
    w = nw;
    h = nh;
  }
  const Eigen::Vector2d corner = grid.CellCentre(cx0 * ratio, cy0 * ratio) -
                                 Eigen::Vector2d::Constant(0.5 * static_cast<double>(fine));
  origin_m_ = corner;
  width_ = w;
  height_ = h;
  const int need_free =
      std::max(1, static_cast<int>(std::ceil(config_.min_free_share * static_cast<float>(ratio * ratio))));
  for (int cy = 0; cy < h; ++cy) {
    for (int cx = 0; cx < w; ++cx) {
      int free = 0;
      bool occupied = false, edge_on = false;
      for (int fy = 0; fy < ratio && !occupied; ++fy) {
        for (int fx = 0; fx < ratio; ++fx) {
          const int gx = (cx0 + cx) * ratio + fx, gy = (cy0 + cy) * ratio + fy;
          if (grid.state(gx, gy) == FreeSpaceGrid::Cell::kOccupied) {
            occupied = true;
            break;
          }
          edge_on = edge_on || SeenEdgeOn(grid, gx, gy);
          free += grid.clear_below_sensor(gx, gy) ? 1 : 0;
        }
      }
      // A wall seen edge-on (from a doorway in its line: many grazing rays, few returns, so the
      // fine grid reads it "not occupied") is not free space: a peer's true wall there would
      // count against the true transform (benchmark m010-warehouse, 3 m of it), a robot's own
      // wall against its own map (m034). Unknown, not occupied. A place the rays crossed was
      // seen through, whatever returned from it once (a person who walked by, the wall copy of
      // a slipped map: m023, the evidence merge rule 6 needs).
      const SummaryCell s = occupied                       ? SummaryCell::kOccupied
                            : free >= need_free && !edge_on ? SummaryCell::kFree
                                                            : SummaryCell::kUnknown;
      cells_[static_cast<std::size_t>(cy) * static_cast<std::size_t>(w) + static_cast<std::size_t>(cx)] =
          static_cast<std::uint8_t>(s);
    }
  }
  for (const DistilledWall& wall : walls) FindOpenings(grid, wall);
  ComputeClearance();
  return Ok();
}

void FreeSpaceSummary::FindOpenings(const FreeSpaceGrid& grid, const DistilledWall& wall) {
  const double horizontal = wall.normal.head<2>().norm();
  if (!(horizontal > 0.9) || !wall.a.allFinite() || !wall.b.allFinite()) return;
  const Eigen::Vector2d n = wall.normal.head<2>() / horizontal;
  const double d = wall.d / horizontal;
  // The extent's ends on the wall's line.
  const Eigen::Vector2d foot = -d * n, u(-n.y(), n.x());
  const Eigen::Vector2d a = foot + u.dot(wall.a - foot) * u, b = foot + u.dot(wall.b - foot) * u;
  const double length = (b - a).norm();
  const double step = static_cast<double>(grid.resolution());
  if (length < static_cast<double>(config_.min_opening_m)) return;
  auto clear_at = [&](const Eigen::Vector2d& p) {
    int x = 0, y = 0;
    return grid.ToCell(p, x, y) && grid.clear_below_sensor(x, y) &&
           grid.state(x, y) != FreeSpaceGrid::Cell::kOccupied;
  };
  // Nothing ever returned from the cell. Not the grid's state: a wall seen edge-on is crossed
  // by many grazing rays and hit by few, so its cells read "not occupied" although solid; an
  // opening there would contradict a peer's true wall (m010-warehouse of the benchmark).
  auto unhit_at = [&](const Eigen::Vector2d& p) {
    int x = 0, y = 0;
    return grid.ToCell(p, x, y) && !grid.ever_occupied(x, y);
  };
  const auto steps = static_cast<int>(length / step);
  int run_start = -1, last_open = -2;
  auto close_run = [&](int end) {
    if (run_start < 0) return;
    const double width = (end - run_start + 1) * step;
    if (width >= static_cast<double>(config_.min_opening_m) && opening_count_ < openings_.size()) {
      const Eigen::Vector2d dir = (b - a) / length;
      openings_[opening_count_++] = {a + dir * (run_start * step), a + dir * ((end + 1) * step)};
    }
    run_start = -1;
  };
  for (int i = 0; i <= steps; ++i) {
    const Eigen::Vector2d p = a + (b - a) * (static_cast<double>(i) * step / length);
    // Seen through: clear in front and behind, and no return across the wall's body (a plane
    // estimated a few centimetres off its face must not open the whole wall).
    bool open = clear_at(p + static_cast<double>(config_.opening_front_m) * n) &&
                clear_at(p - static_cast<double>(config_.opening_behind_m) * n);
    for (double across = -0.3; open && across <= 0.15; across += step) open = unhit_at(p + across * n);
    if (open) {
      // One cell missed (a grazing ray) does not split an opening.
      if (run_start < 0 || i - last_open > 2) {
        close_run(last_open);
        run_start = i;
      }
      last_open = i;
    }
  }
  close_run(last_open);
}

void FreeSpaceSummary::ComputeClearance() {
  const std::size_t n = cells();
  free_cells_ = 0;
  for (std::size_t k = 0; k < n; ++k) {
    const bool free = cells_[k] == static_cast<std::uint8_t>(SummaryCell::kFree);
    free_cells_ += free ? 1 : 0;
    clearance_[k] = free ? kFar : 0;
  }
  // Two passes of the chamfer transform; the grid's border counts as not free (beyond it the
  // robot knows nothing).
  auto at = [&](int x, int y) -> std::uint16_t {
    if (x < 0 || y < 0 || x >= width_ || y >= height_) return 0;
    return clearance_[static_cast<std::size_t>(y) * static_cast<std::size_t>(width_) + static_cast<std::size_t>(x)];
  };
  auto relax = [](std::uint16_t& v, std::uint16_t neighbour, std::uint16_t cost) {
    const std::uint32_t c = static_cast<std::uint32_t>(neighbour) + cost;
    if (c < v) v = static_cast<std::uint16_t>(std::min<std::uint32_t>(c, kFar));
  };
  for (int y = 0; y < height_; ++y) {
    for (int x = 0; x < width_; ++x) {
      std::uint16_t& v = clearance_[static_cast<std::size_t>(y) * static_cast<std::size_t>(width_) + static_cast<std::size_t>(x)];
      if (v == 0) continue;
      relax(v, at(x - 1, y), kAxis);
      relax(v, at(x, y - 1), kAxis);
      relax(v, at(x - 1, y - 1), kDiagonal);
      relax(v, at(x + 1, y - 1), kDiagonal);
    }
  }
  for (int y = height_ - 1; y >= 0; --y) {
    for (int x = width_ - 1; x >= 0; --x) {
      std::uint16_t& v = clearance_[static_cast<std::size_t>(y) * static_cast<std::size_t>(width_) + static_cast<std::size_t>(x)];
      if (v == 0) continue;
      relax(v, at(x + 1, y), kAxis);
      relax(v, at(x, y + 1), kAxis);
      relax(v, at(x + 1, y + 1), kDiagonal);
      relax(v, at(x - 1, y + 1), kDiagonal);
    }
  }
}

bool FreeSpaceSummary::Cell(const Eigen::Vector2d& p, int& x, int& y) const {
  const double fx = (p.x() - origin_m_.x()) / static_cast<double>(cell_m_);
  const double fy = (p.y() - origin_m_.y()) / static_cast<double>(cell_m_);
  if (!(fx >= 0 && fy >= 0 && fx < width_ && fy < height_)) return false;
  x = static_cast<int>(fx);
  y = static_cast<int>(fy);
  return true;
}

SummaryCell FreeSpaceSummary::state(int x, int y) const {
  if (x < 0 || y < 0 || x >= width_ || y >= height_) return SummaryCell::kUnknown;
  return static_cast<SummaryCell>(
      cells_[static_cast<std::size_t>(y) * static_cast<std::size_t>(width_) + static_cast<std::size_t>(x)]);
}

SummaryCell FreeSpaceSummary::state_at(const Eigen::Vector2d& p_map) const {
  int x = 0, y = 0;
  return Cell(p_map, x, y) ? state(x, y) : SummaryCell::kUnknown;
}

float FreeSpaceSummary::clearance_m(const Eigen::Vector2d& p_map) const {
  int x = 0, y = 0;
  if (!Cell(p_map, x, y)) return 0.0f;
  const std::uint16_t v =
      clearance_[static_cast<std::size_t>(y) * static_cast<std::size_t>(width_) + static_cast<std::size_t>(x)];
  // The chamfer distance counts to the centre of the nearest non-free cell; its edge is half a
  // cell nearer.
  return std::max(0.0f, (static_cast<float>(v) / kAxis - 0.5f) * cell_m_);
}

}  // namespace msgraphs::core
