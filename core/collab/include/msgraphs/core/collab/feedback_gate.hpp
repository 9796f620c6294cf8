// SPDX-License-Identifier: MIT
// The feedback gate: a peer's wall, brought into this map through the collaborative estimate,
// is fed back as a prior on this robot's own wall only while the two agree within their
// covariances (CollabSessionConfig::feedback_gate_chi2). A prior that disagrees says the
// origin it went through is off by more than the covariances hold; fed back, it would bend the
// own map towards that error.
#pragma once

#include "msgraphs/core/graph/distilled_graph.hpp"
#include "msgraphs/core/graph/s_graph.hpp"

namespace msgraphs::core {

/// The squared Mahalanobis distance between `prior` and `own` (two normal angles and the
/// offset, in the prior's wall basis, under both covariances summed); infinity when they face
/// opposite ways or the summed covariance is not positive definite.
double PriorDisagreement(const PlanePrior& prior, const DistilledWall& own);

}  // namespace msgraphs::core
