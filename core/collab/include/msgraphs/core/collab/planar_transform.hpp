// SPDX-License-Identifier: MIT
// The transform between two robots' map frames as the merge decision searches it. Every map
// frame is gravity-aligned (each robot's frame is its first base pose, levelled by its floor),
// so the unknown is a yaw and a horizontal translation; the height offset follows from the two
// floors. p_a = R(yaw) p_b + t.
#pragma once

#include <Eigen/Geometry>
#include <cmath>
#include <numbers>

namespace msgraphs::core {

struct PlanarTransform {
  double yaw_rad = 0;
  Eigen::Vector2d t_m = Eigen::Vector2d::Zero();

  Eigen::Matrix2d R() const {
    const double c = std::cos(yaw_rad), s = std::sin(yaw_rad);
    return (Eigen::Matrix2d() << c, -s, s, c).finished();
  }
  Eigen::Vector2d operator*(const Eigen::Vector2d& p) const { return R() * p + t_m; }
  /// (this * other)(p) = this(other(p)).
  PlanarTransform operator*(const PlanarTransform& o) const {
    return {std::remainder(yaw_rad + o.yaw_rad, 2 * std::numbers::pi), R() * o.t_m + t_m};
  }
  PlanarTransform inverse() const {
    const Eigen::Matrix2d Rt = R().transpose();
    return {-yaw_rad, -(Rt * t_m)};
  }
  /// The SE(3) transform, with `dz_m` the height offset (floor_a - floor_b).
  Eigen::Isometry3d ToIsometry(double dz_m) const {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear() = Eigen::AngleAxisd(yaw_rad, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    T.translation() << t_m.x(), t_m.y(), dz_m;
    return T;
  }
  /// The planar part of an SE(3) transform between gravity-aligned frames.
  static PlanarTransform FromIsometry(const Eigen::Isometry3d& T) {
    const Eigen::Vector3d x = T.linear().col(0);
    return {std::atan2(x.y(), x.x()), T.translation().head<2>()};
  }
};

/// True when two transforms place a map within `distance_m` and `angle_rad` of each other,
/// measured at `reach_m` from the origin (a yaw error moves far points more).
inline bool SameTransform(const PlanarTransform& a, const PlanarTransform& b, double distance_m,
                          double angle_rad) {
  const double dyaw = std::fabs(std::remainder(a.yaw_rad - b.yaw_rad, 2 * std::numbers::pi));
  return dyaw <= angle_rad && (a.t_m - b.t_m).norm() <= distance_m;
}

}  // namespace msgraphs::core
