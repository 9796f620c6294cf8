// SPDX-License-Identifier: MIT
// Room matching between two robots (paper section VI-B) and the geometric consistency check
// the paper lacks.
//
// - A received room descriptor whose Scan Context distance to one of ours is below SC_th (0.35)
//   proposes a pair, with the yaw between the two room frames from the best column shift.
// - Fine alignment: VGICP of the other robot's room cloud onto ours, seeded with that yaw (and,
//   rooms being nearly symmetric, the three other quarter turns); accepted when the fitness
//   (mean squared nearest-neighbour distance, m^2) is below ICP_th (0.07). The match is the
//   transform between the two robots' map frames.
// - Consistency: every accepted match between the same two robots proposes the same map-to-map
//   transform if they are right. Pairs that agree (translation and yaw) form a graph; its
//   maximum cliques, taken one after the other from what is left, are the competing hypotheses
//   (MatchHypotheses). Identical rooms of a symmetric building each align perfectly but to
//   different transforms, so they gather in a rival hypothesis instead of joining the truth.
//   ConsistentMatches keeps the largest unless it is smaller than `min_consistent` (one match
//   alone cannot be checked) or a rival is as large; the collaborative session decides among
//   hypotheses by the rest of the two maps instead (hypothesis_check.hpp).
#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <span>
#include <vector>

#include "msgraphs/base/bounded_vector.hpp"
#include "msgraphs/base/expected.hpp"
#include "msgraphs/core/descriptors/scan_context.hpp"
#include "msgraphs/core/graph/distilled_graph.hpp"
#include "msgraphs/core/perception/covariances.hpp"
#include "msgraphs/core/perception/kdtree.hpp"
#include "msgraphs/core/registration/gaussian_voxel_map.hpp"
#include "msgraphs/core/registration/vgicp.hpp"

namespace msgraphs::core {

struct RoomMatchConfig {
  float sc_threshold = 0.35f;           ///< the paper's SC_th
  double icp_fitness_threshold = 0.07;  ///< the paper's ICP_th, m^2
  double vgicp_resolution_m = 0.5;
  double consistency_translation_m = 0.3;
  double consistency_yaw_rad = 0.05;
  std::size_t min_consistent = 2;
  std::size_t max_points = 60000;
  VgicpConfig vgicp;
  Status Validate() const;
};

/// One room of robot a matched with one room of robot b.
struct RoomMatch {
  std::uint16_t robot_a = 0, robot_b = 0;
  std::uint32_t room_a = 0, room_b = 0;
  float sc_distance = 1.0f;
  double fitness_m2 = 0;
  bool fine_aligned = false;
  Eigen::Isometry3d T_a_b = Eigen::Isometry3d::Identity();  ///< map b into map a
};

class RoomMatcher {
 public:
  Status Init(const RoomMatchConfig& config);

  /// Aligns room b's cloud (its room frame) onto room a's, starting from `yaw_rad`
  /// (p_a = Rz(yaw) p_b). Fills match.T_a_b from the room frames; kNotConverged / kDegenerate
  /// when no seed aligns within ICP_th.
  Status FineAlign(std::span<const Eigen::Vector3f> cloud_a,
                   const Eigen::Isometry3d& T_mapa_rooma,
                   std::span<const Eigen::Vector3f> cloud_b,
                   const Eigen::Isometry3d& T_mapb_roomb,
                   double yaw_rad,
                   RoomMatch& match);

  const RoomMatchConfig& config() const { return config_; }

 private:
  RoomMatchConfig config_;
  KdTree tree_a_, tree_b_;
  BoundedVector<Eigen::Vector3f> normals_;
  BoundedVector<Eigen::Matrix3f> covariances_a_, covariances_b_;
  GaussianVoxelMap map_a_;
  Vgicp vgicp_;
};

/// Without fine alignment: the transform from the room frames and the Scan Context yaw alone.
Eigen::Isometry3d MatchFromRoomFrames(const Eigen::Isometry3d& T_mapa_rooma,
                                      const Eigen::Isometry3d& T_mapb_roomb,
                                      double yaw_rad);

/// The competing hypotheses about the map-to-map transform: disjoint sets of mutually
/// consistent matches (all between the same two robots), as bit sets over `matches`, largest
/// first (the maximum clique, then the maximum clique of the rest, ...). Stops when `out` is full
/// or the next set is smaller than `min_matches` (at least 1). At most 64 matches are considered.
std::size_t MatchHypotheses(std::span<const RoomMatch> matches,
                            const RoomMatchConfig& config,
                            std::size_t min_matches,
                            std::span<std::uint64_t> out);

/// Indices of the largest set of mutually consistent matches; empty when it is smaller than
/// config.min_consistent or when a disjoint set is as large (two hypotheses, no answer yet).
std::size_t ConsistentMatches(std::span<const RoomMatch> matches,
                              const RoomMatchConfig& config,
                              std::span<std::uint32_t> out);

/// The indices a hypothesis bit set holds, ascending, into `out`; returns how many.
std::size_t HypothesisMembers(std::uint64_t hypothesis, std::span<std::uint32_t> out);

}  // namespace msgraphs::core
