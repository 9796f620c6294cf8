// SPDX-License-Identifier: MIT
// Spot's walking controller in the simulator: follows a polyline like Spot (turn in place when
// far off heading, otherwise walk and steer), turns in place to a heading and stands, with
// speed, turn-rate and acceleration limits. Appends the planar samples to a trajectory and
// stops at the mission's end.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "trajectory.hpp"

namespace msgraphs::sim {

struct WalkerLimits {
  double max_speed_mps = 1.0;
  double max_turn_rate_rps = 0.8;
  double max_accel_mps2 = 0.5;
};

class Walker {
 public:
  /// Walks `trajectory` (which must hold the start pose) until its duration reaches end_s.
  Walker(Trajectory& trajectory, const WalkerLimits& limits, double end_s);

  /// Walks the polyline from its second point on (the first is where the robot stands) and
  /// stops at its end. False if the mission ended first.
  bool Follow(const std::vector<Eigen::Vector2d>& path);
  /// Turns in place to `yaw_rad` (at most the turn rate). False if the mission ended first.
  bool TurnTo(double yaw_rad);
  /// Stands still for `seconds`.
  bool Hold(double seconds);

  bool done() const { return trajectory_.duration_s() >= end_s_; }
  double now_s() const { return trajectory_.duration_s(); }
  const PlanarPose& pose() const { return pose_; }
  Eigen::Vector2d position() const { return {pose_.x, pose_.y}; }

 private:
  void Step(double turn_rps);

  Trajectory& trajectory_;
  WalkerLimits limits_;
  double end_s_;
  PlanarPose pose_;
  double speed_mps_ = 0.0;
};

}  // namespace msgraphs::sim
