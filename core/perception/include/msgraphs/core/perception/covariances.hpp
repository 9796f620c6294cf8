// SPDX-License-Identifier: MIT
// Per-point normals and covariances from the k nearest neighbours (GICP style): the local
// scatter's eigenvectors, with the covariance regularised to a plane, U diag(1e-3, 1, 1) U^T,
// so that every covariance is well conditioned and says "this point lies on a surface".
#pragma once

#include <Eigen/Core>
#include <span>

#include "msgraphs/base/bounded_vector.hpp"
#include "msgraphs/base/expected.hpp"
#include "msgraphs/core/perception/kdtree.hpp"

namespace msgraphs::core {

struct CovarianceConfig {
  std::size_t neighbours = 10;  ///< k, including the point itself (small_gicp uses 10 to 20)
  float max_neighbour_distance_m = 2.0f;
};

struct CovarianceStats {
  std::size_t degenerate = 0;  ///< fewer than 5 neighbours: covariance set to a small sphere
};

/// Fills `normals` and `covariances` (one per point, same order). `tree` must index `points`.
/// Normals are oriented towards `viewpoint` (the sensor) when it is given.
Expected<CovarianceStats> EstimateCovariances(std::span<const Eigen::Vector3f> points, const KdTree& tree,
                                              const CovarianceConfig& config, BoundedVector<Eigen::Vector3f>& normals,
                                              BoundedVector<Eigen::Matrix3f>& covariances,
                                              const Eigen::Vector3f* viewpoint = nullptr);

}  // namespace msgraphs::core
