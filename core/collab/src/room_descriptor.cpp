// SPDX-License-Identifier: MIT
#include "msgraphs/core/collab/room_descriptor.hpp"

#include <algorithm>
#include <array>
#include <cmath>

#include "msgraphs/core/geometry/se3.hpp"

namespace msgraphs::core {
namespace {
constexpr float kLayerM = 0.1f;  // height histogram for the ceiling
}  // namespace

Status RoomDescriptorConfig::Validate() const {
  if (!(voxel_m > 0) || !(margin_m >= 0) || !(max_height_m > min_height_m) || !(corridor_half_length_m > 0) ||
      max_points < 100 || max_cloud_points < 100 || !(ceiling_margin_m >= 0) || !(min_ceiling_m > min_height_m) ||
      !(ceiling_layer_share > 0 && ceiling_layer_share < 1) || max_height_m > 20.0f) {
    return Error{Errc::kInvalidConfig,
                 "room descriptor: voxel, heights (up to 20 m) and capacities must be positive"};
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
  raw_.Init(config.max_points);
  thinned_.Init(config.max_points);
  voxel_.Init(config.max_points);
  layers_.assign(static_cast<std::size_t>(std::ceil(config.max_height_m / kLayerM)) + 2, 0);
  return Ok();
}

float RoomDescriptorBuilder::CropHeight(std::span<const Eigen::Vector3f> points) {
  std::fill(layers_.begin(), layers_.end(), 0u);
  for (const Eigen::Vector3f& p : points) {
    const auto k = static_cast<std::size_t>(std::max(0.0f, p.z()) / kLayerM);
    if (k < layers_.size()) ++layers_[k];
  }
  // Windows of two layers (a plane's points straddle a boundary) from min_ceiling_m up; the
  // ceiling is the lowest that stands out of the walls' even share of every height.
  const auto first = static_cast<std::size_t>(config_.min_ceiling_m / kLayerM);
  std::uint64_t above = 0;
  std::size_t windows = 0;
  std::array<std::uint32_t, 256> counts{};
  for (std::size_t k = first; k + 1 < layers_.size() && windows < counts.size(); ++k, ++windows) {
    counts[windows] = layers_[k] + layers_[k + 1];
    above += layers_[k];
  }
  last_ceiling_ = false;
  if (windows == 0 || above == 0) return config_.max_height_m;
  std::array<std::uint32_t, 256> sorted = counts;
  std::nth_element(sorted.begin(), sorted.begin() + static_cast<std::ptrdiff_t>(windows / 2),
                   sorted.begin() + static_cast<std::ptrdiff_t>(windows));
  const std::uint32_t median = sorted[windows / 2];
  for (std::size_t w = 0; w < windows; ++w) {
    if (counts[w] >= 4 * std::max<std::uint32_t>(median, 1) &&
        static_cast<double>(counts[w]) >= static_cast<double>(config_.ceiling_layer_share) * static_cast<double>(above)) {
      last_ceiling_ = true;
      return static_cast<float>(first + w) * kLayerM - config_.ceiling_margin_m;
    }
  }
  return config_.max_height_m;
}

Status RoomDescriptorBuilder::Build(const LocalMapper& mapper,
                                    const DistilledRoom& room,
                                    BoundedVector<Eigen::Vector3f>& cloud,
                                    ScanContext& descriptor) {
  const SGraph& graph = mapper.graph();
  const double floor_z = -mapper.config().base_height_m;  // the map frame is the first base pose
  const Eigen::Isometry3d T_room_map = RoomFrame(room, floor_z).inverse();
  const double half_x = 0.5 * room.size_x_m;
  const double half_y = room.shape == RoomShape::kFourWall ? 0.5 * room.size_y_m
                                                           : static_cast<double>(config_.corridor_half_length_m);
  const auto crop_x = static_cast<float>(half_x) + config_.margin_m,
             crop_y = static_cast<float>(half_y) + config_.margin_m;
  raw_.clear();
  last_thinnings_ = 0;
  float leaf = config_.voxel_m;
  // Full: keep the voxel centroids and go on; if that frees too little, coarser voxels.
  auto thin = [&]() {
    for (int attempt = 0; attempt < 8; ++attempt) {
      static_cast<void>(voxel_.Downsample(raw_.span(), leaf, thinned_));
      ++last_thinnings_;
      if (2 * thinned_.size() <= raw_.capacity()) break;
      leaf *= 1.5f;
    }
    raw_.clear();
    for (const Eigen::Vector3f& p : thinned_) raw_.push_back(p);
  };
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
      if (raw_.full()) thin();
      static_cast<void>(raw_.try_push_back(r));
    }
  }
  if (keyframes == 0 || raw_.empty())
    return Error{Errc::kDegenerate, "room descriptor: no keyframe cloud inside the room"};
  last_crop_m_ = CropHeight(raw_.span());
  std::size_t kept = 0;
  for (const Eigen::Vector3f& p : raw_) {
    if (p.z() <= last_crop_m_) raw_[kept++] = p;
  }
  raw_.resize_down(kept);
  if (raw_.empty()) return Error{Errc::kDegenerate, "room descriptor: nothing below the ceiling"};
  const std::size_t cap = std::min(cloud.capacity(), config_.max_cloud_points);
  for (int attempt = 0;; ++attempt) {
    static_cast<void>(voxel_.Downsample(raw_.span(), leaf, cloud));
    if ((cloud.size() <= cap && voxel_.stats().overflowed == 0) || attempt == 12) break;
    leaf *= 1.5f;
  }
  if (cloud.size() > cap) cloud.resize_down(cap);
  last_voxel_m_ = leaf;
  return descriptor.Build(cloud.span(), config_.scan_context);
}

}  // namespace msgraphs::core
