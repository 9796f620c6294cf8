// SPDX-License-Identifier: MIT
// The collaborative S-Graph's solve (paper section VII): every other robot's origin as a free
// node in this robot's map frame, tied by room-to-room and wall-to-wall factors from accepted
// room matches. Robots walk level floors in gravity-aligned odometry frames, so an origin is
// planar: x, y and yaw (z, roll and pitch are zero by construction of the frames).
// Ceres is private; factors carry Huber kernels.
#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <memory>

#include "msgraphs/base/expected.hpp"
#include "msgraphs/core/graph/distilled_graph.hpp"

namespace msgraphs::core {

struct CollaborativeGraphConfig {
  std::size_t max_robots = 16;
  std::size_t max_factors = 4096;
  double room_sigma_m = 0.10;        ///< room centres of the same room seen by two robots
  double room_yaw_sigma_rad = 0.05;  ///< room orientation (modulo quarter turns)
  double wall_sigma_floor_m = 0.02;  ///< added to the walls' own offset uncertainty
  double wall_sigma_floor_rad = 0.01;
  double huber = 2.0;
  int max_iterations = 50;
  Status Validate() const;
};

class CollaborativeGraph {
 public:
  CollaborativeGraph();
  ~CollaborativeGraph();
  CollaborativeGraph(const CollaborativeGraph&) = delete;
  CollaborativeGraph& operator=(const CollaborativeGraph&) = delete;

  Status Init(const CollaborativeGraphConfig& config);
  /// Drops every factor and origin (the accepted matches changed: rebuilt from them).
  void Clear();

  /// Starts (or restarts) robot `robot`'s origin at T_self_robot (projected to x, y, yaw).
  Status SetInitial(std::uint16_t robot, const Eigen::Isometry3d& T_self_robot);
  /// The same room: its centre and yaw in this robot's map (a) and in robot b's map.
  Status AddRoomRoom(std::uint16_t robot_b,
                     const Eigen::Vector2d& centre_a,
                     double yaw_a,
                     const Eigen::Vector2d& centre_b,
                     double yaw_b);
  /// The same wall, in each robot's map, with each side's covariance.
  Status AddWallWall(std::uint16_t robot_b,
                     const DistilledWall& wall_a,
                     const DistilledWall& wall_b);

  /// A direct measurement of robot b's origin (a fine alignment of one room's clouds).
  Status AddOriginMeasurement(std::uint16_t robot_b,
                              const Eigen::Isometry3d& T_self_robot,
                              double sigma_m,
                              double sigma_rad);

  /// Solves; returns the final cost. Robots without factors keep their initial values.
  Expected<double> Solve();

  bool has_robot(std::uint16_t robot) const;
  Eigen::Isometry3d T_self_robot(std::uint16_t robot) const;
  std::size_t factors(std::uint16_t robot) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace msgraphs::core
