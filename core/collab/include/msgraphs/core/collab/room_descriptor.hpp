// SPDX-License-Identifier: MIT
// Room descriptors (paper section VI-A): the room-centred cloud (the stored clouds of the
// keyframes taken inside the room, in the room frame, cropped to the room's bounds plus a
// margin, heights above the floor between the floor and the ceiling, voxel-downsampled) and its
// Scan Context. The room frame: origin at the room's centre on the floor, x along the normal of
// the room's first wall, z up. Sized at Init; Build allocates nothing.
#pragma once

#include <Eigen/Geometry>

#include "msgraphs/base/bounded_vector.hpp"
#include "msgraphs/base/expected.hpp"
#include "msgraphs/core/descriptors/scan_context.hpp"
#include "msgraphs/core/graph/distilled_graph.hpp"
#include "msgraphs/core/perception/voxel_grid.hpp"
#include "msgraphs/core/slam/local_mapper.hpp"

namespace msgraphs::core {

struct RoomDescriptorConfig {
  float voxel_m =
      0.2f;  ///< what fine alignment needs (0.5 m VGICP voxels); 4x fewer points than 0.1 m
  float margin_m = 0.3f;                ///< beyond the walls (they are in the cloud)
  float min_height_m = 0.05f;           ///< above the floor: leaves the floor out
  float max_height_m = 2.4f;            ///< and the ceiling
  float corridor_half_length_m = 6.0f;  ///< a corridor has no length: crop along it here
  ScanContextConfig scan_context{20, 60, 12.0f, 0.0f};
  std::size_t max_points = 60000;
  Status Validate() const;
};

/// T_map_room of a distilled room, given where the floor is in the map frame.
Eigen::Isometry3d RoomFrame(const DistilledRoom& room, double floor_z_map);

class RoomDescriptorBuilder {
 public:
  Status Init(const RoomDescriptorConfig& config);

  /// Builds the room cloud (into `cloud`, room frame) and its Scan Context. kDegenerate when no
  /// keyframe inside the room has a stored cloud any more.
  Status Build(const LocalMapper& mapper,
               const DistilledRoom& room,
               BoundedVector<Eigen::Vector3f>& cloud,
               ScanContext& descriptor);

  const RoomDescriptorConfig& config() const { return config_; }

 private:
  RoomDescriptorConfig config_;
  BoundedVector<Eigen::Vector3f> raw_;
  VoxelDownsampler voxel_;
};

}  // namespace msgraphs::core
