// SPDX-License-Identifier: MIT
// A robot's observed free space, coarse and compact, for the negative evidence of the merge
// decision: a wall of one robot standing where the other robot has seen through counts against
// the transform that put it there (merge_rule.hpp).
//
// A 2-D grid in the robot's map frame over the bounding box of what its free-space grid knows,
// at `cell_m` (0.2 m: 2 x 2 cells of the 0.1 m grid; coarser cells swallow the end wall of a
// narrow corridor in the conflict test's clearance), each cell unknown, free or occupied:
// - occupied when one of its fine cells is (FreeSpaceGrid::state: returns there outweigh the
//   rays through it; a few grazing returns off a door's jamb do not close the door);
// - free when at least `min_free_share` of its fine cells are clear below the sensor (crossed by
//   descending rays: no obstacle as tall as a wall can stand there, whatever passed over a rack
//   towards the ceiling) and none is a wall seen edge-on: returns in the obstacle band there
//   (FreeSpaceGrid::ever_occupied), rays through it in one direction only
//   (FreeSpaceGrid::clear_across), and more returns a step or two along those rays. Its
//   grazing rays outnumber its returns, so the fine grid reads it "not occupied", but it is
//   no free space;
// - unknown otherwise.
// And the openings: where the robot saw through one of its own walls (a door, a wide opening),
// from the fine grid: clear on both sides of the wall's line and no return ever across its body
// (FreeSpaceGrid::ever_occupied: a wall seen edge-on is crossed by more rays than hit it). A peer's wall
// across one of them is a lintel, not a conflict; a peer's opening on a wall seen solid here is.
// After Build or Decode, every free cell carries its clearance (chamfer distance to the nearest
// non-free cell), so that a conflict is only counted well inside what was seen (a wall one
// cell off the edge of free space is the transform's or the map's error, not evidence).
//
// Bounded: max_cells is allocated at Init; a bounding box larger than that is cropped around
// the map origin and the crop counted (`cropped()`). Build and Decode allocate nothing.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <span>
#include <vector>

#include "msgraphs/base/expected.hpp"
#include "msgraphs/core/graph/distilled_graph.hpp"
#include "msgraphs/core/perception/free_space_grid.hpp"

namespace msgraphs::core {

struct FreeSpaceSummaryConfig {
  float cell_m = 0.2f;
  /// 524,288 cells: 145 m x 145 m at 0.2 m, 1.5 MB with the clearance.
  std::size_t max_cells = std::size_t{1} << 19;
  /// Half the fine cells seen free: a cell on the edge of what was seen stays unknown.
  float min_free_share = 0.5f;
  std::size_t max_openings = 256;
  /// An opening: at least this wide (a narrow door is 0.7 m), the wall's line free at this
  /// distance in front of the face and this far behind it (beyond the thickest walls, 0.3 m).
  float min_opening_m = 0.5f;
  float opening_front_m = 0.2f;
  float opening_behind_m = 0.45f;
  Status Validate() const;
};

enum class SummaryCell : std::uint8_t { kUnknown = 0, kFree = 1, kOccupied = 2 };

/// Where a robot saw through one of its walls: a segment on the wall's line, map frame.
struct Opening {
  Eigen::Vector2d a = Eigen::Vector2d::Zero(), b = Eigen::Vector2d::Zero();
};

class FreeSpaceSummary {
 public:
  Status Init(const FreeSpaceSummaryConfig& config);

  /// From this robot's free-space grid and its distilled walls (for the openings).
  /// kDegenerate when the grid knows no cell yet. No allocation.
  Status Build(const FreeSpaceGrid& grid, std::span<const DistilledWall> walls);

  /// Sets the grid directly (the decoder): `width * height <= max_cells`. Clears the cells.
  Status Reset(const Eigen::Vector2d& origin_m, float cell_m, int width, int height);
  void set(std::size_t index, SummaryCell state) { cells_[index] = static_cast<std::uint8_t>(state); }
  /// The decoder's: false when the store is full.
  bool add_opening(const Opening& o);
  /// Recomputes every free cell's clearance (Build does it; the decoder calls it).
  void ComputeClearance();

  SummaryCell state(int x, int y) const;
  SummaryCell state_at(const Eigen::Vector2d& p_map) const;
  /// Distance from `p_map` to the nearest cell that is not free, in metres (0 when the cell is
  /// not free or outside the grid). Resolution: the cell size.
  float clearance_m(const Eigen::Vector2d& p_map) const;

  bool empty() const { return width_ == 0 || height_ == 0; }
  int width() const { return width_; }
  int height() const { return height_; }
  float cell_m() const { return cell_m_; }
  const Eigen::Vector2d& origin_m() const { return origin_m_; }
  std::size_t cells() const { return static_cast<std::size_t>(width_) * static_cast<std::size_t>(height_); }
  std::span<const std::uint8_t> raw() const { return {cells_.data(), cells()}; }
  std::size_t free_cells() const { return free_cells_; }
  std::span<const Opening> openings() const { return {openings_.data(), opening_count_}; }
  /// True when `p_map` lies within `margin_m` of one of the openings.
  bool NearOpening(const Eigen::Vector2d& p_map, double margin_m) const;
  std::uint64_t cropped() const { return cropped_; }
  const FreeSpaceSummaryConfig& config() const { return config_; }

 private:
  bool Cell(const Eigen::Vector2d& p, int& x, int& y) const;
  void FindOpenings(const FreeSpaceGrid& grid, const DistilledWall& wall);

  FreeSpaceSummaryConfig config_;
  Eigen::Vector2d origin_m_ = Eigen::Vector2d::Zero();
  float cell_m_ = 0.4f;
  int width_ = 0, height_ = 0;
  std::size_t free_cells_ = 0;
  std::uint64_t cropped_ = 0;
  std::vector<std::uint8_t> cells_;
  std::vector<std::uint16_t> clearance_;  // chamfer units (3 per cell), saturating
  std::vector<Opening> openings_;
  std::size_t opening_count_ = 0;
};

}  // namespace msgraphs::core
