// SPDX-License-Identifier: MIT
#include "msgraphs/core/collab/wall_index.hpp"

#include <algorithm>

namespace msgraphs::core {

Status WallIndex::Init(std::size_t max_walls) {
  if (max_walls < 1) return Error{Errc::kInvalidConfig, "wall index: max_walls must be positive"};
  walls_.assign(max_walls, AlignWall{});
  size_ = dropped_ = 0;
  bin_start_.fill(0);
  return Ok();
}

void WallIndex::Build(std::span<const DistilledWall> walls, double min_length_m) {
  size_ = dropped_ = 0;
  total_length_m_ = 0;
  for (const DistilledWall& w : walls) {
    const double horizontal = w.normal.head<2>().norm();
    if (!(horizontal > std::cos(20.0 * std::numbers::pi / 180.0)) || !w.a.allFinite() ||
        !w.b.allFinite() || !std::isfinite(w.d)) {
      continue;
    }
    const double length = (w.b - w.a).norm();
    if (!(length >= min_length_m)) continue;
    AlignWall a;
    a.id = w.id;
    a.n = w.normal.head<2>() / horizontal;
    a.d = w.d / horizontal;
    // The extent's ends projected on the line (the stored extent is the observed points').
    const Eigen::Vector2d foot = -a.d * a.n;
    const Eigen::Vector2d u(-a.n.y(), a.n.x());
    a.a = foot + u.dot(w.a - foot) * u;
    a.b = foot + u.dot(w.b - foot) * u;
    a.length_m = (a.b - a.a).norm();
    a.angle_rad = std::atan2(a.n.y(), a.n.x());
    if (size_ < walls_.size()) {
      walls_[size_++] = a;
      continue;
    }
    // Full: keep the longest (they carry the most evidence).
    ++dropped_;
    auto shortest = std::min_element(walls_.begin(), walls_.end(),
                                     [](const AlignWall& x, const AlignWall& y) { return x.length_m < y.length_m; });
    if (shortest->length_m < a.length_m) *shortest = a;
  }
  std::sort(walls_.begin(), walls_.begin() + static_cast<std::ptrdiff_t>(size_),
            [](const AlignWall& x, const AlignWall& y) {
              const int bx = Bin(x.angle_rad), by = Bin(y.angle_rad);
              return bx != by ? bx < by : x.d < y.d;
            });
  bin_start_.fill(0);
  for (std::size_t i = 0; i < size_; ++i) {
    total_length_m_ += walls_[i].length_m;
    ++bin_start_[static_cast<std::size_t>(Bin(walls_[i].angle_rad)) + 1];
  }
  for (int b = 0; b < kBins; ++b) bin_start_[static_cast<std::size_t>(b) + 1] += bin_start_[static_cast<std::size_t>(b)];
}

}  // namespace msgraphs::core
