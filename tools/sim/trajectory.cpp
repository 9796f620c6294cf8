// SPDX-License-Identifier: MIT
#include "trajectory.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace msgraphs::sim {

PlanarPose Trajectory::Planar(double t) const {
  if (samples_.empty()) return {};
  const double u = std::clamp(t / dt_, 0.0, static_cast<double>(samples_.size() - 1));
  const auto i = static_cast<std::size_t>(std::floor(u));
  if (i + 1 >= samples_.size()) return samples_.back();
  const double f = u - static_cast<double>(i);
  const PlanarPose& a = samples_[i];
  const PlanarPose& b = samples_[i + 1];
  const double dyaw = std::remainder(b.yaw - a.yaw, 2 * std::numbers::pi);
  return {a.x + f * (b.x - a.x), a.y + f * (b.y - a.y), a.yaw + f * dyaw};
}

Eigen::Isometry3d Trajectory::Pose(double t) const {
  const PlanarPose p = Planar(t);
  const GaitOffsets g = gait_.At(t / dt_);
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = (Eigen::AngleAxisd(p.yaw, Eigen::Vector3d::UnitZ()) *
                Eigen::AngleAxisd(g.pitch_rad, Eigen::Vector3d::UnitY()) *
                Eigen::AngleAxisd(g.roll_rad, Eigen::Vector3d::UnitX()))
                   .toRotationMatrix();
  T.translation() = Eigen::Vector3d(p.x, p.y, base_z_ + g.z_m);
  return T;
}

double Trajectory::PathLength(double t) const {
  double length = 0;
  const double end = std::min(t, duration_s());
  for (std::size_t i = 1; i < samples_.size() && dt_ * static_cast<double>(i) <= end; ++i) {
    length += std::hypot(samples_[i].x - samples_[i - 1].x, samples_[i].y - samples_[i - 1].y);
  }
  return length;
}

}  // namespace msgraphs::sim
