// SPDX-License-Identifier: MIT
// SE(3) and SO(3) on Eigen: exponential and logarithm maps, interpolation and checks.
//
// Conventions (docs/conventions.md): T_a_b maps points from frame b into frame a, so
// T_a_c = T_a_b * T_b_c. Tangent vectors are [rho; phi] with translation part first, in
// metres and radians, matching the right-hand-side perturbation T * Exp(xi) used by the
// graph factors. None of these functions allocate.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace msgraphs::core {

using Vector6d = Eigen::Matrix<double, 6, 1>;

/// Rotation vector (axis * angle, rad) to rotation matrix. Exact near zero.
Eigen::Matrix3d So3Exp(const Eigen::Vector3d& phi_rad);
/// Rotation matrix to rotation vector, angle in [0, pi]. Stable near 0 and near pi.
Eigen::Vector3d So3Log(const Eigen::Matrix3d& R);

/// SO(3) left Jacobian J(phi), and its inverse; needed to map between SE(3) tangent spaces.
Eigen::Matrix3d So3LeftJacobian(const Eigen::Vector3d& phi_rad);
Eigen::Matrix3d So3LeftJacobianInverse(const Eigen::Vector3d& phi_rad);

/// xi = [rho; phi] to a rigid transform: rotation Exp(phi), translation J(phi) * rho.
Eigen::Isometry3d Se3Exp(const Vector6d& xi);
/// Inverse of Se3Exp.
Vector6d Se3Log(const Eigen::Isometry3d& T);

/// Geodesic interpolation: alpha = 0 gives T_a, 1 gives T_b (constant-velocity motion between
/// two poses, as used to deskew a sweep from per-point time).
Eigen::Isometry3d Interpolate(const Eigen::Isometry3d& T_a, const Eigen::Isometry3d& T_b,
                              double alpha);

/// True when every entry is finite and the rotation block is orthonormal with det +1 to
/// `tolerance`: the check applied to every pose that enters from outside (network, files).
bool IsValidRigidTransform(const Eigen::Isometry3d& T, double tolerance = 1e-6);

/// Rotation about z by yaw (rad); the planar motion models and room frames use it.
Eigen::Matrix3d RotZ(double yaw_rad);

}  // namespace msgraphs::core
