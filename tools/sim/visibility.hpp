// SPDX-License-Identifier: MIT
// Which wall faces a robot's lidar saw, and where: every return on a wall's long face is
// counted in 0.5 m bins along the face (from the wall's start point), per face (a: the side
// World::Wall::normal() points to, b: the other). Only walls: furniture, people, floor,
// ceiling, door reveals and wall ends are not counted. Ground truth for "which robots could
// share structure" (shared_truth.hpp).
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "scene.hpp"
#include "world.hpp"

namespace msgraphs::sim {

class WallVisibility {
 public:
  static constexpr double kBinM = 0.5;

  WallVisibility() = default;
  /// Bins for every wall of `level` of `world` (allocates; the world must outlive this).
  WallVisibility(const World& world, int level);

  /// Counts a return at `point` (world frame) if `hit` is on a wall face. No allocation.
  void Record(const Hit& hit, const Eigen::Vector3d& point);
  /// Adds another counter's hits (same world).
  void Merge(const WallVisibility& other);
  void Clear();

  std::size_t walls() const { return offset_.empty() ? 0 : offset_.size() - 1; }
  int bins(std::size_t wall) const { return bins_[wall]; }
  /// Hits of bin `bin` of face `face` (+1: a, -1: b) of wall `wall`.
  std::uint32_t hits(std::size_t wall, int face, int bin) const {
    return counts_[offset_[wall] + static_cast<std::size_t>((face > 0 ? 0 : bins_[wall]) + bin)];
  }
  /// Length of solid wall face in a bin (door openings excluded), metres.
  double solid_m(std::size_t wall, int bin) const {
    return solid_m_[offset_[wall] / 2 + static_cast<std::size_t>(bin)];
  }
  const World* world() const { return world_; }

 private:
  const World* world_ = nullptr;
  std::vector<int> bins_;            // per wall (0 for walls of other levels)
  std::vector<std::size_t> offset_;  // per wall: first count (face a bins, then face b)
  std::vector<std::uint32_t> counts_;
  std::vector<double> solid_m_;  // per wall and bin
};

}  // namespace msgraphs::sim
