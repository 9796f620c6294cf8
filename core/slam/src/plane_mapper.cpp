// SPDX-License-Identifier: MIT
#include "msgraphs/core/slam/plane_mapper.hpp"
#include "msgraphs/base/snapshot_archive.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace msgraphs::core {
namespace {

constexpr double kDegToRad = std::numbers::pi / 180.0;

PlaneClass ClassOf(const ExtractedPlane& p) {
  if (p.kind == PlaneKind::kVertical) return PlaneClass::kWall;
  // Horizontal: the normal points to the sensor, so up means the plane is below it (the floor).
  return p.normal.z() > 0 ? PlaneClass::kFloor : PlaneClass::kCeiling;
}

// The piece of wall a plane's points cover, in the map frame.
WallExtent ExtentOf(const ExtractedPlane& p, const Eigen::Isometry3d& T_map_kf) {
  WallExtent e;
  const double cu = p.basis_u.dot(p.centroid);
  const Eigen::Vector3d a = p.centroid + p.basis_u * (p.u_min - cu);
  const Eigen::Vector3d b = p.centroid + p.basis_u * (p.u_max - cu);
  e.a = (T_map_kf * a).head<2>();
  e.b = (T_map_kf * b).head<2>();
  const double z0 = T_map_kf.translation().z();
  e.z_min = z0 + p.z_min;
  e.z_max = z0 + p.z_max;
  e.valid = true;
  return e;
}

// Interval of an extent along direction `dir`.
void Along(const WallExtent& e, const Eigen::Vector2d& dir, double& lo, double& hi) {
  lo = dir.dot(e.a);
  hi = dir.dot(e.b);
  if (lo > hi) std::swap(lo, hi);
}

}  // namespace

Status PlaneAssociationConfig::Validate() const {
  if (!(gate_chi2 > 0) || !(pose_sigma_rad > 0) || !(pose_sigma_m > 0) || !(extent_gap_m >= 0) ||
      !(max_normal_angle_deg > 0 && max_normal_angle_deg < 90) || !(covariance_floor_m > 0) ||
      !std::isfinite(min_rise_above_sensor_m) || !std::isfinite(sensor_height_m)) {
    return Error{Errc::kInvalidConfig,
                 "plane association: gate, sigmas and angles must be positive"};
  }
  return Ok();
}

Status PlaneMapper::Init(std::size_t max_planes, const PlaneAssociationConfig& config) {
  if (auto s = config.Validate(); !s) return s;
  config_ = config;
  extents_.assign(max_planes, WallExtent{});
  stats_ = {};
  return Ok();
}

Eigen::Matrix3d PlaneObservationCovariance(const ExtractedPlane& p, double floor_m) {
  const double floor2 = floor_m * floor_m;
  // Centroid parameters from origin parameters: d_c = d + (alpha u + beta v).c.
  Eigen::Matrix3d K = Eigen::Matrix3d::Identity();
  K(2, 0) = p.basis_u.dot(p.centroid);
  K(2, 1) = p.basis_v.dot(p.centroid);
  Eigen::Matrix3d at_centroid = K * p.covariance * K.transpose();
  for (int i = 0; i < 3; ++i) at_centroid(i, i) = std::max(at_centroid(i, i), floor2);
  const Eigen::Matrix3d K_inv = K.inverse();
  const Eigen::Matrix3d at_origin = K_inv * at_centroid * K_inv.transpose();
  return 0.5 * (at_origin + at_origin.transpose());
}

