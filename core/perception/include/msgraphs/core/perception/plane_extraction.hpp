// SPDX-License-Identifier: MIT
// Walls (vertical planes) and floors/ceilings (horizontal planes) from one keyframe cloud by
// sequential RANSAC, improved over the original S-Graphs+ extractor
// (reference/original-s-graphs-notes.md 1.4-1.7):
// - hypotheses from one point and its normal, scored on a fixed random subset, inliers by
//   distance (2 sigma of the lidar's range noise, not 1 cm) and by normal agreement, so that
//   surfaces meeting at a corner do not merge;
// - every plane refitted by PCA on its inliers, and a covariance from that fit (the
//   information of the fit's residuals over the supporting points' extent), not identity;
// - a plane's inliers split into separate wall segments where they leave a gap along the wall
//   (two rooms' collinear walls are different walls);
// - horizontal planes kept when large enough and reported like the others (the original never
//   associated them).
// Planes are in Hesse form n.p + d = 0 with n pointing to the sensor side (d > 0). Everything
// is sized at Init; Extract allocates nothing.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <span>
#include <vector>

#include "msgraphs/base/bounded_vector.hpp"
#include "msgraphs/base/expected.hpp"

namespace msgraphs::core {

enum class PlaneKind : std::uint8_t { kVertical, kHorizontal };

struct ExtractedPlane {
  PlaneKind kind = PlaneKind::kVertical;
  Eigen::Vector3d normal = Eigen::Vector3d::UnitX();  ///< unit, towards the sensor
  double d = 0.0;                                     ///< n.p + d = 0, d >= 0
  /// Covariance of the minimal perturbation (alpha, beta, delta_d): n' = normalise(n + alpha
  /// basis_u + beta basis_v), d' = d + delta_d. From the fit: sigma^2 (sum J^T J)^-1 with
  /// J_i = [basis_u.p_i, basis_v.p_i, 1], so many points spread over a large extent give a
  /// small covariance and a small patch far away a large one.
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Identity();
  Eigen::Vector3d basis_u = Eigen::Vector3d::UnitY();  ///< horizontal along a wall
  Eigen::Vector3d basis_v = Eigen::Vector3d::UnitZ();
  std::size_t inliers = 0;
  double rms_m = 0.0;
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  /// Extent of the supporting points along basis_u (walls: along the wall) and in height: along
  /// the `up` the extraction was given (gravity in the keyframe frame; the frame's z if none).
  double u_min = 0, u_max = 0, z_min = 0, z_max = 0;
};

struct PlaneExtractionConfig {
  float distance_threshold_m = 0.06f;  ///< inlier distance: 2 sigma of the VLP-16's 3 cm noise
  float normal_threshold_deg = 25.0f;  ///< inlier point normals must agree this well
  int ransac_iterations = 200;
  std::size_t score_subset = 1500;  ///< points a hypothesis is scored on
  std::size_t min_vertical_inliers = 100;
  std::size_t min_horizontal_inliers = 500;
  float max_tilt_deg = 15.0f;  ///< vertical: normal within this of horizontal; horizontal: of z
  float segment_gap_m = 1.0f;  ///< a wall's points split where they leave a larger gap
  std::size_t max_planes = 48;
  float min_sigma_m = 0.01f;  ///< floor on the residual sigma used for the covariance
  std::uint64_t seed = 1;

  Status Validate() const;
};

class PlaneExtractor {
 public:
  void Init(std::size_t max_points);

  /// Points in the sensor (keyframe) frame and their normals (zero normals are skipped).
  /// Appends to `planes` (cleared first); kCapacityExceeded when it fills up (the planes found
  /// so far are kept). `up` (unit, keyframe frame) is gravity's up as the pose estimate has it:
  /// heights are measured along it, so a walking robot's roll and pitch (a few degrees) do not
  /// stretch a 3 m desk face into a 0.9 m "wall".
  Status Extract(std::span<const Eigen::Vector3f> points,
                 std::span<const Eigen::Vector3f> normals,
                 const PlaneExtractionConfig& config,
                 BoundedVector<ExtractedPlane>& planes,
                 const Eigen::Vector3d& up = Eigen::Vector3d::UnitZ());

  /// The plane of points[members] (PCA), with its covariance, normal towards the frame origin.
  bool Fit(std::span<const Eigen::Vector3f> points,
           std::span<const std::uint32_t> members,
           const PlaneExtractionConfig& config,
           ExtractedPlane& plane,
           const Eigen::Vector3d& up = Eigen::Vector3d::UnitZ()) const {
    return FitAndDescribe(points, members, config, up, plane);
  }

 private:
  bool FitAndDescribe(std::span<const Eigen::Vector3f> points,
                      std::span<const std::uint32_t> members,
                      const PlaneExtractionConfig& config,
                      const Eigen::Vector3d& up,
                      ExtractedPlane& plane) const;

  std::vector<std::uint32_t> remaining_;
  std::vector<std::uint32_t> inliers_;
  std::vector<std::uint32_t> used_;  // == round_: consumed by the current plane
  std::uint32_t round_ = 0;
  std::vector<std::pair<float, std::uint32_t>> along_;
  std::vector<std::uint32_t> segment_;
  std::vector<std::uint32_t> subset_;
};

}  // namespace msgraphs::core
