// SPDX-License-Identifier: MIT
// Marginal covariances of planes from a Ceres problem that holds them (SGraphSolveJob on its
// copy, which SGraph::PlaneMarginals runs too): one factorisation of the whole problem
// (SuiteSparse QR), each plane's ambient (normal, offset) block projected on its own (u, v)
// tangent basis. Allocates (Ceres' covariance): never on a per-keyframe path.
#pragma once

#include <Eigen/Core>
#include <span>

#include "msgraphs/base/expected.hpp"

namespace ceres {
class Problem;
}

namespace msgraphs::core::sgraph {

/// A plane's parameter blocks in the problem and the basis its covariance is expressed in.
struct PlaneBlocks {
  const double* n = nullptr;  // normal, 3 (sphere manifold)
  const double* d = nullptr;  // offset, 1
  Eigen::Vector3d basis_u = Eigen::Vector3d::UnitX(), basis_v = Eigen::Vector3d::UnitY();
};

/// covariances[i]: planes[i]'s over (alpha, beta, delta_d). kDegenerate when the problem is
/// rank deficient or a result is not finite.
Status PlaneCovariances(ceres::Problem& problem,
                        std::span<const PlaneBlocks> planes,
                        std::span<Eigen::Matrix3d> covariances);

}  // namespace msgraphs::core::sgraph
