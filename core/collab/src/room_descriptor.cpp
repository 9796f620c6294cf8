// SPDX-License-Identifier: MIT
#include "msgraphs/core/collab/room_descriptor.hpp"

#include <cmath>

#include "msgraphs/core/geometry/se3.hpp"

namespace msgraphs::core {

Status RoomDescriptorConfig::Validate() const {
  if (!(voxel_m > 0) || !(margin_m >= 0) || !(max_height_m > min_height_m) ||
      !(corridor_half_length_m > 0) || max_points < 100) {
    return Error{Errc::kInvalidConfig,
                 "room descriptor: voxel, heights and capacity must be positive"};
  }
  return scan_context.Validate();
}

Eigen::Isometry3d RoomFrame(const DistilledRoom& room, double floor_z_map) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = RotZ(room.yaw_rad);
  T.translation() << room.centre.x(), room.centre.y(), floor_z_map;
  return T;
}

Status RoomDescriptorBuilder::Init(const RoomDescriptorConfig& config) {
  if (auto s = config.Validate(); !s) return s;
  config_ = config;
  raw_.Init(config.max_points * 8);
  voxel_.Init(config.max_points * 8);
  return Ok();
}

Status RoomDescriptorBuilder::Build(const LocalMapper& mapper,
                                    const DistilledRoom& room,
                                    BoundedVector<Eigen::Vector3f>& cloud,
                                    ScanContext& descriptor) {
  const SGraph& graph = mapper.graph();
  const double floor_z = -mapper.config().base_height_m;  // the map frame is the first base pose
  const Eigen::Isometry3d T_room_map = RoomFrame(room, floor_z).inverse();
  const double half_x = 0.5 * room.size_x_m;
  const double half_y = room.shape == RoomShape::kFourWall
                            ? 0.5 * room.size_y_m
                            : static_cast<double>(config_.corridor_half_length_m);
  const auto crop_x = static_cast<float>(half_x) + config_.margin_m,
             crop_y = static_cast<float>(half_y) + config_.margin_m;
  raw_.clear();
  std::size_t keyframes = 0;
  for (std::uint32_t k = 0; k < graph.keyframe_slots(); ++k) {
    if (!graph.keyframe_active(k)) continue;
    const Eigen::Isometry3d T_room_kf = T_room_map * graph.keyframe_pose(k);
    const Eigen::Vector3d p = T_room_kf.translation();
    if (std::fabs(p.x()) > half_x || std::fabs(p.y()) > half_y) continue;  // taken outside the room
    const auto points = mapper.keyframe_cloud(k);
    if (points.empty()) continue;
    ++keyframes;
    const Eigen::Affine3f T = T_room_kf.cast<float>();
    for (const Eigen::Vector3f& q : points) {
      const Eigen::Vector3f r = T * q;
      if (std::fabs(r.x()) > crop_x || std::fabs(r.y()) > crop_y) continue;
      if (r.z() < config_.min_height_m || r.z() > config_.max_height_m) continue;
      if (!raw_.try_push_back(r)) break;
    }
  }
  if (keyframes == 0 || raw_.empty())
    return Error{Errc::kDegenerate, "room descriptor: no keyframe cloud inside the room"};
  if (auto s = voxel_.Downsample(raw_.span(), config_.voxel_m, cloud); !s) return s;
  return descriptor.Build(cloud.span(), config_.scan_context);
}

}  // namespace msgraphs::core
