// SPDX-License-Identifier: MIT
// Synthetic geometry for core tests: points on the inside faces of a box room (walls, floor,
// ceiling) with Gaussian noise, deterministic from a seed.
#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <random>
#include <vector>

namespace msgraphs::test {

/// A pose on the floor plane: x, y and yaw.
inline Eigen::Isometry3d PlanarPose(double x, double y, double yaw_rad) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(yaw_rad, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  T.translation() << x, y, 0;
  return T;
}

inline std::vector<Eigen::Vector3f> BoxRoom(double sx, double sy, double sz, std::size_t n, double noise_m,
                                            std::uint32_t seed, const Eigen::Isometry3d& T = Eigen::Isometry3d::Identity(),
                                            bool with_ceiling = true) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::normal_distribution<double> g(0.0, noise_m);
  const double areas[6] = {sy * sz, sy * sz, sx * sz, sx * sz, sx * sy, with_ceiling ? sx * sy : 0.0};
  double total = 0;
  for (double a : areas) total += a;
  std::vector<Eigen::Vector3f> out;
  out.reserve(n);
  while (out.size() < n) {
    double pick = u(rng) * total;
    int face = 0;
    while (face < 5 && pick > areas[face]) pick -= areas[face++];
    Eigen::Vector3d p(u(rng) * sx, u(rng) * sy, u(rng) * sz);
    switch (face) {
      case 0: p.x() = 0; break;
      case 1: p.x() = sx; break;
      case 2: p.y() = 0; break;
      case 3: p.y() = sy; break;
      case 4: p.z() = 0; break;
      default: p.z() = sz; break;
    }
    p += Eigen::Vector3d(g(rng), g(rng), g(rng));
    out.push_back((T * p).cast<float>());
  }
  return out;
}

}  // namespace msgraphs::test
