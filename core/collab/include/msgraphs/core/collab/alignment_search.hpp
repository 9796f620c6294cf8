// SPDX-License-Identifier: MIT
// Every transform that could lay one robot's map onto another's, refined and scored: the
// hypotheses among which the merge rule chooses (merge_rule.hpp).
//
// Candidates come from every pair of compatible structures of the two maps:
// - corners: two walls of a map whose lines meet at `min_corner_angle_rad` or more, each ending
//   within `corner_reach_m` of the meeting point (a partly seen room has them, a room seen from
//   its door has its far corners). Two corners pair when they open by the same angle and their
//   walls leave on the same sides; the pair gives the yaw (from the normals) and the
//   translation (from the meeting points). Every rotation and translation that lays a shared
//   corner onto itself is therefore proposed, whatever the building's rotation;
// - rooms: two four-wall rooms of the same size (within `room_size_tolerance`), in each of the
//   orientations their rectangle allows (two, four for a square): the symmetry ambiguity of a
//   rectangle is carried as separate hypotheses;
// - seeds given by the caller (room descriptor matches).
// Besides, one-direction alignments ("channels"): every pair of walls, one of each map, gives a
// yaw and an offset across the two walls' common line but nothing along it. Pairs are grouped
// by (yaw, line direction, offset across); a family whose walls could coincide along at least
// `min_channel_agreement_m` (the sum over its pairs of the shorter wall) is scored at the mean
// of its pairs' offsets along the line, refined, and kept in `channels()` (the strongest
// `max_channels` by agreement), whatever it fixes across. Two robots that share nothing but a
// long corridor agree on it along one direction only; no corner pair proposes that, and a
// weaker transform elsewhere must not win as if it had no rival (merge_rule.hpp, rule 3).
// Candidates are clustered on a (yaw, x, y) grid; each cluster's mean is scored by wall
// agreement, kept when it constrains both directions at least `keep_constraint_m`, refined on its
// coinciding walls, scored again and merged with any hypothesis it became. The result is sorted by
// agreement, best first.
//
// Sized at Init; Search allocates nothing. A full cluster table or hypothesis store is counted
// (stats); lost candidates make the search `truncated()`, and the merge rule then refuses to
// decide.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "msgraphs/base/bounded_vector.hpp"
#include "msgraphs/base/expected.hpp"
#include "msgraphs/core/collab/free_space_conflict.hpp"
#include "msgraphs/core/collab/planar_transform.hpp"
#include "msgraphs/core/collab/wall_agreement.hpp"
#include "msgraphs/core/collab/wall_index.hpp"
#include "msgraphs/core/graph/distilled_graph.hpp"

