// SPDX-License-Identifier: MIT
// The merge rule with place evidence (place_evidence.hpp): a decision the rule left undecided
// between two transforms (a rival within the margin, or a stronger hypothesis refuted) is
// weighed on the peer's place clouds held. The candidates are the leader, the transform that
// blocks it, and every standing hypothesis strong enough to block a leader at the wider
// (symmetric) margin. Each is tallied on every place; the one with the most net support
// (explained minus contradicted cells) is the champion, and every candidate it beats in the
// duel is set aside; then the rule decides again without them, and so on for a few rounds.
// The champion is not merged by this: it must still win under the rule. When nothing is set
// aside, the decision says which two transforms a new place should tell apart.
//
// No allocation (the candidates and the set-aside list are bounded).
#pragma once

#include <Eigen/Core>
#include <span>

#include "msgraphs/base/bounded_vector.hpp"
#include "msgraphs/core/collab/merge_rule.hpp"
#include "msgraphs/core/collab/place_evidence.hpp"

namespace msgraphs::core {

/// A peer's place cloud: points relative to `centre_m` (the peer's frame) and its floor.
struct PlaceView {
  Eigen::Vector2d centre_m = Eigen::Vector2d::Zero();
  std::span<const Eigen::Vector3f> points;
};

struct PlaceDecision {
  MergeDecision decision;
  std::size_t duels = 0;  ///< tournaments held (on at least one place)
  /// Undecided on the places held: a new place should tell these two apart.
  bool wants_place = false;
  PlanarTransform first, second;
};

/// `d`: the rule's decision on `in` (not keeping a merge). `set_aside` collects the transforms
/// set aside (in.set_aside points into it afterwards); at most its capacity are.
PlaceDecision DecideWithPlaces(MergeInputs& in, const AlignmentSearch& search, const MergeRuleConfig& config,
                               const MergeDecision& d, std::span<const PlaceView> places, double cell_m,
                               PlaceScorer& scorer, BoundedVector<PlanarTransform>& set_aside);

}  // namespace msgraphs::core
