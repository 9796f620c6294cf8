// SPDX-License-Identifier: MIT
#include "msgraphs/core/geometry/umeyama.hpp"

#include <Eigen/SVD>

namespace msgraphs::core {

Expected<Eigen::Isometry3d> AlignUmeyama(std::span<const Eigen::Vector3d> a, std::span<const Eigen::Vector3d> b) {
  if (a.size() != b.size()) return Error{Errc::kInvalidArgument, "umeyama: point sets differ in size"};
  if (a.size() < 3) return Error{Errc::kDegenerate, "umeyama: fewer than 3 pairs"};
  Eigen::Vector3d ma = Eigen::Vector3d::Zero(), mb = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < a.size(); ++i) {
    ma += a[i];
    mb += b[i];
  }
  ma /= static_cast<double>(a.size());
  mb /= static_cast<double>(b.size());
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (std::size_t i = 0; i < a.size(); ++i) cov += (b[i] - mb) * (a[i] - ma).transpose();
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(cov, Eigen::ComputeFullU | Eigen::ComputeFullV);
  const Eigen::Vector3d s = svd.singularValues();
  if (!(s(1) > 1e-12 * std::max(1.0, s(0)))) return Error{Errc::kDegenerate, "umeyama: points are collinear"};
  Eigen::Matrix3d S = Eigen::Matrix3d::Identity();
  if ((svd.matrixU() * svd.matrixV().transpose()).determinant() < 0) S(2, 2) = -1;
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = svd.matrixU() * S * svd.matrixV().transpose();
  T.translation() = mb - T.linear() * ma;
  return T;
}

}  // namespace msgraphs::core
