// SPDX-License-Identifier: MIT
// Positive evidence for a transform between two maps: the walls of map b, laid into map a's
// frame, that fall onto walls of map a (same facing within `angle_rad`, same line within
// `offset_m`, overlapping along the wall). Each overlap of length l on a wall of normal n adds
// l n n^T to a 2 x 2 information matrix:
// - agreement_m, its trace: metres of wall that coincide;
// - constraint_m, its smaller eigenvalue: metres of coinciding wall in the weakest direction.
//   A corridor's two walls alone fix nothing along the corridor (constraint 0); a room's four
//   walls fix both directions.
// RefineTransform: Gauss-Newton on the coinciding pairs (the ends of every overlap to the other
// wall's line), re-associating at each step; a direction without constraint is left as it was.
// No allocation; O(walls_b * log) per call.
#pragma once

#include <Eigen/Core>

#include "msgraphs/core/collab/planar_transform.hpp"
#include "msgraphs/core/collab/wall_index.hpp"

namespace msgraphs::core {

struct WallAgreementConfig {
  /// Coinciding walls: a correct transform between two maps is good to a few centimetres and a
  /// fraction of a degree, each map's walls to about 2 cm; the offset allows a 0.5 degree error
  /// 20 m away.
  double angle_rad = 0.052;  // 3 degrees
  double offset_m = 0.2;
  Status Validate() const;
};

struct WallAgreement {
  double agreement_m = 0;
  double constraint_m = 0;
  std::size_t pairs = 0;
  Eigen::Matrix2d information = Eigen::Matrix2d::Zero();
};

WallAgreement ScoreAgreement(const WallIndex& a, const WallIndex& b, const PlanarTransform& T_a_b,
                             const WallAgreementConfig& config);

PlanarTransform RefineTransform(const WallIndex& a, const WallIndex& b, PlanarTransform T_a_b,
                                const WallAgreementConfig& config, int iterations);

}  // namespace msgraphs::core
