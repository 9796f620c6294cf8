// SPDX-License-Identifier: MIT
// A place cloud: what this robot's map holds within a radius of one place, the merge decision's
// fallback evidence (place_evidence.hpp). Built from the stored keyframe clouds taken within
// `keyframe_reach_m` of the place, cropped to the disc and to the free-space grid's obstacle
// band (the heights the receiver's free space was built from: a point of this cloud and an
// occupied cell of the receiver's summary describe the same kind of thing), voxel-downsampled,
// relative to (centre, floor). A cloud beyond `max_points` gets coarser voxels until it fits.
//
// Sized at Init; Build allocates nothing.
#pragma once

#include <Eigen/Core>

#include "msgraphs/base/bounded_vector.hpp"
#include "msgraphs/base/expected.hpp"
#include "msgraphs/core/perception/voxel_grid.hpp"
#include "msgraphs/core/slam/local_mapper.hpp"

namespace msgraphs::core {

struct PlaceCloudConfig {
  /// The stored keyframe clouds' voxel (LocalMapperConfig::store_voxel_m): nothing finer exists.
  float voxel_m = 0.2f;
  /// Keyframes farther than this from the disc are left out: a VLP-16's rings are 2 degrees
  /// apart, 0.35 m at 10 m, coarser than the voxel beyond it.
  float keyframe_reach_m = 10.0f;
  std::size_t max_raw_points = 60000;  ///< held while building (thinned beyond)
  std::size_t max_points = 4000;       ///< the cloud (3 bytes a point on the wire: 12 kB)
  Status Validate() const;
};

class PlaceCloudBuilder {
 public:
  Status Init(const PlaceCloudConfig& config);

  /// Points of `mapper`'s map within `radius_m` of `centre_map` (horizontally), relative to
  /// (centre, floor), into `cloud` (capacity at least max_points). kDegenerate when no stored
  /// keyframe cloud reaches the disc.
  Status Build(const LocalMapper& mapper, const Eigen::Vector2d& centre_map, float radius_m,
               BoundedVector<Eigen::Vector3f>& cloud);

  const PlaceCloudConfig& config() const { return config_; }
  float last_voxel_m() const { return last_voxel_m_; }

 private:
  PlaceCloudConfig config_;
  BoundedVector<Eigen::Vector3f> raw_, thinned_;
  VoxelDownsampler voxel_;
  float last_voxel_m_ = 0;
};

}  // namespace msgraphs::core
