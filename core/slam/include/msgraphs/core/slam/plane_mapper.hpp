// SPDX-License-Identifier: MIT
// Plane data association for the local S-Graph: each plane extracted from a keyframe goes to
// the mapped plane it matches, or becomes a new one.
//
// Unlike the original (reference/original-s-graphs-notes.md 1.7 and 1.17):
// - the gate is a true Mahalanobis distance in the measurement's minimal coordinates
//   (alpha, beta, delta_d) with the extractor's fitted covariance plus the keyframe's and the
//   landmark's uncertainty in radians and metres, against a chi-square threshold;
// - a wall must also overlap the mapped wall's extent along it (within a gap): two rooms'
//   collinear walls stay two walls; an interval test, not the O(N M) point check;
// - horizontal planes (floor and ceiling) are associated too, on the same rule;
// - a plane seen from its back (the other face of a wall) never associates.
// Wall extents (endpoints along the wall and heights) are kept here, in the map frame, for
// room detection. Sized at Init. Associate allocates: the observations and planes it adds to
// the S-Graph are Ceres residual blocks (a keyframe's cost, local_mapper.hpp); its own
// candidate lists are bounded vectors sized at Init.
#pragma once

#include <Eigen/Geometry>
#include <span>
#include <vector>

#include "msgraphs/base/bounded_vector.hpp"
#include "msgraphs/base/expected.hpp"
#include "msgraphs/core/graph/s_graph.hpp"
#include "msgraphs/core/perception/plane_extraction.hpp"
#include "msgraphs/core/perception/room_segmentation.hpp"

namespace msgraphs {
class SnapshotReader;
class SnapshotWriter;
}  // namespace msgraphs

namespace msgraphs::core {

struct PlaneAssociationConfig {
  double gate_chi2 = 16.27;            ///< 3 dof, 99.9 %
  double pose_sigma_rad = 0.035;       ///< keyframe-plus-landmark uncertainty: 2 degrees
  double pose_sigma_m = 0.02;          ///< (tighter merges parallel walls 10 cm apart)
  double max_normal_angle_deg = 25.0;  ///< coarse pre-gate before the Mahalanobis test
  double extent_gap_m = 1.0;           ///< a wall's new piece must be this close to its extent
  double min_wall_length_m = 0.5;      ///< shorter or lower vertical planes are furniture faces
  double min_wall_height_m = 0.8;
  /// A wall rises above the sensor: every upward beam of the VLP-16 (+1 to +15 degrees) hits a
  /// wall in range above the sensor's height, a desk, a sofa or a low cabinet only below it. A
  /// vertical plane whose highest return (along gravity, keyframe frame) is not this much above
  /// the sensor is a furniture face, whatever its size. The margin covers Spot's body bob (a
  /// few cm) and a degree of tilt error over a few metres. This is also what keeps the maps'
  /// walls consistent with their free space: a descending ray that passed over a 0.75 m desk
  /// marks its cells clear below the sensor (free_space_grid.hpp), so another robot's map
  /// must not hold that desk's face as a wall standing there (free_space_conflict.hpp).
  double min_rise_above_sensor_m = 0.1;
  /// The sensor's height in the keyframe frame: LocalMapper sets it from T_base_lidar.
  double sensor_height_m = 0.0;
  double covariance_floor_m = 0.01;  ///< per-axis floor on the measured covariance (sigma)
  Status Validate() const;
};

struct PlaneAssociationStats {
  std::uint64_t associated = 0, created = 0, furniture = 0, slanted = 0, rejected = 0;
};

/// A wall's extent in the map frame: its two ends (xy) and the heights seen.
struct WallExtent {
  Eigen::Vector2d a = Eigen::Vector2d::Zero(), b = Eigen::Vector2d::Zero();
  double z_min = 0, z_max = 0;
  bool valid = false;
};

/// The covariance a plane observation enters the graph with: the fit's, floored per axis at
/// `floor_m` (metres for the offset, radians for the two angles) where the plane was seen, its
/// centroid, not at the keyframe's origin where the measurement is expressed. A wall patch seen
/// metres along the wall fixes its offset well where it is and its angle less well, so the
/// offset at the origin inherits the angle's error times that lever (d at the origin = d at the
/// centroid - (alpha u + beta v).c). Flooring the origin's offset alone said it was precise:
/// with the VLP-16's 3 cm range noise along oblique rays, a patch's fitted normal leans towards
/// the line of sight by a few tenths of a degree (errors in variables), within the angle floor,
/// and carried 3 m to the origin that was a 1-2 cm bias (walls seen from afar came out closer).
/// With the encoders replaced by the truth, a robot's map shrank by 0.56 % and its ATE was
/// 5.1 cm; floored at the centroid, 0.18 % and 1.7 cm (docs/s-graph.md, "Plane covariance").
Eigen::Matrix3d PlaneObservationCovariance(const ExtractedPlane& p, double floor_m);

class PlaneMapper {
 public:
  /// Its state in a snapshot (LocalMapper::Save / Load): the reader fails on a store of another
  /// size or a value out of range.
  void Save(SnapshotWriter& w) const;
  void Load(SnapshotReader& r);
  Status Init(std::size_t max_planes, const PlaneAssociationConfig& config);

  /// Associates the keyframe's planes (keyframe frame) through the graph's current estimate of
  /// the keyframe and adds the observations (creating planes as needed).
  Status Associate(SGraph& graph, std::uint32_t keyframe, std::span<const ExtractedPlane> planes);

  /// Walls for room detection: every wall observed at least `min_observations` times, as 2-D
  /// lines from the graph's current estimate with the stored extent projected onto them.
  /// `ids[i]` is the graph plane of `walls[i]`.
  void MapWalls(const SGraph& graph,
                std::uint32_t min_observations,
                BoundedVector<MapWall>& walls,
                BoundedVector<std::uint32_t>& ids) const;

  const WallExtent& extent(std::uint32_t plane) const { return extents_[plane]; }
  const PlaneAssociationStats& stats() const { return stats_; }

 private:
  template <class Archive>
  void Io(Archive& ar);
  PlaneAssociationConfig config_;
  std::vector<WallExtent> extents_;
  PlaneAssociationStats stats_;
};

}  // namespace msgraphs::core
