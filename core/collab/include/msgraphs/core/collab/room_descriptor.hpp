// SPDX-License-Identifier: MIT
// Room descriptors (paper section VI-A): the room-centred cloud (the stored clouds of the
// keyframes taken inside the room, in the room frame, cropped to the room's bounds plus a
// margin, heights above the floor between the floor and the ceiling, voxel-downsampled) and its
// Scan Context. The room frame: origin at the room's centre on the floor, x along the normal of
// the room's first wall, z up.
// - The ceiling is measured, not assumed: the lowest dense horizontal layer of the room's points
//   above `min_ceiling_m` (a ceiling is seen from everywhere in a room, so both robots find the
//   same one); the crop stops `ceiling_margin_m` below it. A room open to the sky (or above the
//   sensor's reach) keeps everything it saw up to `max_height_m`.
// - A room of any size gets a cloud: when the points exceed the store the raw cloud is thinned
//   on the way (voxelised and kept), and when the voxelised cloud exceeds `max_cloud_points` the
//   voxels grow (x1.5 at a time) until it fits; `last_voxel_m()` says which size was used.
// Sized at Init; Build allocates nothing.
#pragma once

#include <Eigen/Geometry>
#include <vector>

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
  float min_height_m = 0.05f;  ///< above the floor: leaves the floor out
  /// Crop below the measured ceiling (lamps, beams, ducts hang there) ...
  float ceiling_margin_m = 0.3f;
  /// ... looked for above this (desks and shelves make dense layers too) ...
  float min_ceiling_m = 1.9f;
  /// ... as a 0.1 m layer holding at least this share of the room's points above min_ceiling_m.
  float ceiling_layer_share = 0.25f;
  /// Without a ceiling, up to this (a VLP-16 sees 15 degrees up: 5 m at 18 m).
  float max_height_m = 8.0f;
  float corridor_half_length_m = 6.0f;  ///< a corridor has no length: crop along it here
  ScanContextConfig scan_context{20, 60, 12.0f, 0.0f};
  std::size_t max_points = 60000;         ///< raw points held while building (thinned beyond)
  std::size_t max_cloud_points = 12000;  ///< the room cloud (coarser voxels beyond)
  Status Validate() const;
};

/// T_map_room of a distilled room, given where the floor is in the map frame.
Eigen::Isometry3d RoomFrame(const DistilledRoom& room, double floor_z_map);

class RoomDescriptorBuilder {
 public:
  Status Init(const RoomDescriptorConfig& config);

  /// Builds the room cloud (into `cloud`, room frame; its capacity at least max_cloud_points)
  /// and its Scan Context. kDegenerate when no keyframe inside the room has a stored cloud any
  /// more.
  Status Build(const LocalMapper& mapper,
               const DistilledRoom& room,
               BoundedVector<Eigen::Vector3f>& cloud,
               ScanContext& descriptor);

  const RoomDescriptorConfig& config() const { return config_; }
  /// Of the last Build: the voxel size the cloud needed, the crop height, whether a ceiling was
  /// found, and how often the raw points were thinned.
  float last_voxel_m() const { return last_voxel_m_; }
  float last_crop_height_m() const { return last_crop_m_; }
  bool last_found_ceiling() const { return last_ceiling_; }
  std::size_t last_thinnings() const { return last_thinnings_; }

 private:
  /// The crop height from the points' heights (room frame, above the floor).
  float CropHeight(std::span<const Eigen::Vector3f> points);

  RoomDescriptorConfig config_;
  BoundedVector<Eigen::Vector3f> raw_, thinned_;
  VoxelDownsampler voxel_;
  std::vector<std::uint32_t> layers_;  // points per 0.1 m of height
  float last_voxel_m_ = 0, last_crop_m_ = 0;
  bool last_ceiling_ = false;
  std::size_t last_thinnings_ = 0;
};

}  // namespace msgraphs::core
