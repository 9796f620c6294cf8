// SPDX-License-Identifier: MIT
// Distillation (paper section V): the local S-Graph reduced to what other robots need: the
// origin (this robot's map frame, implicit), walls with their covariances, rooms with their
// walls, and the floor. Keyframes stay home.
//
// Versioned and incremental: each wall and room carries the graph version in which it last
// changed by more than the resend thresholds, so the codec can send only what changed since
// what a peer acknowledged. An Update that finds the S-Graph at the revision of the last one
// (SGraphStats::revision) computes nothing. Its own stores are sized at
// Init. Update allocates: with
// `marginal_covariances` (the default) it asks the S-Graph for the walls' marginals, which
// ceres::Covariance computes with heap memory of its own (SGraph::PlaneMarginals); without
// them, Update allocates nothing.
#pragma once

#include <cstdint>
#include <vector>

#include "msgraphs/base/expected.hpp"
#include "msgraphs/core/graph/distilled_graph.hpp"
#include "msgraphs/core/graph/s_graph.hpp"
#include "msgraphs/core/slam/plane_mapper.hpp"

namespace msgraphs::core {

struct DistillerConfig {
  std::uint32_t min_wall_observations = 3;  ///< walls of a room are always included
  double resend_distance_m = 0.01;          ///< a wall's offset or a room's centre moved this much
  double resend_angle_rad = 0.0017;         ///< or a normal turned this much (0.1 degree)
  double resend_covariance_ratio = 0.5;     ///< or a wall's uncertainty changed by this factor
  /// The floor's height in the map frame: the map frame is the first base pose, so minus the
  /// base's height above the floor (LocalMapperConfig::base_height_m).
  double floor_z_m = 0;
  /// Wall covariances as marginals of the whole local optimisation (keyframe uncertainty
  /// included); otherwise, or when the problem is rank deficient, the plane's own information
  /// (conditional on the keyframes).
  bool marginal_covariances = true;
  std::size_t max_walls = 1024;
  std::size_t max_rooms = 256;
  Status Validate() const;
};

class Distiller {
 public:
  /// `graph` gives the capacities of the S-Graph it will distil (its plane and room ids).
  Status Init(std::uint16_t robot, const SGraphConfig& graph, const DistillerConfig& config);

  /// Refreshes the distilled graph from the local one; true when something changed (the graph's
  /// version then went up and the changed elements carry it).
  bool Update(const SGraph& graph, const PlaneMapper& planes);

  const DistilledGraph& graph() const { return out_; }
  struct Stats {
    std::uint64_t marginal_updates = 0, marginal_failures = 0;
    std::uint64_t unchanged = 0;  ///< Updates that found the S-Graph as it was (nothing computed)
  };
  const Stats& stats() const { return stats_; }

 private:
  DistillerConfig config_;
  DistilledGraph out_;
  std::vector<std::int32_t> wall_slot_;  // local plane id -> index in out_.walls, -1 if absent
  std::vector<std::int32_t> room_slot_;  // local room id -> index in out_.rooms, -1 if absent
  std::vector<std::uint8_t> needed_;     // per local plane: a room uses it
  BoundedVector<std::uint32_t> eligible_;
  std::vector<Eigen::Matrix3d> marginals_;
  Stats stats_;
  bool updated_once_ = false;
  std::uint64_t revision_ = 0;  // the S-Graph's at the last Update
};

}  // namespace msgraphs::core
