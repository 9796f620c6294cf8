// SPDX-License-Identifier: MIT
// The merge decision's bounded fallback: point-level evidence for the pairs walls and free space
// leave undecided (merge_rule.hpp: a rival within the margin, or a stronger hypothesis refuted).
// The robot asks the peer for its points around a place where the two transforms in question
// lay the peer's map differently (place_messages.hpp, place_cloud.hpp), lays those points into
// its own free-space summary by each transform, and counts cells:
// - explained: the point lands on or next to a cell this robot saw occupied;
// - contradicted: it lands at least `clearance_m` (the wall-level test's clearance) inside
//   free space this robot saw through.
// Points are what the walls lack: door jambs, short walls, furniture, pillars, the clutter of a
// room (a room's walls are alike in a repeated wing, its contents rarely are).
//
// The duel: transform L beats X when X is contradicted by at least `margin_ratio` times L's
// contradicted cells plus `min_stretch_m` of cells (the least the wall-level test counts), and
// L's net support (explained minus contradicted) is at least X's. Negative evidence decides,
// as in the merge rule; the net support keeps a transform that lays the points where this
// robot never looked (nothing explained, nothing contradicted) from winning on one artefact of
// the other (a door closed since one robot passed: five cells in seen-through space). In a
// structure that truly repeats, both transforms lay the points on alike surroundings and
// neither wins: the pair stays undecided.
//
// Bounded: the bytes requested from one peer (`budget_bytes_per_peer`), the clouds held per
// peer, the places asked for. No allocation after Init (the scratch is sized there).
#pragma once

#include <Eigen/Core>
#include <optional>
#include <span>
#include <vector>

#include "msgraphs/base/expected.hpp"
#include "msgraphs/core/collab/free_space_summary.hpp"
#include "msgraphs/core/collab/planar_transform.hpp"
#include "msgraphs/core/collab/wall_index.hpp"

namespace msgraphs::core {

struct PlaceEvidenceConfig {
  /// Bytes of place clouds one peer may send this robot (and this robot one peer) over the
  /// session; 0 turns the fallback off. 4 clouds at the largest (12 kB each) plus requests.
  std::size_t budget_bytes_per_peer = 50000;
  /// The disc asked for: a doorway and what stands on both sides of it.
  float radius_m = 5.0f;
  std::size_t max_places_per_peer = 4;  ///< clouds held per peer (the oldest gives way)
  std::size_t max_asked_per_peer = 16;  ///< places asked for per peer (never asked again)
  std::size_t max_requests_queued = 8;  ///< requests from peers awaiting the next exchange
  /// A place is worth asking for where the two transforms lay it at least this far apart
  /// (five summary cells: far enough that they meet different surroundings).
  double min_separation_m = 1.0;
  /// A place needs this share of the disc's coarse lattice (1 m) known to the other robot
  /// under both transforms, and to the peer around it: a place nobody saw decides nothing.
  double min_known_share = 0.25;
  Status Validate() const;
};

/// Cells of this robot's summary the peer's points reached under one transform.
struct PlaceTally {
  std::size_t explained = 0, contradicted = 0;
  PlaceTally& operator+=(const PlaceTally& o) {
    explained += o.explained;
    contradicted += o.contradicted;
    return *this;
  }
};

enum class DuelOutcome : std::uint8_t { kUndecided, kFirstWins, kSecondWins };

/// Scratch for counting distinct cells (sized at Init: the largest cloud).
class PlaceScorer {
 public:
  void Init(std::size_t max_points);
  /// The peer's `points` (relative to `centre_b` and its floor, peer frame) laid into this
  /// robot's frame by T_a_b, against its summary `free_a`.
  PlaceTally Score(std::span<const Eigen::Vector3f> points, const Eigen::Vector2d& centre_b,
                   const PlanarTransform& T_a_b, const FreeSpaceSummary& free_a, double clearance_m);

 private:
  std::vector<std::uint32_t> explained_, contradicted_;
};

/// The duel's rule (above) on tallies summed over the places that tell the two apart;
/// `min_cells` is min_stretch_m in summary cells.
DuelOutcome Duel(const PlaceTally& first, const PlaceTally& second, double margin_ratio, std::size_t min_cells);

/// Where to ask the peer (b) for a cloud to tell T_first from T_second apart. Candidates lie
/// along b's walls (every metre); a candidate qualifies where both transforms lay it at least
/// min_separation_m apart, on ground both robots know (min_known_share of the disc, for b
/// around it and for this robot under either transform), away from the places already asked
/// (half the radius). Among those, the one with the most clutter around it: cells b's summary
/// holds occupied away from its walls (furniture, pillars, the contents of a room: walls are
/// alike in a repeated wing, what stands between them rarely is), then the best known.
/// Scratch for the clutter (a wall mask and a summed-area table) is sized at Init.
class PlaceChooser {
 public:
  void Init(std::size_t max_cells);
  std::optional<Eigen::Vector2d> Choose(const WallIndex& walls_b, const FreeSpaceSummary& free_b,
                                        const FreeSpaceSummary& free_a, const PlanarTransform& T_first,
                                        const PlanarTransform& T_second, std::span<const Eigen::Vector2d> asked,
                                        const PlaceEvidenceConfig& config);

 private:
  /// Clutter cells in the square of half-side `half_m` around `p` (b's frame).
  std::uint32_t ClutterAround(const FreeSpaceSummary& free_b, const Eigen::Vector2d& p, double half_m) const;

  std::vector<std::uint8_t> near_wall_;
  std::vector<std::uint32_t> sat_;  // (width + 1) x (height + 1)
};

}  // namespace msgraphs::core
