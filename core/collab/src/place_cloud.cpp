// SPDX-License-Identifier: MIT
#include "msgraphs/core/collab/place_cloud.hpp"

#include <algorithm>

namespace msgraphs::core {

Status PlaceCloudConfig::Validate() const {
  if (!(voxel_m > 0) || !(keyframe_reach_m >= 0) || max_raw_points < 100 || max_points < 10)
    return Error{Errc::kInvalidConfig, "place cloud: voxel, reach and capacities must be positive"};
  return Ok();
}

Status PlaceCloudBuilder::Init(const PlaceCloudConfig& config) {
  if (auto s = config.Validate(); !s) return s;
  config_ = config;
  raw_.Init(config.max_raw_points);
  thinned_.Init(config.max_raw_points);
  voxel_.Init(config.max_raw_points);
  return Ok();
}

Status PlaceCloudBuilder::Build(const LocalMapper& mapper, const Eigen::Vector2d& centre_map, float radius_m,
                                BoundedVector<Eigen::Vector3f>& cloud) {
  cloud.clear();
  const SGraph& graph = mapper.graph();
  const float floor_z = -static_cast<float>(mapper.config().base_height_m);  // map frame: first base pose
  const float low = mapper.config().grid.obstacle_min_height_m, high = mapper.config().grid.obstacle_max_height_m;
  const Eigen::Vector3f origin(static_cast<float>(centre_map.x()), static_cast<float>(centre_map.y()), floor_z);
  const float r2 = radius_m * radius_m;
  const double reach_m = static_cast<double>(radius_m + config_.keyframe_reach_m);
  float leaf = config_.voxel_m;
  raw_.clear();
  // Full: keep the voxel centroids and go on; if that frees too little, coarser voxels.
  auto thin = [&]() {
    for (int attempt = 0; attempt < 8; ++attempt) {
      static_cast<void>(voxel_.Downsample(raw_.span(), leaf, thinned_));
      if (2 * thinned_.size() <= raw_.capacity()) break;
      leaf *= 1.5f;
    }
    raw_.clear();
    for (const Eigen::Vector3f& p : thinned_) raw_.push_back(p);
  };
  std::size_t keyframes = 0;
  for (std::uint32_t k = 0; k < graph.keyframe_slots(); ++k) {
    if (!graph.keyframe_active(k)) continue;
    const Eigen::Isometry3d T_map_kf = graph.keyframe_pose(k);
    if ((T_map_kf.translation().head<2>() - centre_map).norm() > reach_m) continue;
    const auto points = mapper.keyframe_cloud(k);
    if (points.empty()) continue;
    ++keyframes;
    const Eigen::Affine3f T = T_map_kf.cast<float>();
    for (const Eigen::Vector3f& q : points) {
      const Eigen::Vector3f r = T * q - origin;
      if (r.head<2>().squaredNorm() > r2 || r.z() < low || r.z() > high) continue;
      if (raw_.full()) thin();
      static_cast<void>(raw_.try_push_back(r));
    }
  }
  if (keyframes == 0 || raw_.empty()) return Error{Errc::kDegenerate, "place cloud: no keyframe cloud reaches the place"};
  const std::size_t cap = std::min(cloud.capacity(), config_.max_points);
  for (int attempt = 0;; ++attempt) {
    static_cast<void>(voxel_.Downsample(raw_.span(), leaf, cloud));
    if ((cloud.size() <= cap && voxel_.stats().overflowed == 0) || attempt == 12) break;
    leaf *= 1.5f;
  }
  if (cloud.size() > cap) cloud.resize_down(cap);
  last_voxel_m_ = leaf;
  return Ok();
}

}  // namespace msgraphs::core
