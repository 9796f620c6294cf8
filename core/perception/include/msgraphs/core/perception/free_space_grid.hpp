// SPDX-License-Identifier: MIT
// A bounded 2-D free-space grid accumulated from keyframes (the part of voxblox's ESDF that
// room segmentation needs): every lidar ray marks the cells it crosses free; points in the
// obstacle height band mark their cell occupied. Rays that descend from the sensor (towards a
// point below it) also mark the cells they cross clear below the sensor: no obstacle as tall
// as the sensor stands there, since it would have stopped the ray; rays that pass over a box
// towards the ceiling say nothing of that kind (`clear_below_sensor`). Fixed size from configuration;
// points outside the grid are counted and ignored. The grid is a window that can follow the robot
// (Follow): a building larger than the window keeps the free space around the robot, the rooms
// already found stay in the graph. Integrate and Follow allocate nothing.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <span>
#include <vector>

#include "msgraphs/base/expected.hpp"

namespace msgraphs {
class SnapshotReader;
class SnapshotWriter;
}  // namespace msgraphs

namespace msgraphs::core {

struct FreeSpaceGridConfig {
  float resolution_m = 0.1f;
  int width = 1024;   ///< cells along x
  int height = 1024;  ///< cells along y
  Eigen::Vector2f origin_m{-51.2f, -51.2f};  ///< map coordinates of cell (0, 0)'s corner
  float obstacle_min_height_m = 0.25f;  ///< above the floor: below is floor and clutter-free space
  float obstacle_max_height_m = 2.0f;   ///< above: ceiling, lamps; they do not block walking
  float max_range_m = 25.0f;
  /// Cells the window moves by, at least (a whole number of free-space summary cells keeps the
  /// summary's cells on the same places in the map).
  int follow_step_cells = 40;

  Status Validate() const;
};

class FreeSpaceGrid {
 public:
  /// Its state in a snapshot (LocalMapper::Save / Load): the reader fails on a store of another
  /// size or a value out of range.
  void Save(SnapshotWriter& w) const;
  void Load(SnapshotReader& r);
  enum class Cell : std::uint8_t { kUnknown, kFree, kOccupied };

  Status Init(const FreeSpaceGridConfig& config);

  /// `points` and `sensor` in the map frame; `floor_z` is the floor's height there.
  void Integrate(const Eigen::Vector3f& sensor, std::span<const Eigen::Vector3f> points, float floor_z);

  Cell state(int x, int y) const;
  /// True when any return in the obstacle band ever fell in the cell (whatever rays crossed it
  /// since: rays passing over a low obstacle towards the ceiling do not make it free here). For
  /// evidence that must not call an obstacle free.
  bool ever_occupied(int x, int y) const;
  /// True when at least `min_rays` descending rays crossed the cell (see the header comment).
  bool clear_below_sensor(int x, int y, unsigned min_rays = 1) const;
  /// True when descending rays crossed the cell in two directions at least one sector
  /// (`kDirectionSectors` over a half turn) apart. A wall seen edge-on is crossed only by the
  /// rays that graze along it, all in one direction; a place seen through is crossed from
  /// wherever the robot stood.
  bool clear_across(int x, int y) const;
  /// The sectors of the descending rays that crossed the cell, a bit each.
  std::uint8_t clear_directions(int x, int y) const;
  /// Ray directions are kept in this many sectors of a half turn (22.5 degrees each).
  static constexpr int kDirectionSectors = 8;
  bool ToCell(const Eigen::Vector2d& p, int& x, int& y) const;
  Eigen::Vector2d CellCentre(int x, int y) const;
  int width() const { return config_.width; }
  int height() const { return config_.height; }
  float resolution() const { return config_.resolution_m; }
  std::uint64_t outside() const { return outside_; }
  /// Moves the window (whole cells, by multiples of follow_step_cells) so that `sensor_m` is at
  /// its centre, once the sensor is nearer an edge than its range (or a quarter of the window,
  /// if that is less): what it sees then stays inside. Cells that leave the window are
  /// forgotten. True when it moved.
  bool Follow(const Eigen::Vector2f& sensor_m);
  std::uint64_t moves() const { return moves_; }
  Eigen::Vector2f origin_m() const { return config_.origin_m; }
  void Clear();

 private:
  template <class Archive>
  void Io(Archive& ar);
  void Ray(int x0, int y0, int x1, int y1, bool mark_end_free, bool descending);
  template <typename T>
  void Shift(std::vector<T>& cells, int dx, int dy) const;

  FreeSpaceGridConfig config_;
  std::vector<std::uint16_t> free_;
  std::vector<std::uint16_t> occupied_;
  std::vector<std::uint16_t> clear_low_;
  std::vector<std::uint8_t> low_directions_;  // per cell: a bit per sector of descending rays crossing it
  std::uint64_t outside_ = 0;
  std::uint64_t moves_ = 0;
  Eigen::Vector2f origin0_m_ = Eigen::Vector2f::Zero();  // the configured origin
  Eigen::Vector2i moved_cells_ = Eigen::Vector2i::Zero();  // since: origin = origin0 + moved * res
};

}  // namespace msgraphs::core
