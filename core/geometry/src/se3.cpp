// SPDX-License-Identifier: MIT
#include "msgraphs/core/geometry/se3.hpp"

#include <algorithm>
#include <cmath>

namespace msgraphs::core {
namespace {

// Below this angle the closed forms lose precision; their Taylor series take over.
constexpr double kSmallAngleRad = 1e-6;

Eigen::Matrix3d Hat(const Eigen::Vector3d& v) {
  Eigen::Matrix3d m;
  m << 0.0, -v.z(), v.y(), v.z(), 0.0, -v.x(), -v.y(), v.x(), 0.0;
  return m;
}

}  // namespace

Eigen::Matrix3d So3Exp(const Eigen::Vector3d& phi_rad) {
  const double angle = phi_rad.norm();
  if (angle < kSmallAngleRad) {
    const Eigen::Matrix3d K = Hat(phi_rad);
    return Eigen::Matrix3d::Identity() + K + 0.5 * K * K;
  }
  return Eigen::AngleAxisd(angle, phi_rad / angle).toRotationMatrix();
}

Eigen::Vector3d So3Log(const Eigen::Matrix3d& R) {
  // Through the quaternion: well conditioned over the whole range, including angle ~ pi where
  // the trace-based formula divides by sin(angle) ~ 0.
  Eigen::Quaterniond q(R);
  q.normalize();
  if (q.w() < 0.0) q.coeffs() = -q.coeffs();  // angle in [0, pi]
  const double sin_half = q.vec().norm();
  if (sin_half < 0.5 * kSmallAngleRad) return 2.0 * q.vec() / q.w();
  const double angle = 2.0 * std::atan2(sin_half, q.w());
  return q.vec() * (angle / sin_half);
}

Eigen::Matrix3d So3LeftJacobian(const Eigen::Vector3d& phi_rad) {
  const double angle = phi_rad.norm();
  const Eigen::Matrix3d K = Hat(phi_rad);
  if (angle < kSmallAngleRad) return Eigen::Matrix3d::Identity() + 0.5 * K + K * K / 6.0;
  const double a2 = angle * angle;
  return Eigen::Matrix3d::Identity() + (1.0 - std::cos(angle)) / a2 * K +
         (angle - std::sin(angle)) / (a2 * angle) * K * K;
}

Eigen::Matrix3d So3LeftJacobianInverse(const Eigen::Vector3d& phi_rad) {
  const double angle = phi_rad.norm();
  const Eigen::Matrix3d K = Hat(phi_rad);
  if (angle < kSmallAngleRad) return Eigen::Matrix3d::Identity() - 0.5 * K + K * K / 12.0;
  const double half = 0.5 * angle;
  const double cot_half = std::cos(half) / std::sin(half);
  return Eigen::Matrix3d::Identity() - 0.5 * K +
         (1.0 - half * cot_half) / (angle * angle) * K * K;
}

Eigen::Isometry3d Se3Exp(const Vector6d& xi) {
  const Eigen::Vector3d rho = xi.head<3>();
  const Eigen::Vector3d phi = xi.tail<3>();
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = So3Exp(phi);
  T.translation() = So3LeftJacobian(phi) * rho;
  return T;
}

Vector6d Se3Log(const Eigen::Isometry3d& T) {
  const Eigen::Vector3d phi = So3Log(T.linear());
  Vector6d xi;
  xi.head<3>() = So3LeftJacobianInverse(phi) * T.translation();
  xi.tail<3>() = phi;
  return xi;
}

Eigen::Isometry3d Interpolate(const Eigen::Isometry3d& T_a, const Eigen::Isometry3d& T_b,
                              double alpha) {
  const Vector6d xi = Se3Log(T_a.inverse() * T_b);
  return T_a * Se3Exp(alpha * xi);
}

bool IsValidRigidTransform(const Eigen::Isometry3d& T, double tolerance) {
  if (!T.matrix().allFinite()) return false;
  const Eigen::Matrix3d R = T.linear();
  const double orthonormality_error = (R.transpose() * R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
  return orthonormality_error <= tolerance && std::abs(R.determinant() - 1.0) <= tolerance;
}

Eigen::Matrix3d RotZ(double yaw_rad) {
  return Eigen::AngleAxisd(yaw_rad, Eigen::Vector3d::UnitZ()).toRotationMatrix();
}

}  // namespace msgraphs::core
