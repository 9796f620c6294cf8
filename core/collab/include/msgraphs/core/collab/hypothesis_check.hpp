// SPDX-License-Identifier: MIT
// Telling competing match hypotheses apart by the rest of the two maps.
//
// In a building with a row of identical rooms, the rooms of one robot match several rooms of
// the other, and the matches split into disjoint consistent sets: the truth, and the building
// shifted by its period. Counting matches cannot always choose (3 against 3 is common, and a
// shifted set can even be the larger one). The walls can: laid into this robot's frame by the
// true transform, the other robot's walls fall onto this robot's walls along their whole shared
// length (the corridor, the partitions of the other row, the building's end walls); shifted by
// a room period, the corridor overlaps less, the end walls and the other row's partitions fall
// where there is no wall.
//
// WallAgreement_m scores one transform; ChooseHypothesis decides among the scored sets.
// Allocation-free, O(walls_a x walls_b) per hypothesis.
#pragma once

#include <Eigen/Geometry>
#include <cstddef>
#include <span>

#include "msgraphs/base/expected.hpp"
#include "msgraphs/core/graph/distilled_graph.hpp"

namespace msgraphs::core {

struct HypothesisCheckConfig {
  /// Off: hypotheses are compared by their match counts alone (the ablation; a tie waits).
  bool use_walls = true;
  /// Two walls coincide when their normals agree within this angle and their offsets within
  /// this distance once laid in one frame (room-match transforms are good to a few cm and a
  /// tenth of a degree; 0.2 m allows a 0.3 degree yaw error 40 m away).
  double wall_angle_rad = 0.09;
  double wall_offset_m = 0.2;
  /// A hypothesis wins when its agreement is at least `margin_ratio` times the next one's plus
  /// `margin_m`: a clear difference, several metres of wall, not the noise of extents.
  double margin_ratio = 1.2;
  double margin_m = 3.0;
  Status Validate() const;
};

/// Total length (m) along which robot b's walls, laid into a's frame by T_a_b, coincide with
/// one of a's walls (same facing, same offset, overlapping extents). Each of b's walls counts
/// once, with its longest overlap.
double WallAgreement_m(const DistilledGraph& a,
                       const DistilledGraph& b,
                       const Eigen::Isometry3d& T_a_b,
                       const HypothesisCheckConfig& config);

/// Which hypothesis to accept, given each one's match count (largest first, as MatchHypotheses
/// returns them, single matches included) and its wall agreement:
/// - the one whose walls agree clearly best, if it holds at least `min_consistent` matches;
///   a single match clearly better than every set vetoes them all (the sets are then a symmetric
///   mismatch in waiting: its second match will decide);
/// - when no walls are clearly best, the largest set if it is strictly larger than the next and
///   holds at least `min_consistent`;
/// - otherwise none (-1: wait for more).
int ChooseHypothesis(std::span<const std::size_t> match_counts,
                     std::span<const double> agreement_m,
                     std::size_t min_consistent,
                     const HypothesisCheckConfig& config);

}  // namespace msgraphs::core
