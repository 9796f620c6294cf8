// SPDX-License-Identifier: MIT
// Rooms without voxblox. Regions: a Euclidean distance transform of the free-space grid; cells
// within 0.8 m of an obstacle are cut (voxblox's free-space radius), which separates rooms at
// their doors; connected components of what remains are room cores, grown back over the cut
// cells (each takes the nearest core).
// Rooms: the walls bordering a region vote for its orientation (angles mod 90 degrees, so a
// building rotated to the map works); opposite walls facing into the region pair up. Two pairs
// make a four-wall room, one pair a two-wall corridor (the original S-Graphs+ rules, with a
// true orientation instead of the map axes). Sized at Init; nothing allocates afterwards.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "msgraphs/base/bounded_vector.hpp"
#include "msgraphs/base/expected.hpp"
#include "msgraphs/core/perception/free_space_grid.hpp"

namespace msgraphs::core {

struct RoomSegmentationConfig {
  /// Free cells within this distance of an obstacle are cut (voxblox's 0.8 m free-space radius):
  /// passages up to twice as wide, doors, separate regions; cores are grown back over them.
  float door_cut_clearance_m = 0.8f;
  float min_region_area_m2 = 1.5f;
  /// A gap of up to this width between two collinear pieces of a wall is an opening (a door, an
  /// open doorway) and is closed before segmenting, so that rooms joined by openings wider than
  /// the door cut still separate. Kept below common corridor widths (2.4 m): partition walls
  /// aligned across a corridor are collinear too, and closing them would cut the corridor.
  /// 0 disables.
  float close_openings_up_to_m = 2.2f;
  Status Validate() const;
};

struct RoomRegion {
  std::uint16_t label = 0;
  std::size_t cells = 0;
  double area_m2 = 0;
  Eigen::Vector2d centroid = Eigen::Vector2d::Zero();
};

/// A wall as room detection sees it: a vertical plane in the map frame reduced to a 2-D line
/// n.x + d = 0 (n unit, pointing to the side the sensor saw it from) and its segment.
struct MapWall {
  std::uint32_t id = 0;
  Eigen::Vector2d normal = Eigen::Vector2d::UnitX();
  double d = 0;
  Eigen::Vector2d a = Eigen::Vector2d::Zero(), b = Eigen::Vector2d::Zero();
};

enum class RoomKind : std::uint8_t { kRoom, kCorridor };

struct DetectedRoom {
  RoomKind kind = RoomKind::kRoom;
  std::uint16_t region = 0;
  Eigen::Vector2d centre = Eigen::Vector2d::Zero();
  /// Direction of the room frame's x axis. Rooms: in [-pi/4, pi/4), the orientation modulo 90
  /// degrees (a rectangle is symmetric under quarter turns). Corridors: in [-pi/4, 3 pi/4), the
  /// x axis pointing across the corridor (from its low-x wall to its high-x wall).
  double yaw_rad = 0;
  double size_x_m = 0, size_y_m = 0;  ///< wall-to-wall distances; a corridor's size_y is its length
  /// Indices into the walls given: low x, high x, low y, high y (room frame); -1 where absent
  /// (a corridor has only its x pair).
  std::array<std::int32_t, 4> walls{-1, -1, -1, -1};
  std::size_t support_cells = 0;
};

struct RoomDetectionConfig {
  float wall_search_m = 1.5f;        ///< region cells this close in front of a wall support it
  float min_width_m = 1.0f;
  float angle_tolerance_deg = 12.0f;
  float max_centre_outside_m = 0.5f;
  std::size_t min_support_cells = 15;
  Status Validate() const;
};

class RoomSegmenter {
 public:
  Status Init(int width, int height, std::size_t max_regions, std::size_t max_walls);

  /// Labels the grid's regions; fills `regions` (cleared first). `walls` (optional) close
  /// openings: a wall's extent is blocked where it crosses free space (a doorway under a lintel
  /// of the same plane), and so are gaps between collinear wall pieces (see the config).
  /// kCapacityExceeded (regions kept so far) when more regions than `max_regions` exist.
  Status Segment(const FreeSpaceGrid& grid, const RoomSegmentationConfig& config, BoundedVector<RoomRegion>& regions,
                 std::span<const MapWall> walls = {});

  /// Rooms and corridors from the regions of the last Segment and the map's walls.
  Status DetectRooms(const FreeSpaceGrid& grid, std::span<const RoomRegion> regions, std::span<const MapWall> walls,
                     const RoomDetectionConfig& config, BoundedVector<DetectedRoom>& rooms);

  std::uint16_t label(int x, int y) const { return labels_[Index(x, y)]; }
  /// Distance to the nearest non-free cell, metres.
  float clearance(int x, int y) const;

 private:
  std::size_t Index(int x, int y) const {
    return static_cast<std::size_t>(y) * static_cast<std::size_t>(width_) + static_cast<std::size_t>(x);
  }
  void DistanceTransform1D(int n);
  void CloseOpenings(const FreeSpaceGrid& grid, std::span<const MapWall> walls, float max_gap_m);

  int width_ = 0, height_ = 0;
  float resolution_ = 0.1f;
  std::vector<float> dist2_;       // squared distance in cells
  std::vector<std::uint16_t> labels_;
  std::vector<std::uint32_t> queue_;
  std::vector<float> f_, z_, d_;
  std::vector<int> v_;
  std::vector<std::uint32_t> support_;  // walls x regions cell counts
  std::vector<std::uint8_t> keep_;      // per label: region kept
  std::vector<std::uint8_t> blocked_;   // openings closed for segmentation
  std::size_t max_regions_ = 0, max_walls_ = 0;
};

}  // namespace msgraphs::core
