// SPDX-License-Identifier: MIT
#include "s_graph_covariance.hpp"

#include <ceres/ceres.h>

#include <utility>
#include <vector>

namespace msgraphs::core::sgraph {

Status PlaneCovariances(ceres::Problem& problem,
                        std::span<const PlaneBlocks> planes,
                        std::span<Eigen::Matrix3d> covariances) {
  if (covariances.size() < planes.size())
    return Error{Errc::kCapacityExceeded, "plane marginals: output shorter than the plane list"};
  if (planes.empty()) return Ok();
  std::vector<std::pair<const double*, const double*>> blocks;
  blocks.reserve(planes.size() * 3);
  for (const PlaneBlocks& p : planes) {
    blocks.emplace_back(p.n, p.n);
    blocks.emplace_back(p.n, p.d);
    blocks.emplace_back(p.d, p.d);
  }
  ceres::Covariance::Options options;
  options.algorithm_type = ceres::SPARSE_QR;
  options.num_threads = 1;
  ceres::Covariance covariance(options);
  if (!covariance.Compute(blocks, &problem))
    return Error{Errc::kDegenerate, "plane marginals: the problem is rank deficient"};
  for (std::size_t i = 0; i < planes.size(); ++i) {
    const PlaneBlocks& p = planes[i];
    // Ambient blocks (normal in R^3, offset), projected on the plane's own (u, v) basis.
    Eigen::Matrix<double, 3, 3, Eigen::RowMajor> nn;
    Eigen::Vector3d nd;
    double dd = 0;
    if (!covariance.GetCovarianceBlock(p.n, p.n, nn.data()) ||
        !covariance.GetCovarianceBlock(p.n, p.d, nd.data()) ||
        !covariance.GetCovarianceBlock(p.d, p.d, &dd)) {
      return Error{Errc::kDegenerate, "plane marginals: block not available"};
    }
    Eigen::Matrix4d full;
    full.topLeftCorner<3, 3>() = nn;
    full.topRightCorner<3, 1>() = nd;
    full.bottomLeftCorner<1, 3>() = nd.transpose();
    full(3, 3) = dd;
    Eigen::Matrix<double, 3, 4> B = Eigen::Matrix<double, 3, 4>::Zero();
    B.block<1, 3>(0, 0) = p.basis_u.transpose();
    B.block<1, 3>(1, 0) = p.basis_v.transpose();
    B(2, 3) = 1.0;
    covariances[i] = B * full * B.transpose();
    if (!covariances[i].allFinite()) return Error{Errc::kDegenerate, "plane marginals: not finite"};
  }
  return Ok();
}

}  // namespace msgraphs::core::sgraph
