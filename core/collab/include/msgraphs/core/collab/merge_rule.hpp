// SPDX-License-Identifier: MIT
// The merge decision: whether robot b's map is placed in robot a's, and by which transform.
// Safe by construction: a merge needs positive evidence, no contradiction, and no standing
// alternative; otherwise the pair stays undecided and the decision says why.
//
// Given every hypothesis of the alignment search (alignment_search.hpp), best wall agreement
// first, with its conflicts in both directions (free_space_conflict.hpp):
// 1. A hypothesis with more than `refute_conflict_m` of conflict (or a share of its agreement:
//    conflict_per_agreement) is refuted: one robot mapped a
//    wall (or saw through an opening) where the other saw through (or saw a solid wall).
// 2. The leader is the first hypothesis not refuted. It must agree along at least
//    `min_agreement_m` of wall and `min_constraint_m` in its weakest direction (two directions
//    fixed, not a corridor's slide), and its own conflict must be at most `accept_conflict_m`.
// 3. Every other hypothesis not refuted that constrains both directions at least
//    `min_rival_constraint_m` is a rival; the leader must beat each by the margin:
//    agreement >= margin_ratio * rival's + margin_m. In one direction too: a channel of the
//    search (an alignment along one wall line, alignment_search.hpp), probed along that line
//    where the rule would merge, that agrees at least as much as the leader and stands is a
//    rival the leader cannot beat (`one_direction_rivals`): robots that share only a corridor
//    agree along it and fix nothing along it, and no corner pair proposes that.
// 4. Symmetry: each map's own symmetries (the alignment search of a map with itself: a row of
//    identical rooms, a room's half turn) composed with the leader give alternatives that lay b
//    on another copy of the same structure. If one of them is not refuted, the structure the
//    robots share repeats and the difference in agreement may be nothing but which copy each
//    robot saw more of: the margin becomes `symmetric_margin_ratio`, and the alternative is a
//    rival too. So are the leader's slides along either principal direction of its agreement that
//    stand (a structure repeated along it: racks at a pitch, a hall's bays).
// 5. No refuted hypothesis may beat the leader by the margin, in agreement and in its weakest
//    direction both, nor by the margin in agreement net of its own conflict while stronger in
//    its weakest direction by `margin_m` (kContradicted): when the strongest evidence two maps
//    have in common is contradicted, the likeliest explanation is an error in the free space or
//    the maps (the true transform refuted by an artefact), not that a much weaker alternative is
//    true; and a weaker alternative is what a repeated structure (a mirrored wing) offers.
// 6. Neither map may contradict its own free space: its walls, laid on themselves by the
//    identity (the one transform known to be true), must stand under the undo limit
//    (kSelfContradicted). A robot whose map slipped (an encoder slip its scan matching did not
//    catch) has walls where it saw through; its negative evidence then refutes the truth and
//    lets aliases stand, so no new merge is made on it (benchmark m023: robot 1's map, 20 cm
//    off, 5-8 m of its walls in its own free space from 70 s on, merged robot 2 half turned at
//    90 s; every other map of that mission: at most 1.1 m). A merge already made is judged as
//    before.
// 7. Then: merge with the leader, once it has led `confirmations` consecutive decisions, each
//    confirming one on a newer graph with more wall on wall in its weakest direction.
// A merged pair is kept while its hypothesis has at most `undo_conflict_m` of conflict and no
// rival beats it by the margin (hysteresis: accept at accept_conflict_m, refute others beyond
// refute_conflict_m, undo a merge beyond undo_conflict_m).
//
// Why this does not merge wrongly (docs/multi-robot.md, "The merge rule"): a wrong transform
// that wins must (a) contradict nothing either robot saw, (b) lay walls on walls in two
// directions, and (c) beat the true transform, which the search proposes whenever the robots
// share a corner or a room, by the margin. In a building that does not repeat, (a) fails for
// the wrong transform as soon as the maps overlap beyond the shared structure; where it
// repeats, (c) fails, because the true transform then stands as a rival.
#pragma once

