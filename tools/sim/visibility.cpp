// SPDX-License-Identifier: MIT
#include "visibility.hpp"

#include <algorithm>
#include <cmath>

namespace msgraphs::sim {

WallVisibility::WallVisibility(const World& world, int level) : world_(&world) {
  bins_.assign(world.walls.size(), 0);
  offset_.assign(world.walls.size() + 1, 0);
  for (std::size_t w = 0; w < world.walls.size(); ++w) {
    const Wall& wall = world.walls[w];
    if (wall.level == level)
      bins_[w] = std::max(1, static_cast<int>(std::ceil(wall.length() / kBinM - 1e-9)));
    offset_[w + 1] = offset_[w] + 2 * static_cast<std::size_t>(bins_[w]);
  }
  counts_.assign(offset_.back(), 0);
  solid_m_.assign(offset_.back() / 2, 0.0);
  for (std::size_t w = 0; w < world.walls.size(); ++w) {
    const Wall& wall = world.walls[w];
    for (int b = 0; b < bins_[w]; ++b) {
      const double lo = b * kBinM, hi = std::min(wall.length(), (b + 1) * kBinM);
      double solid = std::max(0.0, hi - lo);
      for (const Door& d : wall.doors) {
        solid -= std::max(0.0, std::min(hi, d.offset_m + d.width_m) - std::max(lo, d.offset_m));
      }
      solid_m_[offset_[w] / 2 + static_cast<std::size_t>(b)] = std::max(0.0, solid);
    }
  }
}

void WallVisibility::Record(const Hit& hit, const Eigen::Vector3d& point) {
  if (hit.wall < 0 || hit.face == 0 || static_cast<std::size_t>(hit.wall) >= bins_.size()) return;
  const auto w = static_cast<std::size_t>(hit.wall);
  if (bins_[w] == 0) return;
  const Wall& wall = world_->walls[w];
  const double along = (point.head<2>() - wall.start).dot(wall.direction());
  // The face runs half a thickness past each end (corners close): those hits go to the end bins.
  const int bin = std::clamp(static_cast<int>(std::floor(along / kBinM)), 0, bins_[w] - 1);
  ++counts_[offset_[w] + static_cast<std::size_t>((hit.face > 0 ? 0 : bins_[w]) + bin)];
}

void WallVisibility::Merge(const WallVisibility& other) {
  for (std::size_t i = 0; i < counts_.size() && i < other.counts_.size(); ++i)
    counts_[i] += other.counts_[i];
}

void WallVisibility::Clear() { std::fill(counts_.begin(), counts_.end(), 0u); }

}  // namespace msgraphs::sim
