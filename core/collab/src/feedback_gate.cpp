// SPDX-License-Identifier: MIT
#include "msgraphs/core/collab/feedback_gate.hpp"

#include <Eigen/Cholesky>
#include <limits>

namespace msgraphs::core {

double PriorDisagreement(const PlanePrior& prior, const DistilledWall& own) {
  constexpr double kNever = std::numeric_limits<double>::infinity();
  if (prior.normal.dot(own.normal) <= 0) return kNever;
  // The own wall's covariance refers to its own basis, which for walls within the gate's few
  // degrees of each other is the prior's to second order.
  Eigen::Vector3d u, v;
  WallBasis(prior.normal, u, v);
  const Eigen::Vector3d e(u.dot(own.normal), v.dot(own.normal), own.d - prior.d);
  const Eigen::LLT<Eigen::Matrix3d> llt(prior.covariance + own.covariance);
  if (llt.info() != Eigen::Success || !e.allFinite()) return kNever;
  return e.dot(llt.solve(e));
}

}  // namespace msgraphs::core
