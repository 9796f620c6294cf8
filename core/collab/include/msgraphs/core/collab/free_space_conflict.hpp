// SPDX-License-Identifier: MIT
// Negative evidence for a transform between two maps: what one robot mapped, laid into the
// other's frame, where the other robot saw something else.
// - A wall in seen-through space: samples of robot x's walls that fall at least `clearance_m`
//   inside robot y's free space (FreeSpaceSummary::clearance_m), except across y's openings and
//   in the doorways between two pieces of one of y's walls that x's wall spans (a wall over a
//   doorway is its lintel, seen by one robot and not the other), and within `extent_tolerance_m` of the wall's ends (an
//   extent grows with every point associated to the plane and overshoots now and then; a wrong
//   transform lays whole walls across free space, not their last half metre); only where x
//   saw its wall (x's own summary occupied within `door_wall_distance_m` of the sample: an
//   extent spans the doorways between two sightings of the wall, doorways x never saw into);
//   only stretches of at least `min_stretch_m`; and each place once (a wall held twice, or
//   both faces of a thin wall, lies on the same stretch of y's free space).
// - An opening on a solid wall: samples of x's openings that fall on cells y saw occupied next
//   to one of y's walls, away from y's own openings; counted when they cover at least
//   `door_solid_share` of the opening (a correct transform leaves the jambs, a fraction of it,
//   and a door y saw only edge-on may look closed in part), and when y saw no opening of its
//   own on that line within `max_opening_m` (then both saw one door, its extent differently);
//   openings narrower than `min_door_m` do not count.
// Both are lengths in metres; the merge rule compares them with its thresholds (merge_rule.hpp).
// No allocation.
#pragma once

#include "msgraphs/base/expected.hpp"
#include "msgraphs/core/collab/free_space_summary.hpp"
#include "msgraphs/core/collab/planar_transform.hpp"
#include "msgraphs/core/collab/wall_index.hpp"

namespace msgraphs::core {

struct FreeSpaceConflictConfig {
  /// Beyond the first ring of free cells (0.2 m cells: their centres lie 0.1 m from the edge of
  /// free space, the next ring's 0.3 m): a wall exactly on the other robot's wall may fall in the
  /// free cell next to it (the summary's quantisation), and a correct transform is good to a few
  /// centimetres.
  double clearance_m = 0.3;
  double sample_step_m = 0.1;
  double extent_tolerance_m = 0.5;
  /// An opening this close is the same opening; a wall sample this close to one is its lintel.
  double opening_margin_m = 0.3;
  /// Stretches of a wall shorter than this in seen-through space do not count: a wrong transform
  /// lays walls across free space, the maps' own noise a short stretch of one here and there.
  double min_stretch_m = 1.0;
  double door_solid_share = 0.8;
  double door_wall_distance_m = 0.3;  ///< an occupied cell this close to a wall line is that wall
  double max_opening_m = 3.0;         ///< the widest doorway (building codes: double doors 2.4 m)
  /// An opening narrower than the narrowest door (building codes: 0.8 m clear) as the summary
  /// measures it is no evidence on a solid wall: a gap between returns, a door seen edge-on.
  /// The summary's openings are a lower bound on the doorway: a sample along the wall opens
  /// only where no return fell across the wall's body and the cells in front and behind were
  /// seen clear, so each jamb (its face's cell, the sample's quantisation, its shadow on the
  /// cells behind when seen at an angle) takes up to 0.15 m at 0.1 m grid cells; the shipped
  /// worlds' 1.0 m doors read 0.7 m. So the narrowest door reads 0.5 m: the summary's own
  /// `min_opening_m`. At 0.8 no door of the shipped worlds counted, and a half turn that laid
  /// the rotated office's doors on solid wall merged (docs/merge-decision.md).
  double min_door_m = 0.5;
  Status Validate() const;
};

struct FreeSpaceConflict {
  double walls_in_free_m = 0;
  double openings_on_solid_m = 0;
  double total_m() const { return walls_in_free_m + openings_on_solid_m; }
};

enum class ConflictKind : std::uint8_t { kWallInFree, kOpeningOnSolid };

/// Told of every stretch that counted (y's frame), for audits (msgraphs_collab --explain).
class ConflictVisitor {
 public:
  virtual ~ConflictVisitor() = default;
  virtual void Counted(ConflictKind kind, const Eigen::Vector2d& a_y, const Eigen::Vector2d& b_y, double length_m) = 0;
};

/// Robot x's walls and openings (x's frame), laid into robot y's frame by T_y_x, against y's
/// summary and walls. `between_robots` (false for a map laid on itself, merge rule 6): x's walls
/// count only where x's summary saw them, and one face of a wall once. A map against itself
/// counts every stretch: there the wall and the free space are one robot's, and a face held
/// twice where that robot saw through is the slip the check is for (benchmark m023: deduplicated,
/// a slipped map passed the check and merged a peer half turned).
FreeSpaceConflict ConflictOf(const WallIndex& walls_x, const FreeSpaceSummary& summary_x,
                             const PlanarTransform& T_y_x, const WallIndex& walls_y,
                             const FreeSpaceSummary& summary_y, const FreeSpaceConflictConfig& config,
                             ConflictVisitor* visitor = nullptr, bool between_robots = true);

}  // namespace msgraphs::core
