// SPDX-License-Identifier: MIT
// One map's walls as 2-D lines for the merge decision, indexed so that "which of my walls does
// this transformed wall lie on" costs a few comparisons instead of a scan: walls are binned by
// the direction of their normal (2 degree bins) and sorted by their line offset within a bin.
// A wall keeps its facing: the normal points to the side its robot saw it from, so the two faces
// of a partition are two walls and never coincide.
// Sized at Init (max_walls); Build and the queries allocate nothing.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <span>
#include <vector>

#include "msgraphs/base/expected.hpp"
#include "msgraphs/core/graph/distilled_graph.hpp"

namespace msgraphs::core {

struct AlignWall {
  std::uint32_t id = 0;              ///< DistilledWall id
  Eigen::Vector2d n = Eigen::Vector2d::UnitX();  ///< unit, horizontal
  double d = 0;                      ///< n.x + d = 0
  Eigen::Vector2d a = Eigen::Vector2d::Zero(), b = Eigen::Vector2d::Zero();  ///< extent
  double length_m = 0;
  double angle_rad = 0;  ///< of n, in [-pi, pi)
};

class WallIndex {
 public:
  static constexpr int kBins = 180;

  Status Init(std::size_t max_walls);
  /// Near-vertical walls (normal within 20 degrees of horizontal) at least `min_length_m` long
  /// with a finite extent. More than max_walls: the longest are kept (counted in `dropped()`).
  void Build(std::span<const DistilledWall> walls, double min_length_m);

  std::span<const AlignWall> walls() const { return {walls_.data(), size_}; }
  std::size_t dropped() const { return dropped_; }
  double total_length_m() const { return total_length_m_; }

  /// Calls visit(const AlignWall&) for every wall whose normal is within `angle_rad` of `n`
  /// and whose offset is within `offset_m` of `d`.
  template <typename Visit>
  void ForEachNear(const Eigen::Vector2d& n, double d, double angle_rad, double offset_m,
                   Visit&& visit) const {
    const double cos_tol = std::cos(angle_rad);
    const double angle = std::atan2(n.y(), n.x());
    const int span = static_cast<int>(std::ceil(angle_rad / kBinRad)) + 1;
    const int centre = Bin(angle);
    for (int k = -span; k <= span; ++k) {
      const int bin = ((centre + k) % kBins + kBins) % kBins;
      // Binary search for the first wall with offset >= d - offset_m.
      std::uint32_t lo = bin_start_[static_cast<std::size_t>(bin)];
      std::uint32_t hi = bin_start_[static_cast<std::size_t>(bin) + 1];
      while (lo < hi) {
        const std::uint32_t mid = (lo + hi) / 2;
        if (walls_[mid].d < d - offset_m) lo = mid + 1;
        else hi = mid;
      }
      for (std::uint32_t i = lo; i < bin_start_[static_cast<std::size_t>(bin) + 1]; ++i) {
        const AlignWall& w = walls_[i];
        if (w.d > d + offset_m) break;
        if (w.n.dot(n) >= cos_tol) visit(w);
      }
    }
  }

 private:
  static constexpr double kBinRad = 2.0 * std::numbers::pi / kBins;
  static int Bin(double angle_rad) {
    const int b = static_cast<int>(std::floor((angle_rad + std::numbers::pi) / kBinRad));
    return std::clamp(b, 0, kBins - 1);
  }

  std::vector<AlignWall> walls_;
  std::size_t size_ = 0, dropped_ = 0;
  double total_length_m_ = 0;
  std::array<std::uint32_t, kBins + 1> bin_start_{};
};

}  // namespace msgraphs::core
