// SPDX-License-Identifier: MIT
// The collaborative S-Graph (paper section VII), held by one robot ("self"):
// - every robot's origin (its map frame in self's map frame) is a free SE(3) node; self's is
//   the gauge, fixed at identity;
// - walls and rooms of every robot are nodes in self's map frame, each tied to its robot's
//   origin by what that robot measured (the distilled estimate, with its covariance), and each
//   room to its walls (its centre midway between each facing pair, as in the local S-Graph);
// - room-to-room (same centre, orientation equal up to quarter turns) and wall-to-wall (same
//   plane) factors join the nodes of accepted matches; a corridor is tied across its axis and
//   in height only (its centre along it is wherever its robot's view of it was centred); a
//   fine alignment adds a direct measurement of an origin;
// - a weak gravity factor per origin: every robot's map frame is gravity-aligned (its IMU),
//   which fixes roll and pitch when the matched rooms alone would not.
// One global solve estimates every origin and refines every wall and room from all robots'
// measurements. Ceres is private; every factor has a Huber kernel.
//
// Persistent and updated incrementally: each update (BeginUpdate, then the Add calls, then
// Solve) declares the whole graph as it should now be. What was declared before keeps its node
// values (the solve starts where the last one ended) and its Ceres factor, with its
// measurement replaced in place; what is new is added; what the update left out is removed at
// Solve. A robot whose origin SetInitial moves has its nodes restarted from their
// measurements. Capacities are fixed at Init (an update declares at most max_walls walls,
// max_rooms rooms and max_factors factors; beyond, kCapacityExceeded). Not allocation-free:
// Ceres allocates for every factor added and for every solve (a solve runs on the
// collaborative thread only when a merge or a merged map changed).
#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <memory>

#include "msgraphs/base/expected.hpp"
#include "msgraphs/core/graph/distilled_graph.hpp"

namespace msgraphs::core {

struct CollaborativeGraphConfig {
  std::size_t max_robots = 16;   ///< robot ids 1 .. max_robots - 1
  std::size_t max_walls = 2048;  ///< nodes, all robots together
  std::size_t max_rooms = 512;
  std::size_t max_factors = 8192;
  double room_sigma_m = 0.07;         ///< a room centre as its robot measured it
  double room_same_sigma_m = 0.01;    ///< two nodes of the same room
  double room_yaw_sigma_rad = 0.05;   ///< room orientation (modulo quarter turns)
  double wall_sigma_floor_m = 0.014;  ///< added to the walls' own offset uncertainty
  double wall_sigma_floor_rad = 0.007;
  double wall_same_sigma_m = 0.005;  ///< two nodes of the same wall
  double wall_same_sigma_rad = 0.002;
  double gravity_sigma_rad = 0.02;  ///< how level each robot's map frame is
  /// A room's centre midway between two facing walls: the local S-Graph's room factor
  /// (SGraphConfig::room_sigma_m), so that a room holds its walls here as it does there.
  double room_wall_sigma_m = 0.05;
  double huber = 2.0;
  int max_iterations = 50;
  Status Validate() const;
};

struct CollaborativeGraphUpdate {
  std::size_t added = 0;
  std::size_t kept = 0;
  std::size_t removed = 0;  ///< at Solve
};

class CollaborativeGraph {
 public:
  CollaborativeGraph();
  ~CollaborativeGraph();
  CollaborativeGraph(const CollaborativeGraph&) = delete;
  CollaborativeGraph& operator=(const CollaborativeGraph&) = delete;

  Status Init(const CollaborativeGraphConfig& config, std::uint16_t self_robot);
  /// Starts an update: until Solve, the Add and SetInitial calls declare the graph anew; Solve
  /// first removes every origin, node and factor the update did not declare.
  void BeginUpdate();

  /// Starts (or restarts) robot `robot`'s origin at T_self_robot.
  Status SetInitial(std::uint16_t robot, const Eigen::Isometry3d& T_self_robot);

  /// Robot `robot`'s wall as it measured it (its map frame, its covariance); returns the node's
  /// handle (the same handle when that wall is already a node). The robot needs an origin.
  Expected<std::uint32_t> AddWall(std::uint16_t robot, const DistilledWall& wall);
  /// Robot `robot`'s room (centre and yaw in its map frame, on its floor at floor_z_m).
  Expected<std::uint32_t> AddRoom(std::uint16_t robot, const DistilledRoom& room, double floor_z_m);

  /// A room node's centre lies midway between two facing walls of its own robot (its
  /// room-to-wall edge, one per pair: a four-wall room has two, a corridor one). Refused when
  /// the walls do not face each other across the room's measured centre.
  Status AddRoomWalls(std::uint32_t room, std::uint32_t wall_a, std::uint32_t wall_b);
  /// Two wall nodes are the same plane.
  Status AddWallWall(std::uint32_t wall_a, std::uint32_t wall_b);
  /// Two room nodes are the same room: same centre, frames equal up to quarter turns. When
  /// either is a corridor, the same line across it (and the same height), nothing along it.
  Status AddRoomRoom(std::uint32_t room_a, std::uint32_t room_b);
  /// A direct measurement of robot b's origin (a fine alignment of one room's clouds).
  Status AddOriginMeasurement(std::uint16_t robot_b,
                              const Eigen::Isometry3d& T_self_robot,
                              double sigma_m,
                              double sigma_rad);

  /// Robot b walks self's floor: `floor_point_b` (on b's floor, b's map frame) lies at height
  /// `floor_z_self` in self's frame.
  Status AddSameFloor(std::uint16_t robot_b, const Eigen::Vector3d& floor_point_b, double floor_z_self,
                      double sigma_m);

  /// Removes what the update left out, then solves; returns the final cost. A failed or non-finite solve restores the previous values.
  Expected<double> Solve();

  std::uint16_t self() const;
  bool has_robot(std::uint16_t robot) const;
  Eigen::Isometry3d T_self_robot(std::uint16_t robot) const;
  /// Factors that touch robot `robot`'s origin or its nodes.
  std::size_t factors(std::uint16_t robot) const;
  /// Nodes declared in this update (after Solve: in the graph).
  std::size_t walls() const;
  std::size_t rooms() const;
  /// Factors added, kept (their measurements updated in place) and removed by the last update.
  const CollaborativeGraphUpdate& last_update() const;
  /// A wall node's estimate in self's map frame (id and extent as its robot sent them; extent
  /// mapped through the origin).
  DistilledWall wall(std::uint32_t handle) const;
  std::uint16_t wall_robot(std::uint32_t handle) const;
  /// A room node's centre in self's map frame.
  Eigen::Vector3d room_centre(std::uint32_t handle) const;
  std::uint16_t room_robot(std::uint32_t handle) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace msgraphs::core
