// SPDX-License-Identifier: MIT
// Voxel downsampling on a bounded hash grid: every occupied voxel becomes the centroid of its
// points. Capacity (points and voxels) is fixed at Init; a call never allocates. When a cloud
// occupies more voxels than the capacity, points falling in new voxels are dropped and counted
// (`overflowed`), and the call returns kCapacityExceeded after producing everything it could.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <span>
#include <vector>

#include "msgraphs/base/bounded_vector.hpp"
#include "msgraphs/base/expected.hpp"

namespace msgraphs::core {

/// Integer voxel coordinates packed into 63 bits (21 bits each, +-2^20 voxels per axis); false
/// when one is out of that range. The one packing every voxel table uses.
bool PackVoxelCoordinates(std::int64_t x, std::int64_t y, std::int64_t z, std::uint64_t& key);

/// Voxel key of a point: false when it is too far out (|coordinate| / leaf >= 2^20) or not finite.
bool VoxelKey(const Eigen::Vector3f& p, float inverse_leaf, std::uint64_t& key);

/// Slot hash for open-addressing tables keyed by voxel keys (MurmurHash3's 64-bit finaliser,
/// first half): packed keys differ in few high bits, so they are mixed before masking.
inline std::uint64_t VoxelHash(std::uint64_t key) {
  key ^= key >> 33;
  key *= 0xFF51AFD7ED558CCDull;
  key ^= key >> 33;
  return key;
}

struct VoxelGridStats {
  std::size_t input = 0;
  std::size_t output = 0;
  std::size_t rejected = 0;    ///< non-finite or out-of-range coordinates
  std::size_t overflowed = 0;  ///< points whose voxel did not fit
};

class VoxelDownsampler {
 public:
  void Init(std::size_t max_voxels);
  std::size_t capacity() const { return sum_.size(); }

  /// Appends the centroids to `out` (cleared first). kInvalidArgument for a leaf <= 0.
  Status Downsample(std::span<const Eigen::Vector3f> points,
                    float leaf_m,
                    BoundedVector<Eigen::Vector3f>& out);
  const VoxelGridStats& stats() const { return stats_; }
  std::size_t peak_voxels() const { return peak_; }

 private:
  // One slot's key, epoch and voxel index side by side: a probe into a table much larger than
  // the cache costs one miss, not three.
  struct Slot {
    std::uint64_t key = 0;
    std::uint32_t epoch = 0;  ///< the slot is in use in this call when equal to epoch_
    std::uint32_t value = 0;  ///< index into sum_ / count_
  };
  std::vector<Slot> slots_;
  std::vector<Eigen::Vector3d> sum_;
  std::vector<std::uint32_t> count_;
  std::uint32_t epoch_ = 0;
  std::size_t peak_ = 0;
  VoxelGridStats stats_;
};

/// Keeps finite points with min_range_m <= |p| <= max_range_m; returns how many were rejected
/// as non-finite (`rejected_non_finite`) and out of range.
struct RangeFilterStats {
  std::size_t kept = 0, out_of_range = 0, non_finite = 0, overflowed = 0;
};
RangeFilterStats RangeFilter(std::span<const Eigen::Vector3f> points,
                             float min_range_m,
                             float max_range_m,
                             BoundedVector<Eigen::Vector3f>& out);

}  // namespace msgraphs::core
