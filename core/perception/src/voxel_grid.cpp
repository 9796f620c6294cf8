// SPDX-License-Identifier: MIT
#include "msgraphs/core/perception/voxel_grid.hpp"

#include <cmath>

namespace msgraphs::core {
namespace {
constexpr std::int64_t kHalfRange = 1 << 20;

}  // namespace

bool PackVoxelCoordinates(std::int64_t x, std::int64_t y, std::int64_t z, std::uint64_t& key) {
  key = 0;
  const std::int64_t c[3] = {x, y, z};
  for (int a = 0; a < 3; ++a) {
    if (c[a] <= -kHalfRange || c[a] >= kHalfRange - 1) return false;
    key |= static_cast<std::uint64_t>(c[a] + kHalfRange) << (21 * a);
  }
  return true;
}

bool VoxelKey(const Eigen::Vector3f& p, float inverse_leaf, std::uint64_t& key) {
  std::int64_t c[3];
  for (int a = 0; a < 3; ++a) {
    const float f = std::floor(p[a] * inverse_leaf);
    // Range-checked in float first: a NaN or huge value must not reach the integer conversion.
    if (!(f > -static_cast<float>(kHalfRange) && f < static_cast<float>(kHalfRange - 1)))
      return false;
    c[a] = static_cast<std::int64_t>(f);
  }
  return PackVoxelCoordinates(c[0], c[1], c[2], key);
}

void VoxelDownsampler::Init(std::size_t max_voxels) {
  std::size_t table = 16;
  while (table < 2 * max_voxels) table *= 2;
  slots_.assign(table, Slot{});
  sum_.assign(max_voxels, Eigen::Vector3d::Zero());
  count_.assign(max_voxels, 0);
  epoch_ = 0;
  peak_ = 0;
}

Status VoxelDownsampler::Downsample(std::span<const Eigen::Vector3f> points,
                                    float leaf_m,
                                    BoundedVector<Eigen::Vector3f>& out) {
  out.clear();
  stats_ = {};
  stats_.input = points.size();
  if (!(leaf_m > 0.0f) || !std::isfinite(leaf_m))
    return Error{Errc::kInvalidArgument, "voxel grid: leaf must be > 0"};
  if (sum_.empty()) return Error{Errc::kInvalidArgument, "voxel grid: Init was not called"};
  if (++epoch_ == 0) {  // wrapped: forget every slot explicitly
    for (Slot& s : slots_) s.epoch = 0;
    epoch_ = 1;
  }
  const float inverse_leaf = 1.0f / leaf_m;
  const std::size_t mask = slots_.size() - 1;
  std::uint32_t used = 0;
  for (const Eigen::Vector3f& p : points) {
    std::uint64_t key = 0;
    if (!p.allFinite() || !VoxelKey(p, inverse_leaf, key)) {
      ++stats_.rejected;
      continue;
    }
    std::size_t i = VoxelHash(key) & mask;
    while (slots_[i].epoch == epoch_ && slots_[i].key != key) i = (i + 1) & mask;
    Slot& slot = slots_[i];
    if (slot.epoch != epoch_) {
      if (used == sum_.size()) {
        ++stats_.overflowed;
        continue;
      }
      slot = {key, epoch_, used};
      sum_[used].setZero();
      count_[used] = 0;
      ++used;
    }
    const std::uint32_t v = slot.value;
    sum_[v] += p.cast<double>();
    ++count_[v];
  }
  if (used > peak_) peak_ = used;
  for (std::uint32_t v = 0; v < used; ++v) {
    if (!out.try_push_back((sum_[v] / count_[v]).cast<float>())) {
      stats_.overflowed += count_[v];
    }
  }
  stats_.output = out.size();
  if (stats_.overflowed > 0)
    return Error{Errc::kCapacityExceeded,
                 "voxel grid: more voxels than capacity; extra points dropped"};
  return Ok();
}

RangeFilterStats RangeFilter(std::span<const Eigen::Vector3f> points,
                             float min_range_m,
                             float max_range_m,
                             BoundedVector<Eigen::Vector3f>& out) {
  out.clear();
  RangeFilterStats s;
  const float min2 = min_range_m * min_range_m, max2 = max_range_m * max_range_m;
  for (const Eigen::Vector3f& p : points) {
    if (!p.allFinite()) {
      ++s.non_finite;
      continue;
    }
    const float r2 = p.squaredNorm();
    if (r2 < min2 || r2 > max2) {
      ++s.out_of_range;
      continue;
    }
    if (!out.try_push_back(p)) {
      ++s.overflowed;
      continue;
    }
    ++s.kept;
  }
  return s;
}

}  // namespace msgraphs::core
