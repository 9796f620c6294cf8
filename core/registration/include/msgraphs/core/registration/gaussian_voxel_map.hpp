// SPDX-License-Identifier: MIT
// The target side of VGICP: points and their covariances aggregated per voxel into a mean and
// the average covariance (Koide et al., ICRA 2021; small_gicp's additive voxels). Bounded hash
// map sized at Init; Build allocates nothing.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <span>
#include <vector>

#include "msgraphs/base/expected.hpp"

namespace msgraphs::core {

struct GaussianVoxel {
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  std::uint32_t points = 0;
};

class GaussianVoxelMap {
 public:
  void Init(std::size_t max_voxels);

  /// kCapacityExceeded (after filling what fits) when the cloud needs more voxels.
  Status Build(std::span<const Eigen::Vector3f> points, std::span<const Eigen::Matrix3f> covariances,
               double resolution_m);

  /// The voxel containing p, or nullptr.
  const GaussianVoxel* Lookup(const Eigen::Vector3d& p) const;
  /// The voxel at integer offset (dx, dy, dz) from the one containing p, or nullptr.
  const GaussianVoxel* Lookup(const Eigen::Vector3d& p, int dx, int dy, int dz) const;

  double resolution() const { return resolution_; }
  std::size_t voxels() const { return used_; }
  std::size_t capacity() const { return voxels_.size(); }

 private:
  std::size_t Find(std::uint64_t key) const;

  double resolution_ = 1.0;
  std::vector<std::uint64_t> keys_;  // 0 = empty slot (keys are offset so never 0)
  std::vector<std::uint32_t> slot_value_;
  std::vector<GaussianVoxel> voxels_;
  std::size_t used_ = 0;
};

}  // namespace msgraphs::core
