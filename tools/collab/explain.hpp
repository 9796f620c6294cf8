// SPDX-License-Identifier: MIT
// Why a view merged or did not, against the truth: for robot A's view of robot B, the true
// transform between their map frames (each robot's own truth alignment) judged by the same
// machinery A ran (the alignment search over A's and B's final maps, the conflicts with both
// free-space summaries, the merge rule), and a cause for every view that is not right:
// - "no free space": a summary never arrived;
// - "truth not proposed": no hypothesis of the search lies near the truth;
// - "truth refuted" / "truth conflicted": the truth's own conflict is beyond the rule's thresholds
//   (what the free-space evidence gets wrong);
// - "too little shared": the truth's agreement is below the rule's minimum (the robots did not
//   see enough of the same walls);
// - "ambiguous": the truth stands but a rival within the margin stands too;
// - "a map contradicts itself": the rule would merge, but one robot's walls stand in its own
//   free space (merge rule 6);
// - "merged wrongly" / "merged, then undone" and so on from the final decision.
// --explain DIR also draws each summary with the other robot's walls laid in by the truth (PPM:
// unknown grey, free white, occupied black, the other's walls orange, red where they conflict,
// openings blue; the other's openings magenta), and again under the rule's leader where that is
// not the truth (`_leader.ppm`).
#pragma once

#include <string>
#include <vector>

#include "evaluation.hpp"
#include "mission.hpp"
#include "msgraphs/core/collab/alignment_search.hpp"

namespace msgraphs::tools::collab {

struct ViewExplanation {
  int viewer = 0, robot = 0;
  bool checked = false;       ///< both robots have truth alignments and free space
  const char* cause = "";     ///< see the file comment ("right" when merged right)
  core::Hypothesis truth;     ///< the true transform, refined and scored
  bool proposed = false;      ///< a hypothesis of the search lies near it
  std::size_t rank = 0;       ///< its place by agreement among the hypotheses (0 first)
  std::size_t hypotheses = 0;
  core::MergeDecision decision;  ///< the rule, re-run on the final maps
  double leader_truth_distance_m = 0;  ///< how far the rule's leader is from the truth
  /// When merged: how far the merge's own transform and the solved estimate are from the truth.
  double merge_truth_distance_m = 0, solved_truth_distance_m = 0;
};

/// Every view of a room-based mission (empty for the keyframe baseline). `pictures_dir` empty:
/// no pictures.
std::vector<ViewExplanation> ExplainViews(const Mission& mission, const Evaluation& evaluation,
                                          const std::string& pictures_dir);

}  // namespace msgraphs::tools::collab