namespace msgraphs::core {

struct AlignmentSearchConfig {
  double min_wall_length_m = 0.8;  ///< shorter walls are furniture faces and door jambs
  double corner_reach_m = 1.0;     ///< a corner's walls end this close to where they meet
  double min_corner_angle_rad = 0.35;         ///< 20 degrees: wings meeting at 30 degrees count
  double corner_angle_tolerance_rad = 0.087;  ///< 5 degrees
  double room_size_tolerance_m = 0.5;         ///< or 10 % of the size, whichever is larger
  double bin_m = 0.5, bin_rad = 0.035;        ///< the cluster grid (2 degrees)
  double keep_constraint_m = 0.5;
  int refine_iterations = 4;
  /// Two hypotheses this close are one (after refinement).
  double same_distance_m = 0.3, same_angle_rad = 0.026;
  std::size_t max_corners = 2048;     ///< per map
  std::size_t max_clusters = 65536;   ///< a power of two
  std::size_t max_hypotheses = 256;
  /// One-direction families worth scoring: the merge rule's min_agreement_m (a family whose
  /// walls cannot coincide along that much cannot out-agree any leader). 0: no channels.
  double min_channel_agreement_m = 8.0;
  std::size_t max_channels = 16;            ///< the strongest families kept
  /// A power of two; filled to three quarters at most (then truncated: the rule refuses to
  /// decide). Families are (yaw, line, offset across) bins of wall pairs: a few thousand for two
  /// maps of a few hundred walls each (none truncated over the 40-mission benchmark); 64 Ki
  /// entries (4.7 MB) leave room for two maps at the distiller's 1,024 walls in a few directions.
  std::size_t max_channel_families = 65536;
  WallAgreementConfig agreement;
  Status Validate() const;
};

/// Where a hypothesis came from (bits).
enum HypothesisSource : std::uint8_t {
  kFromCorners = 1,
  kFromRooms = 2,
  kFromSeed = 4,
  kFromSymmetry = 8,
  kFromChannel = 16,
};

struct Hypothesis {
  PlanarTransform T_a_b;
  std::uint32_t votes = 0;   ///< corner and room pairs that proposed it
  std::uint8_t sources = 0;  ///< HypothesisSource bits
  WallAgreement agreement;
  bool conflict_known = false;
  FreeSpaceConflict conflict_b_in_a, conflict_a_in_b;  ///< b's walls in a's free space, and back
  double conflict_m() const { return conflict_b_in_a.total_m() + conflict_a_in_b.total_m(); }
};

struct AlignmentSearchStats {
  std::size_t corners_a = 0, corners_b = 0;
  std::size_t candidates = 0, clusters = 0, kept = 0;
  std::size_t clusters_dropped = 0, hypotheses_dropped = 0, corners_dropped = 0;
  std::size_t channel_families = 0, channels_scored = 0, channel_families_dropped = 0;
};

/// A corner of one map (its two walls' lines meet there) and a cluster of candidate transforms.
struct AlignmentCorner {
  Eigen::Vector2d p = Eigen::Vector2d::Zero();
  double angle_rad = 0;    ///< of the first wall's normal
  double opening_rad = 0;  ///< from the first wall's normal to the second's, in (0, pi)
  std::int8_t side_i = 0, side_j = 0;
  std::uint32_t wall_i = 0, wall_j = 0;
};
/// A family of wall pairs that agree on a yaw and an offset across one line direction.
struct AlignmentChannelFamily {
  std::uint64_t key = 0;
  bool used = false;
  double weight_m = 0;  ///< sum of the shorter wall of each pair: the most they could agree
  double cos_sum = 0, sin_sum = 0, across_sum = 0, along_sum = 0;
  Eigen::Vector2d n = Eigen::Vector2d::UnitX();  ///< the line's normal (canonical), map a
};
struct AlignmentCluster {
  std::uint64_t key = 0;
  bool used = false;
  std::uint32_t votes = 0;
  std::uint8_t sources = 0;
  double cos_sum = 0, sin_sum = 0;
  Eigen::Vector2d t_sum = Eigen::Vector2d::Zero();
};


class AlignmentSearch {
 public:
  Status Init(const AlignmentSearchConfig& config);

  /// The hypotheses of map b in map a's frame. `self`: a and b are one map (its symmetries):
  /// the identity and corners paired with themselves are left out. Returns how many.
  std::size_t Search(const WallIndex& a, std::span<const DistilledRoom> rooms_a, const WallIndex& b,
                     std::span<const DistilledRoom> rooms_b, std::span<const PlanarTransform> seeds,
                     bool self);

  std::span<Hypothesis> hypotheses() { return hypotheses_.span(); }
  std::span<const Hypothesis> hypotheses() const { return hypotheses_.span(); }
  /// One-direction alignments (not of a self search), strongest first.
  std::span<const Hypothesis> channels() const { return channels_.span(); }
  const AlignmentSearchStats& stats() const { return stats_; }
  /// Candidates were lost (a full corner store or cluster table): a rival may be missing. A full
  /// hypothesis store only drops the weakest, which cannot decide anything.
  bool truncated() const {
    return stats_.clusters_dropped > 0 || stats_.corners_dropped > 0 || stats_.channel_families_dropped > 0;
  }
  const AlignmentSearchConfig& config() const { return config_; }

  /// Refines and scores one transform (a composite of a symmetry and a hypothesis, say).
  Hypothesis Evaluate(const WallIndex& a, const WallIndex& b, const PlanarTransform& T_a_b) const;

 private:
  using Corner = AlignmentCorner;
  using Cluster = AlignmentCluster;
  void Corners(const WallIndex& walls, BoundedVector<Corner>& out);
  void Vote(const PlanarTransform& T, std::uint32_t votes, std::uint8_t source);
  void Keep(const Hypothesis& h);
  void Channels(const WallIndex& a, const WallIndex& b);

  AlignmentSearchConfig config_;
  BoundedVector<Corner> corners_a_, corners_b_;
  std::vector<Cluster> clusters_;
  BoundedVector<Hypothesis> hypotheses_;
  std::vector<AlignmentChannelFamily> families_;
  BoundedVector<Hypothesis> channels_;
  AlignmentSearchStats stats_;
};

}  // namespace msgraphs::core
