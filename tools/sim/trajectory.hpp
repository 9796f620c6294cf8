// SPDX-License-Identifier: MIT
// A robot's true planar motion: (t, x, y, yaw) samples at a fixed rate, linearly interpolated.
// The base frame is level at a fixed height above the floor (Spot's body while walking).
#pragma once

#include <Eigen/Geometry>
#include <vector>

namespace msgraphs::sim {

struct PlanarPose {
  double x = 0, y = 0, yaw = 0;
};

class Trajectory {
 public:
  Trajectory() = default;
  Trajectory(double dt_s, double base_z_m) : dt_(dt_s), base_z_(base_z_m) {}

  void Append(const PlanarPose& p) { samples_.push_back(p); }
  double duration_s() const { return samples_.empty() ? 0.0 : dt_ * static_cast<double>(samples_.size() - 1); }
  double dt_s() const { return dt_; }
  double base_z_m() const { return base_z_; }
  const std::vector<PlanarPose>& samples() const { return samples_; }

  PlanarPose Planar(double t) const;
  /// T_world_base at time t (clamped to the trajectory's span).
  Eigen::Isometry3d Pose(double t) const;
  /// Distance travelled from 0 to t.
  double PathLength(double t) const;

 private:
  double dt_ = 0.01;
  double base_z_ = 0.5;
  std::vector<PlanarPose> samples_;
};

}  // namespace msgraphs::sim
