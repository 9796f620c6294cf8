// SPDX-License-Identifier: MIT
// The collaborative graph's factors (collaborative_graph.hpp), as Ceres functors. Their
// measurements are plain members so that the graph can update them in place between solves
// (a persistent graph: a changed measurement is the same factor with a new value).
#pragma once

#include <Eigen/Geometry>
#include <cmath>

namespace msgraphs::core::collab_factors {

// Origins: Eigen quaternion (x, y, z, w) and translation; p_self = R p_robot + t.
template <typename T>
Eigen::Matrix<T, 3, 3> Rotation(const T* q) {
  return Eigen::Quaternion<T>(q[3], q[0], q[1], q[2]).toRotationMatrix();
}

// A wall node (n, d in self's frame) against what its robot measured: the S-Graph's
// keyframe-to-plane factor (sgraph::PlaneResidual) with the robot's origin as the "keyframe".

// Two nodes of one wall. As sgraph::WallWallResidual, with its own angle and offset sigmas
// (that one's single sigma is in the S-Graph's snapshot format).
struct WallSame {
  double inv_sigma_rad, inv_sigma_m;
  template <typename T>
  bool operator()(const T* n_a, const T* d_a, const T* n_b, const T* d_b, T* r) const {
    for (int i = 0; i < 3; ++i) r[i] = (n_b[i] - n_a[i]) * T(inv_sigma_rad);
    r[3] = (d_b[0] - d_a[0]) * T(inv_sigma_m);
    return true;
  }
};


// A room node (centre in self's frame) against its robot's measurement (robot frame).
struct RoomMeasured {
  Eigen::Vector3d centre;
  double inv_sigma;
  template <typename T>
  bool operator()(const T* q, const T* t, const T* p, T* r) const {
    const Eigen::Matrix<T, 3, 3> R = Rotation(q);
    const Eigen::Map<const Eigen::Matrix<T, 3, 1>> p_self(p), t_self(t);
    const Eigen::Matrix<T, 3, 1> e = R.transpose() * (p_self - t_self) - centre.cast<T>();
    for (int i = 0; i < 3; ++i) r[i] = e[i] * T(inv_sigma);
    return true;
  }
};

struct RoomSame {
  double inv_sigma;
  template <typename T>
  bool operator()(const T* p_a, const T* p_b, T* r) const {
    for (int i = 0; i < 3; ++i) r[i] = (p_b[i] - p_a[i]) * T(inv_sigma);
    return true;
  }
};

// Two nodes of the same corridor: the same line across, the same floor; nothing along. A
// corridor's centre along its length is the centroid of whatever stretch its robot saw, so
// two robots' centres differ along it by up to the corridor's length (a 1 cm tie there slid a
// merged origin 7.6 m along a corridor, benchmark m011). The across axis is the corridor's
// room-frame x axis (the normal of its wall pair) through its robot's origin.
struct CorridorSame {
  double yaw_rad, inv_sigma;
  template <typename T>
  bool operator()(const T* q, const T* p_a, const T* p_b, T* r) const {
    const Eigen::Matrix<T, 3, 1> across =
        Rotation(q) * Eigen::Matrix<T, 3, 1>(T(std::cos(yaw_rad)), T(std::sin(yaw_rad)), T(0));
    const Eigen::Matrix<T, 3, 1> e(p_b[0] - p_a[0], p_b[1] - p_a[1], p_b[2] - p_a[2]);
    r[0] = across.dot(e) * T(inv_sigma);
    r[1] = e[2] * T(inv_sigma);
    return true;
  }
};

// The two rooms' x axes (each robot's measured yaw through its origin) agree up to quarter
// turns: sin(4 delta) / 4 is delta near each of them.
struct RoomYaw {
  double yaw_a, yaw_b, inv_sigma;
  template <typename T>
  bool operator()(const T* q_a, const T* q_b, T* r) const {
    const Eigen::Matrix<T, 3, 1> x_a =
        Rotation(q_a) * Eigen::Matrix<T, 3, 1>(T(std::cos(yaw_a)), T(std::sin(yaw_a)), T(0));
    const Eigen::Matrix<T, 3, 1> x_b =
        Rotation(q_b) * Eigen::Matrix<T, 3, 1>(T(std::cos(yaw_b)), T(std::sin(yaw_b)), T(0));
    const T delta = atan2(x_a[0] * x_b[1] - x_a[1] * x_b[0], x_a[0] * x_b[0] + x_a[1] * x_b[1]);
    r[0] = sin(T(4.0) * delta) / T(4.0) * T(inv_sigma);
    return true;
  }
};

struct Gravity {
  double inv_sigma;
  template <typename T>
  bool operator()(const T* q, T* r) const {
    const Eigen::Matrix<T, 3, 3> R = Rotation(q);
    r[0] = R(0, 2) * T(inv_sigma);
    r[1] = R(1, 2) * T(inv_sigma);
    return true;
  }
};

struct OriginMeasured {
  Eigen::Quaterniond q_m;
  Eigen::Vector3d t_m;
  double inv_sigma_m, inv_sigma_rad;
  template <typename T>
  bool operator()(const T* q, const T* t, T* r) const {
    const Eigen::Quaternion<T> e =
        q_m.conjugate().cast<T>() * Eigen::Quaternion<T>(q[3], q[0], q[1], q[2]);
    const T sign = e.w() < T(0) ? T(-1) : T(1);
    for (int i = 0; i < 3; ++i) {
      r[i] = T(2.0) * sign * e.vec()[i] * T(inv_sigma_rad);
      r[3 + i] = (t[i] - T(t_m[i])) * T(inv_sigma_m);
    }
    return true;
  }
};

// Two robots walk the same floor: robot b's floor point, through its origin, is at self's
// floor height. Vertical walls say nothing of heights, and their normals' slight tilts would
// otherwise let the origin's height wander.
struct SameFloor {
  Eigen::Vector3d p_b;  // a point on robot b's floor, its map frame
  double z_self, inv_sigma;
  template <typename T>
  bool operator()(const T* q, const T* t, T* r) const {
    const Eigen::Matrix<T, 3, 1> p = Rotation(q) * p_b.cast<T>() + Eigen::Matrix<T, 3, 1>(t[0], t[1], t[2]);
    r[0] = (p[2] - T(z_self)) * T(inv_sigma);
    return true;
  }
};

// A room's centre lies midway between two of its facing walls (the local S-Graph's room
// factor, pair by pair): its signed distances to both (each wall's normal faces into the
// room) are equal.
struct RoomBetweenWalls {
  double inv_sigma;
  template <typename T>
  bool operator()(const T* p, const T* n_a, const T* d_a, const T* n_b, const T* d_b, T* r) const {
    const T to_a = n_a[0] * p[0] + n_a[1] * p[1] + n_a[2] * p[2] + d_a[0];
    const T to_b = n_b[0] * p[0] + n_b[1] * p[1] + n_b[2] * p[2] + d_b[0];
    r[0] = T(0.5) * (to_a - to_b) * T(inv_sigma);
    return true;
  }
};

}  // namespace msgraphs::core::collab_factors