#include <algorithm>
#include <cstdint>
#include <span>

#include "msgraphs/base/expected.hpp"
#include "msgraphs/core/collab/alignment_search.hpp"
#include "msgraphs/core/collab/free_space_conflict.hpp"
#include "msgraphs/core/collab/free_space_summary.hpp"
#include "msgraphs/core/collab/wall_index.hpp"

namespace msgraphs::core {

struct MergeRuleConfig {
  double min_agreement_m = 8.0;
  /// Both directions fixed by at least this much coinciding wall: more than the jambs of a door
  /// and a rack end or two (1-2 m each), which coincide by chance in a repeated layout.
  double min_constraint_m = 6.0;
  double accept_conflict_m = 0.25;
  double refute_conflict_m = 0.5;
  /// A merged transform is undone only beyond this much conflict (or a rival beating it): the
  /// hysteresis that keeps one noisy exchange from flapping a merge.
  double undo_conflict_m = 1.0;
  double min_rival_constraint_m = 1.0;
  double margin_ratio = 1.5;
  double margin_m = 3.0;
  double symmetric_margin_ratio = 3.0;
  std::size_t max_symmetries = 16;  ///< each map's strongest symmetries composed with the leader
  /// Slides of the leader along each principal direction probed each way (rule 4); 0: none. The
  /// probes are 2 agreement offsets apart, wider when b's extent needs more than this many.
  std::size_t max_slide_probes = 128;
  /// Rule 3 in one direction: the search's channels (alignments along one wall line, which fix
  /// nothing along it) probed along that line; one that agrees at least as much as the leader
  /// and stands makes the decision ambiguous. Off only to measure what it costs.
  bool one_direction_rivals = true;
  /// A new merge needs the same leader to win this many decisions, no other leader winning in
  /// between (each decision is on new data: the search and the rule run when a map or a free
  /// space changed), so that what the robots see next can refute it before it is acted on: two
  /// robots that just left identical rooms agree perfectly on the wrong copy until one of them
  /// sees past it. A decision confirms only on a newer graph that added at least
  /// `conflict.min_stretch_m` of wall on wall to the leader in its weakest direction (its
  /// constraint; wall along that direction cannot tell a slide along it: collab_merge.cpp).
  /// 1: at once.
  std::uint32_t confirmations = 2;
  /// The conflict limits grow with the evidence: each is the larger of its value above and
  /// this share of the hypothesis' agreement (times 1, 2, 4 for accept, refute, undo). Maps a
  /// few centimetres off and wall extents that overshoot leave conflict in proportion to what
  /// was mapped (1-2 m against 200-400 m of agreeing wall after 5 minutes in the shipped
  /// worlds; 4.1 m against 350 m, 1.2 %, in the office fleet test with Spot's gait, a known
  /// defect: its test records without the gait); a wrong transform lays whole walls across
  /// free space, metres for every room it misplaces (2 % would keep the one-room-off merge of
  /// MergeRule.AMergeContradictedLaterIsOverturned).
  double conflict_per_agreement = 0.0025;
  FreeSpaceConflictConfig conflict;
  Status Validate() const;
  double AcceptLimit(const Hypothesis& h) const {
    return std::max(accept_conflict_m, conflict_per_agreement * h.agreement.agreement_m);
  }
  double RefuteLimit(const Hypothesis& h) const {
    return std::max(refute_conflict_m, 2 * conflict_per_agreement * h.agreement.agreement_m);
  }
  double UndoLimit(const Hypothesis& h) const {
    return std::max(undo_conflict_m, 4 * conflict_per_agreement * h.agreement.agreement_m);
  }
};

enum class MergeVerdict : std::uint8_t {
  kNoFreeSpace,   ///< a robot's free-space summary is missing: no negative evidence, no merge
  kNoHypothesis,  ///< nothing aligns two walls of each map yet
  kRefuted,       ///< every hypothesis contradicts what a robot saw
  kInsufficient,  ///< the leader agrees too little (or in one direction only)
  kConflicted,    ///< the leader contradicts a little: not refuted, not acceptable
  kAmbiguous,     ///< a rival stands within the margin
  kTruncated,     ///< the search lost candidates (a bounded store was full)
  /// The strongest evidence (a hypothesis beating the leader by the margin) is refuted: either
  /// the free space is in error or the maps disagree; a weaker alternative is not trusted.
  kContradicted,
  /// The rule would merge, but one of the two maps contradicts its own free space (rule 6).
  kSelfContradicted,
  /// The rule would merge, but this leader has not yet led `confirmations` consecutive
  /// decisions (the session's bookkeeping, collab_merge.cpp).
  kUnconfirmed,
  kMerge,
};
const char* ToString(MergeVerdict verdict);

struct MergeDecision {
  MergeVerdict verdict = MergeVerdict::kNoHypothesis;
  Hypothesis leader, rival;         ///< rival: the strongest standing one (when there is one)
  bool has_leader = false, has_rival = false;
  /// kRefuted: the best hypothesis by agreement, refuted (for the log: what contradicted it).
  Hypothesis best_refuted;
  bool has_best_refuted = false;
  bool rival_from_symmetry = false;  ///< the rival is a symmetry of one map composed with the leader
  bool rival_one_direction = false;  ///< the rival fixes one direction only (a channel)
  bool symmetric = false;            ///< a symmetry alternative stands: the wider margin applied
  bool keeping = false;     ///< the leader is the current merge (hysteresis applied)
  bool overturned = false;  ///< kAmbiguous while merged, and the rival beats the current merge
  std::size_t hypotheses = 0, refuted = 0;
  /// Rule 6, measured when the rule would merge anew: each map's walls in its own free space (m).
  double self_conflict_a_m = 0, self_conflict_b_m = 0;
  /// The fallback (the session's bookkeeping, collab_places.cpp): transforms set aside by place
  /// evidence for this decision, and the place clouds weighed.
  std::size_t set_aside = 0, places = 0;
};

/// Everything the rule looks at for one robot pair. `sym_a`, `sym_b`: the maps' own symmetries
/// (AlignmentSearch::Search of a map with itself), strongest first.
struct MergeInputs {
  const WallIndex* walls_a = nullptr;
  const WallIndex* walls_b = nullptr;
  const FreeSpaceSummary* free_a = nullptr;
  const FreeSpaceSummary* free_b = nullptr;
  std::span<Hypothesis> hypotheses;  ///< conflicts are filled in as the rule needs them
  bool truncated = false;
  std::span<const Hypothesis> sym_a, sym_b;
  std::span<const Hypothesis> channels;  ///< AlignmentSearch::channels(): one-direction alignments
  /// Transforms point-level evidence has set aside (place_evidence.hpp: a duel lost on the
  /// points of a place): neither leader, nor rival, nor stronger refuted evidence.
  std::span<const PlanarTransform> set_aside;
};

/// Decides. `search` evaluates the symmetry alternatives. `current` (optional): the transform
/// the pair is merged with now, which keeps the merge under the hysteresis rule.
MergeDecision DecideMerge(MergeInputs& in, const AlignmentSearch& search, const MergeRuleConfig& config,
                          const PlanarTransform* current);

/// A map against itself (rule 6): its walls and openings laid on its own free space by the
/// identity; `h` gets the identity's agreement and conflict. True when it stands under the undo
/// limit (the most lenient: a map is consistent unless it would undo a merge with itself).
bool SelfConsistent(const WallIndex& walls, const FreeSpaceSummary& free, const AlignmentSearch& search,
                    const MergeRuleConfig& config, Hypothesis& h);

/// Fills h's conflicts (both directions).
void MeasureConflict(Hypothesis& h, const MergeInputs& in, const FreeSpaceConflictConfig& config);

}  // namespace msgraphs::core
