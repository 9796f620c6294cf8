// SPDX-License-Identifier: MIT
#include "msgraphs/core/registration/gaussian_voxel_map.hpp"

#include <algorithm>
#include <cmath>

#include "msgraphs/core/perception/voxel_grid.hpp"

namespace msgraphs::core {
namespace {

// The packed voxel key with bit 63 set, so that 0 marks an empty slot. Coordinates are computed
// in double (map-sized clouds at fine resolutions), range-checked before the conversion.
bool Key(const Eigen::Vector3d& p,
         double inverse_resolution,
         int dx,
         int dy,
         int dz,
         std::uint64_t& key) {
  const Eigen::Vector3d f = (p * inverse_resolution).array().floor();
  if (!(f.cwiseAbs().maxCoeff() < 1e9)) return false;  // NaN too
  if (!PackVoxelCoordinates(static_cast<std::int64_t>(f.x()) + dx,
                            static_cast<std::int64_t>(f.y()) + dy,
                            static_cast<std::int64_t>(f.z()) + dz, key)) {
    return false;
  }
  key |= 1ull << 63;
  return true;
}

}  // namespace

void GaussianVoxelMap::Init(std::size_t max_voxels) {
  std::size_t table = 16;
  while (table < 2 * max_voxels) table *= 2;
  keys_.assign(table, 0);
  slot_value_.assign(table, 0);
  voxels_.assign(max_voxels, GaussianVoxel{});
  used_ = 0;
}

std::size_t GaussianVoxelMap::Find(std::uint64_t key) const {
  const std::size_t mask = keys_.size() - 1;
  std::size_t slot = VoxelHash(key) & mask;
  while (keys_[slot] != 0 && keys_[slot] != key) slot = (slot + 1) & mask;
  return slot;
}

Status GaussianVoxelMap::Build(std::span<const Eigen::Vector3f> points,
                               std::span<const Eigen::Matrix3f> covariances,
                               double resolution_m) {
  std::fill(keys_.begin(), keys_.end(), 0);
  used_ = 0;
  if (voxels_.empty()) return Error{Errc::kInvalidArgument, "voxel map: Init was not called"};
  if (!(resolution_m > 0.0) || !std::isfinite(resolution_m))
    return Error{Errc::kInvalidArgument, "voxel map: resolution must be > 0"};
  if (points.size() != covariances.size())
    return Error{Errc::kInvalidArgument, "voxel map: one covariance per point"};
  resolution_ = resolution_m;
  const double inverse = 1.0 / resolution_m;
  bool overflow = false;
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Eigen::Vector3d p = points[i].cast<double>();
    std::uint64_t key = 0;
    if (!p.allFinite() || !covariances[i].allFinite() || !Key(p, inverse, 0, 0, 0, key)) continue;
    const std::size_t slot = Find(key);
    if (keys_[slot] == 0) {
      if (used_ == voxels_.size()) {
        overflow = true;
        continue;
      }
      keys_[slot] = key;
      slot_value_[slot] = static_cast<std::uint32_t>(used_);
      voxels_[used_] = GaussianVoxel{};
      ++used_;
    }
    GaussianVoxel& v = voxels_[slot_value_[slot]];
    v.mean += p;
    v.covariance += covariances[i].cast<double>();
    ++v.points;
  }
  for (std::size_t i = 0; i < used_; ++i) {
    voxels_[i].mean /= voxels_[i].points;
    voxels_[i].covariance /= voxels_[i].points;
  }
  if (overflow) return Error{Errc::kCapacityExceeded, "voxel map: more voxels than capacity"};
  return Ok();
}

const GaussianVoxel* GaussianVoxelMap::Lookup(const Eigen::Vector3d& p,
                                              int dx,
                                              int dy,
                                              int dz) const {
  std::uint64_t key = 0;
  if (used_ == 0 || !Key(p, 1.0 / resolution_, dx, dy, dz, key)) return nullptr;
  const std::size_t slot = Find(key);
  return keys_[slot] == 0 ? nullptr : &voxels_[slot_value_[slot]];
}

const GaussianVoxel* GaussianVoxelMap::Lookup(const Eigen::Vector3d& p) const {
  return Lookup(p, 0, 0, 0);
}

}  // namespace msgraphs::core