Status PlaneMapper::Associate(SGraph& graph,
                              std::uint32_t keyframe,
                              std::span<const ExtractedPlane> planes) {
  const Eigen::Isometry3d T = graph.keyframe_pose(keyframe);
  const double cos_max = std::cos(config_.max_normal_angle_deg * kDegToRad);
  const Eigen::Matrix3d pose_covariance =
      Eigen::Vector3d(config_.pose_sigma_rad * config_.pose_sigma_rad,
                      config_.pose_sigma_rad * config_.pose_sigma_rad,
                      config_.pose_sigma_m * config_.pose_sigma_m)
          .asDiagonal();
  for (const ExtractedPlane& p : planes) {
    const PlaneClass cls = ClassOf(p);
    if (cls == PlaneClass::kWall && (p.u_max - p.u_min < config_.min_wall_length_m ||
                                     p.z_max - p.z_min < config_.min_wall_height_m ||
                                     p.z_max < config_.sensor_height_m + config_.min_rise_above_sensor_m)) {
      ++stats_.furniture;
      continue;
    }
    PlaneMeasurement z;
    z.normal = p.normal;
    z.d = p.d;
    z.basis_u = p.basis_u;
    z.basis_v = p.basis_v;
    z.covariance = PlaneObservationCovariance(p, config_.covariance_floor_m);
    const WallExtent extent = cls == PlaneClass::kWall ? ExtentOf(p, T) : WallExtent{};
    const Eigen::Vector3d n_map = T.linear() * p.normal;
    const Eigen::Matrix3d S_inv = (z.covariance + pose_covariance).inverse();

    std::int64_t best = -1;
    double best_m2 = config_.gate_chi2;
    for (std::uint32_t id = 0; id < graph.plane_slots(); ++id) {
      const MapPlane mp = graph.plane(id);
      if (!mp.active || mp.plane_class != cls || mp.normal.dot(n_map) < cos_max) continue;
      // Predicted in the keyframe frame, compared in the measurement's minimal coordinates.
      const Eigen::Vector3d n_k = T.linear().transpose() * mp.normal;
      const double d_k = mp.d + mp.normal.dot(T.translation());
      const Eigen::Vector3d e(p.basis_u.dot(n_k), p.basis_v.dot(n_k), d_k - p.d);
      const double m2 = e.dot(S_inv * e);
      if (!(m2 < best_m2)) continue;
      if (cls == PlaneClass::kWall && extents_[id].valid) {
        const Eigen::Vector2d dir = Eigen::Vector2d(-mp.normal.y(), mp.normal.x()).normalized();
        double lo_a, hi_a, lo_b, hi_b;
        Along(extents_[id], dir, lo_a, hi_a);
        Along(extent, dir, lo_b, hi_b);
        if (lo_b > hi_a + config_.extent_gap_m || lo_a > hi_b + config_.extent_gap_m) continue;
      }
      best = id;
      best_m2 = m2;
    }
    std::uint32_t id = 0;
    if (best >= 0) {
      id = static_cast<std::uint32_t>(best);
    } else {
      auto created = graph.AddPlane(n_map, p.d - n_map.dot(T.translation()), cls);
      if (!created) {
        ++stats_.rejected;
        continue;
      }
      id = *created;
    }
    if (!graph.AddPlaneObservation(keyframe, id, z)) {
      ++stats_.rejected;
      continue;
    }
    if (best >= 0)
      ++stats_.associated;
    else
      ++stats_.created;
    if (cls != PlaneClass::kWall || id >= extents_.size()) continue;
    WallExtent& stored = extents_[id];
    if (!stored.valid) {
      stored = extent;
      continue;
    }
    // Union along the wall (on the current line), heights widened.
    const MapPlane mp = graph.plane(id);
    const Eigen::Vector2d n2 = mp.normal.head<2>().normalized();
    const Eigen::Vector2d dir(-n2.y(), n2.x());
    double lo_a, hi_a, lo_b, hi_b;
    Along(stored, dir, lo_a, hi_a);
    Along(extent, dir, lo_b, hi_b);
    const Eigen::Vector2d foot = -mp.d * n2;
    stored.a = foot + dir * std::min(lo_a, lo_b);
    stored.b = foot + dir * std::max(hi_a, hi_b);
    stored.z_min = std::min(stored.z_min, extent.z_min);
    stored.z_max = std::max(stored.z_max, extent.z_max);
  }
  return Ok();
}

void PlaneMapper::MapWalls(const SGraph& graph,
                           std::uint32_t min_observations,
                           BoundedVector<MapWall>& walls,
                           BoundedVector<std::uint32_t>& ids) const {
  walls.clear();
  ids.clear();
  for (std::uint32_t id = 0; id < graph.plane_slots() && id < extents_.size(); ++id) {
    const MapPlane mp = graph.plane(id);
    if (!mp.active || mp.plane_class != PlaneClass::kWall || mp.observations < min_observations ||
        !extents_[id].valid) {
      continue;
    }
    const Eigen::Vector2d n2 = mp.normal.head<2>();
    if (n2.norm() < 0.9) continue;  // tilted too far to be a wall any more
    MapWall w;
    w.id = static_cast<std::uint32_t>(walls.size());
    w.normal = n2.normalized();
    w.d = mp.d / n2.norm();
    const Eigen::Vector2d dir(-w.normal.y(), w.normal.x());
    double lo, hi;
    Along(extents_[id], dir, lo, hi);
    const Eigen::Vector2d foot = -w.d * w.normal;
    w.a = foot + dir * lo;
    w.b = foot + dir * hi;
    // walls[i] is the graph's plane ids[i]: both have room, or neither takes it.
    if (walls.full() || ids.full()) break;
    walls.push_back(w);
    ids.push_back(id);
  }
}


template <class Archive>
void PlaneMapper::Io(Archive& ar) {
  IoSameSize(ar, extents_.size());
  if (ar.failed()) return;
  for (WallExtent& e : extents_) {
    ar(e.a.data(), 2);
    ar(e.b.data(), 2);
    ar(e.z_min);
    ar(e.z_max);
    IoBool(ar, e.valid);
    if constexpr (Archive::kLoading) {
      // Finite and ordered, as observations leave an extent (room segmentation bounds its
      // walk along a wall by the grid's size, whatever the length).
      if (e.valid && !(e.a.allFinite() && e.b.allFinite() && std::isfinite(e.z_min) &&
                       std::isfinite(e.z_max) && e.z_min <= e.z_max))
        ar.Fail();
    }
  }
  ar(stats_);
}

void PlaneMapper::Save(SnapshotWriter& w) const { const_cast<PlaneMapper*>(this)->Io(w); }
void PlaneMapper::Load(SnapshotReader& r) { Io(r); }

}  // namespace msgraphs::core
