// SPDX-License-Identifier: MIT
// A robot's true motion: planar (t, x, y, yaw) samples at a fixed rate, linearly interpolated,
// plus Spot's gait (gait.hpp): the body's height bob and its roll and pitch rocking, so the
// base frame's pose is full 6-DOF. Time t runs from the robot's own start; start_s() is the
// mission time of t = 0 (robots can start at different times).
#pragma once

#include <Eigen/Geometry>
#include <vector>

#include "gait.hpp"

namespace msgraphs::sim {

struct PlanarPose {
  double x = 0, y = 0, yaw = 0;
};

class Trajectory {
 public:
  Trajectory() = default;
  Trajectory(double dt_s, double base_z_m) : dt_(dt_s), base_z_(base_z_m) {}

  void Append(const PlanarPose& p) { samples_.push_back(p); }
  double duration_s() const {
    return samples_.empty() ? 0.0 : dt_ * static_cast<double>(samples_.size() - 1);
  }
  double dt_s() const { return dt_; }
  double base_z_m() const { return base_z_; }
  const std::vector<PlanarPose>& samples() const { return samples_; }
  double start_s() const { return start_s_; }
  void set_start_s(double mission_time_s) { start_s_ = mission_time_s; }

  /// Computes the gait along the samples appended so far (call once the path is complete; until
  /// then, and without it, the base frame is level at base_z_m).
  void SetGait(const GaitParams& gait) { gait_.Build(samples_, dt_, gait); }
  const GaitTrack& gait() const { return gait_; }

  PlanarPose Planar(double t) const;
  /// T_world_base at time t (clamped to the trajectory's span): position, yaw and the gait's
  /// height, roll and pitch (rotation Rz(yaw) Ry(pitch) Rx(roll)).
  Eigen::Isometry3d Pose(double t) const;
  /// Distance travelled from 0 to t (planar).
  double PathLength(double t) const;

 private:
  double dt_ = 0.01;
  double base_z_ = 0.5;
  double start_s_ = 0.0;
  std::vector<PlanarPose> samples_;
  GaitTrack gait_;
};

}  // namespace msgraphs::sim
