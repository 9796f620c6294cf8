// SPDX-License-Identifier: MIT
#include "msgraphs/core/perception/covariances.hpp"

#include <Eigen/Eigenvalues>

namespace msgraphs::core {

Expected<CovarianceStats> EstimateCovariances(std::span<const Eigen::Vector3f> points, const KdTree& tree,
                                              const CovarianceConfig& config, BoundedVector<Eigen::Vector3f>& normals,
                                              BoundedVector<Eigen::Matrix3f>& covariances,
                                              const Eigen::Vector3f* viewpoint) {
  normals.clear();
  covariances.clear();
  if (tree.size() != points.size()) return Error{Errc::kInvalidArgument, "covariances: tree does not index these points"};
  if (normals.capacity() < points.size() || covariances.capacity() < points.size()) {
    return Error{Errc::kCapacityExceeded, "covariances: output capacity below the point count"};
  }
  if (config.neighbours < 3 || config.neighbours > KdTree::kMaxK) {
    return Error{Errc::kInvalidConfig, "covariances: neighbours must be 3..64"};
  }
  CovarianceStats stats;
  std::uint32_t idx[KdTree::kMaxK];
  float d2[KdTree::kMaxK];
  const float max_d2 = config.max_neighbour_distance_m * config.max_neighbour_distance_m;
  // Filled by index, visited in the tree's leaf order (consecutive queries share their paths).
  for (std::size_t i = 0; i < points.size(); ++i) {
    normals.push_back(Eigen::Vector3f::Zero());
    covariances.push_back(Eigen::Matrix3f::Identity() * 1e-2f);
  }
  for (const std::uint32_t at : tree.leaf_order()) {
    const Eigen::Vector3f& p = points[at];
    const std::size_t n = tree.Knn(p, config.neighbours, idx, d2, max_d2);
    if (n < 5) {
      ++stats.degenerate;  // left as the small sphere
      continue;
    }
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    for (std::size_t i = 0; i < n; ++i) mean += points[idx[i]].cast<double>();
    mean /= static_cast<double>(n);
    Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
    for (std::size_t i = 0; i < n; ++i) {
      const Eigen::Vector3d q = points[idx[i]].cast<double>() - mean;
      scatter += q * q.transpose();
    }
    scatter /= static_cast<double>(n);
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig;
    eig.computeDirect(scatter);
    const Eigen::Matrix3d U = eig.eigenvectors();  // columns by ascending eigenvalue
    Eigen::Vector3d normal = U.col(0);
    if (viewpoint != nullptr && normal.dot((*viewpoint - p).cast<double>()) < 0) normal = -normal;
    const Eigen::Matrix3d C = U * Eigen::Vector3d(1e-3, 1.0, 1.0).asDiagonal() * U.transpose();
    normals[at] = normal.cast<float>();
    covariances[at] = C.cast<float>();
  }
  return stats;
}

}  // namespace msgraphs::core
