// SPDX-License-Identifier: MIT
// The S-Graph's residuals as Ceres auto-differentiated functors (private to core_graph).
// Formulas: docs/s-graph.md; the original's, for comparison, in
// reference/original-s-graphs-notes.md 1.6 and 1.11-1.14.
#pragma once

#include <ceres/rotation.h>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace msgraphs::core::sgraph {

/// Relative pose T_i^-1 T_j against the measurement Z: e = [Z_R^T (t_ij - t_z); Log(Z_R^T R_ij)],
/// whitened by the upper factor of the information (r^T r = e^T Omega e).
struct RelativePoseResidual {
  Eigen::Quaterniond q_z;
  Eigen::Vector3d t_z;
  Eigen::Matrix<double, 6, 6> sqrt_information;
  template <typename T>
  bool operator()(const T* qi, const T* ti, const T* qj, const T* tj, T* r) const {
    const Eigen::Map<const Eigen::Quaternion<T>> Qi(qi), Qj(qj);
    const Eigen::Map<const Eigen::Matrix<T, 3, 1>> Ti(ti), Tj(tj);
    const Eigen::Quaternion<T> Qz = q_z.cast<T>();
    const Eigen::Quaternion<T> dq = Qz.conjugate() * (Qi.conjugate() * Qj);
    Eigen::Matrix<T, 6, 1> e;
    e.template head<3>() = Qz.conjugate() * (Qi.conjugate() * (Tj - Ti) - t_z.cast<T>());
    const T quat[4] = {dq.w(), dq.x(), dq.y(), dq.z()};
    T axis[3];
    ceres::QuaternionToAngleAxis(quat, axis);
    e.template tail<3>() << axis[0], axis[1], axis[2];
    Eigen::Map<Eigen::Matrix<T, 6, 1>> res(r);
    res = sqrt_information.cast<T>() * e;
    return true;
  }
};

/// Keyframe-to-plane: the map plane (n, d) predicted in the keyframe frame (n_k = R^T n,
/// d_k = d + n.t) against the measurement, in the measurement's own minimal coordinates:
/// e = [u.n_k, v.n_k, d_k - d_m] (u, v span the measured plane), so that the extractor's
/// covariance over (alpha, beta, delta_d) weighs it directly.
struct PlaneResidual {
  Eigen::Vector3d basis_u, basis_v;
  double d_measured;
  Eigen::Matrix3d sqrt_information;
  template <typename T>
  bool operator()(const T* q, const T* t, const T* n, const T* d, T* r) const {
    const Eigen::Map<const Eigen::Quaternion<T>> Q(q);
    const Eigen::Map<const Eigen::Matrix<T, 3, 1>> tr(t), nm(n);
    const Eigen::Matrix<T, 3, 1> n_k = Q.conjugate() * nm;
    const T d_k = d[0] + nm.dot(tr);
    Eigen::Matrix<T, 3, 1> e(basis_u.cast<T>().dot(n_k), basis_v.cast<T>().dot(n_k),
                             d_k - T(d_measured));
    Eigen::Map<Eigen::Matrix<T, 3, 1>> res(r);
    res = sqrt_information.cast<T>() * e;
    return true;
  }
};

/// A prior on a map plane (another robot's measurement of the same wall, through the
/// collaborative graph): e = [u.n, v.n, d - d_m] with (u, v) spanning the prior's plane.
struct PlanePriorResidual {
  Eigen::Vector3d basis_u, basis_v;
  double d_prior;
  Eigen::Matrix3d sqrt_information;
  template <typename T>
  bool operator()(const T* n, const T* d, T* r) const {
    const Eigen::Map<const Eigen::Matrix<T, 3, 1>> nm(n);
    Eigen::Matrix<T, 3, 1> e(basis_u.cast<T>().dot(nm), basis_v.cast<T>().dot(nm),
                             d[0] - T(d_prior));
    Eigen::Map<Eigen::Matrix<T, 3, 1>> res(r);
    res = sqrt_information.cast<T>() * e;
    return true;
  }
};

/// The midline of two walls facing each other (both normals point into the room): the points
/// equally far in front of both, (n_a - n_b).p + (d_a - d_b) = 0, in the xy plane.
template <typename T>
void Midline(const T* n_a,
             const T* d_a,
             const T* n_b,
             const T* d_b,
             Eigen::Matrix<T, 2, 1>& normal,
             T& offset) {
  normal << n_a[0] - n_b[0], n_a[1] - n_b[1];
  offset = d_a[0] - d_b[0];
}

/// Four-wall room: its centre is where the two midlines cross.
struct RoomResidual {
  double inv_sigma;
  template <typename T>
  bool operator()(const T* c,
                  const T* na,
                  const T* da,
                  const T* nb,
                  const T* db,
                  const T* nc,
                  const T* dc,
                  const T* nd,
                  const T* dd,
                  T* r) const {
    Eigen::Matrix<T, 2, 1> m1, m2;
    T o1, o2;
    Midline(na, da, nb, db, m1, o1);
    Midline(nc, dc, nd, dd, m2, o2);
    Eigen::Matrix<T, 2, 2> A;
    A.row(0) = m1.transpose();
    A.row(1) = m2.transpose();
    const T det = A.determinant();
    if (!(ceres::abs(det) > T(1e-6))) return false;  // parallel pairs: no centre (never accepted)
    const Eigen::Matrix<T, 2, 1> centre = A.inverse() * Eigen::Matrix<T, 2, 1>(-o1, -o2);
    r[0] = (c[0] - centre[0]) * T(inv_sigma);
    r[1] = (c[1] - centre[1]) * T(inv_sigma);
    return true;
  }
};

/// Corridor: across, the centre lies on the midline; along, at the free-space cluster's
/// position (a constant, unlike the original's r = m + (k - (k.u)u), which is undefined when the
/// corridor's axis passes through the map origin).
struct CorridorResidual {
  Eigen::Vector2d anchor;
  double inv_sigma;
  template <typename T>
  bool operator()(const T* c, const T* na, const T* da, const T* nb, const T* db, T* r) const {
    Eigen::Matrix<T, 2, 1> m;
    T o;
    Midline(na, da, nb, db, m, o);
    const T norm = m.norm();
    if (!(norm > T(1e-6))) return false;
    const Eigen::Matrix<T, 2, 1> across = m / norm;
    const Eigen::Matrix<T, 2, 1> along(-across[1], across[0]);
    const Eigen::Matrix<T, 2, 1> cc(c[0], c[1]);
    r[0] = (across.dot(cc) + o / norm) * T(inv_sigma);
    r[1] = along.dot(cc - anchor.cast<T>()) * T(inv_sigma);
    return true;
  }
};

/// The same wall twice: normals and offsets agree.
struct WallWallResidual {
  double inv_sigma;
  template <typename T>
  bool operator()(const T* na, const T* da, const T* nb, const T* db, T* r) const {
    for (int i = 0; i < 3; ++i) r[i] = (na[i] - nb[i]) * T(inv_sigma);
    r[3] = (da[0] - db[0]) * T(inv_sigma);
    return true;
  }
};

/// Floor to room: their offset stays as measured when the room joined (weak).
struct FloorRoomResidual {
  Eigen::Vector2d offset;
  double inv_sigma;
  template <typename T>
  bool operator()(const T* f, const T* c, T* r) const {
    r[0] = (f[0] - c[0] - T(offset.x())) * T(inv_sigma);
    r[1] = (f[1] - c[1] - T(offset.y())) * T(inv_sigma);
    return true;
  }
};

}  // namespace msgraphs::core::sgraph
